// autumn difftest — two engines on the same seeds and random actions; every
// frame, trigger value, coverage count and error message must agree
// (harness/difftest.hpp). Episodes that end in the same runtime error on both
// engines agree, but are counted and listed apart from those that ran through.
#include <fmt/core.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/program_files.hpp"

namespace autumn::cli {
namespace {

struct DifftestOptions {
  std::vector<std::string> programs;
  DiffOptions diff;
  bool json = false;
};

void register_difftest(CLI::App* cmd, DifftestOptions& o) {
  cmd->add_option("PROGRAMS", o.programs, "Program files or folders")->required();
  cmd->add_option("--seeds", o.diff.seeds, "Episodes (seeds) per program")->default_val(8)->check(int_count());
  cmd->add_option("--steps", o.diff.steps, "Steps per episode")->default_val(200)->check(int_count());
  cmd->add_option("--first-seed", o.diff.first_seed, "First seed")->default_val(0)->check(seed_number());
  cmd->add_option("--engine", o.diff.engine_b, "Engine compared with interp")
      ->check(CLI::IsMember(engine_names()))
      ->default_val("compiled");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of text");
}

struct ProgramDiff {
  std::string program;
  std::string status;  // agreed | diverged | load error | setup failed
  DiffResult result;
};

ProgramDiff diff_program(const DifftestOptions& o, const std::filesystem::path& f) {
  ProgramDiff d{f.string(), "agreed", {}};
  auto program = load_or_report(f.string(), std::nullopt);
  if (!program) {
    d.status = "load error";
    return d;
  }
  d.result = diff_engines(program, o.diff);
  if (d.result.setup_failed) d.status = "setup failed";
  else if (!d.result.divergence.empty()) d.status = "diverged";
  return d;
}

void print_text(const DifftestOptions& o, const std::vector<ProgramDiff>& diffs) {
  size_t episodes = 0, errored = 0, steps = 0, failed = 0;
  for (const auto& d : diffs) {
    const DiffResult& r = d.result;
    if (d.status == "load error") fmt::print("FAILED {}: the program does not load\n", d.program);
    if (d.status == "diverged" || d.status == "setup failed")
      fmt::print("{} {}: {}\n", d.status == "diverged" ? "DIVERGED" : "SETUP FAILED", d.program, r.divergence);
    if (r.errored)
      fmt::print("ERRORED {}: {} of {} episodes ended in the same runtime error on both engines; first at {}\n",
                 d.program, r.errored, r.episodes, r.first_error);
    episodes += r.episodes, errored += r.errored, steps += r.steps, failed += d.status != "agreed";
  }
  fmt::print("{} programs, {} episodes: {} ran every step, {} ended in the same runtime error; {} steps compared "
             "({} vs {}); {} programs failed\n",
             diffs.size(), episodes, episodes - errored, errored, steps, o.diff.engine_a, o.diff.engine_b, failed);
}

nlohmann::json diffs_json(const DifftestOptions& o, const std::vector<ProgramDiff>& diffs) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& d : diffs)
    rows.push_back({{"program", d.program}, {"status", d.status}, {"episodes", d.result.episodes},
                    {"errored_episodes", d.result.errored}, {"first_error", d.result.first_error},
                    {"steps", d.result.steps}, {"divergence", d.result.divergence}});
  return {{"engines", {o.diff.engine_a, o.diff.engine_b}}, {"programs", rows}};
}

int run_difftest(const DifftestOptions& o) {
  auto files = expand_programs(o.programs);
  if (files.empty()) {
    std::cerr << "autumn difftest: no programs given\n";
    return kExitUsage;
  }
  DifftestOptions run = o;
  run.diff.limits = episode_limits();
  std::vector<ProgramDiff> diffs;
  Progress progress("difftest", files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    progress.item(i, files[i].stem().string());
    diffs.push_back(diff_program(run, files[i]));
  }
  progress.done();
  if (o.json) std::cout << diffs_json(o, diffs).dump() << "\n";
  else print_text(o, diffs);
  for (const auto& d : diffs)
    if (d.status != "agreed") return kExitFailed;
  return kExitOk;
}

}  // namespace

Subcommand add_difftest_command(CLI::App& app) {
  auto o = std::make_shared<DifftestOptions>();
  CLI::App* cmd = app.add_subcommand("difftest", "Differential test of two engines under random actions");
  register_difftest(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [o] { return run_difftest(*o); }};
}

}  // namespace autumn::cli
