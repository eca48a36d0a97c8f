#!/usr/bin/env bash
# The README's quick start, as written: runs every line of the ```sh block that
# follows "each line below is run by the test suite" from the source root, in
# order, and fails on the first line that fails (printing it). The set-up block
# before it (scripts/main-job.sh) is what CI's build already does.
set -euo pipefail
cd "$(dirname "$0")/.."
lines=$(awk '/each line below is run by the test suite/ {armed=1; next}
             armed && /^```sh/ {inside=1; next}
             inside && /^```/ {exit}
             inside && NF {print}' README.md)
n=$(printf '%s\n' "$lines" | grep -c .)
if [ "$n" -lt 5 ]; then
  echo "readme_quick_start: found $n commands in README.md's quick start, expected at least 5" >&2
  exit 1
fi
i=0
while IFS= read -r line; do
  i=$((i + 1))
  echo "== [$i/$n] $line"
  if ! out=$(bash -c "$line" 2>&1); then
    printf '%s\n' "$out" | tail -20
    echo "readme_quick_start: command $i failed: $line" >&2
    exit 1
  fi
  printf '%s\n' "$out" | tail -3
done <<< "$lines"
echo "readme_quick_start: all $n commands ran"
