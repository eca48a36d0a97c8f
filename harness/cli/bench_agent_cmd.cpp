// autumn bench-agent — the simulator agent's throughput per program
// (harness/agent/bench_agent): a 10,000-rollout MFP query, and BFS successors per
// second on one thread and on --threads threads. --shard K/N measures a slice of
// the programs, --merge puts the slices' JSON back together (shard_options.hpp);
// every program's measurements use --seed, never its place in the list, and a
// program --grid leaves out is recorded in its shard as "skipped". The
// throughput figures are each shard's machine's: shards compare only when their
// nodes are alike.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <iostream>
#include <thread>

#include "harness/agent/bench_agent.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/cli/shard_options.hpp"
#include "harness/engine.hpp"
#include "harness/program_files.hpp"

namespace autumn::cli {
namespace {

using namespace autumn::agent;
namespace fs = std::filesystem;

struct BenchAgentCommand {
  std::vector<std::string> paths;
  BenchAgentOptions agent;
  bool json = false;
  ShardOptions shards;  // --shard, --merge, --json-out
};

void register_bench_agent(CLI::App* cmd, BenchAgentCommand& o) {
  CLI::Option* programs = cmd->add_option("PROGRAMS", o.paths, "Programs, or folders of programs; not with --merge")
                              ->check(CLI::ExistingPath);
  cmd->add_option("--engine", o.agent.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("compiled");
  cmd->add_option("--threads", o.agent.threads, "Threads of the MFP query and the parallel BFS run (0: all cores)")
      ->default_val(2)
      ->check(cli::thread_count());
  cmd->add_option("--rollouts", o.agent.rollouts, "MFP rollouts")->default_val(10000)->check(cli::big_count(1));
  cmd->add_option("--mfp-steps", o.agent.mfp_steps, "Actions in the MFP trajectory")->default_val(70)->check(cli::int_count(1));
  cmd->add_option("--seed", o.agent.seed, "Seed of the generated MFP task and of the rollouts")
      ->default_val(1)
      ->check(cli::seed_number());
  cmd->add_option("--bfs-nodes", o.agent.bfs_nodes, "BFS: successors to generate per run")
      ->default_val(1000000)
      ->check(cli::big_count(1));
  cmd->add_option("--bfs-depth", o.agent.bfs_depth, "BFS: depth limit")->default_val(12)->check(cli::int_count(1));
  cmd->add_option("--seconds", o.agent.seconds, "BFS: time limit per run")
      ->default_val(10)
      ->check(cli::number_at_least(0.001, "POSITIVE"));
  cmd->add_option("--repeat", o.agent.bfs_repeat,
                  "BFS: runs of each measurement (one thread, --threads threads), alternating between the two; the "
                  "fastest is reported, since a busy machine slows a run and nothing speeds one")
      ->default_val(1)
      ->check(cli::int_count(1));
  cmd->add_option("--grid", o.agent.grid,
                      "Only programs with this GRID_SIZE (0: all) among those found in folders; files named here "
                      "always run")
      ->default_val(16)
      ->check(cli::int_count());
  cmd->add_option("--only", o.agent.only, "Run only one measurement")->check(CLI::IsMember({"mfp", "bfs"}));
  cmd->footer(
      "Columns: program; grid (GRID_SIZE); code (specialised or embedded module, or the engine when not "
      "compiled); mfp s (seconds of one --rollouts MFP query on --threads threads); rollout/s (rollouts per "
      "second of that query); ok (whether it chose the right answer); actions (the BFS's action set size); "
      "depth (BFS levels completed; * the search space ran out: left out of the medians); bfs nodes "
      "(successors generated on one thread); bfs/s 1t (successors per second on one thread); bfs/s Nt (on "
      "--threads threads); per thread (bfs/s Nt / N). With --repeat, each BFS figure is the fastest of its runs. - where "
      "a measurement did not run. Below the table, beside the BFS's scaling over threads: the machine's own, an "
      "arithmetic loop that shares nothing timed alone and on every thread next to each program's runs (JSON: "
      "machine_scaling_n_threads), for a machine whose cores other work shares.");
  cmd->add_flag("--json", o.json, "Print one JSON object");
  add_shard_options(cmd, o.shards, programs, "programs", "the order given (each folder's sorted by name)");
}

ShardFormat bench_agent_shard_format() {
  return {"bench-agent",
          "programs",
          "programs",
          {"engine", "threads", "rollouts", "mfp_steps", "bfs_nodes", "bfs_depth", "bfs_repeat", "seed", "seconds", "grid",
           "only", "program_set"}};
}

// Prints a report (the table, or JSON) and writes --json-out. No rows is a
// failure, except in a shard (its JSON still counts for the merge).
int finish_bench_agent(const BenchAgentCommand& c, const nlohmann::json& report,
                       const std::vector<BenchAgentRow>& rows, const BenchAgentOptions& opts) {
  const bool shard = report.contains("shard");
  if (rows.empty() && !shard)
    return command_failed("bench-agent", fmt::format("no program has GRID_SIZE {} (use --grid 0)", opts.grid));
  if (c.json) std::cout << report.dump() << "\n";
  else if (rows.empty()) fmt::print("no program of this shard has GRID_SIZE {}\n", opts.grid);
  else fmt::print("{}", bench_agent_table(rows, opts));
  if (std::string why = write_json_out(c.shards, report); !why.empty()) return command_failed("bench-agent", why);
  return 0;
}

int run_bench_agent_merge(const BenchAgentCommand& c) {
  const MergedShards m = merge_shard_files(c.shards, bench_agent_shard_format());
  std::vector<BenchAgentRow> rows;
  BenchAgentOptions opts;
  try {
    for (const auto& p : m.rows) rows.push_back(bench_agent_row_from_json(p));
    opts = bench_agent_options_from_json(m.settings);
  } catch (const nlohmann::json::exception& e) {
    return command_failed("bench-agent", std::string("a shard's rows are not bench-agent's: ") + e.what());
  }
  nlohmann::json report = m.settings;
  report["programs"] = m.rows;
  return finish_bench_agent(c, report, rows, opts);
}

int run_bench_agent(const CLI::App* cmd, const BenchAgentCommand& c) {
  try {
    if (int status = check_shard_options("bench-agent", cmd, c.shards, !c.paths.empty())) return status;
    if (c.shards.merging()) return run_bench_agent_merge(c);
    const Shard shard = chosen_shard(c.shards);
    BenchAgentOptions opts = c.agent;
    for (const std::string& p : c.paths)
      if (fs::is_directory(p) && program_files(p).empty()) return command_failed("bench-agent", "no .sexp or .au programs in " + p);
    const std::vector<fs::path> programs = expand_programs(c.paths);
    for (const std::string& p : c.paths)
      if (!fs::is_directory(p)) opts.named.push_back(p);  // never filtered out by --grid
    if (opts.threads == 0) opts.threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<size_t> skipped;  // indices in this shard's list
    std::vector<BenchAgentRow> rows = bench_agent(select_shard(programs, shard), opts, progress_bar(), &skipped);
    nlohmann::json report = bench_agent_json(rows, opts);
    report["program_set"] = c.paths;
    if (!c.shards.shard.empty()) {
      for (size_t& i : skipped) i = shard_unit_index(shard, i);
      report["shard"] = shard_json(shard, "programs", programs.size(), skipped);
    }
    return finish_bench_agent(c, report, rows, opts);
  } catch (const std::exception& e) {
    return command_failed("bench-agent", e.what());
  }
}

}  // namespace

Subcommand add_bench_agent_command(CLI::App& app) {
  auto o = std::make_shared<BenchAgentCommand>();
  CLI::App* cmd = app.add_subcommand(
      "bench-agent", "Throughput of the simulator agent: a 10,000-rollout MFP query and BFS expansion per program");
  register_bench_agent(cmd, *o);
  return {cmd, [cmd, o] { return run_bench_agent(cmd, *o); }};
}

}  // namespace autumn::cli
