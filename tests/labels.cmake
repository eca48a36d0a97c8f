# labels.cmake — the test tiers: ctest LABELS for every GoogleTest test, by name.
#
# ctest runs this after the listing of autumn_tests (tests/CMakeLists.txt adds
# it to TEST_INCLUDE_FILES), with the listed names in autumn_tests_TESTS. The
# first rule whose pattern matches a name gives its labels:
#   quick     seconds each and no more than a few small module compiles: the
#             inner loop (`scripts/test.sh --quick`, `ctest -L quick`)
#   compiled  compiles modules on demand and compares the two engines
#   agent     the simulator agent (task files, MFP, change detection, planning)
#   cli       the autumn/autumnc commands as a user runs them
#   untiered  no rule matched: still run by the full suite; give it a rule
# A test named in kSlow (over ~15 s on this 2-core machine, measured; the table
# is in docs/design.md, "Tests") loses "quick" and gains "slow". Slow tests
# start first (COST).

set(rules
  "^(PaintMarks|StateHash|HashOrder|Parser|Diagnostics|Lint|IrPasses|IrVerify|IrText|ModuleKey|SnapshotHash|StateValidationMisc|Limits|Generated|WarmStart)\\.|quick"
  "^(Reader|TraceEpisodes|Files/Diagnostic|Files/IrFile|Traces/Conformance|Programs/CorpusProgram|Programs/Snapshot|Builtin/StateValidation)[./]|quick"
  "^Guide\\.Reference|quick"
  "^(Files/LoweringFile|EmitBytes|CompiledEngine)[./]|quick,compiled"
  "^Agent(Particles|ThreadPool|StateHashSet|SeenSet|HugePages|WarmBlocks|TaskFile|Score|ClickModel|Eval|CdPairs|MakeCd|DrawSearch|Choice)\\.|quick,agent"
  "^AgentIce\\.(MaskedFramePrediction|ChangeDetectionScores)$|quick,agent"
  "^AgentPlanning\\.(Travel|LimitFraction|OnClones|Fill|LocalSearch|Shortening|Skeleton|StagesTable)|quick,agent"
  "^(Engines/RandomBaseline|RandomBaselineMfp|RandomBaselineCli|PaperProtocol)[./]|quick,agent"
  "^(Cli|HonestOutput|Pictures|Shards|RenderAllJson)\\.|quick,cli"
  "^FirstRun\\.UnwritableCacheFallsBack$|quick,cli"
  "^(Traces/CompiledConformance|Programs/Differential|Programs/CopyAndSnapshot|Files/Golden|Files/RuntimeFailure|Files/LimitProgram|CellsBudget)[./]|compiled"
  "^(FirstRun|Guide)\\.|compiled"
  "^(ModuleStore|ModuleBuild|BuiltinModules)\\.|compiled"
  "^(Agent[A-Za-z]*|MakeTask)\\.|agent")

set(kSlow
  MakeTask.EveryProgramWithEitherEngine
  AgentPlanning.TimedGoalsGetPlansNoLongerThanTheGenerators
  AgentPlanning.FocusedClicksReachSpreadOutGoals
  AgentPlanning.FocusedSetsKeepTheModeButtons
  AgentPlanning.SkeletonSearchEndsWhenAnOfferIsCompleted
  AgentPlanning.BestFirstFollowsThingsThatKeepMoving
  AgentPlanning.ReachingClicksWaitForSlowEffects
  AgentMakeCd.EveryProgramIsDetectedAtItsChange
  AgentIce.Planning
  AgentCdPairs.EveryPairIsDetectedAtItsChange
  AgentDrawSearch.FindsARandomFirstFrame
  Guide.EveryExampleShowsItsFramesOnBothEngines
  HonestOutput.EvalDoesNotCountCompilesAsSolveTime
  Cli.DifftestGoesOnPastBadPrograms
  Programs/Differential.CompiledAgreesWithInterpreter/ajl_turing_complete
  Programs/Differential.CompiledAgreesWithInterpreter/construct_own_class
  Programs/CopyAndSnapshot.KeepTheFuture/construct_own_class
  Files/LoweringFile.SpecialisesAsExpectedAndAgreesWithTheInterpreter/construct_own_class
  Traces/CompiledConformance.MatchesEveryFrame/ajl_rink)

# The slow tests start first (ctest COST; a fresh tree has no timings of its
# own): a long test started last runs alone on one core at the end.

# Searches that run on a pool of two threads (and again on one) take one ctest
# slot like any other test: with PROCESSORS 2 they waited for both slots, which
# `-j2` frees only when nothing else is left, so they ran last, one at a time,
# with a core a third idle (measured on a fresh clone: the last five minutes of
# the release tests). Started first instead (kSlow), they overlap the rest.

foreach(test IN LISTS autumn_tests_TESTS)
  set(labels untiered)
  foreach(rule IN LISTS rules)
    string(FIND "${rule}" "|" bar REVERSE)
    string(SUBSTRING "${rule}" 0 ${bar} pattern)
    math(EXPR after "${bar} + 1")
    string(SUBSTRING "${rule}" ${after} -1 found)
    if(test MATCHES "${pattern}")
      string(REPLACE "," ";" labels "${found}")
      break()
    endif()
  endforeach()
  string(REGEX REPLACE "  # GetParam.*" "" bare "${test}")  # a parameterised test's name ends so
  list(FIND kSlow "${bare}" slow)
  set(cost 0)
  if(slow GREATER -1)
    list(REMOVE_ITEM labels quick)
    list(APPEND labels slow)
    set(cost 100)
  endif()
  set_tests_properties("${test}" PROPERTIES LABELS "${labels}" COST ${cost})
endforeach()
