// autumn baseline random — the AutumnBench paper's memoryless random agent over
// task files (harness/agent/random_baseline): per task, its success probability
// and mean steps over --rollouts episodes; the shape scripts/compare-agents.py reads.
// --shard K/N runs a slice of the task files, --merge puts the slices' JSON back
// together (shard_options.hpp); a task's row depends on its file and the options
// only (rollout r draws from (--seed, r)), never on its shard.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/agent/random_baseline.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/cli/shard_options.hpp"
#include "harness/engine.hpp"

namespace autumn::cli {
namespace {

using namespace autumn::agent;

struct RandomCommand {
  std::vector<std::string> paths;
  RandomOptions agent;
  unsigned threads = 0;
  bool json = false;
  ShardOptions shards;  // --shard, --merge, --json-out
};

void register_random(CLI::App* cmd, RandomCommand& o) {
  CLI::Option* tasks =
      cmd->add_option("TASKS", o.paths, "Task files, or folders of them (searched recursively); not with --merge")
          ->check(CLI::ExistingPath);
  cmd->add_option("--rollouts", o.agent.rollouts, "Episodes per task")->default_val(50)->check(cli::big_count(1));
  cmd->add_option("--timeout", o.agent.timeout, "Steps per episode")->default_val(1000)->check(cli::int_count(1));
  cmd->add_option("--seed", o.agent.seed, "Seed of the policy (episode r draws from (seed, r))")
      ->default_val(0)
      ->check(cli::seed_number());
  cmd->add_option("--engine", o.agent.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("compiled");
  cmd->add_option("--programs", o.agent.programs_dir, "Folder of the tasks' programs (default: programs/ beside each task's folder)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--threads", o.threads, "Worker threads (0: all cores)")->default_val(0)->check(cli::thread_count());
  cmd->add_flag("--json", o.json, "Print one JSON object (the shape scripts/compare-agents.py reads)");
  cmd->footer(
      "Columns: task; type; score (+- se) (MFP: the chance of picking the right choice at random; change "
      "detection: the probability that the trigger condition fires within --timeout steps; planning: the "
      "probability of reaching the goal; se: the binomial standard error over --rollouts episodes); successes "
      "(episodes that succeeded); mean steps (steps to success, over the successful episodes; - without any); "
      "seconds (wall clock of the task's episodes).");
  add_shard_options(cmd, o.shards, tasks, "task files", "the order given (folders searched as eval does)");
}

// Prints a report (the table, or JSON), writes --json-out; exit status 1 when a task failed.
int finish_random(const RandomCommand& c, const nlohmann::json& report, const std::vector<RandomRow>& rows) {
  if (c.json) std::cout << report.dump() << "\n";
  else fmt::print("{}", random_table(rows));
  if (std::string why = write_json_out(c.shards, report); !why.empty()) return command_failed("baseline random", why);
  const auto errors = std::count_if(rows.begin(), rows.end(), [](const RandomRow& r) { return !r.error.empty(); });
  if (errors) std::cerr << "autumn baseline random: " << errors << " task" << (errors == 1 ? "" : "s") << " failed\n";
  return errors ? 1 : 0;
}

ShardFormat random_shard_format() { return {"baseline random", "tasks", "tasks", {"agent", "task_set"}}; }

int run_random_merge(const RandomCommand& c) {
  const MergedShards m = merge_shard_files(c.shards, random_shard_format());
  std::vector<RandomRow> rows;
  try {
    for (const auto& t : m.rows) rows.push_back(random_row_from_json(t));
  } catch (const nlohmann::json::exception& e) {
    return command_failed("baseline random", std::string("a shard's rows are not baseline random's: ") + e.what());
  }
  if (rows.empty()) return command_failed("baseline random", "no task files in the paths given");
  nlohmann::json report = m.settings;
  report["tasks"] = m.rows;
  return finish_random(c, report, rows);
}

int run_random(const CLI::App* cmd, const RandomCommand& c) {
  try {
    if (int status = check_shard_options("baseline random", cmd, c.shards, !c.paths.empty())) return status;
    if (c.shards.merging()) return run_random_merge(c);
    const Shard shard = chosen_shard(c.shards);
    const std::vector<RandomUnit> units = random_units(c.paths);
    if (units.empty()) return command_failed("baseline random", "no task files in the paths given");
    ThreadPool pool(c.threads);
    const std::vector<RandomRow> rows = run_random_units(select_shard(units, shard), c.agent, pool, progress_bar());
    nlohmann::json report = random_report_json(rows, c.agent, c.paths);
    if (!c.shards.shard.empty()) report["shard"] = shard_json(shard, "tasks", units.size());
    return finish_random(c, report, rows);
  } catch (const std::exception& e) {
    return command_failed("baseline random", e.what());
  }
}

}  // namespace

// `baseline` groups the reference agents; `random` is the one there is.
Subcommand add_baseline_command(CLI::App& app) {
  auto o = std::make_shared<RandomCommand>();
  CLI::App* baseline = app.add_subcommand("baseline", "Reference agents the paper compares against (baseline random)");
  baseline->require_subcommand(1);
  CLI::App* cmd = baseline->add_subcommand(
      "random", "The paper's memoryless random agent: success probability and mean steps per task, by rollouts");
  register_random(cmd, *o);
  return {cmd, [cmd, o] { return run_random(cmd, *o); }};
}

}  // namespace autumn::cli
