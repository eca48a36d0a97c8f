// The compiled engine against the golden traces and against the interpreter.
//
// Modules of bundled programs are built in (generated/); others are compiled on
// demand into AUTUMN_CACHE_DIR (build/module-cache under ctest). Long runs of the
// differential test: autumn difftest programs ../shared/conformance/programs --seeds 50 --steps 500
#include <gtest/gtest.h>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/lower.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/policy.hpp"
#include "harness/trace_check.hpp"
#include "test_support.hpp"

namespace autumn::compiled_engine_test {
namespace {

using testing::trace_names;

class CompiledConformance : public ::testing::TestWithParam<std::string> {};

TEST_P(CompiledConformance, MatchesEveryFrame) {
  if (GetParam() == "MISSING_SHARED_CORPUS")
    GTEST_SKIP() << "SKIPPED LOUDLY: no conformance corpus at " << testing::shared_dir();
  const auto dir = testing::shared_dir() / "conformance";
  TraceFile file = load_trace_file((dir / "traces" / (GetParam() + ".json")).string());
  auto program = load_program_file((dir / "programs" / (GetParam() + ".sexp")).string(), file.triggering_condition);
  std::string why;
  auto env = make_environment("compiled", program, &why);
  ASSERT_TRUE(env) << why;
  CheckResult r = check_traces(*env, file);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.frames_matched, r.frames_total);
  EXPECT_EQ(r.triggers_matched, r.triggers_total);
}

INSTANTIATE_TEST_SUITE_P(Traces, CompiledConformance, ::testing::ValuesIn(trace_names()),
                         [](const auto& info) { return info.param; });

std::vector<std::filesystem::path> diff_programs() {
  auto out = testing::files_in(testing::source_dir() / "programs", ".au");
  // The golden quirk programs too: each pins down a corner the lowering must keep.
  for (const auto& p : testing::files_in(testing::source_dir() / "tests/golden", ".au")) out.push_back(p);
  // And the lowering's construct programs, under random actions rather than their one script.
  for (const auto& p : testing::files_in(testing::source_dir() / "tests/lowering", ".au")) out.push_back(p);
  // And the stress programs written to trip the lowering (tests/stress/README.md).
  for (const auto& p : testing::files_in(testing::source_dir() / "tests/stress", ".au")) out.push_back(p);
  for (const auto& p : testing::files_in(testing::shared_dir() / "conformance/programs", ".sexp")) out.push_back(p);
  return out;
}

class Differential : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(Differential, CompiledAgreesWithInterpreter) {
  auto program = load_program_file(GetParam().string());
  DiffOptions o;
  // 107 programs x 8 seeds x 200 steps: about 170k steps compared in CI. An
  // embedded module (tests/lowering's "expect: embedded") runs the interpreter
  // itself, so the comparison checks only the embedding (reset, inputs, frames,
  // errors), which two short episodes cover. A program's "; random-limits:"
  // header sets the episodes' limits (test_support.hpp: construct_own_class
  // recurses to the call-depth limit every step; at the default it took 27 s
  // here for these 20 steps on each engine; 1 s at call-depth=200).
  const bool specialised = lower_program(*program, "p").ok;
  o.seeds = specialised ? 8 : 2;
  o.steps = specialised ? 200 : 10;
  o.limits = testing::random_limits(GetParam());
  DiffResult r = diff_engines(program, o);
  EXPECT_FALSE(r.setup_failed) << r.divergence;
  EXPECT_EQ(r.divergence, "") << GetParam();
  EXPECT_GT(r.episodes, 0u);
}

INSTANTIATE_TEST_SUITE_P(Programs, Differential, ::testing::ValuesIn(diff_programs()),
                         [](const auto& info) { return info.param.stem().string(); });

// copy_from() and save_state()/load_state(), which the planner stores its open
// states with: an environment overwritten by copy_from, and one restored from a
// snapshot, must continue exactly as the original (frames, trigger, hash). Every
// specialised program must support snapshots (embedded ones may decline).
class CopyAndSnapshot : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(CopyAndSnapshot, KeepTheFuture) {
  auto program = load_program_file(GetParam().string());
  const bool specialised = lower_program(*program, "p").ok;
  std::string why;
  auto env = make_environment("compiled", program, &why);
  auto copy = make_environment("compiled", program, &why);
  auto restored = make_environment("compiled", program, &why);
  ASSERT_TRUE(env && copy && restored) << why;
  const Limits limits = testing::random_limits(GetParam());  // its "; random-limits:", or the defaults
  for (Environment* e : {env.get(), copy.get(), restored.get()}) e->set_limits(limits);
  // Embedded modules (the interpreter inside, no snapshots) check copy_from on one episode.
  for (uint64_t seed : {0ull, 3ull}) {
    if (!specialised && seed > 0) break;
    ASSERT_TRUE(env->reset(seed)) << env->error();
    RandomPolicy policy(seed + 17);
    // An embedded module runs the interpreter: a shorter episode.
    const size_t split = specialised ? 20 + seed * 10 : 4, total = split + (specialised ? 60 : 6);
    std::vector<Action> actions;
    for (size_t i = 0; i < total; ++i) actions.push_back(policy.next(env->frame()));
    bool ok = true;
    for (size_t i = 0; ok && i < split; ++i) ok = env->step(actions[i]);
    if (!ok) continue;  // programs may legitimately fail under random input
    // Targets that have been somewhere else first: nothing of that may survive.
    ASSERT_TRUE(copy->reset(seed + 1));
    ASSERT_TRUE(restored->reset(seed + 2));
    for (int k = 0; k < 3; ++k) copy->step(Action::click(k, k)), restored->step(Action{Action::Kind::Down, 0, 0});
    ASSERT_TRUE(copy->copy_from(*env));
    std::vector<uint8_t> bytes;
    const bool saved = env->save_state(bytes);
    EXPECT_TRUE(saved || !specialised) << "a specialised program must support snapshots";
    if (saved) {
      ASSERT_TRUE(restored->load_state(bytes.data(), bytes.size())) << restored->error();
    }
    auto rows = [](const Environment& e) { return frame_rows(e.frame(), e.palette()); };
    for (size_t i = split; i <= total; ++i) {
      if (i > split) {
        bool a = env->step(actions[i - 1]);
        ASSERT_EQ(a, copy->step(actions[i - 1])) << "step " << i;
        if (saved) {
          ASSERT_EQ(a, restored->step(actions[i - 1])) << "step " << i;
        }
        if (!a) break;
      }
      ASSERT_EQ(rows(*copy), rows(*env)) << "copy, step " << i;
      ASSERT_EQ(copy->state_hash(), env->state_hash()) << "copy, step " << i;
      ASSERT_EQ(copy->triggered(), env->triggered()) << "copy, step " << i;
      if (!saved) continue;
      ASSERT_EQ(rows(*restored), rows(*env)) << "snapshot, step " << i;
      ASSERT_EQ(restored->state_hash(), env->state_hash()) << "snapshot, step " << i;
      ASSERT_EQ(restored->triggered(), env->triggered()) << "snapshot, step " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Programs, CopyAndSnapshot, ::testing::ValuesIn(diff_programs()),
                         [](const auto& info) { return info.param.stem().string(); });

TEST(CompiledEngine, CorruptSnapshotIsAnError) {
  auto program = load_program_file((testing::source_dir() / "programs/breakout.au").string());
  auto env = make_environment("compiled", program, nullptr);
  ASSERT_TRUE(env && env->reset(0));
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(env->save_state(bytes));
  bytes.resize(bytes.size() / 2);
  EXPECT_FALSE(env->load_state(bytes.data(), bytes.size()));
  EXPECT_TRUE(env->failed());
  EXPECT_NE(env->error().find("snapshot"), std::string::npos) << env->error();
}

TEST(CompiledEngine, BadProgramIsAnErrorNotACrash) {
  EXPECT_THROW(load_program(SourceFile{"bad.au", "(program (= x"}), CompileError);
}

TEST(CompiledEngine, CloneBranchesIndependently) {
  auto program = load_program_file((testing::source_dir() / "tests/golden/stale_occupancy.au").string());
  std::string why;
  auto env = make_environment("compiled", program, &why);
  ASSERT_TRUE(env) << why;
  ASSERT_TRUE(env->reset(0));
  auto branch = env->clone();
  ASSERT_TRUE(env->step(Action::noop()));
  EXPECT_NE(frame_rows(env->frame(), env->palette()), frame_rows(branch->frame(), branch->palette()));
  ASSERT_TRUE(branch->step(Action::noop()));
  EXPECT_EQ(frame_rows(env->frame(), env->palette()), frame_rows(branch->frame(), branch->palette()));
  EXPECT_EQ(env->state_hash(), branch->state_hash());
}

// Environment::frame_cell reads a compiled frame cell by cell without copying it
// (the planner's goal test): the same ids as frame(), its colours named in the
// palette in the same order, also on a copy whose frame was never made.
TEST(CompiledEngine, FrameCellsReadOneByOneAreTheFrame) {
  for (const char* name : {"programs/color_flood.au", "programs/fireworks.au", "programs/garden.au"}) {
    SCOPED_TRACE(name);
    auto program = load_program_file((testing::source_dir() / name).string());
    std::string why;
    auto cells = make_environment("compiled", program, &why), whole = make_environment("compiled", program, &why);
    ASSERT_TRUE(cells && whole) << why;
    auto copy = cells->clone();
    ASSERT_TRUE(cells->reset(5) && whole->reset(5));
    RandomPolicy policy(9);
    for (int step = 0; step < 40; ++step) {
      const Frame& f = whole->frame();
      const Palette& p = whole->palette();
      ASSERT_EQ(cells->frame_side(), f.size);
      for (size_t i = f.cells.size(); i-- > 0;) {  // bottom-up: not the order pull() names colours in
        const uint16_t id = cells->frame_cell(i);
        ASSERT_EQ(id, f.cells[i]) << "step " << step << ", cell " << i;
        ASSERT_EQ(cells->cell_palette().name(id), p.name(f.cells[i]));
      }
      ASSERT_TRUE(copy->copy_from(*cells));
      const size_t last = f.cells.size() - 1;
      EXPECT_EQ(copy->cell_palette().name(copy->frame_cell(last)), p.name(f.cells[last]));
      const Action a = policy.next(f);
      const bool ok = whole->step(a);
      ASSERT_EQ(cells->step(a), ok);
      if (!ok) break;
    }
    EXPECT_EQ(cells->frame(), whole->frame());
    ASSERT_EQ(cells->palette().size(), whole->palette().size());
    for (uint16_t id = 0; id < whole->palette().size(); ++id) EXPECT_EQ(cells->palette().name(id), whole->palette().name(id));
  }
}

}  // namespace
}  // namespace autumn::compiled_engine_test
