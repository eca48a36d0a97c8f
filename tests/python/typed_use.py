"""typed_use.py — a user's fully annotated script, for mypy only (ctest python_stubs_mypy; never run).

It uses autumnc as docs/python.md documents it, with the types written out,
so a stub in python/autumnc/_core.pyi that disagrees with the documented API
(a wrong return type, a missing method, an argument taken by keyword that the
extension takes by position only) fails the check. Each `# type: ignore[...]`
marks a call the extension refuses: mypy's warn_unused_ignores makes it an
error if the stubs accepted it.
"""
import copy
import pickle
from typing import Any, Optional

import numpy as np
import numpy.typing as npt

import autumnc
from autumnc.interpreter_module import Interpreter


def reference_loop(program: str, seed: int) -> tuple[str, bool, int]:
    i = Interpreter()
    said: str = i.run_script(program, autumnc.stdlib(), "", seed)
    i.click(1, 2)
    stepped: str = i.step()
    i.left()
    i.step()
    frame_json: str = i.render_all()
    grid: npt.NDArray[np.uint8] = i.render_grid()
    names: list[str] = i.palette()
    value: str = i.evaluate_to_string("GRID_SIZE")
    i.evaluate_to_string(expr="GRID_SIZE")  # type: ignore[call-arg]
    state: bytes = i.get_state()
    twin: Interpreter = copy.deepcopy(i)
    twin.set_state(state)
    rate: int = i.get_frame_rate()
    return said + stepped + frame_json + value + names[int(grid[0, 0])], i.get_trigger_state(), rate + twin.state_hash()


def one_env(path: str) -> float:
    env = autumnc.Env(path, seed=3, engine="compiled", max_episode_steps=50)
    obs, info = env.reset(seed=4)
    total = 0.0
    for a in range(5):
        obs, reward, terminated, truncated, info = env.step(a)
        total += reward
        if terminated or truncated:
            break
    env.step(np.int64(0))
    env.step(1.5)  # type: ignore[arg-type]
    first: npt.NDArray[np.uint8] = obs
    error: Optional[Any] = info.get("error")
    return total + float(first.sum()) + env.grid_size + (error is None) + env.state_hash()


def batch(path: str) -> bytes:
    vec = autumnc.VecEnv(path, 4, num_threads=2, engine="compiled")
    obs, rewards, terminated, truncated, info = vec.step(np.zeros(4, dtype=np.int64))
    vec.step([0, 1, 2, 3])
    kept: npt.NDArray[np.uint8] = obs.copy()
    r: npt.NDArray[np.float32] = rewards
    done: npt.NDArray[np.bool_] = terminated | truncated
    states: list[autumnc.EnvState] = vec.clone([0, 1])
    data: bytes = states[0].to_bytes()
    back: autumnc.EnvState = autumnc.EnvState.from_bytes(path, data)
    vec.restore([2, 3], [back, pickle.loads(pickle.dumps(states[1]))])
    hashes: npt.NDArray[np.uint64] = vec.state_hash()
    step_count: int = states[0].steps + states[0].episode + int(states[0].done)
    return data + kept.tobytes() + r.tobytes() + done.tobytes() + hashes.tobytes() + bytes(step_count)


def errors(text: str) -> str:
    try:
        Interpreter().run_script(text, "", "")
    except autumnc.ParseError as e:
        return str(e)
    except autumnc.AutumnRuntimeError as e:
        return str(e)
    return autumnc.__version__ + " ".join(autumnc.colour_names())
