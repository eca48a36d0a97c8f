#!/usr/bin/env bash
# sanitize.sh [configure|build|test] — the unit tests under AddressSanitizer and
# UndefinedBehaviorSanitizer, in the clang-14 tree build-fuzz/ (shared with
# scripts/fuzz.sh; configured on first use). "configure" only sets the tree up,
# "build" builds it, "test" runs the tests on it; nothing: build, then test.
#
# The compiled engine's suites that compile modules on demand are left out here
# (they run the project's compiler per program, minutes under ASan, and the
# modules are not instrumented); AUTUMN_TEST_ENGINES=interp makes the suites
# that check both engines check the interpreter only. The built-in modules
# (generated/) are instrumented and run where a suite uses them.
#
# ASan's frames are several times larger: the main thread gets a 64 MiB stack
# (the parser's 1,000 levels of nesting need it there, not in release builds),
# and eval_nesting, whose point is where the interpreter's own depth guard
# trips, is left to the release run (here the stack guard trips first, at
# another construct). readme_quick_start needs the release tree and Python.
set -euo pipefail
cd "$(dirname "$0")/.."
tree=build-fuzz
if [ ! -f "$tree/build.ninja" ]; then
  cmake -S . -B "$tree" -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DAUTUMN_SANITIZE=ON -DAUTUMN_FUZZ=ON -DAUTUMN_PYTHON=OFF >/dev/null
fi
mode=${1:-all}
case "$mode" in configure|build|test|all) ;; *) echo "sanitize.sh: unknown mode '$mode'" >&2; exit 2 ;; esac
[ "$mode" = configure ] && exit 0

if [ "$mode" != test ]; then nice -n 5 ninja -C "$tree" -j2 autumn_tests autumn autumnc; fi
[ "$mode" = build ] && exit 0
cd "$tree"
# The cases run in batches of ten, one process a batch, and the suites left to
# the release run (those that compile modules on demand, the agent's searches,
# a few others) are not among them: tests/sanitize_batches.cmake lists both and
# says why. A batch's cases' own times go to gtest/batch-N.xml.
# The interpreter's golden traces replay the first two of each file's eight episodes here
# (AUTUMN_TRACE_EPISODES; the release run replays all eight on both engines), and the suite
# reads a file only as far as its second episode: under ASan the JSON lexer was most of a
# trace's time. All eight episodes of 68 programs were 123 of this stage's 351 test-seconds;
# now 70 programs take about 66 (sand and ajl_rink run here again).
# ASan records 8 frames of each allocation's and free's stack, not 30: a report
# still shows the faulting access's whole stack, and the interpreter's many small
# allocations cost less to record (6% of this stage's CPU on the heaviest tests).
rm -rf gtest
ulimit -s 65536
AUTUMN_TEST_ENGINES=interp AUTUMN_TRACE_EPISODES=2 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:malloc_context_size=8 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure -j2 -L asan --output-junit ctest-junit.xml
