// autumn difftest — two engines on the same seeds and random actions; every
// frame, trigger value, coverage count and error message must agree
// (harness/difftest.hpp). Episodes that end in the same runtime error on both
// engines agree, but are counted and listed apart from those that ran through;
// so are those the per-step budgets' allowance ends (difftest.cpp: the
// interpreter stopped by a budget the compiled engine's smaller count stayed
// within, the two agreeing there once it is raised).
// Each program is tested in a child process (harness/isolate.hpp): one that
// crashes it is reported CRASHED, and the run goes on with the next.
// --shard K/N tests a slice of the programs, --merge puts the slices' JSON back
// together (shard_options.hpp): every program runs seeds --first-seed on,
// whatever its place in the list, so its row is the whole run's.
#include <fmt/core.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/cli/shard_options.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/isolate.hpp"
#include "harness/program_files.hpp"

namespace autumn::cli {
namespace {

struct DifftestOptions {
  std::vector<std::string> programs;
  DiffOptions diff;
  bool json = false;
  ShardOptions shards;  // --shard, --merge, --json-out
};

void register_difftest(CLI::App* cmd, DifftestOptions& o) {
  CLI::Option* programs = cmd->add_option("PROGRAMS", o.programs, "Program files or folders; not with --merge");
  cmd->add_option("--seeds", o.diff.seeds, "Episodes (seeds) per program")->default_val(8)->check(int_count());
  cmd->add_option("--steps", o.diff.steps, "Steps per episode")->default_val(200)->check(int_count());
  cmd->add_option("--first-seed", o.diff.first_seed, "First seed")->default_val(0)->check(seed_number());
  cmd->add_option("--engine", o.diff.engine_b, "Engine compared with interp")
      ->check(CLI::IsMember(engine_names()))
      ->default_val("compiled");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of text");
  add_shard_options(cmd, o.shards, programs, "programs", "the order given (each folder's sorted by name)");
}

struct ProgramDiff {
  std::string program;
  std::string status;  // agreed | diverged | load error | setup failed | crashed
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

// The line's first word for a program that failed with a reason; null for the others.
const char* failure_word(const std::string& status) {
  if (status == "diverged") return "DIVERGED";
  if (status == "crashed") return "CRASHED";
  if (status == "setup failed") return "SETUP FAILED";
  return nullptr;
}

void print_text(const DifftestOptions& o, const std::vector<ProgramDiff>& diffs) {
  size_t episodes = 0, errored = 0, budget = 0, steps = 0, failed = 0;
  for (const auto& d : diffs) {
    const DiffResult& r = d.result;
    if (d.status == "load error") fmt::print("FAILED {}: the program does not load\n", d.program);
    if (const char* word = failure_word(d.status)) fmt::print("{} {}: {}\n", word, d.program, r.divergence);
    if (r.errored)
      fmt::print("ERRORED {}: {} of {} episodes ended in the same runtime error on both engines; first at {}\n",
                 d.program, r.errored, r.episodes, r.first_error);
    if (r.budget_ended)
      fmt::print("BUDGET {}: {} of {} episodes ended where a per-step budget stopped the interpreter and not the {} "
                 "engine, or at another construct (its count is larger: runtime/limits.hpp allows it); first at {}\n",
                 d.program, r.budget_ended, r.episodes, o.diff.engine_b, r.first_budget);
    episodes += r.episodes, errored += r.errored, budget += r.budget_ended, steps += r.steps;
    failed += d.status != "agreed";
  }
  fmt::print("{} programs, {} episodes: {} ran every step, {} ended in the same runtime error, {} on a per-step "
             "budget; {} steps compared ({} vs {}); {} programs failed\n",
             diffs.size(), episodes, episodes - errored - budget, errored, budget, steps, o.diff.engine_a,
             o.diff.engine_b, failed);
}

nlohmann::json diff_json(const ProgramDiff& d) {
  return {{"program", d.program},
          {"status", d.status},
          {"episodes", d.result.episodes},
          {"errored_episodes", d.result.errored},
          {"first_error", d.result.first_error},
          {"budget_episodes", d.result.budget_ended},
          {"first_budget", d.result.first_budget},
          {"steps", d.result.steps},
          {"divergence", d.result.divergence}};
}

nlohmann::json diffs_json(const DifftestOptions& o, const std::vector<ProgramDiff>& diffs) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& d : diffs) rows.push_back(diff_json(d));
  return {{"engines", {o.diff.engine_a, o.diff.engine_b}},
          {"seeds", o.diff.seeds},
          {"steps", o.diff.steps},
          {"first_seed", o.diff.first_seed},
          {"program_set", o.programs},
          {"limits", episode_limits_json()},
          {"programs", rows}};
}

ProgramDiff diff_from_json(const nlohmann::json& j) {
  ProgramDiff d{j.at("program").get<std::string>(), j.at("status").get<std::string>(), {}};
  d.result.episodes = j.at("episodes").get<size_t>();
  d.result.errored = j.at("errored_episodes").get<size_t>();
  d.result.first_error = j.at("first_error").get<std::string>();
  d.result.budget_ended = j.value("budget_episodes", size_t{0});  // absent from shards of earlier builds
  d.result.first_budget = j.value("first_budget", std::string());
  d.result.steps = j.at("steps").get<size_t>();
  d.result.divergence = j.at("divergence").get<std::string>();
  d.result.setup_failed = d.status == "setup failed";
  return d;
}

// diff_program in a child process: its row comes back as JSON; a child that
// dies (a crash in either engine, the loader or the compile) is the program's
// failure, "crashed", and the next program runs.
ProgramDiff diff_program_isolated(const DifftestOptions& o, const std::filesystem::path& f) {
  Isolated run = run_isolated([&] { return diff_json(diff_program(o, f)).dump(); });
  if (run.finished) {
    try {
      return diff_from_json(nlohmann::json::parse(run.output));
    } catch (const nlohmann::json::exception& e) {
      run.death = std::string("sent back a result that is not a row: ") + e.what();
    }
  }
  ProgramDiff d{f.string(), "crashed", {}};
  d.result.divergence = "the process testing it " + run.death;
  return d;
}

ShardFormat difftest_shard_format() {
  return {"difftest", "programs", "programs", {"engines", "seeds", "steps", "first_seed", "program_set", "limits"}};
}

// Prints the report (text, or JSON) and writes --json-out; 1 when a program did not agree.
int finish_difftest(const DifftestOptions& o, const nlohmann::json& report, const std::vector<ProgramDiff>& diffs) {
  if (o.json) std::cout << report.dump() << "\n";
  else print_text(o, diffs);
  if (std::string why = write_json_out(o.shards, report); !why.empty()) return command_failed("difftest", why);
  for (const auto& d : diffs)
    if (d.status != "agreed") return kExitFailed;
  return kExitOk;
}

int run_difftest_merge(const DifftestOptions& o) {
  const MergedShards m = merge_shard_files(o.shards, difftest_shard_format());
  std::vector<ProgramDiff> diffs;
  DifftestOptions run = o;
  try {
    for (const auto& p : m.rows) diffs.push_back(diff_from_json(p));
    run.diff.engine_a = m.settings.at("engines").at(0).get<std::string>();
    run.diff.engine_b = m.settings.at("engines").at(1).get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    return command_failed("difftest", std::string("a shard's rows are not difftest's: ") + e.what());
  }
  nlohmann::json report = m.settings;
  report["programs"] = m.rows;
  return finish_difftest(run, report, diffs);
}

int run_difftest_programs(const DifftestOptions& o) {
  const auto all = expand_programs(o.programs);
  if (all.empty()) {
    std::cerr << "autumn difftest: no programs given\n";
    return kExitUsage;
  }
  const Shard shard = chosen_shard(o.shards);
  const auto files = select_shard(all, shard);
  DifftestOptions run = o;
  run.diff.limits = episode_limits();
  std::vector<ProgramDiff> diffs;
  Progress progress("difftest", files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    progress.item(i, files[i].stem().string());
    diffs.push_back(diff_program_isolated(run, files[i]));
  }
  progress.done();
  nlohmann::json report = diffs_json(o, diffs);
  if (!o.shards.shard.empty()) report["shard"] = shard_json(shard, "programs", all.size());
  return finish_difftest(o, report, diffs);
}

int run_difftest(const CLI::App* cmd, const DifftestOptions& o) {
  if (int status = check_shard_options("difftest", cmd, o.shards, !o.programs.empty())) return status;
  try {
    return o.shards.merging() ? run_difftest_merge(o) : run_difftest_programs(o);
  } catch (const std::exception& e) {
    return command_failed("difftest", e.what());
  }
}

}  // namespace

Subcommand add_difftest_command(CLI::App& app) {
  auto o = std::make_shared<DifftestOptions>();
  CLI::App* cmd = app.add_subcommand("difftest", "Differential test of two engines under random actions");
  register_difftest(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [cmd, o] { return run_difftest(cmd, *o); }};
}

}  // namespace autumn::cli
