"""autumnc.Env and autumnc.VecEnv: Gymnasium shapes, exactness against single
environments and the interpreter, thread-count independence, the GIL released,
clone/restore, and clear errors."""
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import autumnc
from conftest import PROGRAMS, bundled_program

SOKOBAN = os.path.join(PROGRAMS, "sokoban.au")
FIREWORKS = os.path.join(PROGRAMS, "fireworks.au")


def actions_for(env_grid, n, seed):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 5 + env_grid * env_grid, size=n)


def test_env_shapes_and_spaces():
    env = autumnc.Env(SOKOBAN, seed=3)
    obs, info = env.reset()
    g = env.grid_size
    assert obs.shape == (g, g) and obs.dtype == np.uint8 and info == {}
    assert env.action_space.n == 5 + g * g and env.observation_space.contains(obs)
    obs, reward, terminated, truncated, info = env.step(1)
    assert (reward, terminated, truncated) == (0.0, False, False)
    with pytest.raises(ValueError):
        env.step(5 + g * g)
    with pytest.raises(ValueError):
        env.step(-1)


def test_env_clone_is_an_env_with_the_same_future():
    """clone() returns the caller's class (spaces included) at the same point of the episode."""
    class Tagged(autumnc.Env):
        pass

    env = Tagged(FIREWORKS, seed=5, engine="interp")
    env.reset()
    env.tag = "mine"
    for a in actions_for(env.grid_size, 7, 1):
        env.step(int(a))
    twin = env.clone()
    assert type(twin) is Tagged and twin.tag == "mine"
    assert twin.action_space.n == env.action_space.n and twin.observation_space.shape == env.observation_space.shape
    assert twin.state_hash() == env.state_hash()
    for a in actions_for(env.grid_size, 20, 2):
        mine, theirs = env.step(int(a)), twin.step(int(a))
        assert np.array_equal(mine[0], theirs[0]) and mine[1:4] == theirs[1:4]
    before = env.state_hash()
    twin.step(0)  # stepping the copy leaves the original where it was
    assert env.state_hash() == before


def test_env_step_refuses_what_vecenv_refuses():
    """A float or a bool is not an action id: refused, not truncated to one."""
    env = autumnc.Env(SOKOBAN, seed=3)
    env.reset()
    for bad in (np.float32(2.9), 2.9, True, np.bool_(True), "2", np.array([1, 2]), 2**70):
        with pytest.raises(ValueError, match="integer|out of range"):
            env.step(bad)
    for good in (2, np.int8(2), np.uint64(2), np.array(2)):
        assert env.step(good)[2] is False  # not terminated: the step ran


def test_env_reset_equals_a_fresh_run_script(stdlib):
    env = autumnc.Env(FIREWORKS, seed=7, engine="compiled")
    g = env.grid_size
    acts = actions_for(g, 30, 1)
    for _ in range(2):  # the second episode starts from the saved initial state
        obs, _ = env.reset()
        i = autumnc.Interpreter("interp")
        i.run_script(bundled_program("fireworks"), stdlib, "", 7)
        assert np.array_equal(obs, i.render_grid())
        for a in acts:
            obs = env.step(int(a))[0]
            if a == 0:
                pass
            elif a < 5:
                getattr(i, ["left", "right", "up", "down"][a - 1])()
            else:
                i.click(int((a - 5) % g), int((a - 5) // g))
            i.step()
            assert np.array_equal(obs, i.render_grid())


def test_env_truncates_and_requires_reset():
    env = autumnc.Env(SOKOBAN, max_episode_steps=3)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)
    env.reset()
    results = [env.step(0) for _ in range(3)]
    assert [r[3] for r in results] == [False, False, True]
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)


def run_vec(program, n, threads, steps, seed=0, engine="compiled"):
    vec = autumnc.VecEnv(program, n, num_threads=threads, seed=seed, engine=engine, max_episode_steps=7)
    obs, _ = vec.reset()
    out = [obs.copy()]
    for t in range(steps):
        obs, rew, term, trunc, info = vec.step(actions_for(vec.grid_size, n, t))
        out.append((obs.copy(), rew.copy(), term.copy(), trunc.copy()))
    return out, vec.state_hash()


@pytest.mark.parametrize("program", [SOKOBAN, FIREWORKS])
def test_vecenv_equals_single_environments(program):
    n, steps = 5, 12
    batched, _ = run_vec(program, n, 2, steps, seed=11)
    g = batched[0].shape[1]
    for i in range(n):
        env = autumnc.Env(program, seed=11 + i, engine="interp", max_episode_steps=7)
        obs, _ = env.reset()
        assert np.array_equal(batched[0][i], obs)
        done, episode = False, 0
        for t in range(steps):
            if done:  # autoreset: the next episode's seed
                episode += 1
                obs, _ = env.reset(seed=11 + i + episode * n)
                assert np.array_equal(batched[t + 1][0][i], obs)
                done = False
                continue
            obs, rew, term, trunc, _ = env.step(int(actions_for(g, n, t)[i]))
            assert np.array_equal(batched[t + 1][0][i], obs), (i, t)
            assert batched[t + 1][3][i] == trunc
            done = term or trunc


def test_vecenv_results_do_not_depend_on_threads():
    one, h1 = run_vec(FIREWORKS, 100, 1, 15)  # 100 slots: two chunks on two threads
    two, h2 = run_vec(FIREWORKS, 100, 2, 15)
    assert np.array_equal(h1, h2)
    for a, b in zip(one[1:], two[1:]):
        assert all(np.array_equal(x, y) for x, y in zip(a, b))


def test_vecenv_clone_restore_round_trip():
    vec = autumnc.VecEnv(FIREWORKS, 4, seed=2)
    vec.reset()
    g = vec.grid_size
    for t in range(5):
        vec.step(actions_for(g, 4, t))
    saved, hashes = vec.clone([0, 1, 2, 3]), vec.state_hash().copy()
    future = [vec.step(actions_for(g, 4, 100 + t))[0].copy() for t in range(5)]
    vec.restore([0, 1, 2, 3], saved)
    assert np.array_equal(vec.state_hash(), hashes)
    assert all(np.array_equal(vec.step(actions_for(g, 4, 100 + t))[0], f) for t, f in enumerate(future))
    vec.restore([3], [saved[0]])  # a state moves to another slot
    assert vec.state_hash()[3] == hashes[0]
    with pytest.raises(IndexError):
        vec.clone([4])


def _stepped_fireworks(n=4, steps=7):
    vec = autumnc.VecEnv(FIREWORKS, n, seed=2, engine="compiled")
    vec.reset()
    for t in range(steps):
        vec.step(actions_for(vec.grid_size, n, t))
    return vec


def test_envstate_pickle_and_bytes_continue_exactly():
    """A pickled state, and one rebuilt from to_bytes(), continue exactly as the
    original: restored into slots beside it and stepped with the same actions,
    the observations and state hashes agree at every step."""
    import pickle

    vec = _stepped_fireworks()
    g = vec.grid_size
    original = vec.clone([0])[0]
    pickled = pickle.loads(pickle.dumps(original))
    from_bytes = autumnc.EnvState.from_bytes(FIREWORKS, original.to_bytes())
    assert original.to_bytes() == pickled.to_bytes() == from_bytes.to_bytes()
    assert (pickled.episode, pickled.steps, pickled.done) == (original.episode, original.steps, original.done) \
        == (0, 7, False)
    assert pickled.state_hash() == from_bytes.state_hash() == original.state_hash()
    twin = autumnc.VecEnv(FIREWORKS, 3, seed=2, engine="compiled")  # another VecEnv of the program
    twin.restore([0, 1, 2], [original, pickled, from_bytes])
    for t in range(12):
        a = int(actions_for(g, 1, 500 + t)[0])
        obs, _, term, _, _ = twin.step([a, a, a])
        assert np.array_equal(obs[0], obs[1]) and np.array_equal(obs[0], obs[2]), f"step {t}"
        h = twin.state_hash()
        assert h[0] == h[1] == h[2], f"step {t}"
    import copy
    assert copy.deepcopy(original).state_hash() == original.state_hash()


def test_envstate_bytes_refuse_other_programs_and_corruption():
    vec = _stepped_fireworks(n=1, steps=3)
    data = vec.clone([0])[0].to_bytes()
    with pytest.raises(ValueError, match="another program"):
        autumnc.EnvState.from_bytes(SOKOBAN, data)
    with pytest.raises(ValueError, match="another program"):
        autumnc.EnvState.from_bytes(FIREWORKS, data, trigger="== 1 1")
    with pytest.raises(ValueError, match="not the bytes of an autumnc EnvState"):
        autumnc.EnvState.from_bytes(FIREWORKS, b"hello")
    for cut in (0, 3, 10, 40, len(data) - 1):
        with pytest.raises(ValueError):
            autumnc.EnvState.from_bytes(FIREWORKS, data[:cut])
    with pytest.raises(ValueError, match="bytes after the end"):
        autumnc.EnvState.from_bytes(FIREWORKS, data + b"x")
    # The snapshot inside names its module's layout: another build's is refused as such.
    k = data.find(b"AUTS")
    assert k > 0
    for offset in (4, 8):  # the snapshot format, the layout digest
        other_build = bytearray(data)
        other_build[k + offset] ^= 1
        with pytest.raises(ValueError, match="saved by another build of this program's module"):
            autumnc.EnvState.from_bytes(FIREWORKS, bytes(other_build))
    # Flipped bytes anywhere in the snapshot: a clear ValueError or a state that
    # loads (a change the format cannot tell from a real state), never a crash.
    rng = np.random.default_rng(1)
    for _ in range(200):
        bad = bytearray(data)
        bad[int(rng.integers(0, len(bad)))] ^= int(rng.integers(1, 256))
        try:
            autumnc.EnvState.from_bytes(FIREWORKS, bytes(bad))
        except ValueError:
            pass
    # restore() refuses another program's state instead of swapping the program.
    other = autumnc.VecEnv(SOKOBAN, 1, engine="compiled")
    with pytest.raises(ValueError, match="another program"):
        other.restore([0], vec.clone([0]))


def test_envstate_without_a_snapshot_says_why():
    vec = autumnc.VecEnv(FIREWORKS, 1, engine="interp")
    state = vec.clone([0])[0]
    with pytest.raises(ValueError, match="cannot save its state as bytes"):
        state.to_bytes()
    import pickle
    with pytest.raises(ValueError, match="cannot save its state as bytes"):
        pickle.dumps(state)


def test_vecenv_bad_input():
    vec = autumnc.VecEnv(SOKOBAN, 3)
    with pytest.raises(ValueError):
        vec.step([0, 1])
    with pytest.raises(ValueError):
        vec.step([0, 1, 10**6])
    with pytest.raises(ValueError, match="integers"):  # not truncated to [0, 1, 2]
        vec.step(np.array([0.0, 1.7, 2.2]))
    with pytest.raises(ValueError, match="integers"):
        vec.step([True, False, True])
    obs = vec.step(np.array([0, 1, 2], dtype=np.uint8))[0]  # any integer dtype
    assert obs.shape[0] == 3
    with pytest.raises(ValueError):
        autumnc.VecEnv(SOKOBAN, 0)
    with pytest.raises(FileNotFoundError):
        autumnc.VecEnv("/nonexistent.au", 2)
    with pytest.raises(autumnc.ParseError):
        autumnc.VecEnv("(program (= x (+ 1 ", 2)


def test_runtime_error_terminates_with_info():
    program = "(program (= GRID_SIZE 4) (= n (initnext 0 (+ (prev n) 1))) (on (== n 2) (= n (+ n \"s\"))))"
    vec = autumnc.VecEnv(program, 2, engine="interp")
    vec.step([0, 0])
    vec.step([0, 0])
    obs, rew, term, trunc, info = vec.step([0, 0])
    assert term.all() and set(info["errors"]) == {0, 1} and "runtime error" in info["errors"][0]
    obs, rew, term, trunc, info = vec.step([0, 0])  # autoreset
    assert not term.any()
    env = autumnc.Env(program, engine="interp")
    env.reset()
    env.step(0)
    env.step(0)
    _, _, terminated, _, info = env.step(0)
    assert terminated and "runtime error" in info["error"]


def test_python_threads_run_while_vecenv_steps():
    """With a 0.2 s switch interval the main thread does not hand the GIL over during
    a step of a few milliseconds, so the other thread can only progress inside step()
    if step() released it."""
    vec = autumnc.VecEnv(FIREWORKS, 4096, num_threads=1)
    counter, stop = [0], threading.Event()

    def spin():
        while not stop.is_set():
            counter[0] += 1

    old = sys.getswitchinterval()
    t = threading.Thread(target=spin)
    t.start()
    time.sleep(0.05)
    sys.setswitchinterval(0.2)
    try:
        acts = np.zeros(4096, dtype=np.int64)
        progressed = 0
        for _ in range(20):
            before = counter[0]
            vec.step(acts)
            progressed += counter[0] > before
            if progressed:
                break
    finally:
        sys.setswitchinterval(old)
        stop.set()
        t.join()
    assert progressed >= 1


def _stepped_state(stdlib):
    i = autumnc.Interpreter("compiled")
    i.run_script(bundled_program("sokoban"), stdlib, "", 3)
    for k in range(6):
        i.click(k, k) if k % 2 else i.left()
        i.step()
    return i, i.get_state()


def test_set_state_refuses_corrupt_bytes(stdlib):
    """A state with a changed, missing or extra byte raises ValueError or loads a
    state that steps: never a crash. A compiled snapshot the module refuses (a
    truth value of 2 as its last byte) is a ValueError, not a silent replay."""
    i, state = _stepped_state(stdlib)
    assert i.engine == "compiled"
    h = i.state_hash()
    with pytest.raises(ValueError, match="corrupt state"):
        i.set_state(state[:-1] + b"\x02")
    for n in range(len(state)):
        with pytest.raises(ValueError):
            i.set_state(state[:n])
    for k in range(len(state)):
        for x in (0x01, 0x80):
            bad = bytearray(state)
            bad[k] ^= x
            try:
                i.set_state(bytes(bad))
            except ValueError:
                continue
            i.right()
            i.step()
    i.set_state(state)  # the good state still loads after all that
    assert i.state_hash() == h


def test_vecenv_used_from_two_threads_raises():
    """step() releases the GIL: another thread calling the same VecEnv meanwhile
    gets a clear RuntimeError (before: a segfault or a deadlock)."""
    vec = autumnc.VecEnv(FIREWORKS, 4096, num_threads=2)
    acts = np.zeros(4096, dtype=np.int64)
    done = threading.Event()

    def stepper():
        for _ in range(40):
            vec.step(acts)
        done.set()

    t = threading.Thread(target=stepper)
    t.start()
    refused = 0
    try:
        while not done.is_set() and not refused:
            try:
                vec.state_hash()
            except RuntimeError as e:
                assert "in use by another thread" in str(e)
                refused += 1
    finally:
        t.join()
    assert refused >= 1
    vec.step(acts)  # usable again once the other call has returned


def test_vecenv_too_many_envs_is_memory_error():
    with pytest.raises(MemoryError, match="num_envs=10000000"):
        autumnc.VecEnv(SOKOBAN, 10**7)
    assert autumnc.VecEnv(SOKOBAN, 3).num_envs == 3


# One step of nine million function calls, within the default budget: over a
# second on the interpreter, which polls for Ctrl-C every 65,536 calls.
LONG_STEP = """(program
  (= GRID_SIZE 4)
  (= n (initnext 0 (+ (prev n)
    (foldl (fn (a j) (+ a (foldl (fn (b i) (+ b (* i 2))) 0 (range 0 3000)))) 0 (range 0 3000))))))
"""


def _ctrl_c_in(seconds):
    """A real SIGINT from another process, as a terminal's Ctrl-C sends it."""
    return subprocess.Popen(["sh", "-c", f"sleep {seconds}; kill -INT {os.getpid()}"])


def test_ctrl_c_stops_a_long_interpreted_step(tmp_path, stdlib):
    """KeyboardInterrupt soon after Ctrl-C, not at the end of the step, on Env
    and on the reference API; the interrupted episode is over, and a new one
    starts normally."""
    path = tmp_path / "long_step.au"
    path.write_text(LONG_STEP)
    env = autumnc.Env(str(path), engine="interp")
    env.reset()
    start = time.monotonic()
    env.step(0)  # the whole step, for scale
    whole = time.monotonic() - start
    killer = _ctrl_c_in(0.2)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        env.step(0)
    assert time.monotonic() - start < max(0.8, whole)
    killer.wait()
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(0)
    assert env.reset()[0].shape == (4, 4)

    from autumnc.interpreter_module import Interpreter
    # The interpreter, named: "auto" would load the compiled module once an
    # earlier run has cached it, and specialised code ends this step at once
    # with its loop budget (nothing long to interrupt).
    i = Interpreter(engine="interp")
    i.run_script(LONG_STEP, stdlib, "", 0)
    killer = _ctrl_c_in(0.2)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        i.step()
    assert time.monotonic() - start < max(0.8, whole)
    killer.wait()


def test_ctrl_c_stops_a_long_batched_step(tmp_path):
    """VecEnv too: KeyboardInterrupt soon after Ctrl-C, whether the long step
    runs on the calling thread (one slot) or on the pool's worker as well (33
    slots, two threads); the half-stepped batch asks for a reset, and after it
    steps normally."""
    path = tmp_path / "long_step.au"
    path.write_text(LONG_STEP)
    env = autumnc.VecEnv(str(path), num_envs=1, num_threads=2, engine="interp")
    one = np.zeros(1, dtype=np.int64)
    start = time.monotonic()
    env.step(one)  # the whole step, for scale
    whole = time.monotonic() - start
    killer = _ctrl_c_in(0.2)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        env.step(one)
    assert time.monotonic() - start < max(0.8, whole)
    killer.wait()
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(one)
    obs, info = env.reset()
    assert obs.shape == (1, 4, 4) and "errors" not in info
    _, _, terminated, _, info = env.step(one)
    assert not terminated.any(), info

    # 33 slots on two threads: two chunks, slots 17-32 on the worker. Stopped
    # in the middle of its first step (not at the end of it, `whole`, nor of its
    # chunk, 16 times that), the worker is done in a fraction of a step.
    batch = autumnc.VecEnv(str(path), num_envs=33, num_threads=2, engine="interp")
    many = np.zeros(33, dtype=np.int64)
    killer = _ctrl_c_in(0.2)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        batch.step(many)
    assert time.monotonic() - start < max(0.8, whole / 2)
    killer.wait()
    with pytest.raises(RuntimeError, match="call reset"):
        batch.step(many)
    obs, info = batch.reset()
    assert obs.shape == (33, 4, 4) and "errors" not in info


def test_exit_waits_for_compiles_and_says_so(tmp_path):
    """A script that ends while a module it asked for compiles waits for it (so
    the next run has it) and says so on stderr, rather than pausing silently."""
    program = tmp_path / "fresh.au"
    program.write_text("(program (= GRID_SIZE 4) (= n (initnext %d (+ (prev n) 1))))" % (os.getpid() % 100000))
    script = "import autumnc, sys; autumnc.Env(sys.argv[1], engine='auto').reset()"
    env = dict(os.environ, AUTUMN_CACHE_DIR=str(tmp_path / "cache"))
    run = subprocess.run([sys.executable, "-c", script, str(program)], env=env, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert "autumnc: waiting for 1 module compile this script started" in run.stderr
    assert list((tmp_path / "cache").glob("*.so")), "the compile finished before the process ended"
