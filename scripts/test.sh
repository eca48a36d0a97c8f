#!/usr/bin/env bash
# test.sh [--quick] — the test suite.
#
# Full (the README's test command; .ci/run calls exactly this): build, then
# every ctest test of the release tree (unit, diagnostics, golden, conformance on
# both engines, lowering, guide, CLI, agent and the Python package, one module
# cache shared by the whole run so a program is compiled once); then the unit
# tests again under AddressSanitizer and UndefinedBehaviorSanitizer
# (scripts/sanitize.sh, a clang-14 tree) and a short run of every libFuzzer
# target under both sanitizers (scripts/fuzz.sh, AUTUMN_FUZZ_SECONDS each,
# default 30; two targets at a time, one core each; state for
# AUTUMN_FUZZ_STATE_SECONDS, default 10, beside the second pair). Ends with the wall and CPU time of each
# stage and the ten slowest tests.
#
# --quick: the inner loop. The release build and the tests labelled "quick"
# (tests/labels.cmake: the unit suites, the interpreter's conformance, the
# lowering files, the fast agent, CLI and Python tests). It leaves out the
# compiled engine's conformance and differential suites, the slow agent
# searches, the sanitizer tree and the fuzzers. Under 3 minutes on a built tree.
#
# The conformance corpus is read from ../shared (AUTUMN_SHARED_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

quick=0
case "${1:-}" in
  --quick) quick=1 ;;
  "") ;;
  -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "test.sh: unknown option '$1' (use --quick, or nothing for the full suite)" >&2; exit 2 ;;
esac

# Without the corpus the conformance suites would list no traces and pass with
# hundreds of tests fewer: refuse instead.
shared=${AUTUMN_SHARED_DIR:-$root/../shared}
if [ ! -d "$shared/conformance/traces" ] || [ ! -d "$shared/conformance/programs" ]; then
  echo "test.sh: no conformance corpus at $shared/conformance (its programs/ and traces/ are what the suites check against); put it there or set AUTUMN_SHARED_DIR" >&2
  exit 2
fi

# Stage timings, printed at the end whether the run passed or failed.
stages=()
stage_start=$SECONDS
run_start=$SECONDS
# CPU seconds (user + system) of this shell's finished children, from `times`,
# into $cpu_now: what the suite is bound by on a 2-core runner. Run in this
# shell, not in $( ), whose subshell has no children. Processes nobody waits for
# (a module compile a test started and did not wait on) are not counted.
cpu_file=$(mktemp)
children_cpu() {
  times > "$cpu_file"
  local u s
  { read -r _; read -r u s; } < "$cpu_file"
  cpu_now=$(awk -v u="$u" -v s="$s" 'function sec(x, p) { split(x, p, "m"); return p[1] * 60 + p[2] } BEGIN { printf "%d", sec(u) + sec(s) }')
}
stage() {  # stage NAME COMMAND...: runs COMMAND, records its wall and CPU time
  local name=$1
  shift
  echo "== $name"
  local t0=$SECONDS c0 status=0
  children_cpu
  c0=$cpu_now
  "$@" || status=$?
  children_cpu
  stages+=("$(printf '%-34s %5d s %6d CPU-s  %s' "$name" $((SECONDS - t0)) $((cpu_now - c0)) \
    "$([ $status -eq 0 ] && echo ok || echo "FAILED ($status)")")")
  return $status
}
report() {
  local status=$?
  [ -n "${sanitize_build:-}" ] && kill -- -"$sanitize_build" 2>/dev/null || true
  echo
  echo "== stage times (wall clock; CPU-s of the stage's processes, user + system)"
  for s in "${stages[@]}"; do echo "  $s"; done
  children_cpu
  printf '  %-34s %5d s %6d CPU-s\n' "total" $((SECONDS - run_start)) "$cpu_now"
  rm -f "$cpu_file"
  local reports=()
  for b in build build-fuzz; do [ -f "$b/ctest-junit.xml" ] && reports+=("$b"); done
  if ((${#reports[@]})); then python3 scripts/slowest-tests.py "${reports[@]}" || true; fi
  exit $status
}
trap report EXIT

rm -f build/ctest-junit.xml build-fuzz/ctest-junit.xml
stage "build (release)" bash scripts/bootstrap.sh
if [ "$quick" = 1 ]; then
  stage "ctest -L quick (release)" bash -c 'cd build && ctest --output-on-failure -j2 -L quick --output-junit ctest-junit.xml'
  exit 0
fi
# The sanitizer tree (its tests and the fuzz targets) builds beside the release
# tests at the lowest priority: it takes the CPU those tests leave idle (while
# they wait on a module compile, a pipe, a sleeping thread) and nothing more.
bash scripts/sanitize.sh configure
sanitize_log=build-fuzz/background-build.log
setsid nice -n 19 ninja -C build-fuzz -j2 autumn_tests autumn autumnc fuzz_frontend fuzz_interp fuzz_emit fuzz_task fuzz_state \
    > "$sanitize_log" 2>&1 &
sanitize_build=$!  # its own process group: a failed run stops it (report)
finish_sanitize_build() {
  if ! wait $sanitize_build; then
    echo "the ASan+UBSan tree did not build; the end of $sanitize_log:" >&2
    tail -40 "$sanitize_log" >&2
    return 1
  fi
}
stage "ctest (release, every test)" bash -c 'cd build && ctest --output-on-failure -j2 --output-junit ctest-junit.xml'
stage "build (ASan+UBSan tree): the rest" finish_sanitize_build
stage "ctest under ASan+UBSan" bash scripts/sanitize.sh test
fuzz_group() {  # targets at once (TARGET or TARGET:SECONDS); every one must pass
  local pids=() names=() status=0 t name secs
  for t in "$@"; do
    name=${t%%:*}
    secs=${AUTUMN_FUZZ_SECONDS:-30}
    [ "$t" != "$name" ] && secs=${t#*:}
    AUTUMN_FUZZ_PREBUILT=1 bash scripts/fuzz.sh "$name" "$secs" > "build-fuzz/fuzz-$name.out" 2>&1 &
    pids+=($!)
    names+=("$name")
  done
  for i in "${!pids[@]}"; do wait "${pids[$i]}" || status=1; done
  for name in "${names[@]}"; do cat "build-fuzz/fuzz-$name.out"; done
  return $status
}
stage "fuzz smoke: frontend + interp" fuzz_group frontend interp
# Snapshot loading is cheap per input (thousands a second): a short run, beside
# the second pair rather than alone on one core.
stage "fuzz smoke: emit + task + state" fuzz_group emit task "state:${AUTUMN_FUZZ_STATE_SECONDS:-10}"
