"""render_all() is the same text on both engines.

The compiled engine writes the reference's render_all() JSON from its own
render (python/src/session.cpp; docs/python.md, "Which engine answers"): after
every step of the golden traces it must equal the interpreter's, byte for byte.
"""
import os
import sys

import pytest

from conftest import conformance_program, load_trace, needs_corpus, trace_files

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "reference_style"))
import replay  # noqa: E402


@needs_corpus
@pytest.mark.parametrize("path", trace_files(),
                         ids=lambda p: os.path.basename(p)[:-5] if isinstance(p, str) else "no-corpus")
def test_render_all_text_is_the_same_on_both_engines(path, stdlib):
    """render_all() on the compiled engine is the interpreter's text, byte for
    byte, after every step of every golden trace (served by the compiled
    module, not by replaying the interpreter)."""
    import autumnc

    data = load_trace(path)
    program = conformance_program(data["program"])
    trigger = data.get("triggering_condition", "")
    for t in data["traces"][:2]:
        engines = [autumnc.Interpreter(engine="compiled"), autumnc.Interpreter(engine="interp")]
        for i in engines:
            i.run_script(program, stdlib, trigger, t["seed"])
        assert engines[0].render_all() == engines[1].render_all()
        for n, action in enumerate(t["actions"]):
            for i in engines:
                replay.act(i, action)
                i.step()
            assert engines[0].render_all() == engines[1].render_all(), f"seed {t['seed']}: step {n + 1}"
        assert engines[0].engine == "compiled"
