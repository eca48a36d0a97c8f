#!/usr/bin/env bash
# compile_sample.sh CORPUS N — the emitter's other half (scripts/fuzz.sh emit):
# for N files spread evenly over a fuzz corpus, autumnc emits the module (as it
# lowers, and embedded) and the project's compiler must accept it. Uses the
# release tree build/ (scripts/bootstrap.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
corpus=${1:?usage: fuzz/compile_sample.sh CORPUS N}
n=${2:?usage: fuzz/compile_sample.sh CORPUS N}
[ -x build/autumnc ] || { echo "compile_sample.sh: build/autumnc missing (run scripts/bootstrap.sh)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
mapfile -t files < <(ls "$corpus" | sort)
total=${#files[@]}
[ "$total" -gt 0 ] || { echo "compile_sample.sh: empty corpus $corpus" >&2; exit 1; }
step=$(( total > n ? total / n : 1 ))
loaded=0 compiled=0
for ((k = 0; k < total && loaded < n; k += step)); do
  f=$corpus/${files[$k]}
  for mode in "" --embedded; do
    rm -f "$out"/*.cpp
    if ! build/autumnc "$f" -o "$out" --name m $mode >"$out/log" 2>&1; then
      [ -z "$mode" ] && continue 2  # does not load: nothing to emit
      echo "compile_sample.sh: autumnc $mode failed on $f, which loads:" >&2
      head -5 "$out/log" >&2
      exit 1
    fi
    if ! g++ -std=c++20 -fsyntax-only -I. "$out/m.cpp" 2>"$out/err"; then
      echo "compile_sample.sh: the module emitted for $f${mode:+ ($mode)} does not compile:" >&2
      head -20 "$out/err" >&2
      exit 1
    fi
    compiled=$((compiled + 1))
  done
  loaded=$((loaded + 1))
done
echo "compile_sample.sh: $compiled modules of $loaded corpus programs compile"
