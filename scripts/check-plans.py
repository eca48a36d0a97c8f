#!/usr/bin/env python3
"""Check the plans of an `autumn eval --json-out FILE` run independently of the planner.

The planner searches on the compiled engine and verifies its plan with its own
replay. This script trusts none of that: for every planning task it reads the
prompt (goal and mask), the answers file (the world's seed) and the plan from
the eval JSON, replays the plan with the Python package on the tree-walking
interpreter (`autumnc.Program.run(engine="interp")`: the frames of `autumn run
--json`, colour names), and compares colour *names* on the mask (the goal's ids
read through the task's color_dict.yaml, else AutumnBench's table), at every
frame on the way, the first one included. It also counts the plans no longer
than the generator's K.

    PYTHONPATH=build/python /usr/bin/python3 scripts/check-plans.py TASK_DIR EVAL_JSON

Exit 0 when every plan the eval scored 1 reaches the goal here and every plan
scored 0 does not; 1 on any disagreement; 2 on bad input.
"""
import json
import pathlib
import sys


def die(msg, code=2):
    print(f"check-plans: {msg}", file=sys.stderr)
    sys.exit(code)


def colour_table(task_dir, autumnc):
    """Ids to names, from the task folder's color_dict.yaml ("ID: name" lines);
    without one, AutumnBench's table (ids 0-39 of autumnc.colour_names())."""
    path = task_dir / "color_dict.yaml"
    if not path.is_file():
        return dict(enumerate(autumnc.colour_names()[:40]))
    table = {}
    for n, line in enumerate(path.read_text().splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        key, sep, name = line.partition(":")
        if not sep or not key.strip().isdigit():
            die(f"{path}:{n}: expected 'ID: name'")
        table[int(key)] = name.strip().strip("'\"")
    return table


def program_path(task_dir, name):
    for ext in (".au", ".sexp"):
        p = task_dir / "programs" / (name + ext)
        if p.is_file():
            return p
    die(f"no program {name} under {task_dir / 'programs'}")


def reaches(autumnc, task_dir, ids, prompt, seed, plan):
    """True when some frame of the plan's episode on the interpreter (the first
    one included) shows the goal's colours on the mask."""
    goal, mask = prompt["goal"], prompt["mask"]
    want = [[ids.get(c, f"?{c}") for c in row] for row in goal]
    program = autumnc.Program(str(program_path(task_dir, prompt["program"])))
    frames = program.run(seed=seed, actions=plan, engine="interp")["traces"][0]["frames"]
    for frame in frames:
        rows = [line.split() for line in frame]
        if [len(r) for r in rows] != [len(r) for r in want]:
            return False
        if all(not m or got == exp for row, wrow, mrow in zip(rows, want, mask)
               for got, exp, m in zip(row, wrow, mrow)):
            return True
    return False


def main():
    if len(sys.argv) != 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        sys.exit(0 if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help") else 2)
    task_dir, eval_path = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    if not task_dir.is_dir():
        die(f"{task_dir}: not a folder")
    try:
        rows = json.loads(eval_path.read_text())["tasks"]
    except (OSError, ValueError, KeyError) as e:
        die(f"{eval_path}: not an eval JSON ({e})")
    try:
        import autumnc
    except ImportError as e:
        die(f"cannot import autumnc ({e}); run with PYTHONPATH=build/python /usr/bin/python3")
    ids = colour_table(task_dir, autumnc)

    checked = agree = reached = within_k = 0
    for row in rows:
        if row.get("type") != "planning" or "result" not in row:
            continue
        prompt_path = task_dir / row["task"]
        prompt = json.loads(prompt_path.read_text())
        answers_path = task_dir / "answers" / prompt_path.name
        seed = json.loads(answers_path.read_text()).get("seed", 0) if answers_path.is_file() else 0
        plan = row["result"].get("plan") or []
        found = bool(row["result"].get("found"))
        here = found and reaches(autumnc, task_dir, ids, prompt, seed, plan)
        checked += 1
        reached += here
        if here and row.get("reference_length") is not None and len(plan) <= row["reference_length"]:
            within_k += 1
        if here == (row.get("score") == 1.0):
            agree += 1
        else:
            print(f"DISAGREE {row['task']}: eval scored {row.get('score')}, interpreter replay "
                  f"{'reaches' if here else 'does not reach'} the goal")
    print(f"check-plans: {checked} planning tasks; {reached} plans reach the goal on the interpreter "
          f"(independent replay), {within_k} of them no longer than the generator's K; "
          f"{agree}/{checked} agree with the eval's scores")
    sys.exit(0 if agree == checked else 1)


if __name__ == "__main__":
    main()
