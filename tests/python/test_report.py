"""The comparison report (scripts/compare-agents.py) and the random agent from Python.

The report's numbers are read back from the Markdown table it writes and its
bars from the SVG (each bar carries id="bar:AGENT:TYPE"); the end-to-end test
runs the three agents (the random baseline, the simulator agent by default and
under the paper's protocol) on the repository's change-detection tasks.
"""
import json
import os
import re
import subprocess
import sys

import pytest

import autumnc

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "scripts", "compare-agents.py")
BUILD = os.environ.get("AUTUMN_BUILD_DIR") or os.path.join(REPO, "build")  # as conftest.BUILD
AUTUMN = os.path.join(BUILD, "autumn")


def report(tmp_path, *runs):
    out = str(tmp_path / "cmp")
    r = subprocess.run([sys.executable, SCRIPT, *runs, "--out", out], capture_output=True, text=True)
    return r, out


def table_cells(md):
    """{agent: {type: mean}} from the report's Markdown table."""
    rows = [l for l in md.splitlines() if l.startswith("| ") and not l.startswith("| agent")]
    out = {}
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        means = [float(c.split()[0]) if c[0].isdigit() else None for c in cells[1:]]
        out[cells[0]] = dict(zip(["mfp", "cd", "planning"], means))
    return out


def test_report_numbers_and_bars(tmp_path):
    runs = {
        "ours": [("mfp", 1.0), ("mfp", 0.0), ("cd", 0.5), ("cd", 1.0), ("planning", 1.0)],
        "random": [("mfp", 0.25), ("mfp", 0.25), ("cd", 0.1), ("cd", 0.3), ("planning", 0.0)],
        "mine": [("mfp", 0.5), ("cd", None), ("cd", 0.75), ("planning", 0.5), ("planning", 0.0)],
    }
    paths = []
    for name, rows in runs.items():
        p = tmp_path / f"{name}.json"
        p.write_text(json.dumps({"agent": {"name": name, "seed": 7}, "task_set": ["tasks"],
                                 "tasks": [{"task": f"t{i}", "type": t, "score": s} for i, (t, s) in enumerate(rows)]}))
        paths.append(str(p))
    r, out = report(tmp_path, *paths)
    assert r.returncode == 0, r.stderr
    for ext in ("png", "svg", "md"):
        assert os.path.getsize(f"{out}.{ext}") > 0
    with open(out + ".png", "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    got = table_cells(open(out + ".md").read())
    for name, rows in runs.items():
        for ty in ("mfp", "cd", "planning"):
            scores = [s for t, s in rows if t == ty and s is not None]
            assert got[name][ty] == pytest.approx(sum(scores) / len(scores), abs=5e-4), (name, ty)
    md = open(out + ".md").read()
    assert "1 unscored" in md and "seed 7" in md
    svg = open(out + ".svg").read()
    bars = re.findall(r'id="bar:([^:"]+):([a-z]+)"', svg)
    assert sorted(bars) == sorted((n, t) for n in runs for t in ("mfp", "cd", "planning"))


def test_report_refuses_bad_runs(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"tasks": 3}')
    r, _ = report(tmp_path, str(bad))
    assert r.returncode == 2 and "no \"tasks\" list" in r.stderr
    r, _ = report(tmp_path, str(tmp_path / "missing.json"))
    assert r.returncode == 2 and "cannot read" in r.stderr
    ok = tmp_path / "ok.json"
    ok.write_text('{"tasks": []}')
    r, _ = report(tmp_path, str(ok), str(ok))
    assert r.returncode == 2 and "named alike" in r.stderr


def test_random_baseline_from_python_matches_the_cli(tmp_path):
    tasks = os.path.join(REPO, "tasks", "cd")
    py = autumnc.baseline_random(tasks, rollouts=8, timeout=200, seed=5, engine="interp")
    assert py["agent"]["name"] == "random" and len(py["tasks"]) == 3
    cli = subprocess.run([AUTUMN, "baseline", "random", tasks, "--rollouts", "8", "--timeout", "200", "--seed", "5",
                          "--engine", "interp", "--json"], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    rows = json.loads(cli.stdout)["tasks"]
    assert [(t["task"], t["successes"]) for t in rows] == [(t["task"], t["successes"]) for t in py["tasks"]]
    with pytest.raises(ValueError):
        autumnc.baseline_random(str(tmp_path / "nowhere"))


def test_three_agents_on_the_change_detection_tasks(tmp_path):
    tasks = os.path.join(REPO, "tasks", "cd")
    runs = []
    for name, extra in (("default", ["--rollouts", "1000"]), ("paper", ["--protocol", "paper", "--rollouts", "1000"])):
        out = tmp_path / f"{name}.json"
        r = subprocess.run([AUTUMN, "eval", tasks, "--json-out", str(out), "--threads", "2", *extra],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        runs.append(f"{name}={out}")
    random_run = tmp_path / "random.json"
    random_run.write_text(json.dumps(autumnc.baseline_random(tasks, rollouts=10, timeout=300)))
    runs.append(f"random={random_run}")
    r, out = report(tmp_path, *runs)
    assert r.returncode == 0, r.stderr
    got = table_cells(open(out + ".md").read())
    for label, path in (run.split("=", 1) for run in runs):
        scores = [t["score"] for t in json.load(open(path))["tasks"] if t["score"] is not None]
        assert len(scores) == 3, label
        assert got[label]["cd"] == pytest.approx(sum(scores) / 3, abs=5e-4), label
    assert json.load(open(tmp_path / "paper.json"))["agent"]["protocol"] == "paper"
    assert len(re.findall(r'id="bar:', open(out + ".svg").read())) == 9
