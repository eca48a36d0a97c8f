"""autumnc.distributed on a LocalCluster of two worker processes.

One cluster serves the whole file (a module-scoped fixture: starting one costs
seconds, and CI's budget is tight). Its workers have a module cache of their
own, apart from this process's, and AUTUMN_NO_COMPILE=1 (set through
client.run, so one test can lift it): every compiled module they run was built
here and shipped. Task sets are tiny; the speed-up of two workers is measured by
scripts/bench-distributed.py and reported in docs/scale.md, not timed here.
"""
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

import autumnc  # noqa: E402
from autumnc import _core  # noqa: E402
from autumnc import distributed as ad  # noqa: E402
from conftest import PROGRAMS, REPO  # noqa: E402

CLI = os.path.join(REPO, "build", "autumn")


def _set_no_compile(value):
    if value:
        os.environ["AUTUMN_NO_COMPILE"] = "1"
    else:
        os.environ.pop("AUTUMN_NO_COMPILE", None)
    return _core._compiling_forbidden()


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    cache = tmp_path_factory.mktemp("worker-cache")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                       env={"AUTUMN_CACHE_DIR": str(cache)})
    c = distributed.Client(cluster)
    assert all(c.run(_set_no_compile, True).values())
    c.worker_cache = cache
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def task_folder(tmp_path_factory):
    """A sokoban change-detection task (its changed program is compiled and
    shipped), an MFP task, and a task naming a program that does not exist."""
    root = tmp_path_factory.mktemp("tasks")
    for sub in ("prompts", "programs", "answers"):
        (root / sub).mkdir()
    cd = os.path.join(REPO, "tasks", "cd", "sokoban")
    for sub in ("prompts", "programs", "answers"):
        for f in os.listdir(os.path.join(cd, sub)):
            shutil.copy(os.path.join(cd, sub, f), root / sub / f)
    gen = os.path.join(REPO, "tasks", "generated")
    shutil.copy(os.path.join(gen, "prompts", "sokoban_mfp.json"), root / "prompts")
    shutil.copy(os.path.join(gen, "answers", "sokoban_mfp.json"), root / "answers")
    shutil.copy(os.path.join(gen, "color_dict.yaml"), root)
    broken = json.loads((root / "prompts" / "sokoban_mfp.json").read_text())
    broken["program"] = "no_such_program"
    (root / "prompts" / "broken_mfp.json").write_text(json.dumps(broken))
    return root


def _untimed(value):
    if isinstance(value, dict):
        return {k: _untimed(v) for k, v in value.items()
                if not k.endswith("seconds") and k != "throughput" and "per_second" not in k}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def test_eval_equals_the_single_process_run(client, task_folder):
    """Rows (timing aside), totals and the table's task lines equal the
    in-process run's and the CLI's; workers that may not compile ran the
    shipped module; the broken task is a row saying why."""
    options = dict(rollouts=200, max_steps=60)
    spread = ad.evaluate(client, task_folder, progress=False, **options)
    local = ad.evaluate(None, task_folder, progress=False, **options)
    assert _untimed(spread.report) == _untimed(local.report)
    assert [r["task"] for r in spread.rows] == ["prompts/broken_mfp.json", "prompts/sokoban_cd.json",
                                                "prompts/sokoban_mfp.json"]
    broken = spread.rows[0]
    assert "no_such_program" in broken["error"] and broken["type"] == "mfp"
    assert all("error" not in r for r in spread.rows[1:]), spread.table
    assert spread.report["totals"]["errors"] == 1 and not spread.ok
    assert "1 errors" in spread.table and "task" in spread.table.splitlines()[0]
    # The changed program's module (with the answers' trigger) went to both workers.
    shipped = spread.shipping["workers"]
    assert len(shipped) == 2 and all(e["installed"] or e["had"] for e in shipped.values())
    assert not any(e["refused"] for e in shipped.values())
    if os.path.exists(CLI):
        out = subprocess.run([CLI, "eval", str(task_folder), "--json", "--threads", "1", "--rollouts", "200",
                              "--max-steps", "60"], capture_output=True, text=True).stdout
        assert _untimed(json.loads(out)) == _untimed(spread.report)


def test_a_worker_without_the_compiler_needs_the_shipped_module(client, task_folder):
    """Without shipping, a worker that may not compile reports it in the row."""
    folder = task_folder.parent / "lonely"
    for sub in ("prompts", "programs"):
        (folder / sub).mkdir(parents=True)
    # sokoban with a comment added: not the text built into the package, so a module is needed.
    text = open(os.path.join(PROGRAMS, "sokoban.au")).read() + "\n; the same program, another text\n"
    (folder / "programs" / "lonely.au").write_text(text)
    task = json.loads((task_folder / "prompts" / "sokoban_mfp.json").read_text())
    task["program"] = "lonely"
    (folder / "prompts" / "lonely_mfp.json").write_text(json.dumps(task))
    shutil.copy(task_folder / "color_dict.yaml", folder)
    result = ad.evaluate(client, folder, progress=False, ship=False, rollouts=50)
    assert "AUTUMN_NO_COMPILE" in result.rows[0]["error"]


# A program no other test compiles, as small as compiles fastest (two compiles: here and on a worker).
DOT = """; a dot that walks left and right, and a random spark
(program
  (= GRID_SIZE 6)
  (object Dot (Cell 0 0 "tomato"))
  (object Spark (Cell 0 0 "gold"))
  (: dot Dot)
  (= dot (initnext (Dot (Position 2 2)) (prev dot)))
  (: spark Spark)
  (= spark (initnext (Spark (Position 0 0)) (Spark (Position (uniformChoice (range 0 6)) 5))))
  (on left (= dot (moveLeft (prev dot))))
  (on right (= dot (moveRight (prev dot))))
)
"""


def test_corrupt_transfer_refused_then_recompiled(client, tmp_path):
    """A module whose bytes do not match its manifest's digest is refused by
    every worker; a worker allowed to compile then builds it itself, and its
    rollouts equal this process's."""
    program = str(tmp_path / "dot.au")
    text = DOT
    with open(program, "w") as f:
        f.write(text)
    packages = ad.package_modules([(program, text, None)])
    (pkg,) = packages.values()
    assert pkg and len(pkg["so"]) > 1000 and pkg["manifest"].count("\n") >= 2
    bad = dict(pkg, so=pkg["so"][:5000] + bytes([pkg["so"][5000] ^ 0xFF]) + pkg["so"][5001:])
    report = ad.install_modules(client, [bad])
    assert len(report) == 2
    for entry in report.values():
        assert not entry["installed"] and "digest" in entry["refused"][0][1]
    assert not any(h[0] for h in ad.modules_at_hand(client, [(program, text, None)]).values())
    try:
        client.run(_set_no_compile, False)
        spread = ad.rollouts(client, program, episodes=4, steps=5, batch=4, seed=7, ship=False)
    finally:
        client.run(_set_no_compile, True)
    local = ad.rollouts(None, program, episodes=4, steps=5, batch=4, seed=7)
    for k in ("obs", "actions", "rewards", "done"):
        assert np.array_equal(spread[k], local[k]), k
    assert any(h[0] for h in ad.modules_at_hand(client, [(program, text, None)]).values())
    # Sound bytes are installed, and a worker that has them is not sent them again.
    again = ad.install_modules(client, [pkg])
    assert all(e["had"] == 1 and e["bytes"] == 0 for e in again.values())


def test_rollouts_solve_and_make_tasks(client, task_folder):
    """Batched rollouts equal the in-process ones whatever the batch size;
    solve over a list returns a result per task and an error row for a bad one;
    make_tasks makes what make_task makes."""
    sokoban = os.path.join(PROGRAMS, "sokoban.au")
    a = ad.rollouts(client, sokoban, episodes=6, steps=4, batch=2, seed=3)
    b = ad.rollouts(None, sokoban, episodes=6, steps=4, batch=2, seed=3)
    assert a["obs"].shape[:2] == (6, 5) and a["obs"].dtype == np.uint8
    assert all(np.array_equal(a[k], b[k]) for k in a)
    tasks = [task_folder / "prompts" / "sokoban_mfp.json", task_folder / "prompts" / "broken_mfp.json"]
    rows = ad.solve(client, tasks, progress=False, rollouts=100)
    assert rows[0]["type"] == "masked_frame_prediction" and "result" in rows[0]
    assert rows[1]["task"].endswith("broken_mfp.json") and "no_such_program" in rows[1]["error"]
    made = ad.make_tasks(client, "mfp", [sokoban, "/nonexistent.au"], seeds=[1], steps=6, extend_colours=True,
                         progress=False)
    assert made[0]["task"] == autumnc.make_task("mfp", sokoban, seed=1, steps=6, extend_colours=True)
    assert "cannot open" in made[1]["error"] and made[1]["program"] == "/nonexistent.au"


def test_bench_rows_per_program_on_workers_that_do_not_compile(client, tmp_path):
    """autumn bench across the workers: a row per program in the order given, on
    both engines (the compiled one from shipped modules: the workers do not
    compile), the same steps and grid as the CLI's rows, a program that does not
    load or exist as a row with its error, and the CLI's table."""
    bad = tmp_path / "bad.au"
    bad.write_text("(program (= GRID_SIZE 4) (= x (initnext 0 (+ (prev x) 1)))")  # unclosed
    programs = [os.path.join(PROGRAMS, "sokoban.au"), os.path.join(PROGRAMS, "fireworks.au"), str(bad),
                "/nonexistent.au"]
    result = ad.bench(client, programs, steps=30, progress=False)
    names = [r["program"] for r in result.rows]
    assert names == ["sokoban", "fireworks", "bad", "nonexistent"]
    assert not result.ok
    for r in result.rows[:2]:
        assert r["interp"]["ok"] and r["compiled"]["ok"], r
        assert r["ratio"] > 0 and r["interp"]["clone_ns"] > 0
    assert "bad.au:1:" in result.rows[2]["error"] and "cannot read /nonexistent.au" in result.rows[3]["error"]
    assert result.report["median_ratio"] > 0
    lines = result.table.splitlines()
    assert lines[0].split()[:3] == ["program", "grid", "steps"] and lines[-1].startswith("median over 2 programs")
    if os.path.exists(CLI):
        out = subprocess.run([CLI, "bench", *programs[:2], "--steps", "30", "--json"], capture_output=True,
                             text=True, check=True).stdout
        cli = json.loads(out)["rows"]
        assert [(r["program"], r["grid"], r["steps"]) for r in cli] == \
               [(r["program"], r["grid"], r["steps"]) for r in result.rows[:2]]


def _forbidden():
    return _core._compiling_forbidden()


def test_a_worker_that_joins_later_gets_the_shipped_modules(client, tmp_path):
    """Modules shipped before a worker joined reach it too: a new worker process
    (its own empty cache, AUTUMN_NO_COMPILE=1) takes over from the first two,
    and the units it runs fetch the shipment's packages instead of failing.
    Runs last: it retires the fixture's workers."""
    import sys
    import time

    sokoban = str(tmp_path / "late_sokoban.au")  # not one of the modules built into the package
    with open(os.path.join(PROGRAMS, "sokoban.au"), encoding="utf-8") as f:
        text = f.read().replace("(program", "(program (= lateJoiner 1)", 1)
    with open(sokoban, "w", encoding="utf-8") as f:
        f.write(text)
    shipping = ad.ship_modules(client, [(sokoban, text, None)])
    assert shipping["dataset"] and client.get_dataset(shipping["dataset"])["programs"][0][0] == sokoban
    old = set(client.scheduler_info()["workers"])
    # This file's helpers, as the others import them, before the caller's path (which holds
    # autumnc itself when it runs from the build tree: PYTHONPATH=build/python).
    here = os.path.dirname(os.path.abspath(__file__))
    env = dict(os.environ, AUTUMN_CACHE_DIR=str(tmp_path / "late-cache"), AUTUMN_NO_COMPILE="1",
               PYTHONPATH=os.pathsep.join(p for p in [here, os.environ.get("PYTHONPATH", "")] if p))
    late = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", client.scheduler.address,
                             "--nworkers", "1", "--nthreads", "1", "--no-dashboard"], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while set(client.scheduler_info()["workers"]) == old:
            assert time.monotonic() < deadline, "the new worker did not join"
            time.sleep(0.2)
        (new,) = set(client.scheduler_info()["workers"]) - old
        assert client.run(_forbidden, workers=[new])[new]
        assert not ad.modules_at_hand(client, [(sokoban, text, None)], workers=[new])[new][0]
        client.retire_workers(list(old))
        units = [("sokoban", ad._bench_unit, (text, sokoban, 20, 0))]
        (status, value), = ad._gather(client, units, "bench", False, shipping)
        assert status == "ok", value
        row = json.loads(value)
        assert row["compiled"]["ok"] and row["steps"] == 20, row
        assert ad.modules_at_hand(client, [(sokoban, text, None)], workers=[new])[new][0]
    finally:
        late.terminate()
        late.wait(timeout=30)

