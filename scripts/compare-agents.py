#!/usr/bin/python3
"""compare-agents.py — a figure and a table comparing agents' scores per task type.

Usage: /usr/bin/python3 scripts/compare-agents.py RUN... --out PREFIX [--title TEXT]

Each RUN is a JSON file, optionally named: LABEL=FILE. A run is what
`autumn eval DIR --json-out FILE` writes (the simulator agent, with
`--protocol paper` the paper's), what `autumn baseline random TASKS --json-out
FILE` writes (the random agent), or a user's own results in the same shape:

    {"agent": {"name": "...", ...settings...},      (optional)
     "task_set": ["folder", ...],                   (optional)
     "tasks": [{"task": "...", "type": "mfp" | "cd" | "planning", "score": 0.5}, ...]}

A task whose score is null (no answers to score against) or that has an "error"
is left out of the means and counted in the table. Writes PREFIX.png and
PREFIX.svg (mean score per task type per agent, error bars one standard error
of the mean over tasks, as in the AutumnBench paper's figures) and PREFIX.md
(the same numbers, with the task sets, each agent's settings and seeds). Needs
Debian's python3-matplotlib (run it with /usr/bin/python3). Exit status: 0, or 2
with a one-line reason for a bad argument or run file.
"""
import argparse
import json
import math
import os
import sys

TYPES = ["mfp", "cd", "planning"]
TYPE_NAMES = {"mfp": "masked-frame prediction", "cd": "change detection", "planning": "planning"}


class RunError(Exception):
    pass


def load_run(arg):
    """(label, run dict) from LABEL=FILE or FILE."""
    label, path = (arg.split("=", 1) if "=" in arg and not os.path.exists(arg) else (None, arg))
    try:
        with open(path, encoding="utf-8") as f:
            run = json.load(f)
    except OSError as e:
        raise RunError(f"{path}: cannot read: {e.strerror}")
    except json.JSONDecodeError as e:
        raise RunError(f"{path}: not JSON: {e.msg} at line {e.lineno}")
    if not isinstance(run, dict) or not isinstance(run.get("tasks"), list):
        raise RunError(f"{path}: no \"tasks\" list (expected autumn eval/baseline --json output)")
    for i, t in enumerate(run["tasks"]):
        if not isinstance(t, dict) or "type" not in t:
            raise RunError(f"{path}: task {i} has no \"type\"")
        s = t.get("score")
        if s is not None and not isinstance(s, (int, float)):
            raise RunError(f"{path}: task {i} has a score that is not a number: {s!r}")
    agent = run.get("agent") if isinstance(run.get("agent"), dict) else {}
    if not label:
        label = agent.get("name") or os.path.splitext(os.path.basename(path))[0]
    return label, path, run


def summarise(run):
    """{type: (mean, sem, scored, unscored, errors)} over the run's tasks."""
    out = {}
    for ty in TYPES:
        rows = [t for t in run["tasks"] if t.get("type") == ty]
        errors = sum(1 for t in rows if t.get("error"))
        scores = [float(t["score"]) for t in rows if not t.get("error") and t.get("score") is not None]
        unscored = len(rows) - errors - len(scores)
        if scores:
            mean = sum(scores) / len(scores)
            var = sum((s - mean) ** 2 for s in scores) / (len(scores) - 1) if len(scores) > 1 else 0.0
            sem = math.sqrt(var / len(scores))
        else:
            mean, sem = None, None
        out[ty] = (mean, sem, len(scores), unscored, errors)
    return out


def table(runs, summaries):
    lines = ["| agent | " + " | ".join(TYPE_NAMES[t] for t in TYPES) + " |",
             "|---|" + "---|" * len(TYPES)]
    for (label, _, _), s in zip(runs, summaries):
        cells = []
        for ty in TYPES:
            mean, sem, n, unscored, errors = s[ty]
            cell = "-" if mean is None else f"{mean:.3f} ± {sem:.3f} (n={n})"
            extra = [f"{unscored} unscored"] * bool(unscored) + [f"{errors} errors"] * bool(errors)
            cells.append(cell + (" " + ", ".join(extra) if extra else ""))
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def figure(runs, summaries, prefix, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    width = 0.8 / max(1, len(runs))
    fig, ax = plt.subplots(figsize=(2.2 + 2.2 * len(TYPES), 4.2))
    for k, ((label, _, _), s) in enumerate(zip(runs, summaries)):
        xs = [i - 0.4 + width * (k + 0.5) for i in range(len(TYPES))]
        means = [s[t][0] if s[t][0] is not None else 0.0 for t in TYPES]
        sems = [s[t][1] if s[t][1] is not None else 0.0 for t in TYPES]
        bars = ax.bar(xs, means, width, yerr=sems, capsize=3, label=label)
        for ty, bar in zip(TYPES, bars):
            # Named in the SVG (id="bar:LABEL:TYPE"), so tests read the bars back.
            bar.set_gid(f"bar:{label}:{ty}")
    ax.set_xticks(range(len(TYPES)))
    ax.set_xticklabels([TYPE_NAMES[t] for t in TYPES])
    ax.set_ylabel("mean score")
    ax.set_ylim(0, 1.05)
    ax.set_title(title)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    fig.savefig(prefix + ".png", dpi=120)
    fig.savefig(prefix + ".svg")
    plt.close(fig)


def report(runs, summaries, title):
    parts = [f"# {title}", "", "Mean score per task type (± one standard error of the mean over tasks; n tasks "
             "scored).", "", table(runs, summaries), "", "## Runs", ""]
    for label, path, run in runs:
        agent = run.get("agent") or {}
        settings = ", ".join(f"{k} {v}" for k, v in agent.items() if k != "name") or "not stated"
        task_set = ", ".join(run.get("task_set") or []) or "not stated"
        parts.append(f"- **{label}** (`{path}`): {len(run['tasks'])} tasks from {task_set}; settings: {settings}")
    return "\n".join(parts) + "\n"


def main(argv):
    ap = argparse.ArgumentParser(description="Compare agents' AutumnBench scores per task type: a figure and a table.")
    ap.add_argument("runs", nargs="+", metavar="RUN", help="LABEL=FILE or FILE: an eval/baseline JSON")
    ap.add_argument("--out", required=True, metavar="PREFIX", help="writes PREFIX.png, PREFIX.svg and PREFIX.md")
    ap.add_argument("--title", default="AutumnBench: mean score per task type", help="the figure's title")
    args = ap.parse_args(argv)
    try:
        runs = [load_run(a) for a in args.runs]
    except RunError as e:
        print(f"compare-agents: {e}", file=sys.stderr)
        return 2
    labels = [r[0] for r in runs]
    if len(set(labels)) != len(labels):
        print(f"compare-agents: two runs are named alike ({', '.join(labels)}); name them LABEL=FILE",
              file=sys.stderr)
        return 2
    out_dir = os.path.dirname(os.path.abspath(args.out))
    if not os.path.isdir(out_dir):
        print(f"compare-agents: no folder {out_dir} for --out", file=sys.stderr)
        return 2
    summaries = [summarise(r[2]) for r in runs]
    try:
        figure(runs, summaries, args.out, args.title)
    except ImportError:
        print("compare-agents: needs matplotlib: apt-get install python3-matplotlib, and run /usr/bin/python3",
              file=sys.stderr)
        return 2
    text = report(runs, summaries, args.title)
    with open(args.out + ".md", "w", encoding="utf-8") as f:
        f.write(text)
    print(table(runs, summaries))
    print(f"wrote {args.out}.png, {args.out}.svg and {args.out}.md")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
