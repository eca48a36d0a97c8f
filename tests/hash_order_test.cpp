// The order model must agree with libstdc++'s real container. This build uses
// libstdc++ (GCC), so we can compare against std::unordered_map directly.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "runtime/hash_order.hpp"

namespace autumn::hash_order_test {
namespace {

TEST(HashOrder, StringHashMatchesStdHash) {
  for (std::string s : {"", "a", "ab", "abcdefg", "abcdefgh", "abcdefghi", "GRID_SIZE", "nextLiquidMoveClosestHole"})
    EXPECT_EQ(libstdcxx_string_hash(s), std::hash<std::string>{}(s)) << s;
}

TEST(HashOrder, DocumentedExample) {
  // initnext names a b c d x declared in that order iterate as x c b d a.
  std::vector<std::string> names = {"a", "b", "c", "d", "x"};
  HashOrder h;
  for (int i = 0; i < 5; ++i) h.insert(i, libstdcxx_string_hash(names[i]));
  std::vector<std::string> got;
  h.for_each([&](int k) { got.push_back(names[k]); });
  EXPECT_EQ(got, (std::vector<std::string>{"x", "c", "b", "d", "a"}));
}

TEST(HashOrder, MatchesStdUnorderedMapUnderRandomInsertErase) {
  std::mt19937 rng(12345);
  for (int round = 0; round < 300; ++round) {
    const int universe = 5 + static_cast<int>(rng() % 400);
    std::vector<std::string> names;
    for (int i = 0; i < universe; ++i) names.push_back("v" + std::to_string(rng() % 100000) + "_" + std::to_string(i));
    std::unordered_map<std::string, int> real;
    HashOrder model;
    const int ops = static_cast<int>(rng() % 600);
    for (int op = 0; op < ops; ++op) {
      int k = static_cast<int>(rng() % universe);
      if (rng() % 4 == 0) {
        real.erase(names[k]);
        model.erase(k);
      } else {
        real.emplace(names[k], k);
        model.insert(k, libstdcxx_string_hash(names[k]));
      }
    }
    std::vector<int> want;
    for (const auto& [name, k] : real) want.push_back(k);
    ASSERT_EQ(model.order(), want) << "round " << round;
  }
}

// A map rebuilt from its snapshot (order, bucket count, resize threshold) goes
// on exactly as the original under any further history.
TEST(HashOrder, RestoredMapContinuesLikeTheOriginal) {
  std::mt19937 rng(777);
  for (int round = 0; round < 200; ++round) {
    const int universe = 3 + static_cast<int>(rng() % 200);
    std::vector<std::string> names;
    for (int i = 0; i < universe; ++i) names.push_back("g" + std::to_string(rng() % 100000) + "_" + std::to_string(i));
    std::unordered_map<std::string, int> real;
    HashOrder model;
    auto step = [&](HashOrder& h) {
      int k = static_cast<int>(rng() % universe);
      if (rng() % 3 == 0) {
        real.erase(names[k]);
        h.erase(k);
      } else {
        real.emplace(names[k], k);
        h.insert(k, libstdcxx_string_hash(names[k]));
      }
    };
    for (int op = static_cast<int>(rng() % 300); op > 0; --op) step(model);
    std::vector<std::pair<int, uint64_t>> keys;
    for (int k : model.order()) keys.emplace_back(k, model.hash_of(k));
    HashOrder restored;
    restored.restore(model.bucket_count(), model.next_resize(), keys);
    ASSERT_EQ(restored.order(), model.order());
    for (int op = static_cast<int>(rng() % 300); op > 0; --op) step(restored);
    std::vector<int> want;
    for (const auto& [name, k] : real) want.push_back(k);
    ASSERT_EQ(restored.order(), want) << "round " << round;
  }
}

TEST(HashOrder, RestoreRejectsImpossibleDescriptions) {
  HashOrder h;
  EXPECT_THROW(h.restore(0, 0, {}), std::invalid_argument);
  EXPECT_THROW(h.restore(13, 13, {{1, 5}, {1, 5}}), std::invalid_argument);
  EXPECT_THROW(h.restore(13, 13, {{-1, 5}}), std::invalid_argument);
}

}  // namespace
}  // namespace autumn::hash_order_test
