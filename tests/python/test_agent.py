"""autumnc.solve / make_task / Program: the same content as the CLI's JSON."""
import json
import os
import subprocess
import sys

import pytest

import autumnc
from conftest import BUILD, CONFORMANCE, PROGRAMS, REPO, needs_corpus

SOKOBAN = os.path.join(PROGRAMS, "sokoban.au")
CLI = os.path.join(BUILD, "autumn")


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


def test_wrong_argument_types_name_the_public_argument(tmp_path):
    """A wrong type is refused with the caller's argument name, never the private
    binding's "_run(): incompatible function arguments ... arg1"."""
    p = autumnc.Program(SOKOBAN)
    cases = [
        (lambda: p.run(seed="x"), TypeError, r"^Program\.run: seed must be an integer, got str 'x'$"),
        (lambda: p.run(seed=-1), ValueError, r"^Program\.run: seed must not be negative, got -1$"),
        (lambda: p.run(actions=[3.5]), TypeError, r"^Program\.run: actions\[0\] must be an action string"),
        (lambda: p.run(actions="left"), TypeError, r"^Program\.run: actions must be a list of action strings"),
        (lambda: p.run(engine=None), TypeError, r"^Program\.run: engine must be a string"),
        (lambda: p.check("t.json", engine=1), TypeError, r"^Program\.check: engine must be a string"),
        (lambda: autumnc.solve("t.json", rollouts=2.5), TypeError, r"^autumnc\.solve: rollouts must be an integer"),
        (lambda: autumnc.solve("t.json", time_limit="1"), TypeError, r"^autumnc\.solve: time_limit must be a number"),
        (lambda: autumnc.make_task("mfp", SOKOBAN, steps=True), TypeError,
         r"^autumnc\.make_task: steps must be an integer, got bool True$"),
        (lambda: autumnc.baseline_random("t.json", timeout=-5), ValueError,
         r"^autumnc\.baseline_random: timeout must not be negative"),
    ]
    for call, error, message in cases:
        with pytest.raises(error, match=message):
            call()


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


def test_make_a_change_detection_task_then_solve(tmp_path):
    """make_task("cd") as `autumn make-task cd`: the prompt, the changed program
    beside it, the answers apart; the solver detects the change at t*."""
    out = tmp_path / "prompts" / "sokoban_cd.json"
    prompt, answers = autumnc.make_task("cd", SOKOBAN, seed=3, steps=6, out=out, engine="interp",
                                        with_answers=True)
    assert prompt["type"] == "change_detection" and prompt["wrong_program"] == "sokoban_wrong"
    assert (tmp_path / "programs" / "sokoban_wrong.au").exists()
    assert answers["t_star"] >= 6 and answers["condition"] == ">= cdClock 6"
    result = autumnc.solve(out, engine="interp", rollouts=50, threads=1,
                           answers=tmp_path / "answers" / "sokoban_change_detection.json")
    assert result["result"]["detected"] and result["result"]["t_star"] == answers["t_star"]
    with pytest.raises(ValueError, match="needs out="):
        autumnc.make_task("cd", SOKOBAN)


@needs_corpus
def test_program_check_against_a_trace():
    p = autumnc.Program(os.path.join(CONFORMANCE, "programs", "ice.sexp"))
    r = p.check(os.path.join(CONFORMANCE, "traces", "ice.json"), engine="interp")
    assert r["ok"] and r["frames_matched"] == r["frames_total"] > 0


def _check_plans(task_dir, rows, tmp_path):
    """Runs scripts/check-plans.py over an eval JSON made of `rows`."""
    report = tmp_path / "eval.json"
    report.write_text(json.dumps({"tasks": rows, "totals": {}}))
    package_root = os.path.dirname(os.path.dirname(os.path.abspath(autumnc.__file__)))
    env = dict(os.environ, PYTHONPATH=package_root)  # the autumnc this suite imports
    return subprocess.run([sys.executable, os.path.join(REPO, "scripts", "check-plans.py"), str(task_dir),
                           str(report)], capture_output=True, text=True, env=env)


def test_check_plans_replays_on_the_interpreter(tmp_path):
    # The independent check of blind-eval's plans: a planner's plan reaches the
    # goal on the interpreter; a plan cut to nothing does not, and the script
    # then says the eval's score of 1 disagrees.
    out = tmp_path / "prompts" / "sokoban_planning.json"
    autumnc.make_task("planning", SOKOBAN, seed=4, steps=5, out=out, extend_colours=True)
    solved = autumnc.solve(out, threads=1)["result"]
    assert solved["found"] and solved["verified"]
    row = {"task": "prompts/sokoban_planning.json", "type": "planning", "score": 1.0,
           "reference_length": 5, "result": {"found": True, "plan": solved["plan"]}}
    good = _check_plans(tmp_path, [row], tmp_path)
    assert good.returncode == 0, good.stdout + good.stderr
    assert "1 plans reach the goal on the interpreter" in good.stdout and "1/1 agree" in good.stdout
    row["result"]["plan"] = []
    bad = _check_plans(tmp_path, [row], tmp_path)
    assert bad.returncode == 1 and "DISAGREE prompts/sokoban_planning.json" in bad.stdout
    row["score"] = 0.0
    assert _check_plans(tmp_path, [row], tmp_path).returncode == 0
    assert _check_plans(tmp_path / "nowhere", [row], tmp_path).returncode == 2


def test_solve_protocol_paper_is_the_cli_protocol():
    """solve(protocol="paper") answers as `autumn solve --protocol paper`: the
    same rollouts, choice and environment steps; arguments given explicitly
    still apply; an unknown protocol is a ValueError."""
    task = os.path.join(REPO, "tasks", "generated", "prompts", "whack_a_mole_mfp.json")
    cli = subprocess.run([CLI, "solve", task, "--json", "--protocol", "paper",
                          "--rollouts", "300", "--threads", "1"], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    want = json.loads(cli.stdout)["result"]
    got = autumnc.solve(task, protocol="paper", rollouts=300, threads=1)["result"]
    keys = ("choice", "counts", "accepted", "env_steps", "rollouts", "deterministic")
    assert {k: got[k] for k in keys} == {k: want[k] for k in keys}
    # The same settings given one by one are the same run.
    spelled = autumnc.solve(task, rollouts=300, threads=1, seed_inversion=False, policy="random",
                            search="paper", depth=10)["result"]
    assert {k: spelled[k] for k in keys} == {k: want[k] for k in keys}
    # The default protocol is another run (seed inversion explores more).
    assert autumnc.solve(task, rollouts=300, threads=1)["result"]["env_steps"] != want["env_steps"]
    with pytest.raises(ValueError, match="protocol"):
        autumnc.solve(task, protocol="papers")


def test_solve_defaults_are_the_clis():
    """autumnc.solve, autumnc.distributed and `autumn solve` present one set of
    defaults: each default the CLI's help shows is the signature's (or, for
    the options a protocol sets, the default protocol's), and the paper
    protocol's settings are what --protocol paper documents."""
    import inspect
    import re

    from autumnc import agent, distributed

    helptext = subprocess.run([CLI, "solve", "--help"], capture_output=True, text=True, check=True).stdout
    shown = dict(re.findall(r"^\s+--([a-z-]+) [A-Z]+(?::[^=\n]*)?=(\S+)$", helptext, re.M))
    signature = inspect.signature(autumnc.solve).parameters
    for flag, value in shown.items():
        name = flag.replace("-", "_")
        if name == "threads":
            continue  # threads: 0 everywhere, a machine setting rather than the agent's
        default = signature[name].default if name in signature else distributed._OPTION_DEFAULTS[name]
        if default is None:
            default = agent._PROTOCOLS["default"][name]
        assert str(default).removesuffix(".0") == value, (flag, default, value)
        if name in distributed._OPTION_DEFAULTS:
            assert str(distributed._OPTION_DEFAULTS[name]).removesuffix(".0") == value, flag
    assert len(shown) >= 10, shown
    assert agent._PROTOCOLS["paper"] == dict(rollouts=10000, seed_inversion=False, policy="random",
                                             search="paper", depth=10)
