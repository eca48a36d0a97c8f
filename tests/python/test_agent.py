"""autumnc.solve / make_task / Program: the same content as the CLI's JSON."""
import json
import os
import subprocess

import pytest

import autumnc
from conftest import CONFORMANCE, PROGRAMS, REPO, needs_corpus

SOKOBAN = os.path.join(PROGRAMS, "sokoban.au")
CLI = os.path.join(REPO, "build", "autumn")


def test_program_compile_and_run():
    p = autumnc.Program(SOKOBAN)
    info = p.compile()
    assert info["ok"] and info["kind"] in ("specialised", "embedded") and info["grid_size"] > 0
    trace = p.run(seed=3, actions=["left", "click 1 2", "noop"])
    assert trace["program"] == "sokoban" and len(trace["traces"][0]["frames"]) == 4
    if os.path.exists(CLI):
        out = subprocess.run([CLI, "run", SOKOBAN, "--seed", "3", "--actions", "left,click 1 2,noop", "--json"],
                             capture_output=True, text=True, check=True).stdout
        assert json.loads(out) == trace
    with pytest.raises(ValueError):
        p.run(actions=["jump"])
    with pytest.raises(FileNotFoundError):
        autumnc.Program("/nonexistent.au")


def test_make_task_then_solve(tmp_path):
    out = tmp_path / "prompts" / "sokoban_mfp.json"
    task = autumnc.make_task("mfp", SOKOBAN, seed=1, steps=8, out=out, extend_colours=True)
    assert task["type"] == "masked_frame_prediction" and out.exists()
    assert "seed" not in task and "answer" not in task  # blind: the answers live apart
    answers = json.loads((tmp_path / "answers" / "sokoban_mfp.json").read_text())
    assert 0 <= answers["correct_idx"] < 6 and answers["seed"] == 0
    prompt, again = autumnc.make_task("mfp", SOKOBAN, seed=1, steps=8, extend_colours=True, with_answers=True)
    assert prompt == task and again == answers
    result = autumnc.solve(out, rollouts=50, threads=1)
    assert result["type"] == task["type"] and result["program"] == task["program"]
    assert "result" in result and result["threads"] == 1
    with pytest.raises(ValueError):
        autumnc.make_task("guess", SOKOBAN)
    with pytest.raises(RuntimeError):
        autumnc.solve(tmp_path / "missing.json")


@needs_corpus
def test_program_check_against_a_trace():
    p = autumnc.Program(os.path.join(CONFORMANCE, "programs", "ice.sexp"))
    r = p.check(os.path.join(CONFORMANCE, "traces", "ice.json"), engine="interp")
    assert r["ok"] and r["frames_matched"] == r["frames_total"] > 0
