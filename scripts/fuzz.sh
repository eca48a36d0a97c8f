#!/usr/bin/env bash
# fuzz.sh TARGET SECONDS [libFuzzer options...] — runs one libFuzzer target of
# fuzz/ (frontend, interp, emit, task, state; or "all", SECONDS each) under ASan and
# UBSan for SECONDS, in the clang-14 tree build-fuzz/ (configured and built on
# demand; the same tree serves scripts/sanitize.sh).
#
# Seeds: programs/ and tests/ (and ../shared/conformance/programs when present)
# for the program targets, with a few actions appended for interp; tasks/ and
# tests/ JSON for task; for state, a few picks of module, steps and mutation
# (fuzz_state.cpp builds the valid snapshots itself). The corpus grows in build-fuzz/corpus/TARGET between
# runs; a crash leaves its input in build-fuzz/artifacts/TARGET/ and the script
# fails (exit 1). For emit, the modules of a sample of the corpus are then
# compiled with the project's compiler (FUZZ_COMPILE_SAMPLE files, default 12):
# compiling C++ per input would slow the fuzzer a thousandfold, so the fuzzer
# checks the lowering in process and this step checks that what it emits compiles.
# The last line of each run is libFuzzer's execution count ("stat::number_of_executed_units").
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
target=${1:?usage: scripts/fuzz.sh TARGET SECONDS [libFuzzer options]}
seconds=${2:?usage: scripts/fuzz.sh TARGET SECONDS [libFuzzer options]}
shift 2
tree=build-fuzz

if [ "$target" = all ]; then
  for t in frontend interp emit task state; do bash "$0" "$t" "$seconds" "$@"; done
  exit 0
fi
case "$target" in frontend|interp|emit|task|state) ;; *) echo "fuzz.sh: unknown target '$target'" >&2; exit 2 ;; esac

# AUTUMN_FUZZ_PREBUILT=1 (scripts/test.sh, which runs two targets at once):
# the targets are built already; two ninja runs must not share one tree.
if [ -z "${AUTUMN_FUZZ_PREBUILT:-}" ]; then
  bash scripts/sanitize.sh configure
  nice -n 5 ninja -C "$tree" -j2 "fuzz_$target" >/dev/null
fi

seeds=$tree/seeds/$target corpus=$tree/corpus/$target artifacts=$tree/artifacts/$target
rm -rf "$seeds"
mkdir -p "$seeds" "$corpus" "$artifacts"
shared=${AUTUMN_SHARED_DIR:-$root/../shared}
program_seeds() {
  find programs tests -name '*.au'
  [ -d "$shared/conformance/programs" ] && find "$shared/conformance/programs" -name '*.sexp'
  true
}
i=0
case "$target" in
  frontend|emit)
    program_seeds | while read -r f; do cp "$f" "$seeds/p$((i++))"; done ;;
  interp)
    # PROGRAM, five actions (noop, left, click, up, right), then the count byte.
    program_seeds | while read -r f; do
      { cat "$f"; printf '\000\001\005\003\002\005'; } > "$seeds/p$((i++))"
    done ;;
  state)
    # Per built-in module (byte 0) and step count (byte 1): its valid snapshot
    # unchanged (edit mode, no edits) and cut to 32 bytes with 0xff appended.
    for m in $(seq 0 11); do
      for s in 0 3 7; do
        printf "\\$(printf %o "$m")\\$(printf %o "$s")\000" > "$seeds/m$m-$s"
        printf "\\$(printf %o "$m")\\$(printf %o "$s")\001\040\000\377" > "$seeds/c$m-$s"
      done
    done ;;
  task)
    find tasks tests -name '*.json' | while read -r f; do cp "$f" "$seeds/t$((i++))"; done
    [ -d "$shared/tasks" ] && find "$shared/tasks" -name '*.json' | head -50 | while read -r f; do cp "$f" "$seeds/s$((i++))"; done
    [ -d "$shared/conformance/traces" ] &&
      find "$shared/conformance/traces" -name '*.json' -size -24k | head -10 | while read -r f; do cp "$f" "$seeds/g$((i++))"; done
    true ;;
esac

log=$tree/fuzz-$target.log
status=0
# The interpreter evaluates on a stack of its own (swapcontext), which ASan does
# not follow: libFuzzer's per-input timeout alarm, arriving while on that stack,
# makes ASan report a stack-use-after-scope that is not there. interp therefore
# runs without the alarm; its inputs run under small episode budgets
# (fuzz_interp.cpp), which bound every input's time.
timeout=20
[ "$target" = interp ] && timeout=0
# -entropic=0: libFuzzer 14's default (entropic) scheduler spent 40% of the
# emit target's time updating feature frequencies (50k features); the plain
# scheduler runs 1.7x more inputs per second (emit 81 -> 139/s, interp 193 -> 233/s).
# malloc_context_size=0: ASan records no allocation stacks (its allocator's stack
# depot was a third of the emit target's time); a report still names the bad
# access, and rerunning the artifact (fuzz/fuzz_TARGET FILE) with default options
# shows where the memory came from. The per-input timeout is wall-clock: a
# machine starved by other work (a rebuild) can trip it; rerun the timeout-*
# artifact alone to tell a real hang from that.
# AUTUMN_VERIFY_IR: the emit target's lowerings are verified after every stage
# (compiler/lower/ir_verify.hpp); a broken invariant is an uncaught exception.
AUTUMN_VERIFY_IR=1 ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:malloc_context_size=0} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} \
  nice -n 5 "$tree/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2560 -entropic=0 \
  -print_final_stats=1 -artifact_prefix="$artifacts/" "$@" "$corpus" "$seeds" >"$log" 2>&1 || status=$?
grep -E "^stat::number_of_executed_units|^#[0-9]+ +DONE" "$log" | tail -2 || true
if [ "$status" -ne 0 ]; then
  echo "fuzz.sh: $target failed (exit $status); see $log and $artifacts/" >&2
  grep -E "ERROR|SUMMARY|runtime error|deadly signal|Test unit written" "$log" | head -20 >&2 || true
  exit 1
fi
echo "fuzz.sh: $target ran ${seconds}s without a crash, hang or sanitizer report"

if [ "$target" = emit ]; then
  bash fuzz/compile_sample.sh "$corpus" "${FUZZ_COMPILE_SAMPLE:-12}"
fi
