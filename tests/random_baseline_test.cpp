// random_baseline_test — the paper's random agent against probabilities worked out
// by hand, and the paper protocol's BFS caps (harness/agent/random_baseline.hpp,
// planning.hpp's paper_action_set).
//
// The worlds are tiny programs written into a scratch task folder (prompts/,
// programs/, answers/). The random policy picks one of six action types
// uniformly, a click on a uniform cell, so on a 4x4 grid one given click has
// probability 1/96 a step and one given arrow 1/6; the estimates must land within
// four standard errors of the exact values, on both engines.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "harness/agent/planning.hpp"
#include "harness/agent/random_baseline.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/engine.hpp"
#include "test_support.hpp"

namespace random_baseline_test {
namespace {

namespace fs = std::filesystem;
using namespace autumn;
using namespace autumn::agent;

// A fresh task folder under the test program's scratch root (test_support.hpp),
// removed when the program ends.
fs::path scratch(const std::string& name) {
  const fs::path dir = autumn::testing::scratch_dir("random_baseline", name);
  for (const char* sub : {"prompts", "programs", "answers"}) fs::create_directories(dir / sub);
  return dir;
}

void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

// hit turns true on a click on cell (2, 3) and stays true.
const char kClickOnce[] = R"((program
  (= GRID_SIZE 4)
  (: hit Bool)
  (= hit (initnext false (prev hit)))
  (object Lamp (: lit Bool) (Cell 0 0 (if lit then "red" else "grey")))
  (: lamp Lamp)
  (= lamp (initnext (Lamp false (Position 0 0)) (updateObj (prev lamp) "lit" hit)))
  (on (& clicked (& (== (.. click x) 2) (== (.. click y) 3))) (= hit true)))
)";

// The lamp at (1, 1) turns red on the first `up` and stays red.
const char kUpOnce[] = R"((program
  (= GRID_SIZE 4)
  (object Lamp (: lit Bool) (Cell 0 0 (if lit then "red" else "grey")))
  (: lamp Lamp)
  (= lamp (initnext (Lamp false (Position 1 1)) (prev lamp)))
  (on up (= lamp (updateObj (prev lamp) "lit" true))))
)";

// P(first success at step t) = q (1 - q)^(t - 1): the chance of a success within
// T steps, and the mean t given one.
struct Geometric {
  double p = 0, mean = 0;
};
Geometric geometric(double q, int T) {
  Geometric g;
  for (int t = 1; t <= T; ++t) {
    const double at = q * std::pow(1 - q, t - 1);
    g.p += at;
    g.mean += t * at;
  }
  g.mean /= g.p;
  return g;
}

class RandomBaseline : public ::testing::TestWithParam<std::string> {};

// Change detection: the condition holds from the state after the click on
// (2, 3), so within T steps with probability 1 - (95/96)^T.
TEST_P(RandomBaseline, TriggerOnOneCellMatchesItsProbability) {
  const fs::path dir = scratch("cd_" + GetParam());
  write(dir / "programs" / "lamp.au", kClickOnce);
  write(dir / "programs" / "lamp_wrong.au", kClickOnce);
  write(dir / "prompts" / "lamp_cd.json", R"({"type": "change_detection", "program": "lamp", "wrong_program": "lamp_wrong"})");
  write(dir / "answers" / "lamp_cd.json", R"({"condition": "== hit true"})");
  RandomOptions o;
  o.engine = GetParam();
  o.rollouts = 2000;
  o.timeout = 50;
  o.seed = 3;
  ThreadPool pool(2);
  const RandomResult r = random_baseline(load_task(dir / "prompts" / "lamp_cd.json"), o, pool);
  const Geometric want = geometric(1.0 / 96, o.timeout);
  ASSERT_TRUE(r.score);
  EXPECT_EQ(r.rollouts, 2000u);
  EXPECT_EQ(r.errors, 0u);
  EXPECT_EQ(r.trigger, "== hit true");
  const double se = std::sqrt(want.p * (1 - want.p) / 2000);
  EXPECT_NEAR(*r.score, want.p, 4 * se) << "exact " << want.p;
  ASSERT_TRUE(r.mean_steps);
  // The steps of a success spread over 1..50 (sd about 14): the mean's error is under 0.5.
  EXPECT_NEAR(*r.mean_steps, want.mean, 2.0) << "exact " << want.mean;
  // The same seed gives the same estimate, whatever the threads.
  ThreadPool one(1);
  const RandomResult again = random_baseline(load_task(dir / "prompts" / "lamp_cd.json"), o, one);
  EXPECT_EQ(again.successes, r.successes);
  EXPECT_EQ(*again.mean_steps, *r.mean_steps);
  fs::remove_all(dir);
}

// Planning: the goal (the lamp red) is one `up` away, 1/6 a step; within T = 3
// steps with probability 1 - (5/6)^3.
TEST_P(RandomBaseline, GoalOneActionAwayMatchesItsProbability) {
  const fs::path dir = scratch("planning_" + GetParam());
  write(dir / "programs" / "lamp.au", kUpOnce);
  // The goal: the lamp's cell red (colour id 2 of the built-in table), the mask that cell alone.
  const ColourTable colours;
  const int red = colours.find("red");
  ASSERT_GE(red, 0);
  std::string goal = "[", mask = "[";
  for (int y = 0; y < 4; ++y) {
    goal += y ? ",[" : "[";
    mask += y ? ",[" : "[";
    for (int x = 0; x < 4; ++x) {
      goal += (x ? "," : "") + std::to_string(x == 1 && y == 1 ? red : 0);
      mask += (x ? "," : "") + std::string(x == 1 && y == 1 ? "1" : "0");
    }
    goal += "]";
    mask += "]";
  }
  write(dir / "prompts" / "lamp_planning.json",
        R"({"type": "planning", "program": "lamp", "goal": )" + goal + "], \"mask\": " + mask + "]}");
  RandomOptions o;
  o.engine = GetParam();
  o.rollouts = 3000;
  o.timeout = 3;
  ThreadPool pool(2);
  const RandomResult r = random_baseline(load_task(dir / "prompts" / "lamp_planning.json"), o, pool);
  const Geometric want = geometric(1.0 / 6, 3);
  ASSERT_TRUE(r.score);
  const double se = std::sqrt(want.p * (1 - want.p) / 3000);
  EXPECT_NEAR(*r.score, want.p, 4 * se) << "exact " << want.p;
  ASSERT_TRUE(r.mean_steps);
  EXPECT_NEAR(*r.mean_steps, want.mean, 0.1) << "exact " << want.mean;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Engines, RandomBaseline, ::testing::ValuesIn(autumn::testing::test_engines()));

// Masked-frame prediction: chance over the choices, no rollouts; a task without
// a known answer is not scored (as eval leaves the public ice task unscored).
TEST(RandomBaselineMfp, IsChanceOverTheChoices) {
  const Task task = load_task(autumn::testing::source_dir() / "tasks" / "generated" / "prompts" / "blockfall_mfp.json");
  ThreadPool pool(1);
  const RandomResult r = random_baseline(task, RandomOptions{}, pool);
  ASSERT_TRUE(r.score);
  EXPECT_EQ(r.choices, static_cast<int>(task.choices.size()));
  EXPECT_DOUBLE_EQ(*r.score, 1.0 / static_cast<double>(task.choices.size()));
  EXPECT_EQ(r.rollouts, 0u);
  const fs::path ice = autumn::testing::shared_dir() / "tasks" / "autumnbench" / "prompts" / "ice_mfp.json";
  if (!fs::exists(ice)) return;
  const RandomResult unscored = random_baseline(load_task(ice), RandomOptions{}, pool);
  EXPECT_FALSE(unscored.score);
  EXPECT_EQ(random_json(unscored)["chance"], 1.0 / static_cast<double>(load_task(ice).choices.size()));
}

// The CLI: a table by default, JSON with the agent's settings, an error row that
// does not stop the others (exit 1).
TEST(RandomBaselineCli, TableJsonAndBadTasks) {
  const fs::path dir = scratch("cli");
  write(dir / "programs" / "lamp.au", kUpOnce);
  write(dir / "prompts" / "a_bad.json", R"({"type": "planning", "program": "missing"})");
  write(dir / "prompts" / "b_mfp.json", "not json");
  auto r = autumn::testing::run_cli("baseline random " + (dir / "prompts").string() + " --rollouts 5 --timeout 5 --json", true);
  EXPECT_EQ(r.status, 1) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["agent"]["name"], "random");
  EXPECT_EQ(j["agent"]["rollouts"], 5);
  EXPECT_EQ(j["agent"]["timeout"], 5);
  ASSERT_EQ(j["tasks"].size(), 2u);
  EXPECT_TRUE(j["tasks"][0].contains("error"));
  r = autumn::testing::run_cli("baseline random " + (dir / "prompts").string() + " --timeout 0");
  EXPECT_EQ(r.status, 2) << r.out;
  r = autumn::testing::run_cli("baseline");
  EXPECT_NE(r.status, 0) << r.out;
  fs::remove_all(dir);
}

// The paper protocol's BFS: depth and breadth capped at 10. A dot that `right`
// moves one cell: a goal 10 moves away is found (the first shortest plan, ten
// rights), one 11 away is not.
TEST(PaperProtocol, BfsFindsTenActionsAwayButNotEleven) {
  const fs::path dir = scratch("paper");
  write(dir / "programs" / "dot.au", R"((program
  (= GRID_SIZE 12)
  (object Dot (Cell 0 0 "blue"))
  (: dot Dot)
  (= dot (initnext (Dot (Position 0 0)) (prev dot)))
  (on right (= dot (moveRight (prev dot)))))
)");
  const ColourTable colours;
  for (int away : {10, 11}) {
    std::string goal = "[", mask = "[";
    for (int y = 0; y < 12; ++y) {
      goal += y ? ",[" : "[";
      mask += y ? ",[" : "[";
      for (int x = 0; x < 12; ++x) {
        goal += (x ? "," : "") + std::to_string(y == 0 && x == away ? colours.find("blue") : 0);
        mask += (x ? "," : "") + std::string(y == 0 && x == away ? "1" : "0");
      }
      goal += "]";
      mask += "]";
    }
    const fs::path file = dir / "prompts" / ("dot_" + std::to_string(away) + ".json");
    write(file, R"({"type": "planning", "program": "dot", "goal": )" + goal + "], \"mask\": " + mask + "]}");
    SolveOptions o;
    o.engine = "interp";
    o.search = "paper";
    o.depth = 10;
    o.time_limit = 0;
    ThreadPool pool(2);
    const PlanResult r = solve_planning(load_task(file), o, pool);
    EXPECT_EQ(r.method, away == 10 ? "paper bfs" : "") << away;
    EXPECT_EQ(r.found, away == 10) << planning_summary(r);
    if (r.found) {
      EXPECT_EQ(r.plan, std::vector<Action>(10, Action{Action::Kind::Right}));
      EXPECT_TRUE(r.verified);
    } else {
      EXPECT_EQ(r.bfs_depth_done, 10) << planning_summary(r);
    }
  }
  // Breadth: noop, four arrows, five distinct clicks; the same for the same seed.
  const std::vector<Action> set = paper_action_set(12, 0);
  ASSERT_EQ(set.size(), 10u);
  EXPECT_EQ(set, paper_action_set(12, 0));
  EXPECT_NE(set, paper_action_set(12, 1));
  for (size_t i = 5; i < set.size(); ++i) EXPECT_EQ(set[i].kind, Action::Kind::Click);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace random_baseline_test
