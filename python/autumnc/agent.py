"""The simulator agent and program tools, returning what the CLI prints as JSON.

``solve(task)`` is ``autumn solve TASK --json``; ``baseline_random(tasks)`` is
``autumn baseline random TASKS --json``; ``make_task(kind, program)`` is
``autumn make-task`` (the task as a dict; written to ``out`` when given);
``Program(path).run(...)`` is ``autumn run --json``, ``.check(traces)`` is
``autumn check`` as a dict, ``.compile()`` reports what the compiled engine made
of the program.
"""
import json
import numbers
import os

from . import _core


_KINDS = {
    "int": ("an integer", lambda v: isinstance(v, numbers.Integral) and not isinstance(v, bool)),
    "number": ("a number", lambda v: isinstance(v, numbers.Real) and not isinstance(v, bool)),
    "str": ("a string", lambda v: isinstance(v, str)),
    "bool": ("True or False", lambda v: isinstance(v, (bool, numbers.Integral))),
}


def _check_args(where, **given):
    """Raises TypeError naming ``where``'s own argument (not the private _core
    call's ``arg3``) when a value is not of the kind given as (value, kind);
    "count" is an integer that must not be negative (ValueError)."""
    for name, (value, kind) in given.items():
        what, ok = _KINDS["int" if kind == "count" else kind]
        if not ok(value):
            raise TypeError(f"{where}: {name} must be {what}, got {type(value).__name__} {value!r}")
        if kind == "count" and value < 0:
            raise ValueError(f"{where}: {name} must not be negative, got {value}")


def _action_list(where, actions):
    """The actions as a list of strings ("left", "click 3 4", ...), or TypeError."""
    if isinstance(actions, str):
        raise TypeError(f"{where}: actions must be a list of action strings such as ['left', 'click 3 4'], "
                        f"got the string {actions!r}")
    out = list(actions)
    for i, a in enumerate(out):
        if not isinstance(a, str):
            raise TypeError(f"{where}: actions[{i}] must be an action string such as 'left', 'noop' or "
                            f"'click 3 4', got {type(a).__name__} {a!r}")
    return out


# The agent's defaults and what ``protocol`` sets, unless given explicitly, read
# from the one table the CLI reads too (harness/agent/solve_common): "default" is
# the agent as built; "paper" is the AutumnBench paper's simulator agent (``autumn
# solve --protocol paper``: 10,000 samples without seed inversion, random
# exploration, BFS over ten actions to depth 10).
_PROTOCOL_KEYS = ("rollouts", "seed_inversion", "policy", "search", "depth")
_PROTOCOLS = {p: {k: json.loads(_core._solve_defaults(p))[k] for k in _PROTOCOL_KEYS} for p in _core._protocol_names()}
_DEFAULTS = json.loads(_core._solve_defaults("default"))


def solve(task, engine=_DEFAULTS["engine"], rollouts=None, threads=0, seed=_DEFAULTS["seed"],
          max_steps=_DEFAULTS["max_steps"], policy=None, depth=None, nodes=_DEFAULTS["nodes"], search=None,
          max_plan=_DEFAULTS["max_plan"], time_limit=float(_DEFAULTS["time_limit"]), programs=None,
          answers=None, protocol="default", seed_inversion=None):
    """Answer an AutumnBench task file (MFP, change detection or planning), like ``autumn solve --json``.

    ``protocol`` ("default" or "paper") chooses the settings of ``rollouts``,
    ``seed_inversion``, ``policy``, ``search`` and ``depth`` that are not given
    (None); arguments given explicitly still apply, as on the command line."""
    if protocol not in _PROTOCOLS:
        raise ValueError(f"protocol must be one of {sorted(_PROTOCOLS)}, got {protocol!r}")
    chosen = dict(_PROTOCOLS[protocol])
    for name, value in (("rollouts", rollouts), ("seed_inversion", seed_inversion), ("policy", policy),
                        ("search", search), ("depth", depth)):
        if value is not None:
            chosen[name] = value
    _check_args("autumnc.solve", engine=(engine, "str"), rollouts=(chosen["rollouts"], "count"),
                threads=(threads, "count"), seed=(seed, "count"), max_steps=(max_steps, "count"),
                policy=(chosen["policy"], "str"), depth=(chosen["depth"], "count"), nodes=(nodes, "count"),
                search=(chosen["search"], "str"), max_plan=(max_plan, "count"), time_limit=(time_limit, "number"),
                seed_inversion=(chosen["seed_inversion"], "bool"))
    return json.loads(_core._solve(os.fspath(task), engine, chosen["rollouts"], threads, seed, max_steps,
                                   chosen["policy"], chosen["depth"], nodes, chosen["search"], max_plan,
                                   float(time_limit), os.fspath(programs) if programs else "",
                                   os.fspath(answers) if answers else "", bool(chosen["seed_inversion"])))


def baseline_random(tasks, engine="compiled", rollouts=50, timeout=1000, seed=0, threads=0, programs=None):
    """The paper's random agent on task files or folders, like ``autumn baseline random --json``.

    ``tasks`` is a path or a list of paths. Returns the report: "agent" (its
    settings), "task_set" and "tasks", one row per task with "score" (MFP:
    chance; change detection: the probability that the trigger condition fires
    within ``timeout`` steps; planning: the probability of reaching the goal),
    "stderr", "mean_steps" and "successes" of ``rollouts`` episodes, or "error"."""
    _check_args("autumnc.baseline_random", engine=(engine, "str"), rollouts=(rollouts, "count"),
                timeout=(timeout, "count"), seed=(seed, "count"), threads=(threads, "count"))
    paths = [os.fspath(tasks)] if isinstance(tasks, (str, os.PathLike)) else [os.fspath(t) for t in tasks]
    return json.loads(_core._baseline_random(paths, engine, rollouts, timeout, seed, threads,
                                             os.fspath(programs) if programs else ""))


def make_task(kind, program, seed=0, steps=None, out=None, env_seed=0, engine="compiled", batch=200,
              masked_frames=3, extend_colours=False, answers=None, with_answers=False):
    """Generate an "mfp", "planning" or "cd" (change detection) task for a program file.

    Returns the prompt (what a solver may see); with ``with_answers=True`` a pair
    ``(prompt, answers)`` (the environment seed, correct_idx, reference_plan, or
    for cd t_star and the condition). ``out`` writes both as ``autumn make-task
    --out`` does; ``answers`` names the answers file. A cd task needs ``out``
    (under prompts/): its changed program is written to the sibling programs/,
    and ``steps`` is the clock value the change starts at."""
    _check_args("autumnc.make_task", kind=(kind, "str"), seed=(seed, "count"), env_seed=(env_seed, "count"),
                engine=(engine, "str"), batch=(batch, "count"), masked_frames=(masked_frames, "count"),
                extend_colours=(extend_colours, "bool"))
    if steps is not None:
        _check_args("autumnc.make_task", steps=(steps, "count"))
    made = json.loads(_core._make_task(kind, os.fspath(program), seed, -1 if steps is None else steps,
                                       os.fspath(out) if out else "", env_seed, engine, batch, masked_frames,
                                       extend_colours, os.fspath(answers) if answers else ""))
    return (made["task"], made["answers"]) if with_answers else made["task"]


class Program:
    """An Autumn program file (optionally with a trigger condition)."""

    def __init__(self, path, trigger=None):
        self.path = os.fspath(path)
        self.trigger = trigger
        if not os.path.isfile(self.path):
            raise FileNotFoundError(f"no Autumn program at {self.path!r}")

    def compile(self):
        """Find or build the compiled module: {"ok", "kind", "seconds", "warnings", ...}."""
        return json.loads(_core._compile(self.path, self.trigger))

    def run(self, seed=0, actions=(), engine="compiled"):
        """One episode as a trace dict (the conformance format), like ``autumn run --json``.

        ``seed``: the episode's random seed; ``actions``: action strings ("noop",
        "left", "right", "up", "down", "click X Y"); ``engine``: "compiled" or "interp"."""
        _check_args("Program.run", seed=(seed, "count"), engine=(engine, "str"))
        return json.loads(_core._run(self.path, seed, _action_list("Program.run", actions), self.trigger, engine))

    def check(self, traces, engine="compiled"):
        """Replay a trace file, like ``autumn check``: counts and mismatch reports."""
        _check_args("Program.check", engine=(engine, "str"))
        return json.loads(_core._check(self.path, os.fspath(traces), engine))

    def __repr__(self):
        return f"autumnc.Program({self.path!r})"
