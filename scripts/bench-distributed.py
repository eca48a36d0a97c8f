#!/usr/bin/env python3
"""The figures of docs/scale.md: autumnc.distributed on 1 and on 2 worker processes.

For each worker count it starts a LocalCluster (threads_per_worker=1, a fresh
module cache per run so every shippable module is shipped, AUTUMN_NO_COMPILE=1
on the workers so none of them compiles), evaluates the task folder with one
solver thread per task, and then collects random-policy rollouts of one
program. It prints the wall times (the evaluation's units, and the module
shipping apart), the speed-up, the bytes shipped per module, the rollout
throughput, and checks that both runs' rows agree (timing aside).

    PYTHONPATH=build/python /usr/bin/python3 scripts/bench-distributed.py \\
        [--tasks tasks/generated] [--rollouts 10000] [--program programs/sokoban.au]

Modules are built in this process first (a warm-up, not timed), as a client
does before it ships them. Run it on an otherwise idle machine: the two workers
share its cores with anything else running.
"""
import argparse
import json
import os
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def untimed(value):
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items()
                if not k.endswith("seconds") and k != "throughput" and "per_second" not in k}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def run(n_workers, args, distributed, ad):
    with tempfile.TemporaryDirectory(prefix="autumn-bench-cache-") as cache:
        os.chmod(cache, 0o700)
        env = {"AUTUMN_CACHE_DIR": cache, "AUTUMN_NO_COMPILE": "1"}
        with distributed.LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None, env=env) as cluster, \
                distributed.Client(cluster) as client:
            client.run(lambda: __import__("autumnc.distributed"))  # imports outside the clock
            cpu0 = client.run(time.process_time)
            result = ad.evaluate(client, args.tasks, progress=args.progress, rollouts=args.rollouts)
            cpu1 = client.run(time.process_time)
            result.worker_cpu = sum(cpu1[w] - cpu0[w] for w in cpu1)
            t0 = time.monotonic()
            ad.rollouts(client, args.program, episodes=args.episodes, steps=args.steps, batch=args.batch)
            rollout_seconds = time.monotonic() - t0
    return result, rollout_seconds


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tasks", default=os.path.join(REPO, "tasks", "generated"), help="folder of tasks to evaluate")
    p.add_argument("--rollouts", type=int, default=10000, help="solver's MFP rollouts / CD particles")
    p.add_argument("--program", default=os.path.join(REPO, "programs", "sokoban.au"), help="program for rollouts")
    p.add_argument("--episodes", type=int, default=2048, help="rollout environments")
    p.add_argument("--steps", type=int, default=200, help="steps per rollout environment")
    p.add_argument("--batch", type=int, default=128, help="environments per rollout unit (one VecEnv)")
    p.add_argument("--progress", action="store_true", help="count finished tasks on stderr")
    p.add_argument("--make-mfp", type=int, default=0, metavar="N",
                   help="instead of --tasks: N MFP tasks (seeds 0..N-1) of each of --mfp-programs, made with "
                        "autumnc.distributed.make_tasks into a temporary folder (tasks of similar length)")
    p.add_argument("--mfp-programs", nargs="+", default=[os.path.join(REPO, "programs", "whack_a_mole.au")],
                   help="programs of the --make-mfp tasks")
    p.add_argument("--json", help="also write the figures to this file")
    p.add_argument("--tables", action="store_true", help="print each run's eval table")
    args = p.parse_args()
    try:
        import distributed
    except ImportError:
        sys.exit("bench-distributed: needs Dask distributed (Debian: python3-distributed)")
    import autumnc
    from autumnc import distributed as ad

    made = None
    if args.make_mfp:
        made = tempfile.TemporaryDirectory(prefix="autumn-bench-tasks-")
        t0 = time.monotonic()
        rows = ad.make_tasks(None, "mfp", args.mfp_programs, seeds=range(args.make_mfp), out_dir=made.name,
                             progress=False, extend_colours=True)
        bad = [r for r in rows if "error" in r]
        if bad:
            sys.exit(f"bench-distributed: make_tasks failed: {bad[0]['error']}")
        print(f"made {len(rows)} MFP tasks in {time.monotonic() - t0:.1f} s")
        args.tasks = made.name
    # Warm-up: the client's modules, built before the clocks start.
    ad.evaluate(None, args.tasks, progress=False, rollouts=1, max_steps=1, time_limit=0.01, nodes=1)
    autumnc.Program(args.program).compile()
    figures, reports = {}, {}
    for n in (1, 2):
        result, rollout_seconds = run(n, args, distributed, ad)
        ship = result.shipping or {"seconds": 0, "packages": {}}
        units = result.seconds - ship["seconds"]
        steps = args.episodes * args.steps
        cores = result.worker_cpu / units  # the CPU the workers got: less than n when the machine is shared
        figures[n] = {"eval_seconds": units, "ship_seconds": ship["seconds"], "tasks": len(result.rows),
                      "worker_cpu_seconds": result.worker_cpu, "cores_used": cores,
                      "errors": result.report["totals"]["errors"],
                      "task_seconds": sorted(r["seconds"] for r in result.rows),
                      "rollout_seconds": rollout_seconds, "rollout_steps_per_second": steps / rollout_seconds}
        reports[n] = result.report
        if args.tables:
            print(result.table)
        print(f"{n} worker{'s' if n > 1 else ''}: eval {units:.1f} s for {len(result.rows)} tasks "
              f"(+ {ship['seconds']:.1f} s shipping modules; the workers used {cores:.2f} cores), "
              f"rollouts {steps} steps in {rollout_seconds:.2f} s "
              f"= {steps / rollout_seconds:,.0f} steps/s")
    packages = [p for p in (result.shipping or {"packages": {}})["packages"].values() if p and "so" in p]
    sizes = [len(p["so"]) + len(p["manifest"]) + len(p["built_from"]) for p in packages]
    same = untimed(reports[1]) == untimed(reports[2])
    speedup = figures[1]["eval_seconds"] / figures[2]["eval_seconds"]
    print(f"speed-up of 2 workers: {speedup:.2f}x; rows equal: {same}; "
          f"CPU seconds per task: {figures[1]['worker_cpu_seconds'] / figures[1]['tasks']:.2f} (1 worker), "
          f"{figures[2]['worker_cpu_seconds'] / figures[2]['tasks']:.2f} (2 workers)")
    with open("/proc/loadavg") as f:
        print(f"load average after the runs: {f.read().split()[0]} (anything else running shares the cores)")
    for a, b in zip(reports[1]["tasks"], reports[2]["tasks"]):
        if untimed(a) != untimed(b):
            print(f"  differs: {a['task']}: {a.get('detail') or a.get('error')} | {b.get('detail') or b.get('error')}")
    ts = figures[1]["task_seconds"]
    print(f"task solve times (1 worker): min {ts[0]:.2f} s, median {ts[len(ts) // 2]:.2f} s, max {ts[-1]:.2f} s")
    if sizes:
        print(f"modules shipped: {len(sizes)}, bytes each: min {min(sizes):,}, mean {sum(sizes) // len(sizes):,}, "
              f"max {max(sizes):,}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"workers": figures, "speedup": speedup, "rows_equal": same, "module_bytes": sizes}, f, indent=1)
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
