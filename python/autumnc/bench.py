"""python3 -m autumnc.bench [PROGRAMS...] [--seconds S] [--threads T]

Printed figures, not a test. For each program (default: the 16x16 programs of
programs/ that specialise, and ice from ../shared/conformance when present):

Episodes last 200 steps everywhere.

* VecEnv env-steps/s for N = 1, 16, 256 with random actions, observations
  written into the numpy buffer every step (the engine's frame copied out);
* the reference-style loop through ``Interpreter``: one input, ``step()``,
  ``json.loads(render_all())`` -- what MARAProtocol does -- and the same loop
  with ``render_grid()`` in place of the JSON;
* the cost of one Python call: ``VecEnv.step`` with N = 1 and ``Env.step``.
"""
import argparse
import glob
import json
import os
import time

import numpy as np

from . import Env, Interpreter, Program, VecEnv

_HERE = os.path.dirname(os.path.abspath(__file__))
EPISODE = 200  # steps per episode everywhere, so that programs whose state grows compare fairly


def _default_programs():
    for root in (os.getcwd(), os.path.join(_HERE, "..", "..", "..")):
        found = [os.path.join(root, "programs", n + ".au") for n in ("sheepdog", "snowplow")]
        found = [p for p in found if os.path.isfile(p)]
        if found:
            ice = os.path.join(root, "..", "shared", "conformance", "programs", "ice.sexp")
            return found + ([os.path.normpath(ice)] if os.path.isfile(ice) else [])
    raise SystemExit("no programs given and none found under ./programs")


def _timed(fn, seconds):
    """Calls fn() until `seconds` pass; returns (calls, elapsed)."""
    n, t0 = 0, time.perf_counter()
    while True:
        fn()
        n += 1
        if n % 16 == 0 and time.perf_counter() - t0 >= seconds:
            return n, time.perf_counter() - t0


def vec_rate(path, n, threads, seconds):
    vec = VecEnv(path, n, num_threads=threads, engine="compiled", max_episode_steps=EPISODE)
    actions = np.random.default_rng(0).integers(0, 5 + vec.grid_size ** 2, size=(64, n))
    k = [0]

    def one():
        vec.step(actions[k[0] % 64])
        k[0] += 1

    calls, dt = _timed(one, seconds)
    return calls * n / dt


def interpreter_rate(path, seconds, json_render):
    text = open(path).read()
    i = None
    k = [0]

    def one():
        nonlocal i
        if k[0] % EPISODE == 0:  # a fresh interpreter per episode, as MARAProtocol resets
            i = Interpreter()
            i.run_script(text, "", "", 0)
            i.render_all()
        [i.left, i.right, i.up, i.down, lambda: i.click(3, 4), lambda: None][k[0] % 6]()
        k[0] += 1
        i.step()
        if json_render:
            json.loads(i.render_all())
        else:
            i.render_grid()

    calls, dt = _timed(one, seconds)
    return calls / dt, i.engine


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="python3 -m autumnc.bench", description=__doc__.splitlines()[0],
        epilog="Columns (all in env-steps per second, 200-step episodes, random actions): N=1, N=16, N=256: "
               "a VecEnv of N environments, observations written every step; ref loop (JSON): the "
               "reference-style Interpreter loop reading json.loads(render_all()); ref loop (grid): the same "
               "loop reading render_grid(). kind: specialised or embedded module.")
    ap.add_argument("programs", nargs="*")
    ap.add_argument("--seconds", type=float, default=1.0, help="time per measurement")
    ap.add_argument("--threads", type=int, default=0, help="VecEnv worker threads (0: one per core)")
    args = ap.parse_args(argv)
    programs = args.programs or _default_programs()
    print(f"{'program':<12} {'grid':>4} {'kind':<11} {'N=1':>10} {'N=16':>10} {'N=256':>10}   "
          f"{'ref loop (JSON)':>16} {'ref loop (grid)':>16}   env-steps/s")
    for path in programs:
        info = Program(path).compile()
        if not info["ok"]:
            print(f"{os.path.basename(path)}: cannot compile: {info['error']}")
            continue
        rates = [vec_rate(path, n, args.threads, args.seconds) for n in (1, 16, 256)]
        ref_json, _ = interpreter_rate(path, args.seconds, True)
        ref_grid, engine = interpreter_rate(path, args.seconds, False)
        name = os.path.splitext(os.path.basename(path))[0]
        print(f"{name:<12} {info['grid_size']:>4} {info['kind']:<11} " + " ".join(f"{r:>10,.0f}" for r in rates) +
              f"   {ref_json:>16,.0f} {ref_grid:>16,.0f}   (Interpreter on {engine})")
    path = programs[0]
    vec = VecEnv(path, 1, num_threads=1, engine="compiled")
    a = np.zeros(1, dtype=np.int64)
    calls, dt = _timed(lambda: vec.step(a), args.seconds)
    env = Env(path, engine="compiled")
    env.reset()
    ecalls, edt = _timed(lambda: env.step(0), args.seconds)
    print(f"\nper call on {os.path.basename(path)} (engine step included): VecEnv.step N=1 {dt / calls * 1e6:.2f} us, "
          f"Env.step {edt / ecalls * 1e6:.2f} us")


if __name__ == "__main__":
    main()
