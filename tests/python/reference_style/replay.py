"""A script written against the reference's Python API, as MARAProtocol drives it.

It imports ``interpreter_module`` (here autumnc's, through the one-file recipe
beside it), runs the program with run_script, and per action sets at most one
input, steps, and paints ``json.loads(render_all())`` into a grid of lower-cased
colour names over ``get_background()``. Nothing in it knows about autumnc.
"""
import json

from interpreter_module import Interpreter


def paint(render, background):
    grid_size = render.pop("GRID_SIZE", 0)
    grid = [[background for _ in range(grid_size)] for _ in range(grid_size)]
    for elem in render:
        for cell in render[elem]:
            x, y = cell["position"]["x"], cell["position"]["y"]
            if 0 <= y < grid_size and 0 <= x < grid_size:
                grid[y][x] = cell["color"].lower()
    return [" ".join(row) for row in grid]


def act(interpreter, action):
    parts = action.split()
    if parts[0] == "click":
        interpreter.click(int(parts[1]), int(parts[2]))
    elif parts[0] in ("left", "right", "up", "down"):
        getattr(interpreter, parts[0])()


def replay(program, stdlib, trigger, seed, actions):
    """Frames (rows of colour names) and trigger states of one episode."""
    interpreter = Interpreter()
    interpreter.run_script(program, stdlib, trigger, seed)
    frames = [paint(json.loads(interpreter.render_all()), interpreter.get_background().lower())]
    triggers = []
    for action in actions:
        act(interpreter, action)
        interpreter.step()
        frames.append(paint(json.loads(interpreter.render_all()), interpreter.get_background().lower()))
        triggers.append(interpreter.get_trigger_state())
    return frames, triggers
