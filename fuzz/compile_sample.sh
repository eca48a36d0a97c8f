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
loaded=0
# Emitted first (autumnc is quick), then compiled two at a time (the compiles
# are the cost; CI has two cores).
for ((k = 0; k < total && loaded < n; k += step)); do
  f=$corpus/${files[$k]}
  for mode in "" --embedded; do
    name=m$k${mode:+e}
    if ! build/autumnc "$f" -o "$out" --name "$name" $mode >"$out/log" 2>&1; then
      rm -f "$out/$name.cpp"
      [ -z "$mode" ] && continue 2  # does not load: nothing to emit
      echo "compile_sample.sh: autumnc $mode failed on $f, which loads:" >&2
      head -5 "$out/log" >&2
      exit 1
    fi
    printf '%s\t%s\n' "$name" "$f${mode:+ ($mode)}" >>"$out/list"
  done
  loaded=$((loaded + 1))
done
compiled=0
if [ -s "$out/list" ]; then
  # Each compile writes NAME.err only when it fails.
  # With the flags and precompiled runtime header modules are built with
  # (harness/module_build.cpp): a third of the time of parsing the headers each
  # time. Without the header (a tree built without it), g++ reads the headers.
  pch=build/module_pch/autumn_module.hpp
  flags="-std=c++20 -O2 -fPIC -fvisibility=hidden -DAUTUMN_MODULE_SHARED"
  [ -f "$pch.gch" ] && flags="$flags -include $pch"
  cut -f1 "$out/list" | xargs -P 2 -I{} sh -c 'g++ $3 -fsyntax-only -I. "$1/$2.cpp" 2>"$1/$2.stderr" || mv "$1/$2.stderr" "$1/$2.err"' sh "$out" {} "$flags"
  while IFS=$'\t' read -r name what; do
    if [ -f "$out/$name.err" ]; then
      echo "compile_sample.sh: the module emitted for $what does not compile:" >&2
      head -20 "$out/$name.err" >&2
      exit 1
    fi
    compiled=$((compiled + 1))
  done <"$out/list"
fi
echo "compile_sample.sh: $compiled modules of $loaded corpus programs compile"
