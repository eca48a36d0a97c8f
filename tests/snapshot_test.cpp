// clone() and state_hash(): a clone has the same future as the original, shares
// nothing with it, and hashes alike; replaying the same actions from a fresh
// reset reaches the same hash.
#include <gtest/gtest.h>


#include "compiler/analyse/program.hpp"
#include "harness/engine.hpp"
#include "harness/policy.hpp"
#include "test_support.hpp"

namespace autumn::snapshot_test {
namespace {

// The harness's reproducible policy, unrolled into a fixed action list.
std::vector<Action> random_actions(uint64_t seed, size_t n, int grid) {
  Frame f;
  f.size = grid;
  f.cells.assign(static_cast<size_t>(grid) * grid, 0);
  RandomPolicy policy(seed);
  std::vector<Action> out;
  for (size_t i = 0; i < n; ++i) out.push_back(policy.next(f));
  return out;
}

std::vector<std::string> rows(const Environment& e) { return frame_rows(e.frame(), e.palette()); }

std::vector<std::filesystem::path> sample_programs() {
  std::vector<std::filesystem::path> out;
  for (const char* n : {"ice", "particles", "ajl_snake", "magnets", "paint", "ajl_ricochet_robots", "grow", "sand"}) {
    auto p = testing::shared_dir() / "conformance/programs" / (std::string(n) + ".sexp");
    if (std::filesystem::exists(p)) out.push_back(p);
  }
  for (const auto& p : testing::files_in(testing::source_dir() / "programs", ".au")) out.push_back(p);
  for (const auto& p : testing::files_in(testing::source_dir() / "tests/golden", ".au")) out.push_back(p);
  return out;
}

class Snapshot : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(Snapshot, CloneHasTheSameFutureAndHash) {
  auto program = load_program_file(GetParam().string());
  std::string why;
  auto env = make_environment("interp", program, &why);
  ASSERT_TRUE(env) << why;
  for (uint64_t seed : {0ull, 5ull}) {
    ASSERT_TRUE(env->reset(seed)) << env->error();
    auto actions = random_actions(seed + 11, 40, env->frame().size);
    size_t split = 15;
    bool ok = true;
    for (size_t i = 0; ok && i < split; ++i) ok = env->step(actions[i]);
    if (!ok) continue;  // programs may legitimately fail under random input
    auto copy = env->clone();
    EXPECT_EQ(copy->state_hash(), env->state_hash());
    EXPECT_EQ(rows(*copy), rows(*env));
    // Drive the original elsewhere first: the copy must not notice.
    auto detour = env->clone();
    for (int k = 0; k < 5; ++k) detour->step(Action::click(k, k));
    for (size_t i = split; i < actions.size(); ++i) {
      bool a = env->step(actions[i]);
      bool b = copy->step(actions[i]);
      ASSERT_EQ(a, b) << "step " << i;
      if (!a) break;
      ASSERT_EQ(rows(*copy), rows(*env)) << "step " << i;
      ASSERT_EQ(copy->state_hash(), env->state_hash()) << "step " << i;
    }
  }
}

TEST_P(Snapshot, ReplayReachesTheSameHash) {
  auto program = load_program_file(GetParam().string());
  auto a = make_environment("interp", program, nullptr);
  auto b = make_environment("interp", program, nullptr);
  ASSERT_TRUE(a->reset(3));
  ASSERT_TRUE(b->reset(3));
  EXPECT_EQ(a->state_hash(), b->state_hash());
  for (const Action& act : random_actions(99, 20, a->frame().size)) {
    bool ok = a->step(act);
    ASSERT_EQ(ok, b->step(act));
    if (!ok) break;
    ASSERT_EQ(a->state_hash(), b->state_hash());
  }
}

INSTANTIATE_TEST_SUITE_P(Programs, Snapshot, ::testing::ValuesIn(sample_programs()),
                         [](const auto& info) { return info.param.stem().string(); });

TEST(SnapshotHash, DistinguishesDifferentStates) {
  auto program = load_program_file((testing::source_dir() / "tests/golden/stale_occupancy.au").string());
  auto a = make_environment("interp", program, nullptr);
  ASSERT_TRUE(a->reset(0));
  uint64_t h0 = a->state_hash();
  ASSERT_TRUE(a->step(Action::noop()));
  EXPECT_NE(a->state_hash(), h0);
}

}  // namespace
}  // namespace autumn::snapshot_test
