"""An unchanged reference-style script reproduces the golden traces.

reference_style/replay.py is written against Autumn.cpp's interpreter_module;
the one-file recipe (reference_style/interpreter_module.py) points it at
autumnc. Every trace of ../shared/conformance is replayed and compared frame by
frame, trigger by trigger.
"""
import os
import sys

import pytest

from conftest import conformance_program, load_trace, needs_corpus, trace_files

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "reference_style"))
import replay  # noqa: E402


@needs_corpus
# Without the corpus there are no traces, and pytest passes a placeholder (not a
# path) to `ids`; the test itself is then skipped by needs_corpus.
@pytest.mark.parametrize("path", trace_files(),
                         ids=lambda p: os.path.basename(p)[:-5] if isinstance(p, str) else "no-corpus")
def test_golden_trace(path, stdlib):
    data = load_trace(path)
    program = conformance_program(data["program"])
    trigger = data.get("triggering_condition", "")
    for t in data["traces"]:
        frames, triggers = replay.replay(program, stdlib, trigger, t["seed"], t["actions"])
        for i, (got, want) in enumerate(zip(frames, t["frames"])):
            assert got == want, f"seed {t['seed']}: frame {i} differs"
        assert len(frames) == len(t["frames"])
        if "trigger" in t:
            assert triggers == t["trigger"]


def test_recipe_is_autumnc():
    import interpreter_module
    import autumnc
    assert interpreter_module.Interpreter is autumnc.Interpreter

