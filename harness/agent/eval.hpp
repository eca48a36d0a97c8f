// eval — run every task under a folder and tabulate scores and throughput.
//
// Tasks are the *.json files (recursively, sorted by path) whose "type" is one of
// the three task types; other JSON files (answers, traces) are skipped. Scores:
// MFP 1/0 when the task carries its answer ("-" otherwise, as for the public ice
// task); change detection by the paper's formula when
// <task folder>/../answers/<program>_change_detection.json exists ("-"
// otherwise); planning 1 when the plan replays to the goal on the mask, else 0.
// A task that cannot be loaded or solved is a row with an error and counts as a
// failure (exit status 1). A task's modules are compiled before its clock starts:
// compile time is reported apart (compile_seconds), never as solve time.
#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

struct EvalRow {
  std::string task;  // path relative to the evaluated folder
  std::string type;  // mfp, cd, planning ("?" if unreadable)
  std::optional<double> score;
  double seconds = 0;          // solving, compiles excluded
  double compile_seconds = 0;  // building the task's modules on first use
  double throughput = 0;
  std::string unit;    // rollouts/s, steps/s, nodes/s
  std::string detail;  // choice / detection step / plan length
  std::string error;
  nlohmann::json result;
};

std::vector<fs::path> find_tasks(const fs::path& dir);
EvalRow eval_task(const fs::path& file, const fs::path& root, const SolveOptions& opts, ThreadPool& pool);
// progress(i, n, name) is called before task i (0-based) and once more with i == n.
std::vector<EvalRow> run_eval(const fs::path& dir, const SolveOptions& opts, ThreadPool& pool,
                              const std::function<void(size_t, size_t, const std::string&)>& progress = {});
std::string eval_table(const std::vector<EvalRow>& rows);
nlohmann::json eval_json(const std::vector<EvalRow>& rows);

}  // namespace autumn::agent
