// autumn bench — interpreter versus compiled engine per program: steps/s with
// and without the host render, and the cost of clone() (harness/bench.hpp).
// --shard K/N measures a slice of the programs, --merge puts the slices' JSON
// back together (shard_options.hpp): the rows in the whole run's order, the
// medians recomputed. Every program runs --steps steps from --seed, whatever its
// place in the list; the figures are each shard's machine's.
#include <fmt/core.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/bench.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/cli/shard_options.hpp"
#include "harness/engine.hpp"
#include "harness/program_files.hpp"

namespace autumn::cli {
namespace {

struct BenchOptions {
  std::vector<std::string> programs;
  size_t steps = 1000;
  uint64_t seed = 0;
  bool json = false;
  std::string only;
  double time_cap = kDefaultBenchTimeCap;
  ShardOptions shards;  // --shard, --merge, --json-out
};

void register_bench(CLI::App* cmd, BenchOptions& o) {
  CLI::Option* programs = cmd->add_option("PROGRAMS", o.programs, "Program files or folders; not with --merge");
  cmd->add_option("--steps", o.steps, "Steps per program")->default_val(1000)->check(int_count());
  cmd->add_option("--seed", o.seed, "Seed for the programs and the action policy")->default_val(0)->check(seed_number());
  cmd->add_flag("--json", o.json, "Print JSON");
  cmd->add_option("--time-cap", o.time_cap,
                  "Seconds an engine's first replay (or choosing the actions) may take; past it, every engine is timed "
                  "over the steps done by then, and the row says so (0: no cap)")
      ->default_val(kDefaultBenchTimeCap)
      ->check(number_at_least(0, "NONNEGATIVE"));
  cmd->footer(
      "Columns: program; grid (GRID_SIZE); steps (random actions replayed per measurement, the same on both "
      "engines); interp st/s and compiled st/s (steps per second, each frame rendered, as the benchmark "
      "protocol does); interp bare/s and comp bare/s (steps per second without rendering: isFreePos then sees "
      "the last render's occupancy, so a program whose clicks test it may grow its state and slow down); "
      "interp cl ns and comp "
      "cl ns (nanoseconds to clone the environment after the last step); ratio x (compiled st/s / interp st/s).");
  cmd->add_option("--only", o.only, "Run one engine only (for profiling; not with --shard)")
      ->check(CLI::IsMember(engine_names()));
  add_shard_options(cmd, o.shards, programs, "programs", "the order given (each folder's sorted by name)");
}

int run_one_engine(const BenchOptions& o, const std::vector<std::filesystem::path>& files) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& f : files) {
    auto program = load_or_report(f.string(), std::nullopt);
    if (!program) return kExitFailed;
    BenchRow row = bench_program(f.stem().string(), program, {o.only}, o.steps, o.seed, o.time_cap);
    const auto& e = row.engines[0];
    if (o.json || !o.shards.json_out.empty()) {
      rows.push_back({{"program", row.program}, {"engine", o.only}, {"steps", e.steps}, {"steps_per_s", e.steps_per_s},
                      {"steps_per_s_no_render", e.steps_per_s_no_render}, {"clone_ns", e.clone_ns}, {"error", e.error}});
      if (!row.note.empty()) rows.back()["note"] = row.note;
    }
    if (!o.json)
      fmt::print("{:<32} {} {:.0f} steps/s (render) {:.0f} steps/s (bare) clone {:.0f} ns{}{}\n", row.program, o.only,
                 e.steps_per_s, e.steps_per_s_no_render, e.clone_ns, e.ok ? "" : "  " + e.error,
                 row.note.empty() ? "" : "  (" + row.note + ")");
  }
  if (o.json) std::cout << nlohmann::json({{"rows", rows}}).dump(2) << "\n";
  if (std::string why = write_json_out(o.shards, {{"rows", rows}}); !why.empty()) return command_failed("bench", why);
  return kExitOk;
}

ShardFormat bench_shard_format() { return {"bench", "rows", "programs", {"steps", "seed", "time_cap", "program_set"}}; }

// Prints a report (the table, or JSON) and writes --json-out; 1 when a program failed.
int finish_bench(const BenchOptions& o, const nlohmann::json& report) {
  if (o.json) std::cout << report.dump(2) << "\n";
  else std::cout << bench_table(report);
  if (std::string why = write_json_out(o.shards, report); !why.empty()) return command_failed("bench", why);
  for (const auto& r : report.at("rows"))
    if (!bench_row_ok(r)) return kExitFailed;
  return kExitOk;
}

// The whole run's report from the shards': its rows, the medians recomputed.
int run_bench_merge(const BenchOptions& o) {
  const MergedShards m = merge_shard_files(o.shards, bench_shard_format());
  nlohmann::json report;
  try {
    report = bench_report(m.rows);
    for (const auto& [key, value] : m.settings.items()) report[key] = value;
    return finish_bench(o, report);
  } catch (const nlohmann::json::exception& e) {
    return command_failed("bench", std::string("a shard's rows are not bench's: ") + e.what());
  }
}

int run_bench_programs(const BenchOptions& o) {
  auto all = expand_programs(o.programs);
  if (all.empty()) {
    std::cerr << "autumn bench: no programs given\n";
    return kExitUsage;
  }
  if (!o.only.empty()) return run_one_engine(o, all);
  const Shard shard = chosen_shard(o.shards);
  const std::vector<std::filesystem::path> files = select_shard(all, shard);
  nlohmann::json rows = nlohmann::json::array();
  Progress progress("bench", files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    const auto& f = files[i];
    progress.item(i, f.stem().string());
    std::string why;
    auto program = load_or_report(f.string(), std::nullopt, &why);
    if (!program) {
      rows.push_back(bench_error_row(f.stem().string(), why));
      continue;
    }
    rows.push_back(bench_row_json(bench_program(f.stem().string(), program, {"interp", "compiled"}, o.steps, o.seed, o.time_cap)));
  }
  progress.done();
  nlohmann::json report = bench_report(rows);
  report["steps"] = o.steps;
  report["seed"] = o.seed;
  report["time_cap"] = o.time_cap;
  report["program_set"] = o.programs;
  if (!o.shards.shard.empty()) report["shard"] = shard_json(shard, "programs", all.size());
  return finish_bench(o, report);
}

int run_bench(const CLI::App* cmd, const BenchOptions& o) {
  if (int status = check_shard_options("bench", cmd, o.shards, !o.programs.empty())) return status;
  if (!o.only.empty() && !o.shards.shard.empty()) {
    command_failed("bench", "--only (profiling one engine) does not shard: its rows are not bench's");
    return kExitUsage;
  }
  try {
    return o.shards.merging() ? run_bench_merge(o) : run_bench_programs(o);
  } catch (const std::exception& e) {
    return command_failed("bench", e.what());
  }
}

}  // namespace

Subcommand add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench", "Interpreter vs compiled engine: steps/s with and without render, clone cost");
  register_bench(cmd, *o);
  return {cmd, [cmd, o] { return run_bench(cmd, *o); }};
}

}  // namespace autumn::cli
