// autumn bench-agent — the simulator agent's throughput per program
// (harness/agent/bench_agent): a 10,000-rollout MFP query, and BFS successors per
// second on one thread and on --threads threads.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <iostream>
#include <thread>

#include "harness/agent/bench_agent.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
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
};

void register_bench_agent(CLI::App* cmd, BenchAgentCommand& o) {
  cmd->add_option("PROGRAMS", o.paths, "Programs, or folders of programs")->required()->check(CLI::ExistingPath);
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
      "--threads threads); per thread (bfs/s Nt / N). - where a measurement did not run.");
  cmd->add_flag("--json", o.json, "Print one JSON object");
}

int run_bench_agent(const BenchAgentCommand& c) {
  try {
    BenchAgentOptions opts = c.agent;
    for (const std::string& p : c.paths)
      if (fs::is_directory(p) && program_files(p).empty()) return command_failed("bench-agent", "no .sexp or .au programs in " + p);
    const std::vector<fs::path> programs = expand_programs(c.paths);
    for (const std::string& p : c.paths)
      if (!fs::is_directory(p)) opts.named.push_back(p);  // never filtered out by --grid
    if (opts.threads == 0) opts.threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<BenchAgentRow> rows = bench_agent(programs, opts, progress_bar());
    if (rows.empty()) return command_failed("bench-agent", fmt::format("no program has GRID_SIZE {} (use --grid 0)", opts.grid));
    if (c.json) std::cout << bench_agent_json(rows, opts).dump() << "\n";
    else fmt::print("{}", bench_agent_table(rows, opts));
    return 0;
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
  return {cmd, [o] { return run_bench_agent(*o); }};
}

}  // namespace autumn::cli
