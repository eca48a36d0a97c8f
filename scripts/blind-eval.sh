#!/usr/bin/env bash
# Blind evaluation over every program: makes an MFP task (environment seed 7,
# not the benchmark's 0, so a solver that assumed the seed would be caught), a
# planning task (K = 8 actions) and a change-detection task for each program of
# the given folders, in the benchmark's layout (prompts/ without seeds or
# answers, answers/ apart), then runs `autumn eval` over them and prints the
# per-task table and the per-type table (the JSON goes to OUT/eval.json), and
# checks every plan again on the interpreter (scripts/check-plans.py).
#
#   bash scripts/blind-eval.sh [--plan-steps K] [--kinds mfp,planning,cd] [OUT] [PROGRAM_DIR...]
#
# --plan-steps K (default 8): the planning goal is the frame K random actions
# (clicks included) reach; --kinds limits the task types made.
# OUT (default /tmp/autumn-blind) is emptied first and must be outside the
# repository; the default folders are programs/ and ../shared/conformance/programs.
# A program for which a task cannot be made is listed and skipped (some programs
# never change their frame, or fail under random actions).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
plan_steps=8
kinds="mfp,planning,cd"
while [ $# -gt 0 ]; do
  case "$1" in
    --plan-steps) [ $# -ge 2 ] && [[ "$2" =~ ^[1-9][0-9]*$ ]] || { echo "blind-eval: --plan-steps needs a positive whole number" >&2; exit 2; }
                  plan_steps="$2"; shift 2 ;;
    --kinds) [ $# -ge 2 ] && [[ "$2" =~ ^(mfp|planning|cd)(,(mfp|planning|cd))*$ ]] || { echo "blind-eval: --kinds takes a comma-separated list of mfp, planning, cd" >&2; exit 2; }
             kinds="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "blind-eval: unknown option $1 (--plan-steps K, --kinds LIST)" >&2; exit 2 ;;
    *) break ;;
  esac
done
out="${1:-/tmp/autumn-blind}"
shift || true
dirs=("$@")
((${#dirs[@]})) || dirs=("$repo/programs" "$repo/../shared/conformance/programs")
autumn="$repo/build/autumn"
[ -x "$autumn" ] || { echo "blind-eval: $autumn not built (run scripts/bootstrap.sh)" >&2; exit 1; }
out_abs="$(mkdir -p "$out" && cd "$out" && pwd)"
case "$out_abs/" in "$repo"/*) echo "blind-eval: OUT must be outside the repository" >&2; exit 1 ;; esac
rm -rf "$out_abs"
mkdir -p "$out_abs/prompts"

made=0
n=0
skipped=()
for dir in "${dirs[@]}"; do
  [ -d "$dir" ] || { echo "blind-eval: no folder $dir" >&2; exit 1; }
  for program in "$dir"/*.au "$dir"/*.sexp; do
    [ -e "$program" ] || continue
    name="$(basename "${program%.*}")"
    n=$((n + 1))
    for kind in ${kinds//,/ }; do
      # A seed per program, so the change's clock value K differs between programs.
      args=(make-task "$kind" "$program" --seed "$n" --extend-colours --out "$out_abs/prompts/${name}_${kind}.json")
      case "$kind" in
        mfp) args+=(--env-seed 7) ;;
        planning) args+=(--steps "$plan_steps") ;;
      esac
      if msg="$("$autumn" "${args[@]}" 2>&1)"; then
        made=$((made + 1))
      else
        skipped+=("$name $kind: $(echo "$msg" | tail -1)")
      fi
    done
    echo "blind-eval: made tasks for $name ($made so far)" >&2
  done
done
echo "blind-eval: $made tasks in $out_abs, ${#skipped[@]} skipped" >&2
for s in "${skipped[@]+"${skipped[@]}"}"; do echo "  skipped: $s" >&2; done
"$autumn" eval "$out_abs" --engine compiled --json-out "$out_abs/eval.json"
# The plans again, independently: replayed on the interpreter from Python
# (scripts/check-plans.py), against the prompts and answers, not the planner's own check.
if [[ ",$kinds," == *,planning,* ]]; then
  if [ -d "$repo/build/python/autumnc" ]; then
    PYTHONPATH="$repo/build/python" /usr/bin/python3 "$repo/scripts/check-plans.py" "$out_abs" "$out_abs/eval.json"
  else
    echo "blind-eval: build/python not built; plans not checked independently" >&2
  fi
fi
