#!/usr/bin/env python3
"""slowest-tests.py BUILD_DIR... — the end of every scripts/test.sh run: the ten
slowest tests of the last ctest run in each build tree (its ctest-junit.xml,
from ctest --output-junit), and the time each label took (the sum of test
times, so two -j slots count twice; labels from ctest --show-only=json-v1).
The sanitizer tree runs its cases in batches (tests/sanitize_batches.cmake):
there each case's own time comes from its batch's GoogleTest report
(gtest/batch-N.xml), under the batch's labels.

Reads only the standard library, so any python3 will do."""
import collections
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET


def labels_of(build):
    """Test name -> labels, as ctest lists them."""
    try:
        out = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build, capture_output=True, text=True, check=True)
        listed = json.loads(out.stdout)
    except (OSError, subprocess.CalledProcessError, ValueError):
        return {}
    labels = {}
    for test in listed.get("tests", []):
        for prop in test.get("properties", []):
            if prop.get("name") == "LABELS":
                labels[test["name"]] = prop.get("value") or []
    return labels


def batched_cases(build):
    """(name, seconds) of every case in the tree's batch reports, or None."""
    folder = os.path.join(build, "gtest")
    if not os.path.isdir(folder):
        return None
    cases = []
    for f in sorted(os.listdir(folder)):
        if f.endswith(".xml"):
            for case in ET.parse(os.path.join(folder, f)).iter("testcase"):
                cases.append((f"{case.get('classname', '?')}.{case.get('name', '?')}", float(case.get("time", 0) or 0)))
    return cases


def tests_of(build):
    labels = labels_of(build)
    cases = batched_cases(build)
    if cases is not None:
        batch_labels = sorted({l for n, ls in labels.items() if n.startswith("asan ") for l in ls}) or ["asan"]
        for name, t in cases:
            yield name, t, batch_labels, build
        return
    for case in ET.parse(os.path.join(build, "ctest-junit.xml")).iter("testcase"):
        name = case.get("name", "?")
        yield name.split("  # GetParam")[0], float(case.get("time", 0) or 0), labels.get(name, []), build


def main(builds):
    rows = []
    for b in builds:
        try:
            rows.extend(tests_of(b))
        except (OSError, ET.ParseError) as e:
            print(f"slowest-tests.py: cannot read the test results of {b}: {e}", file=sys.stderr)
    if not rows:
        return 0
    tree_name = {b: ("asan" if "build-fuzz" in b else "release") for b in builds}
    print(f"\n== the ten slowest tests (of {len(rows)})")
    for name, t, _, path in sorted(rows, key=lambda r: -r[1])[:10]:
        print(f"  {t:8.1f} s  [{tree_name[path]}] {name}")
    by_label = collections.defaultdict(lambda: [0.0, 0])
    for _, t, labels, path in rows:
        for l in labels or ["(none)"]:
            key = f"{tree_name[path]}:{l}"
            by_label[key][0] += t
            by_label[key][1] += 1
    print("== test time by tree and label (sum over tests)")
    for key, (t, n) in sorted(by_label.items(), key=lambda kv: -kv[1][0]):
        print(f"  {t:8.1f} s  {n:4d} tests  {key}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
