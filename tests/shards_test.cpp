// --shard K/N and --merge on every command over many units (harness/shards.hpp,
// harness/cli/shard_options.hpp; eval's own test is AgentEval.ShardsMergeToTheWholeRun).
// Each command runs whole and as shards, and the shards' merge must give the
// whole run's JSON and table, except the measured times, named per command;
// then the merge's refusals: a shard missing, one given twice, a shard of
// another run, and options that do not go together. The runs are small (a few
// programs or tasks, a few steps, the programs/ whose modules are built in):
// the suite takes seconds.
#include <gtest/gtest.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "harness/shards.hpp"
#include "test_support.hpp"

namespace autumn::shards_test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::CliResult;
using testing::run_cli;

fs::path scratch(const std::string& name) { return testing::scratch_dir("shards", name); }

std::string program(const std::string& name) { return (testing::source_dir() / "programs" / name).string(); }
json read_json(const fs::path& p) { return json::parse(testing::read_text(p)); }

// `j` without the keys `drop`, at any depth.
json without(json j, const std::set<std::string>& drop) {
  if (j.is_object()) {
    for (const std::string& k : drop) j.erase(k);
    for (auto& [k, v] : j.items()) v = without(v, drop);
  } else if (j.is_array()) {
    for (auto& v : j) v = without(v, drop);
  }
  return j;
}

// One command whole and in `n` shards, and the shards merged (given in reverse
// order); `out` the printed table (stdout), `json` the --json-out file.
struct RoundTrip {
  CliResult whole, merged;
  json whole_json, merged_json;
  std::vector<fs::path> shards;
};

RoundTrip round_trip(const fs::path& dir, const std::string& command, const std::string& inputs,
                     const std::string& options, int n, int status = 0) {
  RoundTrip r;
  const std::string run = command + " " + inputs + " " + options;
  r.whole = run_cli(run + " --json-out " + (dir / "whole.json").string(), true);
  EXPECT_EQ(r.whole.status, status) << run << "\n" << r.whole.out;
  std::string merge = command + " --merge";
  for (int k = 1; k <= n; ++k) {
    const fs::path shard = dir / ("shard-" + std::to_string(k) + ".json");
    const std::string one =
        run + " --shard " + std::to_string(k) + "/" + std::to_string(n) + " --json-out " + shard.string();
    const CliResult s = run_cli(one);
    EXPECT_TRUE(s.status == 0 || s.status == status) << one << "\n" << s.out;
    r.shards.push_back(shard);
  }
  for (int k = n; k >= 1; --k) merge += " " + r.shards[static_cast<size_t>(k - 1)].string();
  r.merged = run_cli(merge + " --json-out " + (dir / "merged.json").string(), true);
  EXPECT_EQ(r.merged.status, status) << merge << "\n" << r.merged.out;
  r.whole_json = read_json(dir / "whole.json");
  r.merged_json = read_json(dir / "merged.json");
  return r;
}

// The refusals every sharded command shares: `r` has two shards; `other` is
// shard 2/2 of a run with different settings; `inputs` and `option` a unit and
// a run option of the command.
void expect_refusals(const std::string& command, const RoundTrip& r, const fs::path& other, const std::string& inputs,
                     const std::string& option, const std::string& differing_key) {
  const std::string one = r.shards[0].string(), two = r.shards[1].string();
  const auto fails = [&](const std::string& args, int status, const std::string& says) {
    const CliResult c = run_cli(command + " " + args);
    EXPECT_EQ(c.status, status) << command << " " << args << "\n" << c.out;
    EXPECT_NE(c.out.find(says), std::string::npos) << command << " " << args << "\n" << c.out;
    EXPECT_EQ(c.out.find("[#"), std::string::npos) << "ran units: " << command << " " << args << "\n" << c.out;
  };
  fails("--merge " + one, 1, "autumn " + command + ": shards missing: 2 (of 2)");
  fails("--merge " + one + " " + one, 1, one + ": shard 1 is also " + one);
  fails("--merge " + one + " " + other.string(), 1,
        other.string() + ": not of the same run as " + one + ": " + differing_key);
  fails("--merge " + one + " " + (r.shards[0].parent_path() / "whole.json").string(), 1, "whole.json: not a shard");
  fails(inputs + " --merge " + one + " " + two, 2, "excludes");
  fails("--merge " + one + " " + two + " --shard 1/2", 2, "excludes");
  fails("--merge " + one + " " + two + " " + option, 2, "is an option of a run");
  fails(inputs + " --shard 3/2", 2, "--shard '3/2': K must be from 1 to N");
  fails("--json", 2, "is required, or --merge SHARD.json");
}

// `table` with every number matching `measured` as "#", and runs of spaces as
// one (a measured column's width varies).
std::string unmeasured(const std::string& table, const std::string& measured = "[0-9]+\\.[0-9]+") {
  return std::regex_replace(std::regex_replace(table, std::regex(measured), "#"), std::regex(" +"), " ");
}

// The first `n` words of each line of `table` (the columns that are not measured).
std::vector<std::string> first_words(const std::string& table, size_t n) {
  std::vector<std::string> out;
  std::istringstream lines(table);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string w, kept;
    for (size_t i = 0; i < n && words >> w; ++i) kept += w + " ";
    out.push_back(kept);
  }
  return out;
}

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

// ------------------------------------------------------------------ one test per command

// survey: the rows and totals, in three shards too; a program ending in a
// runtime error is a row like the others (exit status 1 for the whole run, the
// merge too). time_ms is measured.
TEST(Shards, SurveyMergesToTheWholeRun) {
  const fs::path dir = scratch("survey"), programs = dir / "programs";
  fs::create_directories(programs);
  for (const char* p : {"blockfall.au", "color_flood.au", "sokoban.au", "garden.au"})
    fs::copy_file(program(p), programs / p);
  fs::copy_file(testing::source_dir() / "tests/runtime_errors/division_by_zero.au", programs / "division_by_zero.au");
  for (int n : {2, 3}) {
    const fs::path run = dir / std::to_string(n);
    fs::create_directories(run);
    const RoundTrip r = round_trip(run, "survey", programs.string(), "--steps 6 --seed 3", n, 1);
    EXPECT_EQ(without(r.merged_json, {"time_ms"}), without(r.whole_json, {"time_ms"}));
    EXPECT_EQ(r.merged_json["programs"].size(), 5u);
    for (const json& p : r.merged_json["programs"]) EXPECT_TRUE(p["time_ms"].is_number()) << p;
    EXPECT_EQ(read_json(r.shards[0])["shard"], (json{{"index", 1}, {"count", n}, {"programs", 5}}));
    EXPECT_EQ(unmeasured(r.merged.out), unmeasured(r.whole.out));
    EXPECT_NE(r.merged.out.find("5 programs, "), std::string::npos) << r.merged.out;
    if (n == 3) continue;
    const fs::path other = run / "other.json";
    run_cli("survey " + programs.string() + " --steps 7 --seed 3 --shard 2/2 --json-out " + other.string());
    expect_refusals("survey", r, other, programs.string(), "--steps 6", "steps_per_program is 7 here, 6 there");
  }
}

// difftest: nothing measured, so the JSON and the text are the whole run's
// exactly. Programs given as files, out of name order: the run's order is the
// order given.
TEST(Shards, DifftestMergesToTheWholeRun) {
  const fs::path dir = scratch("difftest");
  const std::string programs = program("sokoban.au") + " " + program("blockfall.au") + " " + program("garden.au");
  const RoundTrip r = round_trip(dir, "difftest", programs, "--seeds 2 --steps 8", 2);
  EXPECT_EQ(r.merged_json, r.whole_json);
  EXPECT_EQ(r.merged.out, r.whole.out);
  ASSERT_EQ(r.merged_json["programs"].size(), 3u);
  EXPECT_EQ(r.merged_json["programs"][0]["program"], program("sokoban.au"));
  EXPECT_EQ(r.merged_json["programs"][0]["episodes"], 2);
  const fs::path other = dir / "other.json";
  run_cli("difftest " + programs + " --seeds 2 --steps 8 --first-seed 5 --shard 2/2 --json-out " + other.string());
  expect_refusals("difftest", r, other, programs, "--seeds 2", "first_seed is 5 here, 0 there");
}

// bench: the rows' programs, grids, step counts and engine outcomes; the
// figures (steps/s, clone ns, ratio) are measured, so only present, and the
// medians are recomputed from the merged rows.
TEST(Shards, BenchMergesToTheWholeRun) {
  const fs::path dir = scratch("bench");
  const std::string programs = program("sokoban.au") + " " + program("blockfall.au") + " " + program("garden.au");
  const RoundTrip r = round_trip(dir, "bench", programs, "--steps 20", 2);
  const std::set<std::string> measured = {"steps_per_s", "steps_per_s_no_render", "clone_ns", "ratio", "median_ratio",
                                          "median_compiled_step_us"};
  EXPECT_EQ(without(r.merged_json, measured), without(r.whole_json, measured));
  std::vector<double> ratios;
  for (const json& row : r.merged_json["rows"]) {
    for (const char* e : {"interp", "compiled"}) {
      EXPECT_GT(row[e]["steps_per_s"].get<double>(), 0) << row;
      EXPECT_GT(row[e]["clone_ns"].get<double>(), 0) << row;
    }
    ratios.push_back(row["ratio"].get<double>());
  }
  ASSERT_EQ(ratios.size(), 3u);
  std::sort(ratios.begin(), ratios.end());
  EXPECT_DOUBLE_EQ(r.merged_json["median_ratio"].get<double>(), ratios[1]);
  EXPECT_EQ(unmeasured(r.merged.out, "[0-9]+(\\.[0-9]+)?"), unmeasured(r.whole.out, "[0-9]+(\\.[0-9]+)?"));
  EXPECT_NE(r.merged.out.find("median over 3 programs"), std::string::npos) << r.merged.out;
  const fs::path other = dir / "other.json";
  run_cli("bench " + programs + " --steps 20 --seed 1 --shard 2/2 --json-out " + other.string());
  expect_refusals("bench", r, other, programs, "--steps 20", "seed is 1 here, 0 there");
  const CliResult only = run_cli("bench " + programs + " --only interp --shard 1/2");
  EXPECT_EQ(only.status, 2) << only.out;
  EXPECT_NE(only.out.find("--only (profiling one engine) does not shard"), std::string::npos) << only.out;
}

// bench-agent: three copies of flood_defense (16x16: their built-in module, no
// search model to compile) and blockfall (8x8), which --grid 16 leaves out: its
// shard records it as skipped and the merge has the whole run's rows, shard 2's
// between shard 1's. The times and rates are measured; the node counts are not
// (one layer of the search, whole).
TEST(Shards, BenchAgentMergesToTheWholeRun) {
  const fs::path dir = scratch("bench_agent"), programs = dir / "programs";
  fs::create_directories(programs);
  for (const char* copy : {"a_flood.au", "b_flood.au", "c_flood.au"})
    fs::copy_file(program("flood_defense.au"), programs / copy);
  fs::copy_file(program("blockfall.au"), programs / "d_blockfall.au");
  const std::string options =
      "--threads 1 --rollouts 20 --mfp-steps 3 --bfs-nodes 300 --bfs-depth 1 --seconds 20";
  const RoundTrip r = round_trip(dir, "bench-agent", programs.string(), options, 2);
  const std::set<std::string> measured = {"mfp_seconds", "mfp_rollouts_per_s", "bfs_seconds_1_thread",
                                          "bfs_seconds_n_threads", "bfs_nodes_per_s_1_thread",
                                          "bfs_nodes_per_s_n_threads"};
  EXPECT_EQ(without(r.merged_json, measured), without(r.whole_json, measured));
  ASSERT_EQ(r.merged_json["programs"].size(), 3u);
  EXPECT_EQ(r.merged_json["programs"][1]["program"], "b_flood");  // shard 2's, between shard 1's two
  for (const json& p : r.merged_json["programs"])
    for (const std::string& key : measured) EXPECT_TRUE(p[key].is_number()) << key << " " << p;
  EXPECT_EQ(read_json(r.shards[1])["shard"]["skipped"], (json{3}));
  EXPECT_FALSE(read_json(r.shards[0])["shard"].contains("skipped"));
  EXPECT_EQ(first_words(r.merged.out, 3), first_words(r.whole.out, 3));  // each row's program, grid and code
  const fs::path other = dir / "other.json";
  run_cli("bench-agent " + programs.string() + " " + options + " --seed 2 --shard 2/2 --json-out " + other.string());
  expect_refusals("bench-agent", r, other, programs.string(), "--grid 0", "seed is 2 here, 1 there");
}

// baseline random: the scores, successes and steps (rollout r draws from (seed,
// r), whichever shard runs the task); "seconds" is measured.
TEST(Shards, BaselineRandomMergesToTheWholeRun) {
  const fs::path dir = scratch("baseline");
  std::string tasks;
  for (const char* t : {"sokoban_planning.json", "blockfall_mfp.json", "sokoban_cd.json", "garden_cd.json"})
    tasks += " " + (testing::source_dir() / "tasks/generated/prompts" / t).string();
  const std::string options = "--engine interp --rollouts 8 --timeout 15 --threads 1";
  const RoundTrip r = round_trip(dir, "baseline random", tasks, options, 2);
  EXPECT_EQ(without(r.merged_json, {"seconds"}), without(r.whole_json, {"seconds"}));
  ASSERT_EQ(r.merged_json["tasks"].size(), 4u);
  for (const json& t : r.merged_json["tasks"]) EXPECT_TRUE(t["seconds"].is_number()) << t;
  const auto summary = [](const std::string& table) { return table.substr(table.find("\ntype ")); };  // per type
  EXPECT_EQ(summary(r.merged.out), summary(r.whole.out));
  const fs::path other = dir / "other.json";
  run_cli("baseline random" + tasks + " " + options + " --seed 9 --shard 2/2 --json-out " + other.string());
  expect_refusals("baseline random", r, other, tasks, "--rollouts 8", "agent/seed is 9 here, 0 there");
}

}  // namespace
}  // namespace autumn::shards_test
