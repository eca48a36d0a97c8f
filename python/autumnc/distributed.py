"""Evaluations, solves, task generation and rollouts on a Dask cluster.

Everything here runs on a ``distributed.Client`` -- a ``LocalCluster`` on a
laptop, or a scheduler's address on a cluster (``Client("tcp://host:8786")``)
-- and is the single-machine computation cut into units: one unit is one task
(``evaluate``, ``solve``), one program and seed (``make_tasks``) or one batch
of environments (``rollouts``), so one slow task never stalls the others. A
unit that fails comes back as a row naming the task and the reason (a worker
that dies is such a row too), never as a lost run. Each unit runs the same C++
as the CLI with the same seeds, so results equal the single-process run's: give
``client=None`` to run the same units in this process.

Modules are compiled once, on the client, and shipped by digest. Before the
units are submitted, ``ship_modules`` builds (or finds) the module of every
program the units need, asks each worker which of them it already has
(``_module_at_hand``: built in, loaded, or in its cache), and sends only the
missing ones: the module's bytes, its manifest (which holds their SHA-256) and
the program text it was built from. The worker files them under its own cache
key through the module store's checks (``_install_module``) -- the digest of
the bytes against the manifest, the program, the ABI, the module's table -- so a
corrupt transfer is refused, and that worker then compiles the module itself if
it can (or the unit's row says why it could not). A worker with
``AUTUMN_NO_COMPILE=1`` in its environment never starts the compiler, so it needs
neither g++ nor the headers. The packages are also published on the cluster as a
Dask dataset (scattered once): a worker that joins after they were shipped
fetches and installs the ones it lacks before its first unit (``_with_modules``).

The evaluation's report and table are the CLI's: rows travel as ``autumn eval``'s
JSON rows, and ``_eval_report`` rebuilds them into the same report and table
(the C++ of ``autumn eval --merge``). Progress is a count on stderr. See
docs/scale.md for setups and measured figures.
"""
import concurrent.futures
import json
import os
import sys
import threading
import time

import numpy as np

from . import _core
from .agent import _DEFAULTS, _PROTOCOLS

__all__ = ["BenchResult", "EvalResult", "bench", "evaluate", "install_modules", "make_tasks", "modules_at_hand", "package_modules",
           "rollouts", "ship_modules", "solve"]

# solve()'s option names and their defaults, and what `protocol` "paper" changes
# unless given: the CLI's, from the one table (autumnc.agent._DEFAULTS, _PROTOCOLS).
_OPTION_DEFAULTS = dict(_DEFAULTS, programs=None)


def _options(protocol, given):
    if protocol not in _PROTOCOLS:
        raise ValueError(f"protocol must be one of {sorted(_PROTOCOLS)}, got {protocol!r}")
    unknown = sorted(set(given) - set(_OPTION_DEFAULTS))
    if unknown:
        raise TypeError(f"unknown option(s) {', '.join(unknown)}; known: {', '.join(sorted(_OPTION_DEFAULTS))}")
    chosen = dict(_OPTION_DEFAULTS)
    chosen.update(_PROTOCOLS[protocol])
    chosen.update({k: v for k, v in given.items() if v is not None})
    if chosen["programs"] is not None:
        chosen["programs"] = os.fspath(chosen["programs"])
    return chosen


# ---------------------------------------------------------------------------- progress

class _Progress:
    """``done/total`` on stderr: redrawn in place on a terminal, a line per unit otherwise."""

    def __init__(self, what, total, enabled):
        self.what, self.total, self.done = what, total, 0
        self.enabled = enabled and total > 0
        self.tty = self.enabled and sys.stderr.isatty()
        self.start = time.monotonic()

    def step(self, name):
        self.done += 1
        if not self.enabled:
            return
        line = f"[{self.done}/{self.total}] {self.what} {name} ({time.monotonic() - self.start:.1f} s)"
        if self.tty:
            sys.stderr.write("\r\033[K" + line + ("\n" if self.done == self.total else ""))
        else:
            sys.stderr.write(line + "\n")
        sys.stderr.flush()


def _guarded(fn, *args):
    """A unit's result as ("ok", value), or its exception as ("error", reason):
    the reason travels back as a row, not as a worker's "Compute Failed" log."""
    try:
        return ("ok", fn(*args))
    except Exception as e:  # noqa: BLE001 -- a row
        return ("error", f"{type(e).__name__}: {e}")


def _gather(client, units, what, progress, shipping=None):
    """Runs ``units`` [(name, fn, args)] and returns their results in order; a
    unit whose future fails (its worker died, its result could not travel)
    gives ``("error", reason)`` in its place. ``shipping`` (ship_modules'
    report): each unit first makes sure its worker has the shipped modules."""
    bar = _Progress(what, len(units), progress)
    results = [None] * len(units)
    if client is None:
        for i, (name, fn, args) in enumerate(units):
            results[i] = _guarded(fn, *args)
            bar.step(name)
        return results
    from distributed import as_completed

    needs = shipping.get("dataset") if shipping else None
    futures = {}
    for i, (name, fn, args) in enumerate(units):
        f = client.submit(_guarded, _with_modules, needs, fn, *args, pure=False,
                          key=f"autumnc-{what}-{i}-{os.urandom(4).hex()}")
        futures[f] = (i, name)
    for f in as_completed(list(futures)):
        i, name = futures[f]
        try:
            results[i] = f.result()
        except Exception as e:  # noqa: BLE001 -- KilledWorker, a result that could not travel, ...
            results[i] = ("error", f"{type(e).__name__}: {e}")
        bar.step(name)
    return results


# ---------------------------------------------------------------------------- modules

def _program_id(program):
    name, text, trigger = program
    return (text, trigger)


def package_modules(programs, max_workers=None):
    """Builds (or finds) the modules of ``programs`` [(name, text, trigger)] in
    this process; returns ``{(text, trigger): package}`` where a package is
    ``{"name", "text", "trigger", "key", "so" (bytes), "manifest", "built_from"}``,
    ``None`` for a module built into the package (nothing to ship), or
    ``{"name", "error"}`` when it cannot be built. Compiles run side by side."""
    unique = {}
    for p in programs:
        unique.setdefault(_program_id(p), p)

    def one(p):
        name, text, trigger = p
        try:
            pkg = _core._module_package(text, name, trigger)
        except Exception as e:  # noqa: BLE001 -- the rows of its tasks say it again
            return {"name": name, "error": str(e)}
        if pkg is not None:
            pkg.update(name=name, text=text, trigger=trigger)
        return pkg

    out = {}
    if not unique:
        return out
    with concurrent.futures.ThreadPoolExecutor(max_workers or os.cpu_count() or 1) as pool:
        for pid, pkg in zip(unique, pool.map(one, unique.values())):
            out[pid] = pkg
    return out


def _worker_inventory(programs):
    """On a worker: which of [(name, text, trigger)] it has without compiling."""
    return [bool(_core._module_at_hand(text, name, trigger)) for name, text, trigger in programs]


def modules_at_hand(client, programs, workers=None):
    """``{worker: [bool]}``: which of ``programs`` [(name, text, trigger)] each
    worker has without compiling (built in, loaded, or in its cache)."""
    return client.run(_worker_inventory, list(programs), workers=workers)


# The datasets of shipped modules this worker process has installed or checked
# (install_modules marks them; a worker that joined later checks on its first unit).
_SHIPPED = set()


def _install_package(p):
    """On a worker: one shipped package through the module store's checks; "" or why refused."""
    return _core._install_module(p["text"], p["name"], p["trigger"], p["so"], p["manifest"], p["built_from"])


def _worker_install(packages, dataset=None):
    """On a worker: installs each package; "" or why refused, per package."""
    out = [_install_package(p) for p in packages]
    if dataset:
        _SHIPPED.add(dataset)
    return out


def _with_modules(dataset, fn, *args):
    """On a worker: ``fn(*args)``, once the worker has every module of the
    shipment published as ``dataset`` (ship_modules). A worker that was there
    when they were shipped has them; one that joined later reads the
    shipment's program list, fetches the packages it lacks and installs them
    (the same checks), once per process. Units carry only the dataset's name."""
    if dataset and dataset not in _SHIPPED:
        from distributed import get_client

        shipment = get_client().get_dataset(dataset)
        for (name, text, trigger), package in zip(shipment["programs"], shipment["packages"]):
            if _core._module_at_hand(text, name, trigger):
                continue
            why = _install_package(package.result())
            if why:
                sys.stderr.write(f"autumnc.distributed: the shipped module of {name} was refused: {why}\n")
        _SHIPPED.add(dataset)
    return fn(*args)


def install_modules(client, packages, workers=None, dataset=None):
    """Sends the shippable ``packages`` (package_modules' values) to the workers
    that lack them. Returns ``{worker: {"had": n, "installed": [names],
    "refused": [(name, reason)], "bytes": shipped}}``. ``dataset``: the name they
    are published under (ship_modules), which the workers then note as installed."""
    shippable = [p for p in packages if p and "so" in p]
    report = {}
    if not shippable:
        return report
    programs = [(p["name"], p["text"], p["trigger"]) for p in shippable]
    inventory = modules_at_hand(client, programs, workers)
    for worker, have in inventory.items():
        missing = [p for p, h in zip(shippable, have) if not h]
        entry = {"had": sum(have), "installed": [], "refused": [], "bytes": 0}
        if missing or dataset:
            answers = client.run(_worker_install, missing, dataset, workers=[worker])[worker]
            for p, why in zip(missing, answers):
                entry["bytes"] += len(p["so"]) + len(p["manifest"]) + len(p["built_from"])
                if why:
                    entry["refused"].append((p["name"], why))
                else:
                    entry["installed"].append(p["name"])
        report[worker] = entry
    return report


def ship_modules(client, programs, workers=None):
    """``package_modules`` then ``install_modules``: every worker ends up with
    the modules of ``programs`` [(name, text, trigger)], each compiled once
    here. Returns ``{"packages": {...}, "workers": install_modules' report,
    "seconds": time spent building and shipping}``;
    a refused transfer is named on stderr (that worker compiles it on use, if it
    may)."""
    start = time.monotonic()
    packages = package_modules(programs)
    shippable = [p for p in packages.values() if p and "so" in p]
    dataset = None
    if shippable:  # for workers that join later (_with_modules): published once, fetched on demand
        import hashlib

        dataset = "autumnc-modules-" + hashlib.sha256("".join(sorted(p["key"] for p in shippable)).encode()).hexdigest()[:16]
        if dataset not in client.list_datasets():
            shipment = {"programs": [(p["name"], p["text"], p["trigger"]) for p in shippable],
                        "packages": client.scatter(shippable)}
            client.publish_dataset(shipment, name=dataset)
    report = install_modules(client, shippable, workers, dataset)
    for worker, entry in report.items():
        for name, why in entry["refused"]:
            sys.stderr.write(f"autumnc.distributed: {worker} refused the module of {name}: {why}\n")
    return {"packages": packages, "workers": report, "seconds": time.monotonic() - start, "dataset": dataset}


def _task_programs(files, options, find_answers):
    programs = []
    text = json.dumps(options)
    for f in files:
        try:
            programs.extend(_core._task_module_programs(f, text, find_answers))
        except Exception:  # noqa: BLE001 -- an unreadable task: its row says why
            pass
    return programs


def _ship_for(client, files, options, find_answers, ship):
    if client is None or not ship or options["engine"] != "compiled":
        return None
    return ship_modules(client, _task_programs(files, options, find_answers))


# ---------------------------------------------------------------------------- eval

def _error_row(task, why):
    return {"task": task, "type": "?", "score": None, "seconds": 0.0, "compile_seconds": 0.0, "throughput": 0.0,
            "unit": "", "detail": "", "answers": False, "stochastic": False, "answered": True, "error": why}


def _eval_unit(file, root, options_text, threads):
    """On a worker: one task, as ``autumn eval`` runs it; its row as eval's JSON text."""
    return _core._eval_task(file, root, options_text, threads)


class _Report:
    """What a distributed CLI command gives back: ``report`` (the dict the
    command prints with --json), ``table`` (the text it prints), ``rows`` (the
    report's rows, under ``_ROWS``), ``shipping`` (ship_modules' report, None
    when nothing was shipped) and ``seconds`` (wall time)."""

    _ROWS = "rows"

    def __init__(self, report, table, shipping, seconds):
        self.report, self.table, self.shipping, self.seconds = report, table, shipping, seconds

    @property
    def rows(self):
        return self.report[self._ROWS]


class EvalResult(_Report):
    """A distributed ``autumn eval`` (see _Report); its rows are the report's "tasks"."""

    _ROWS = "tasks"

    @property
    def ok(self):
        """No task failed or went unanswered (the CLI's exit status 0)."""
        return all("error" not in r and r.get("answered", True) for r in self.rows)

    def __repr__(self):
        t = self.report["totals"]
        return f"autumnc.distributed.EvalResult({t['tasks']} tasks, {t['errors']} errors, {self.seconds:.1f} s)"


def evaluate(client, folder, protocol="default", threads=1, progress=True, ship=True, **options):
    """``autumn eval FOLDER`` with one unit per task on ``client`` (``None``:
    in this process). ``options`` are ``autumnc.solve``'s (rollouts, seed,
    engine, ...); ``threads`` is each task's solver threads (1: one task per
    worker thread). Returns an ``EvalResult``; ``print(result.table)`` is the
    CLI's output, ``result.report`` its JSON."""
    folder = os.fspath(folder)
    chosen = _options(protocol, options)
    text = json.dumps(chosen)
    start = time.monotonic()
    files = _core._find_tasks(folder)
    shipping = _ship_for(client, files, chosen, True, ship)
    units = [(os.path.relpath(f, folder), _eval_unit, (f, folder, text, threads)) for f in files]
    rows = []
    for (name, _, _), (status, value) in zip(units, _gather(client, units, "eval", progress, shipping)):
        rows.append(value if status == "ok" else json.dumps(_error_row(name, value)))
    report, table = _core._eval_report(rows, protocol, text, [folder])
    return EvalResult(json.loads(report), table, shipping, time.monotonic() - start)


# ---------------------------------------------------------------------------- solve, make-task

def _solve_unit(task, options):
    from . import agent

    return agent.solve(task, **options)


def solve(client, tasks, protocol="default", threads=1, progress=True, ship=True, answers=None, **options):
    """``autumnc.solve`` over a list of task files, one unit each; returns the
    results in order, ``{"task": path, "error": reason}`` for a task that failed.
    ``answers`` (one path, or a list parallel to ``tasks``) is solve's."""
    tasks = [os.fspath(t) for t in tasks]
    chosen = _options(protocol, options)
    answer_list = answers if isinstance(answers, (list, tuple)) else [answers] * len(tasks)
    if len(answer_list) != len(tasks):
        raise ValueError(f"answers has {len(answer_list)} entries for {len(tasks)} tasks")
    for name in ("cost", "keep_states"):  # the CLI's, not autumnc.solve's
        if chosen.pop(name) != _OPTION_DEFAULTS[name]:
            raise TypeError(f"autumnc.solve has no option {name!r}")
    per_task = []
    for a in answer_list:
        o = dict(chosen, threads=threads)  # the protocol is applied already
        if a is not None:
            o["answers"] = os.fspath(a)
        per_task.append(o)
    if client is not None and ship and chosen["engine"] == "compiled":
        programs = []
        for t, o in zip(tasks, per_task):
            programs.extend(_task_programs([t], {k: o.get(k) for k in ("engine", "programs", "answers")}, False))
        shipping = ship_modules(client, programs)
    else:
        shipping = None
    units = [(t, _solve_unit, (t, o)) for t, o in zip(tasks, per_task)]
    return [value if status == "ok" else {"task": t, "error": value}
            for t, (status, value) in zip(tasks, _gather(client, units, "solve", progress, shipping))]


def _make_unit(kind, program, seed, out, options):
    from . import agent

    prompt, answers = agent.make_task(kind, program, seed=seed, out=out, with_answers=True, **options)
    return {"program": program, "seed": seed, "out": out, "task": prompt, "answers": answers}


def make_tasks(client, kind, programs, seeds=(0,), out_dir=None, progress=True, ship=True, **options):
    """``autumnc.make_task(kind, program, seed=s)`` for every program and seed,
    one unit each; returns the made tasks in order as ``{"program", "seed",
    "out", "task", "answers"}`` or ``{"program", "seed", "error"}``. With
    ``out_dir`` each is written to ``out_dir/prompts/NAME_KIND[_sSEED].json``
    (the seed only when several are given), its answers under ``answers/``.
    The programs' modules are shipped; a cd task's changed program is compiled
    where it is made (or give engine="interp")."""
    programs = [os.fspath(p) for p in programs]
    seeds = list(seeds)
    engine = options.get("engine", "compiled")
    if client is not None and ship and engine == "compiled":
        listed = []
        for p in programs:
            try:
                with open(p, encoding="utf-8") as f:
                    listed.append((p, f.read(), None))
            except OSError:  # its rows say why
                pass
        shipping = ship_modules(client, listed)
    else:
        shipping = None
    units, meta = [], []
    for p in programs:
        stem = os.path.splitext(os.path.basename(p))[0]
        for s in seeds:
            out = None
            if out_dir is not None:
                suffix = f"_s{s}" if len(seeds) > 1 else ""
                out = os.path.join(os.fspath(out_dir), "prompts", f"{stem}_{kind}{suffix}.json")
            units.append((f"{stem} seed {s}", _make_unit, (kind, p, s, out, options)))
            meta.append((p, s))
    return [value if status == "ok" else {"program": p, "seed": s, "error": value}
            for (p, s), (status, value) in zip(meta, _gather(client, units, "make-task", progress, shipping))]


# ---------------------------------------------------------------------------- bench

class BenchResult(_Report):
    """A distributed ``autumn bench`` (see _Report; the report also has
    "median_ratio" and "median_compiled_step_us"). Each row was measured on one
    worker, alone on its thread: rows from different machines compare those machines."""

    @property
    def ok(self):
        """Every program loaded and ran on both engines (the CLI's exit status 0)."""
        return all("error" not in r and r["interp"]["ok"] and r["compiled"]["ok"] for r in self.rows)

    def __repr__(self):
        return (f"autumnc.distributed.BenchResult({len(self.rows)} programs, median compiled/interp "
                f"{self.report['median_ratio']:.1f}x, {self.seconds:.1f} s)")


def _program_paths(programs):
    """Program files as `autumn bench` expands them: a folder gives its .au and
    .sexp files (sorted), anything else is taken as a file."""
    out = []
    for p in programs:
        p = os.fspath(p)
        if os.path.isdir(p):
            out.extend(sorted(os.path.join(p, f) for f in os.listdir(p) if f.endswith((".au", ".sexp"))))
        else:
            out.append(p)
    return out


def _bench_unit(text, name, steps, seed):
    """On a worker: one program's ``autumn bench`` row, as JSON text."""
    return _core._bench_program(text, name, steps, seed)


def bench(client, programs, steps=1000, seed=0, progress=True, ship=True):
    """``autumn bench PROGRAMS`` (interpreter vs compiled engine: steps/s with
    and without rendering, clone cost) with one unit per program on ``client``
    (``None``: in this process). ``programs`` are program files or folders of
    them. The compiled modules are built once and shipped (``ship``). Returns a
    ``BenchResult``; ``print(result.table)`` is the CLI's output. A program that
    cannot be read or loaded is a row with its "error"."""
    from .agent import _check_args

    _check_args("autumnc.distributed.bench", steps=(steps, "count"), seed=(seed, "count"))
    start = time.monotonic()
    listed, rows = [], {}
    for i, path in enumerate(_program_paths(programs)):
        name = os.path.splitext(os.path.basename(path))[0]
        try:
            with open(path, encoding="utf-8") as f:
                listed.append((i, path, f.read()))
        except (OSError, UnicodeDecodeError) as e:
            rows[i] = json.dumps({"program": name, "error": f"cannot read {path}: {e}"})
    shipping = None
    if client is not None and ship:  # a program that does not load is packaged as an error, not shipped
        shipping = ship_modules(client, [(path, text, None) for _, path, text in listed])
    units = [(os.path.splitext(os.path.basename(path))[0], _bench_unit, (text, path, steps, seed))
             for _, path, text in listed]
    for (i, _, _), (name, _, _), (status, value) in zip(listed, units, _gather(client, units, "bench", progress, shipping)):
        rows[i] = value if status == "ok" else json.dumps({"program": name, "error": value})
    report, table = _core._bench_report([rows[i] for i in sorted(rows)])
    return BenchResult(json.loads(report), table, shipping, time.monotonic() - start)


# ---------------------------------------------------------------------------- rollouts

_local = threading.local()


def _vec_env(text, name, batch, engine, trigger, env_threads):
    """This worker thread's VecEnv for a program (kept: the next batch resets it)."""
    from .envs import VecEnv

    cache = getattr(_local, "envs", None)
    if cache is None:
        cache = _local.envs = {}
    key = (text, name, batch, engine, trigger, env_threads)
    if key not in cache:
        cache[key] = VecEnv((text, name), batch, num_threads=env_threads, engine=engine, trigger=trigger)
    return cache[key]


def _rollout_unit(text, name, batch, steps, seed, index, engine, trigger, env_threads, policy):
    """On a worker: ``batch`` environments for ``steps`` steps from seed
    ``seed + index*batch``, actions drawn from ``policy(rng, batch, n_actions)``
    (uniform without one) with rng ``numpy.random.default_rng([seed, index])``."""
    env = _vec_env(text, name, batch, engine, trigger, env_threads)
    obs, info = env.reset(seed=seed + index * batch)
    n = env.single_action_space.n
    rng = np.random.default_rng([seed, index])
    grid = obs.shape[1:]
    out_obs = np.empty((batch, steps + 1) + grid, np.uint8)
    actions = np.empty((batch, steps), np.int64)
    rewards = np.empty((batch, steps), np.float32)
    terminated = np.empty((batch, steps), bool)
    out_obs[:, 0] = obs
    for t in range(steps):
        a = rng.integers(0, n, size=batch) if policy is None else np.asarray(policy(rng, batch, n), np.int64)
        obs, r, term, trunc, info = env.step(a)
        out_obs[:, t + 1] = obs
        actions[:, t], rewards[:, t], terminated[:, t] = a, r, term | trunc
    return out_obs, actions, rewards, terminated, _core.colour_names()


def rollouts(client, program, episodes, steps, batch=64, seed=0, engine="compiled", trigger=None, env_threads=1,
             policy=None, progress=False, ship=True):
    """Random-policy (or ``policy``) rollouts of a program, one unit per batch
    of ``batch`` environments, each on the worker thread's VecEnv. Environment
    e (0..episodes-1) starts from seed ``seed + e``; an episode that ends is
    reset by the next step, as VecEnv does. Returns numpy arrays: ``obs``
    [episodes, steps+1, H, W] uint8, ``actions`` [episodes, steps] int64,
    ``rewards`` [episodes, steps] float32, ``done`` [episodes, steps] bool.
    ``policy(rng, n, n_actions)`` returns n actions (it must pickle). Colour
    ids are this process's (``autumnc.colour_names()``), whichever worker drew
    the frames. The same arguments give the same arrays on any cluster or with
    ``client=None``."""
    path = os.fspath(program)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if episodes < 1 or steps < 1 or batch < 1:
        raise ValueError("episodes, steps and batch must be at least 1")
    shipping = None
    if client is not None and ship and engine in ("compiled", "auto"):
        shipping = ship_modules(client, [(path, text, trigger)])
    count = (episodes + batch - 1) // batch
    units = [(f"batch {i}", _rollout_unit, (text, path, batch, steps, seed, i, engine, trigger, env_threads, policy))
             for i in range(count)]
    parts = []
    for i, (status, value) in enumerate(_gather(client, units, "rollouts", progress, shipping)):
        if status != "ok":
            raise RuntimeError(f"rollout batch {i} of {path} failed: {value}")
        # Colours beyond the AutumnBench table have ids of the worker's own: into ours.
        lut = np.array([_core._colour_id(name) for name in value[4]], np.uint8)
        parts.append((lut[value[0]],) + value[1:4])
    obs, actions, rewards, done = (np.concatenate([p[k] for p in parts])[:episodes] for k in range(4))
    return {"obs": obs, "actions": actions, "rewards": rewards, "done": done}
