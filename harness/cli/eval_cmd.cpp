// autumn eval — every task in a folder solved by the simulator agent and
// tabulated (harness/agent/eval), or one slice of them for a batch scheduler
// (--shard K/N) and the slices' JSON put back together (--merge).
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>

#include "compiler/read/output.hpp"
#include "harness/agent/eval.hpp"
#include "harness/agent/eval_shards.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/shard_options.hpp"

namespace autumn::cli {
namespace {

using namespace autumn::agent;

struct EvalCommand {
  std::string dir, render_dir;
  SolveOptions search;
  std::string protocol = "default";
  unsigned threads = 0;
  bool json = false;
  ShardOptions shards;  // --shard, --merge, --json-out (shard_options.hpp)
};

void register_eval(CLI::App* cmd, EvalCommand& o) {
  CLI::Option* dir = cmd->add_option("DIR", o.dir, "Folder of tasks (not with --merge)")->check(CLI::ExistingDirectory);
  cmd->add_flag("--json", o.json, "Print one JSON object");
  cmd->add_option("--render", o.render_dir,
                  "Write pictures of each answer as solve --render draws them, named after its task, into the "
                  "folder under DIR where the task sits under the evaluated folder (drawn after the task's clock stops)");
  add_search_options(cmd, o.search, o.threads);
  add_protocol_option(cmd, o.protocol);
  cmd->footer(
      "Columns: task (its file, relative to DIR); type (mfp, cd, planning); score (MFP and planning: 1 for a "
      "right answer or a plan that reaches the goal, else 0; change detection: the benchmark's score of when "
      "the change was detected, 0 to 1; - when there is no answers file to score against; error when the "
      "solver failed); time s (solve time, module compiles not counted: the summary "
      "line gives them); throughput and unit (rollouts/s for MFP, steps/s for change detection, nodes/s for "
      "planning: measured work per second of that solve, - when nothing was measured); detail (what was "
      "answered, or why not). The second table gives the mean score per task type.");
  add_shard_options(cmd, o.shards, dir, "folder's tasks", "path order");
}

// Prints a report (the table, or JSON), writes --json-out; the exit status of
// its rows: 1 when a task failed (an error) or got no answer (no plan), as solve.
int finish_eval(const EvalCommand& c, const nlohmann::json& report, const std::vector<EvalRow>& rows) {
  if (c.json) std::cout << report.dump() << "\n";
  else fmt::print("{}\n{}", eval_table(rows), eval_type_table(rows));
  if (std::string why = write_json_out(c.shards, report); !why.empty()) return command_failed("eval", why);
  const auto errors = std::count_if(rows.begin(), rows.end(), [](const EvalRow& r) { return !r.error.empty(); });
  const auto unanswered =
      std::count_if(rows.begin(), rows.end(), [](const EvalRow& r) { return r.error.empty() && !r.answered; });
  if (unanswered) std::cerr << "autumn eval: " << unanswered << " task" << (unanswered == 1 ? "" : "s") << " got no answer\n";
  return errors || unanswered ? 1 : 0;
}

int run_eval_merge(const EvalCommand& c) {
  std::vector<EvalRow> rows;
  try {
    const nlohmann::json merged = merge_shard_reports(read_json_files(c.shards.merge), c.shards.merge, rows);
    return finish_eval(c, merged, rows);
  } catch (const nlohmann::json::exception& e) {
    return command_failed("eval", std::string("a shard's rows are not eval's: ") + e.what());
  }
}

int run_eval(const CLI::App* cmd, const EvalCommand& c) {
  try {
    if (int status = check_shard_options("eval", cmd, c.shards, !c.dir.empty())) return status;
    if (c.shards.merging()) return run_eval_merge(c);
    const Shard shard = chosen_shard(c.shards);
    ThreadPool pool(c.threads);
    SolveOptions o = c.search;
    apply_protocol(cmd, c.protocol, o);
    const std::vector<fs::path> all = find_tasks(c.dir);
    // --json-out is written after the run, so a file inside DIR is never
    // scanned half-made (an eval JSON is not a task).
    std::vector<EvalRow> rows = run_eval_files(c.dir, select_shard(all, shard), o, pool, progress_bar(), c.render_dir);
    for (const EvalRow& r : rows)
      for (const std::string& p : r.pictures) std::cerr << "autumn eval: wrote " << p << "\n";
    nlohmann::json report = eval_json(rows);
    report["agent"] = eval_agent_json(c.protocol, o);
    report["task_set"] = {c.dir};
    if (!c.shards.shard.empty()) report["shard"] = shard_json(shard, "tasks", all.size());
    return finish_eval(c, report, rows);
  } catch (const std::exception& e) {
    return command_failed("eval", e.what());
  }
}

}  // namespace

Subcommand add_eval_command(CLI::App& app) {
  auto o = std::make_shared<EvalCommand>();
  CLI::App* cmd = app.add_subcommand("eval", "Solve every task in a folder (recursively) and tabulate the scores");
  register_eval(cmd, *o);
  return {cmd, [cmd, o] { return run_eval(cmd, *o); }};
}

}  // namespace autumn::cli
