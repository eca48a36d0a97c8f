// autumn bench — interpreter versus compiled engine per program: steps/s with
// and without the host render, and the cost of clone() (harness/bench.hpp).
#include <fmt/core.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/bench.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
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
};

void register_bench(CLI::App* cmd, BenchOptions& o) {
  cmd->add_option("PROGRAMS", o.programs, "Program files or folders")->required();
  cmd->add_option("--steps", o.steps, "Steps per program")->default_val(1000)->check(int_count());
  cmd->add_option("--seed", o.seed, "Seed for the programs and the action policy")->default_val(0)->check(seed_number());
  cmd->add_flag("--json", o.json, "Print JSON");
  cmd->footer(
      "Columns: program; grid (GRID_SIZE); steps (random actions replayed per measurement, the same on both "
      "engines); interp st/s and compiled st/s (steps per second, each frame rendered, as the benchmark "
      "protocol does); interp bare/s and comp bare/s (steps per second without rendering); interp cl ns and comp "
      "cl ns (nanoseconds to clone the environment after the last step); ratio x (compiled st/s / interp st/s).");
  cmd->add_option("--only", o.only, "Run one engine only (for profiling)")->check(CLI::IsMember(engine_names()));
}

int run_one_engine(const BenchOptions& o, const std::vector<std::filesystem::path>& files) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& f : files) {
    auto program = load_or_report(f.string(), std::nullopt);
    if (!program) return kExitFailed;
    BenchRow row = bench_program(f.stem().string(), program, {o.only}, o.steps, o.seed);
    const auto& e = row.engines[0];
    if (o.json)
      rows.push_back({{"program", row.program}, {"engine", o.only}, {"steps_per_s", e.steps_per_s},
                      {"steps_per_s_no_render", e.steps_per_s_no_render}, {"clone_ns", e.clone_ns}, {"error", e.error}});
    else
      fmt::print("{:<32} {} {:.0f} steps/s (render) {:.0f} steps/s (bare) clone {:.0f} ns{}\n", row.program, o.only,
                 e.steps_per_s, e.steps_per_s_no_render, e.clone_ns, e.ok ? "" : "  " + e.error);
  }
  if (o.json) std::cout << nlohmann::json({{"rows", rows}}).dump(2) << "\n";
  return kExitOk;
}

int run_bench(const BenchOptions& o) {
  auto files = expand_programs(o.programs);
  if (files.empty()) {
    std::cerr << "autumn bench: no programs given\n";
    return kExitUsage;
  }
  if (!o.only.empty()) return run_one_engine(o, files);
  nlohmann::json rows = nlohmann::json::array();
  int failures = 0;
  Progress progress("bench", files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    const auto& f = files[i];
    progress.item(i, f.stem().string());
    std::string why;
    auto program = load_or_report(f.string(), std::nullopt, &why);
    if (!program) {
      rows.push_back(bench_error_row(f.stem().string(), why));
      ++failures;
      continue;
    }
    rows.push_back(bench_row_json(bench_program(f.stem().string(), program, {"interp", "compiled"}, o.steps, o.seed)));
    failures += !bench_row_ok(rows.back());
  }
  progress.done();
  const nlohmann::json report = bench_report(rows);
  if (o.json) std::cout << report.dump(2) << "\n";
  else std::cout << bench_table(report);
  return failures ? kExitFailed : kExitOk;
}

}  // namespace

Subcommand add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench", "Interpreter vs compiled engine: steps/s with and without render, clone cost");
  register_bench(cmd, *o);
  return {cmd, [o] { return run_bench(*o); }};
}

}  // namespace autumn::cli
