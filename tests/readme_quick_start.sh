#!/usr/bin/env bash
# The README's quick start, run as written. The commands are taken from the
# README itself (every ```sh block between "## Quick start" and the next "## "
# heading), so the test follows the text: a command edited there is the command
# run here. They run with bash -e in a scratch checkout made of symbolic links
# (build/ -> this build tree, programs/ -> the sources, ../shared -> the shared
# data), so nothing is copied and the outputs (out/) land in the scratch folder.
# Then the files the text promises are checked. Without ../shared the ice lines
# cannot run: the test reports itself skipped (exit 77), loudly.
#
# Usage: readme_quick_start.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
shared=${AUTUMN_SHARED_DIR:-$src/../shared}

script=$(awk '
  /^## Quick start/ { inside = 1; next }
  inside && /^## / { exit }
  inside && /^```sh$/ { block = 1; next }
  inside && block && /^```$/ { block = 0; next }
  inside && block { print }
' "$src/README.md")
if [ -z "$script" ]; then
  echo "readme_quick_start: no \`\`\`sh blocks under '## Quick start' in $src/README.md" >&2
  exit 1
fi
if [ ! -d "$shared/tasks/autumnbench" ]; then
  echo "SKIPPED LOUDLY: the quick start solves the tasks in $shared/tasks/autumnbench, which is absent" >&2
  exit 77
fi

scratch=$(mktemp -d "${TMPDIR:-/tmp}/readme_quick_start.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/checkout"
ln -s "$build" "$scratch/checkout/build"
ln -s "$src/programs" "$scratch/checkout/programs"
ln -s "$(cd "$shared" && pwd)" "$scratch/shared"
cd "$scratch/checkout"

echo "== the quick start's commands (README.md) =="
printf '%s\n' "$script"
echo "== running them =="
bash -euo pipefail -x -c "$script"

echo "== what they promised =="
for f in out/sokoban.gif out/sokoban.png out/paddle.cpp out/ice/prompts/ice_planning_plan.gif \
         out/ice/prompts/ice_planning_plan.png out/ice/prompts/ice_mfp_answer.png out/ice/prompts/ice_cd_detection.gif; do
  if [ ! -s "$f" ]; then
    echo "readme_quick_start: $f was not written" >&2
    exit 1
  fi
  echo "$f: $(stat -c %s "$f") bytes"
done
[ "$(head -c 6 out/sokoban.gif)" = GIF89a ] || { echo "out/sokoban.gif is not a GIF" >&2; exit 1; }
[ "$(head -c 4 out/sokoban.png | tail -c 3)" = PNG ] || { echo "out/sokoban.png is not a PNG" >&2; exit 1; }
echo "readme_quick_start: every command ran"
