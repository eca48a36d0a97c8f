"""autumnc.Interpreter: the reference binding's surface, its results on both
engines under any call pattern, and the additions (clone, states, grids)."""
import copy
import json
import random

import numpy as np
import pytest

import autumnc
from autumnc.interpreter_module import Interpreter
from conftest import bundled_program

# Every method of Autumn.cpp's binding, with its signature as pybind11 prints it.
REFERENCE_SIGNATURES = {
    "step": "step(self: autumnc._core.Interpreter) -> str",
    "click": "click(self: autumnc._core.Interpreter, x: int, y: int) -> None",
    "left": "left(self: autumnc._core.Interpreter) -> None",
    "right": "right(self: autumnc._core.Interpreter) -> None",
    "up": "up(self: autumnc._core.Interpreter) -> None",
    "down": "down(self: autumnc._core.Interpreter) -> None",
    "get_trigger_state": "get_trigger_state(self: autumnc._core.Interpreter) -> bool",
    "render_all": "render_all(self: autumnc._core.Interpreter) -> str",
    "get_environment_string": "get_environment_string(self: autumnc._core.Interpreter) -> str",
    "get_on_clause_count": "get_on_clause_count(self: autumnc._core.Interpreter) -> int",
    "get_covered_on_clause_count": "get_covered_on_clause_count(self: autumnc._core.Interpreter) -> int",
    "evaluate_to_string": "evaluate_to_string(self: autumnc._core.Interpreter, arg0: str) -> str",
    "restore_environment":
        "restore_environment(self: autumnc._core.Interpreter, arg0: str, arg1: str, arg2: str) -> None",
    "tmp_execute_stmt": "tmp_execute_stmt(self: autumnc._core.Interpreter, arg0: str) -> str",
    "set_verbose": "set_verbose(self: autumnc._core.Interpreter, arg0: bool) -> None",
    "get_verbose": "get_verbose(self: autumnc._core.Interpreter) -> bool",
    "set_random_seed": "set_random_seed(self: autumnc._core.Interpreter, arg0: int) -> None",
    "get_random_seed": "get_random_seed(self: autumnc._core.Interpreter) -> int",
    "get_background": "get_background(self: autumnc._core.Interpreter) -> str",
    "get_frame_rate": "get_frame_rate(self: autumnc._core.Interpreter) -> int",
    "run_script": "run_script(self: autumnc._core.Interpreter, script: str, stdlib: str, triggeringCondition: str, "
                  "randomSeed: int = 42) -> str",
}


@pytest.mark.parametrize("name", sorted(REFERENCE_SIGNATURES))
def test_reference_method_signature(name):
    assert getattr(Interpreter, name).__doc__.splitlines()[0] == REFERENCE_SIGNATURES[name]


def test_keyword_arguments_and_return_strings(stdlib):
    i = Interpreter()
    assert i.run_script(script=bundled_program("sokoban"), stdlib=stdlib, triggeringCondition="") == \
        "Script executed successfully."
    assert i.get_random_seed() == 42
    i.click(x=1, y=2)
    assert i.step() == "Step executed."
    with pytest.raises(TypeError):
        i.evaluate_to_string(expr="GRID_SIZE")  # positional only, as in the reference


def test_errors(stdlib):
    i = Interpreter()
    with pytest.raises(RuntimeError, match="no script"):
        i.step()
    with pytest.raises(RuntimeError, match="get_random_seed"):
        i.get_random_seed()
    with pytest.raises(autumnc.ParseError):
        i.run_script("(program (= x (+ 1", stdlib, "")
    assert i.run_script(bundled_program("sokoban"), stdlib, "(or (a) (b))").startswith("Runtime Error: ")
    assert i.run_script(bundled_program("sokoban"), "(program (= 1))", "").startswith("Runtime Error: ")
    with pytest.raises(autumnc.AutumnRuntimeError):
        i.run_script("(program (= x (+ 1 \"a\")))", stdlib, "")
    program = "(program (= GRID_SIZE 4) (= n (initnext 0 (+ (prev n) 1))) (on (== n 2) (= n (+ n \"s\"))))"
    assert i.run_script(program, stdlib, "") == "Script executed successfully."
    i.step()
    i.render_all()
    i.step()
    with pytest.raises(autumnc.AutumnRuntimeError):
        i.step()
    with pytest.raises(RuntimeError):  # the episode has ended
        i.render_all()
    assert isinstance(autumnc.AutumnRuntimeError("x"), RuntimeError)


def test_evaluate_and_execute(stdlib):
    i = Interpreter()
    i.run_script("(program (= GRID_SIZE 4) (= n (initnext 3 (prev n))))", stdlib, "", 0)
    assert i.evaluate_to_string("n") == "(3: N)"
    assert i.evaluate_to_string("+ n 2") == "(5: N)"
    assert i.evaluate_to_string("true") == "(true: Bool)"
    with pytest.raises(RuntimeError, match="not a name"):
        i.evaluate_to_string("nosuchname")
    with pytest.raises(RuntimeError):
        i.evaluate_to_string("+ n \"a\"")  # a runtime error leaves the state as it was
    assert i.evaluate_to_string("n") == "(3: N)"
    assert '"n": "(7: N)"' in i.tmp_execute_stmt("= n 7")
    assert i.evaluate_to_string("n") == "(7: N)"
    i.restore_environment("(program (= GRID_SIZE 4) (= n (initnext 3 (prev n))))", stdlib, "")
    assert i.evaluate_to_string("n") == "(3: N)"
    assert i.get_random_seed() == 0
    assert i.get_frame_rate() == 8 and i.get_background() == "black"


def paint(render_json, background):
    render = json.loads(render_json)
    g = render.pop("GRID_SIZE")
    grid = [[background] * g for _ in range(g)]
    for cells in render.values():
        for c in cells:
            x, y = c["position"]["x"], c["position"]["y"]
            if 0 <= x < g and 0 <= y < g:
                grid[y][x] = c["color"].lower()
    return grid


def names(grid_ids):
    table = autumnc.colour_names()
    return [[table[v] for v in row] for row in grid_ids]


def random_calls(rng, n, grid):
    """A host-call sequence in no particular protocol: several inputs, renders or none, reseeds."""
    calls = []
    for _ in range(n):
        for _ in range(rng.choice([0, 0, 1, 1, 1, 2])):
            calls.append(rng.choice([("left",), ("right",), ("up",), ("down",),
                                     ("click", rng.randrange(grid), rng.randrange(grid))]))
        calls.append(("step",))
        for _ in range(rng.choice([0, 1, 1, 1, 2])):
            calls.append(rng.choice([("render_all",), ("render_grid",)]))
        if rng.random() < 0.1:
            calls.append(("set_random_seed", rng.randrange(100)))
        if rng.random() < 0.2:
            calls.append(("get_trigger_state",))
    return calls


def perform(i, call):
    name, *args = call
    out = getattr(i, name)(*args)
    if name == "render_grid":
        return names(out)
    if name == "render_all":
        return paint(out, i.get_background()), json.loads(out)
    return out


PROGRAMS = ["sokoban", "fireworks", "whack_a_mole", "snowplow", "breakout", "garden"]


@pytest.mark.parametrize("name", PROGRAMS)
def test_compiled_and_interpreter_agree_on_any_call_pattern(name, stdlib):
    rng = random.Random(name)
    for episode in range(3):
        calls = random_calls(rng, 40, 16)
        seed = rng.randrange(1000)
        a, b = Interpreter("compiled"), Interpreter("interp")
        for i in (a, b):
            i.run_script(bundled_program(name), stdlib, "", seed)
        assert a.engine == "compiled" and b.engine == "interp"
        for k, call in enumerate(calls):
            assert perform(a, call) == perform(b, call), f"episode {episode}, call {k} {call}"
        assert a.get_covered_on_clause_count() == b.get_covered_on_clause_count()


def test_protocol_calls_keep_the_compiled_engine(stdlib):
    i = Interpreter("compiled")
    i.run_script(bundled_program("fireworks"), stdlib, "", 3)
    i.render_all()
    for k in range(30):
        [i.left, i.right, i.up, i.down, lambda: i.click(k % 16, 3), lambda: None][k % 6]()
        i.step()
        i.render_grid()
        i.get_trigger_state()
    assert i.engine == "compiled"
    i.left()
    i.right()
    i.step()  # two inputs in one step: only the interpreter can follow
    assert i.engine == "interp"


def test_clone_and_state_round_trip(stdlib):
    i = Interpreter("compiled")
    i.run_script(bundled_program("fireworks"), stdlib, "", 5)
    for k in range(10):
        i.click(k, k)
        i.step()
        i.render_all()
    state, h = i.get_state(), i.state_hash()
    twin, deep = i.clone(), copy.deepcopy(i)
    later = [perform(i, c) for c in random_calls(random.Random(1), 20, 16)]
    assert [perform(twin, c) for c in random_calls(random.Random(1), 20, 16)] == later
    assert [perform(deep, c) for c in random_calls(random.Random(1), 20, 16)] == later
    i.set_state(state)
    assert i.state_hash() == h
    assert [perform(i, c) for c in random_calls(random.Random(1), 20, 16)] == later
    fresh = Interpreter("interp")
    fresh.run_script(bundled_program("fireworks"), stdlib, "", 5)
    fresh.set_state(state)  # any engine loads any state: the interpreter replays the episode
    assert [perform(fresh, c) for c in random_calls(random.Random(1), 20, 16)] == later
    other = Interpreter()
    other.run_script(bundled_program("sokoban"), stdlib, "", 5)
    with pytest.raises(ValueError):
        other.set_state(state)
    with pytest.raises(ValueError):
        other.set_state(b"garbage")


def test_a_snapshot_of_another_build_is_replayed(stdlib):
    # The compiled snapshot inside a state opens with its module's layout
    # digest; one of another build (another layout) is replayed from the
    # episode's log rather than refused or read into the wrong slots.
    i = Interpreter("compiled")
    i.run_script(bundled_program("sokoban"), stdlib, "", 5)
    for k in range(12):
        [i.left, i.up, i.right, i.down][k % 4]()
        i.step()
    assert i.engine == "compiled"
    state = i.get_state()
    later = [perform(i, c) for c in random_calls(random.Random(2), 20, 16)]
    k = state.find(b"AUTS")
    assert k > 0
    for offset in (8, 4):  # the layout digest, the snapshot format
        changed = bytearray(state)
        changed[k + offset] ^= 1
        other = Interpreter("compiled")
        other.run_script(bundled_program("sokoban"), stdlib, "", 5)
        other.set_state(bytes(changed))
        assert [perform(other, c) for c in random_calls(random.Random(2), 20, 16)] == later


def test_render_grid_matches_render_all(stdlib):
    i = Interpreter("compiled")
    i.run_script(bundled_program("garden"), stdlib, "", 1)
    g = i.render_grid()
    assert g.dtype == np.uint8 and g.ndim == 2 and g.shape[0] == g.shape[1] == json.loads(i.render_all())["GRID_SIZE"]
    assert names(g) == paint(i.render_all(), i.get_background())
    assert autumnc.colour_names()[:3] == i.palette()[:3]


def test_custom_stdlib_is_used(stdlib):
    i = Interpreter()
    program = "(program (= GRID_SIZE 4) (= n (initnext (double 2) (prev n))))"
    extended = stdlib.rstrip()[:-1] + "\n(= double (fn (x) (* x 2))))"
    assert i.run_script(program, extended, "") == "Script executed successfully."
    assert i.evaluate_to_string("n") == "(4: N)"
    assert i.engine == "interp"  # modules are built with the bundled library
    with pytest.raises(ValueError):
        Interpreter("compiled").run_script(program, extended, "")


def test_version_and_the_bundled_stdlib(stdlib):
    """autumnc.__version__ is the release's; autumnc.stdlib() is the bundled
    library's text (what an empty stdlib argument stands for), so passing it is
    passing "" and the program still gets its compiled module."""
    import re
    assert re.fullmatch(r"\d+\.\d+\.\d+", autumnc.__version__)
    assert autumnc.stdlib().strip() == stdlib.strip()
    frames = []
    for text in (autumnc.stdlib(), ""):
        i = Interpreter(engine="interp")
        assert i.run_script(bundled_program("sokoban"), text, "", 0) == "Script executed successfully."
        i.step()
        frames.append(i.render_all())
    assert frames[0] == frames[1]
