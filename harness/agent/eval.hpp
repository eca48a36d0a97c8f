// eval — run every task under a folder and tabulate scores and throughput.
//
// Tasks are the *.json files (recursively, sorted by path) whose "type" is one of
// the three task types; other JSON files (answers, traces) are skipped. A task's
// answers file (find_answers: answers/<task>.json beside prompts/, the benchmark's
// answers/<program>_change_detection.json, or <task>.answers.json) is read only to
// score, after the solver. Scores: MFP 1/0 against its correct_idx ("-" without
// one, as for the public ice task); change detection by the paper's formula with
// its condition ("-" without); planning 1 when the plan replays to the goal on the
// mask in the world the task was made in (the answers' seed), else 0.
// eval_type_table() sums the rows per task type (and deterministic/stochastic).
// A task that cannot be loaded or solved is a row with an error and counts as a
// failure (exit status 1). A task's modules are compiled before its clock starts:
// compile time is reported apart (compile_seconds), never as solve time.
// With a render folder, each solved task's pictures (solve_pictures.hpp, as
// `solve --render` draws them) are written after its clock stops, into the
// render folder's copy of the task's own folder (prompts/x.json: RENDER/prompts/).
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
  bool answers = false;                 // an answers file was found
  bool stochastic = false;              // the task's program draws random numbers
  std::optional<int> plan_length;       // planning: the plan found
  std::optional<int> reference_length;  // planning: the generator's K (its reference plan)
  bool answered = true;                 // false: the solver gave no answer (planning: no plan)
  std::vector<std::string> pictures;    // files written for a render folder
};

std::vector<fs::path> find_tasks(const fs::path& dir);
EvalRow eval_task(const fs::path& file, const fs::path& root, const SolveOptions& opts, ThreadPool& pool,
                  const fs::path& render_dir = {});
// progress(i, n, name) is called before task i (0-based) and once more with i == n.
std::vector<EvalRow> run_eval(const fs::path& dir, const SolveOptions& opts, ThreadPool& pool,
                              const std::function<void(size_t, size_t, const std::string&)>& progress = {});
// The same over some of the folder's tasks (`files`, under `dir`; eval_shards.hpp).
std::vector<EvalRow> run_eval_files(const fs::path& dir, const std::vector<fs::path>& files, const SolveOptions& opts,
                                    ThreadPool& pool,
                                    const std::function<void(size_t, size_t, const std::string&)>& progress = {},
                                    const fs::path& render_dir = {});
std::string eval_table(const std::vector<EvalRow>& rows);
// Per task type (and program kind): tasks, errors, scored, mean score, planning's
// plans no longer than K, mean plan length against mean K, and time.
std::string eval_type_table(const std::vector<EvalRow>& rows);
nlohmann::json eval_json(const std::vector<EvalRow>& rows);
// The report's "agent": what the comparison report (scripts/compare-agents.py)
// names the run by; `protocol` is "default" or "paper".
nlohmann::json eval_agent_json(const std::string& protocol, const SolveOptions& o);

}  // namespace autumn::agent
