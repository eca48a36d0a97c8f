# sanitize_batches.cmake — the sanitizer tree's ctest tests: the GoogleTest cases
# in batches of ten, one process a batch.
#
# An instrumented autumn_tests costs about 0.15 s of CPU to start (ASan maps its
# shadow memory and the 80 MB binary is relocated: some 8,700 page faults),
# whatever the case then does; one process per case made that 75 of the
# ASan+UBSan stage's 340 test-seconds. A batch runs its cases in one process, in
# listing order, so a case still runs alone in its process only in the release
# tree (per case, tests/labels.cmake). What a batch reports: its exit status
# (any failed case fails it, with that case's output under --output-on-failure),
# and each case's time in build-fuzz/gtest/<batch>.xml (scripts/slowest-tests.py
# reads them). One case under the sanitizers, by hand:
#   build-fuzz/tests/autumn_tests --gtest_filter='Suite.Case'
#
# ctest runs this file when it starts (tests/CMakeLists.txt adds it to
# TEST_INCLUDE_FILES in the sanitizer tree), after sanitize_batches_config.cmake,
# which sets batch_exe, batch_dir, batch_env and batch_xml_dir. It lists the cases
# itself (the parameterised suites list the conformance corpus found then, as
# gtest_discover_tests's PRE_TEST mode does) and leaves out those matching
# `skip` or `skip_with_value` below.

# Left to the release run, and why:
# - Suites that compile modules on demand (or run the Python package): the
#   compiled engine's runs the project's compiler per program, minutes under ASan,
#   and the modules are not instrumented. CellsBudget compares the compiled engine
#   with the interpreter by name. The built-in modules (generated/) are
#   instrumented and run where a suite uses them.
# - CLI tests that run a whole planning search or an eval (the ice planning
#   pictures were 105 s and EvalDoesNotCountCompilesAsSolveTime 20 s under ASan):
#   the agent's searches are the release run's; what sanitizers find is in the
#   units they drive, tested here one by one.
# - ALimitedAddressSpace runs under ulimit -v, where ASan cannot map its shadow.
# - ClangInProcessModulesAreExact needs the in-process Clang plugin, which this
#   tree does not build (harness/clang_build/CMakeLists.txt: LLVM's libraries are
#   not sanitized).
# - Two statistical or timing loops: the bench shard round trip (it times each
#   engine for 0.2 s per program and run: 14 s here; the other shard round trips
#   drive the same merge code here) and the random baseline's trigger probability
#   on the interpreter (25 s here; its episodes are the same code the baseline's
#   other tests run).
# - eval_nesting, whose point is where the interpreter's own depth guard trips:
#   ASan's frames are larger and the stack guard trips first, at another construct.
# - ajl_turing_complete's golden trace on the interpreter: its first two episodes
#   are 39 s here, on the same interpreter paths as the rest.
# Three files whose every suite is listed here (agent_test, compiled_engine_test,
# emit_bytes_test) are not compiled into this tree at all (tests/CMakeLists.txt).
set(skip "CompiledConformance|Differential|CellsBudget|LoweringFile|CopyAndSnapshot|CompiledEngine|EmitBytes|Agent|MakeTask|DifftestGoesOn|eval_nesting|EvalDoesNotCountCompilesAsSolveTime|InterpreterMatchesEveryFrame/ajl_turing_complete|ALimitedAddressSpace|ClangInProcessModulesAreExact|BenchMergesToTheWholeRun")
# Matched against "Suite.Case/N GetParam-value" (the engine's case has no name of its own);
# `skip` against the name alone, so that a checkout's path in a value never matches it.
set(skip_with_value "TriggerOnOneCellMatchesItsProbability/[0-9]+ \"interp\"$")
set(batch_size 10)

execute_process(COMMAND "${batch_exe}" --gtest_list_tests
  WORKING_DIRECTORY "${batch_dir}" TIMEOUT 120
  OUTPUT_VARIABLE listing ERROR_QUIET RESULT_VARIABLE listed)
if(NOT listed EQUAL 0)
  # A failing test with the reason, labelled as the batches are: `ctest -L asan`
  # then fails instead of running nothing.
  add_test(asan_listing_failed /bin/sh -c "echo 'autumn_tests --gtest_list_tests failed (${listed}); rebuild build-fuzz' >&2; exit 1")
  set_tests_properties(asan_listing_failed PROPERTIES LABELS asan)
  return()
endif()

# Brackets would keep CMake from splitting the list at the semicolons inside them.
string(REPLACE "[" "(" listing "${listing}")
string(REPLACE "]" ")" listing "${listing}")
string(REPLACE ";" "," listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(suite "")
set(batch "")      # the cases of the batch being filled
set(n_batches 0)

macro(flush_batch)
  list(LENGTH batch size)
  if(size GREATER 0)
    math(EXPR n_batches "${n_batches} + 1")
    string(REPLACE ";" ":" filter "${batch}")
    list(GET batch 0 first)
    set(name "asan ${n_batches}: ${first} +${size}")
    add_test("${name}" "${batch_exe}" "--gtest_filter=${filter}" --gtest_also_run_disabled_tests
      "--gtest_output=xml:${batch_xml_dir}/batch-${n_batches}.xml")
    set_tests_properties("${name}" PROPERTIES WORKING_DIRECTORY "${batch_dir}" ENVIRONMENT "${batch_env}"
      LABELS asan TIMEOUT 900 FAIL_REGULAR_EXPRESSION "\\] 0 tests from 0 test suites ran")
    set(batch "")
  endif()
endmacro()

foreach(line IN LISTS lines)
  if(line MATCHES "^([^ ]+\\.)(  #.*)?$")  # "Suite." (or "Prefix/Suite.")
    set(suite "${CMAKE_MATCH_1}")
  elseif(line MATCHES "^  ([^ ]+)(  # GetParam\\(\\) = (.*))?$")
    set(case "${suite}${CMAKE_MATCH_1}")
    if(NOT case MATCHES "${skip}" AND NOT "${case} ${CMAKE_MATCH_3}" MATCHES "${skip_with_value}")
      list(APPEND batch "${case}")
      list(LENGTH batch size)
      if(size EQUAL batch_size)
        flush_batch()
      endif()
    endif()
  endif()
endforeach()
flush_batch()
if(n_batches EQUAL 0)
  add_test(asan_listing_empty /bin/sh -c "echo 'autumn_tests listed no test cases' >&2; exit 1")
  set_tests_properties(asan_listing_empty PROPERTIES LABELS asan)
endif()
