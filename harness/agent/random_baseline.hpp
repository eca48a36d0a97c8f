// random_baseline — the AutumnBench paper's memoryless random agent, estimated by
// rollouts.
//
// The policy chooses each step uniformly among six action types: click, up, down,
// left, right, noop; a click lands on a uniform cell of the grid. It never looks
// at what it sees. A task's estimate is the fraction of `rollouts` episodes (each
// at most `timeout` steps) that succeed:
//  * change detection: the world is the task's changed program with the answers'
//    trigger condition (and the answers' seed, else the task's, as eval scores);
//    success is the condition holding on a state within the timeout (state t, the
//    state after t steps, for t <= timeout; triggered() after step t + 1 reports
//    it, autumn-semantics §13). Steps are that t. Without an answers file holding
//    the condition there is nothing to estimate: the row says so, no score.
//  * planning: the world is the task's program (seed as above); success is the
//    frame matching the goal on the task's mask after t <= timeout steps (t = 0:
//    the initial frame).
//  * masked-frame prediction: a random agent guesses; its score is chance,
//    1 / (number of choices), exact, with no rollouts; as eval scores, only a
//    task whose answer is known (its answers' correct_idx) gets one.
// Change detection's score is thus the chance that random play exposes the
// change at all (the condition the changed program differs under), not a
// detection: the policy never reports one. The paper's figures read it so.
// A rollout that meets a runtime error of the program ends there as a failure
// (counted in `errors`). The score is the success fraction, with its binomial
// standard error sqrt(p (1 - p) / n). Rollout r draws from its own generator,
// seeded by (seed, r): results do not depend on the thread count.
// Tests: tests/random_baseline_test.cpp (RandomBaseline.*).
#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "harness/agent/solve_common.hpp"
#include "harness/agent/task_file.hpp"

namespace autumn::agent {

struct RandomOptions {
  std::string engine = "compiled";
  fs::path programs_dir;     // empty: default_programs_dir(task file)
  uint64_t rollouts = 50;
  int timeout = 1000;        // steps per rollout
  uint64_t seed = 0;
};

struct RandomResult {
  TaskType type = TaskType::MaskedFramePrediction;
  uint64_t rollouts = 0;     // run (0 for MFP)
  uint64_t successes = 0;
  std::optional<double> score;       // success fraction (MFP: chance); none without answers to score by
  double stderr_of_score = 0;        // binomial standard error of `score` (0 for MFP)
  std::optional<double> mean_steps;  // over the successful rollouts
  uint64_t errors = 0;               // rollouts ended by a runtime error
  uint64_t env_steps = 0;
  int choices = 0;                   // MFP
  uint64_t world_seed = 0;
  std::string trigger;               // cd: the condition estimated
  std::string note;                  // why there is no score
  double seconds = 0;
};

// One draw of the policy on a grid x grid world.
Action uniform_action(std::mt19937_64& rng, int grid);
RandomResult random_baseline(const Task& task, const RandomOptions& o, ThreadPool& pool);
nlohmann::json random_json(const RandomResult& r);

// `autumn baseline random TASKS...`: task files and folders of them (searched
// recursively, as eval does); one row per task, in the order given (folders
// sorted). A task that cannot be loaded or run is a row with an error; the
// others still run.
struct RandomRow {
  std::string task;  // relative to the folder it was found in; a named file as given
  std::string type;  // mfp, cd, planning ("?" if unreadable)
  RandomResult result;
  std::string error;
};
std::vector<RandomRow> run_random_baseline(const std::vector<std::string>& paths, const RandomOptions& o,
                                           ThreadPool& pool,
                                           const std::function<void(size_t, size_t, const std::string&)>& progress = {});
// The same in two steps, for --shard (harness/shards.hpp): the task files the
// paths name, in the run's order, each with its name in the table; and the rows
// of some of them. A row depends on its task and the options only.
struct RandomUnit {
  fs::path file;
  std::string name;
};
std::vector<RandomUnit> random_units(const std::vector<std::string>& paths);
std::vector<RandomRow> run_random_units(const std::vector<RandomUnit>& units, const RandomOptions& o, ThreadPool& pool,
                                        const std::function<void(size_t, size_t, const std::string&)>& progress = {});
std::string random_table(const std::vector<RandomRow>& rows);
// The shape eval --json writes ("tasks": rows with "task", "type", "score"), plus
// "agent" (name and settings, "programs" when --programs is given) and
// "task_set" (the paths), which the comparison report (scripts/compare-agents.py)
// reads.
nlohmann::json random_report_json(const std::vector<RandomRow>& rows, const RandomOptions& o,
                                  const std::vector<std::string>& paths);
// The inverse of a row of random_report_json's "tasks" (for --merge).
RandomRow random_row_from_json(const nlohmann::json& task);

}  // namespace autumn::agent
