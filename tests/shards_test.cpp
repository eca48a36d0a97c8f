// The rule every sharded command slices by and the checks of its merge
// (harness/shards.hpp; eval's round trip is AgentEval.ShardsMergeToTheWholeRun).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "harness/shards.hpp"

namespace autumn {
namespace {

using nlohmann::json;

// ------------------------------------------------------------------ the rule and the checks

TEST(Shards, SliceAndMergeChecks) {
  const std::vector<int> units = {0, 1, 2, 3, 4};
  EXPECT_EQ(select_shard(units, parse_shard("1/2")), (std::vector<int>{0, 2, 4}));
  EXPECT_EQ(select_shard(units, parse_shard("3/3")), (std::vector<int>{2}));
  EXPECT_EQ(shard_unit_index(parse_shard("2/3"), 1), 4u);
  EXPECT_TRUE(select_shard(units, parse_shard("6/6")).empty());
  const ShardFormat f{"survey", "programs", "programs", {"seed"}};
  // Five units in three shards, unit 3 (shard 1) without a row.
  const auto shard = [&](int k, json rows, std::vector<size_t> skipped = {}) {
    return json{{"seed", 1}, {"programs", rows}, {"shard", shard_json(Shard{k, 3}, "programs", 5, skipped)}};
  };
  const json u0 = json::array({"u0"}), u2 = json::array({"u2"}), u14 = json::array({"u1", "u4"});
  const std::vector<json> shards = {shard(2, u14), shard(1, u0, {3}), shard(3, u2)};
  const MergedShards m = merge_shards(shards, {"b", "a", "c"}, f);
  EXPECT_EQ(m.rows, (json{"u0", "u1", "u2", "u4"}));
  EXPECT_EQ(m.settings, (json{{"seed", 1}}));
  const auto refusal = [&](std::vector<json> s) {
    try {
      merge_shards(s, {"a", "b", "c"}, f);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("merged");
  };
  EXPECT_EQ(refusal({shard(1, json::array({"u0", "u3"}), {3}), shard(2, u14), shard(3, u2)}),
            "a: shard 1/3 of 5 programs has 2 rows, not 1")
      << "a row for a skipped unit";
  EXPECT_EQ(refusal({shard(1, u0, {2}), shard(2, u14), shard(3, u2)}),
            "a: its \"skipped\" 2 is not one of its programs");
  json other = shard(3, u2);
  other["seed"] = 2;
  EXPECT_EQ(refusal({shard(1, u0, {3}), shard(2, u14), other}), "c: not of the same run as a: seed is 2 here, 1 there");
  EXPECT_EQ(refusal({shard(1, u0, {3}), shard(2, u14)}), "shards missing: 3 (of 3)");
  EXPECT_EQ(refusal({json{{"seed", 1}}}), "a: not the JSON of `autumn survey` (no \"programs\")");
}

}  // namespace
}  // namespace autumn
