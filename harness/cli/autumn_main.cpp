// autumn — the command-line front door: run programs, check them against golden
// traces. One binary, one subcommand per job; every subcommand has --help.
//
// Exit codes: 0 success; 1 the program or input is bad, or a check failed;
// 2 bad command-line usage. Commands over many programs report a bad one in its
// row and go on. --limits sets the episodes' budget (runtime/limits.hpp).
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <set>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "compiler/analyse/program.hpp"
#include "harness/agent/agent_commands.hpp"
#include "harness/bench.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/policy.hpp"
#include "harness/program_files.hpp"
#include "harness/trace_check.hpp"

namespace {

using namespace autumn;

std::shared_ptr<const Program> load_or_report(const std::string& path, const std::optional<std::string>& trigger) {
  try {
    auto p = load_program_file(path, trigger);
    for (const auto& w : p->warnings) std::cerr << w << "\n";
    return p;
  } catch (const CompileError& e) {
    std::cerr << e.formatted() << "\n";
    return nullptr;
  }
}

// The episodes' limits, set once from --limits before any command runs.
Limits g_limits;

std::unique_ptr<Environment> make_env(const std::string& engine, std::shared_ptr<const Program> p) {
  std::string why;
  auto env = make_environment(engine, std::move(p), &why);
  if (!env) std::cerr << "autumn: " << why << "\n";
  else env->set_limits(g_limits);
  return env;
}

// Adds --limits to a subcommand; the value is parsed into g_limits after parsing.
void add_limits_option(CLI::App* cmd, std::string& spec) {
  const Limits d;
  cmd->add_option("--limits", spec,
                  fmt::format("Episode budget, KEY=N,...: call-depth (default {}), list-length ({}), objects ({}), "
                              "cells ({}), calls ({})",
                              d.call_depth, d.list_length, d.objects, d.cells, d.calls));
}

struct RunOptions {
  std::string program;
  uint64_t seed = 0;
  std::string actions;
  std::string actions_file;
  int steps = -1;
  std::string trigger;
  bool json = false;
  std::string engine = "interp";
};

int cmd_run(const RunOptions& o) {
  std::string why;
  std::string action_text = o.actions;
  if (!o.actions_file.empty()) {
    std::ifstream in(o.actions_file);
    if (!in) {
      std::cerr << "autumn run: cannot open actions file '" << o.actions_file << "'\n";
      return 1;
    }
    std::stringstream buf;
    std::string line;
    bool first = true;
    while (std::getline(in, line)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
      buf << (first ? "" : ",") << line;
      first = false;
    }
    action_text = buf.str();
  }
  auto actions = parse_action_list(action_text, &why);
  if (!actions) {
    std::cerr << "autumn run: " << why << "\n";
    return 1;
  }
  if (o.steps >= 0) {
    if (static_cast<size_t>(o.steps) < actions->size()) {
      std::cerr << "autumn run: " << actions->size() << " actions given but --steps is " << o.steps << "\n";
      return 1;
    }
    actions->resize(o.steps, Action::noop());
  }
  std::optional<std::string> trigger;
  if (!o.trigger.empty()) trigger = o.trigger;
  auto program = load_or_report(o.program, trigger);
  if (!program) return 1;
  auto env = make_env(o.engine, program);
  if (!env) return 2;

  nlohmann::json frames = nlohmann::json::array();
  nlohmann::json triggers = nlohmann::json::array();
  nlohmann::json done_actions = nlohmann::json::array();
  auto emit = [&](size_t index, const std::string& label) {
    auto rows = frame_rows(env->frame(), env->palette());
    if (o.json) {
      frames.push_back(rows);
    } else {
      fmt::print("# frame {} ({})\n", index, label);
      for (const auto& r : rows) fmt::print("{}\n", r);
    }
  };
  bool ok = env->reset(o.seed);
  if (ok) emit(0, "start");
  for (size_t i = 0; ok && i < actions->size(); ++i) {
    ok = env->step((*actions)[i]);
    if (!ok) break;
    done_actions.push_back(format_action((*actions)[i]));
    emit(i + 1, format_action((*actions)[i]));
    if (trigger) {
      if (o.json) triggers.push_back(env->triggered());
      else fmt::print("# trigger {}\n", env->triggered() ? "true" : "false");
    }
  }
  if (o.json) {
    nlohmann::json trace = {{"seed", o.seed}, {"actions", done_actions}, {"frames", frames}};
    if (trigger) trace["trigger"] = triggers;
    nlohmann::json out = {{"program", std::filesystem::path(o.program).stem().string()},
                          {"grid_size", env->frame().size},
                          {"traces", nlohmann::json::array({trace})}};
    if (trigger) out["triggering_condition"] = *trigger;
    if (!ok) out["error"] = env->error();
    std::cout << out.dump() << "\n";
  }
  if (!ok) {
    std::cerr << env->error() << "\n";
    return 1;
  }
  return 0;
}

int cmd_check(const std::string& program_path, const std::string& traces_path, const std::string& engine,
              bool quiet) {
  TraceFile file;
  try {
    file = load_trace_file(traces_path);
  } catch (const std::exception& e) {
    std::cerr << "autumn check: " << e.what() << "\n";
    return 1;
  }
  auto program = load_or_report(program_path, file.triggering_condition);
  if (!program) return 1;
  auto env = make_env(engine, program);
  if (!env) return 2;
  CheckResult r = check_traces(*env, file);
  if (!quiet)
    for (const auto& m : r.mismatches) fmt::print("MISMATCH {}\n", m);
  if (r.triggers_total) fmt::print("matched {}/{} trigger values\n", r.triggers_matched, r.triggers_total);
  fmt::print("matched {}/{} frames in {} traces\n", r.frames_matched, r.frames_total, r.traces);
  return r.ok() ? 0 : 1;
}

int cmd_survey(const std::string& dir, int steps, uint64_t seed, const std::string& engine) {
  if (!std::filesystem::is_directory(dir)) {
    std::cerr << "autumn survey: '" << dir << "' is not a directory\n";
    return 1;
  }
  auto files = program_files(dir);
  if (files.empty()) {
    std::cerr << "autumn survey: no .au or .sexp programs in '" << dir << "'\n";
    return 1;
  }
  fmt::print("{:<36} {:>5} {:>6} {:>7} {:>9} {:>9} {:>9}  {}\n", "program", "grid", "steps", "frames", "distinct",
             "clauses", "ms", "status");
  int failures = 0;
  size_t total_steps = 0, total_frames = 0;
  for (const auto& f : files) {
    auto program = load_or_report(f.string(), std::nullopt);
    std::string name = f.stem().string();
    if (!program) {
      fmt::print("{:<36} {:>5} {:>6} {:>7} {:>9} {:>9} {:>9}  {}\n", name, "-", 0, 0, 0, "-", 0, "load error");
      ++failures;
      continue;
    }
    auto env = make_env(engine, program);
    if (!env) {
      fmt::print("{:<36} {:>5} {:>6} {:>7} {:>9} {:>9} {:>9}  {}\n", name, "-", 0, 0, 0, "-", 0, "engine error");
      ++failures;
      continue;
    }
    auto t0 = std::chrono::steady_clock::now();
    bool ok = env->reset(seed);
    size_t frames = ok ? 1 : 0, done = 0;
    std::set<std::vector<uint16_t>> distinct;
    int grid = ok ? env->frame().size : 0;
    if (ok) distinct.insert(env->frame().cells);
    RandomPolicy policy(seed);
    for (int i = 0; ok && i < steps; ++i) {
      if (!(ok = env->step(policy.next(env->frame())))) break;
      ++done;
      ++frames;
      distinct.insert(env->frame().cells);
    }
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::string clauses = fmt::format("{}/{}", env->covered_on_clause_count(), env->on_clause_count());
    fmt::print("{:<36} {:>5} {:>6} {:>7} {:>9} {:>9} {:>9.1f}  {}\n", name, grid, done, frames, distinct.size(),
               clauses, ms, ok ? "ok" : "error");
    if (!ok) {
      std::cerr << "  " << env->error() << "\n";
      ++failures;
    }
    total_steps += done;
    total_frames += frames;
  }
  fmt::print("{} programs, {} steps, {} frames, {} failed\n", files.size(), total_steps, total_frames, failures);
  return failures ? 1 : 0;
}

int cmd_bench(const std::vector<std::string>& args, size_t steps, uint64_t seed, bool json, const std::string& only) {
  auto files = expand_programs(args);
  if (files.empty()) {
    std::cerr << "autumn bench: no programs given\n";
    return 1;
  }
  if (!only.empty()) {  // one engine only: for profiling it
    for (const auto& f : expand_programs(args)) {
      auto program = load_or_report(f.string(), std::nullopt);
      if (!program) return 1;
      BenchRow row = bench_program(f.stem().string(), program, {only}, steps, seed);
      const auto& e = row.engines[0];
      fmt::print("{:<32} {} steps/s {:.0f} (render) {:.0f} (bare) clone {:.0f} ns{}\n", row.program, only,
                 e.steps_per_s, e.steps_per_s_no_render, e.clone_ns, e.ok ? "" : "  " + e.error);
    }
    return 0;
  }
  const std::vector<std::string> engines = {"interp", "compiled"};
  nlohmann::json rows = nlohmann::json::array();
  std::vector<double> ratios, compiled_us;
  if (!json)
    fmt::print("{:<32} {:>4} {:>6} {:>12} {:>12} {:>12} {:>12} {:>10} {:>10} {:>8}\n", "program", "grid", "steps",
               "interp st/s", "compiled st/s", "interp bare", "compiled bare", "interp cl", "comp cl", "ratio");
  int failures = 0;
  for (const auto& f : files) {
    auto program = load_or_report(f.string(), std::nullopt);
    if (!program) {
      ++failures;
      continue;
    }
    std::cerr << "bench: " << f.stem().string() << "...\r" << std::flush;
    BenchRow row = bench_program(f.stem().string(), program, engines, steps, seed);
    const auto& in = row.engines[0];
    const auto& co = row.engines[1];
    double ratio = (in.ok && co.ok && in.steps_per_s > 0) ? co.steps_per_s / in.steps_per_s : 0;
    if (ratio > 0) {
      ratios.push_back(ratio);
      compiled_us.push_back(1e6 / co.steps_per_s);
    }
    if (!in.ok || !co.ok) ++failures;
    if (json) {
      nlohmann::json r = {{"program", row.program}, {"grid", row.grid}, {"steps", in.steps}, {"ratio", ratio}};
      for (size_t i = 0; i < engines.size(); ++i)
        r[engines[i]] = {{"ok", row.engines[i].ok},
                         {"steps_per_s", row.engines[i].steps_per_s},
                         {"steps_per_s_no_render", row.engines[i].steps_per_s_no_render},
                         {"clone_ns", row.engines[i].clone_ns},
                         {"error", row.engines[i].error}};
      rows.push_back(r);
    } else {
      fmt::print("{:<32} {:>4} {:>6} {:>12.0f} {:>12.0f} {:>12.0f} {:>12.0f} {:>10.0f} {:>10.0f} {:>7.1f}x\n",
                 row.program, row.grid, in.steps, in.steps_per_s, co.steps_per_s, in.steps_per_s_no_render,
                 co.steps_per_s_no_render, in.clone_ns, co.clone_ns, ratio);
      for (const auto& e : row.engines)
        if (!e.error.empty()) std::cerr << "  " << row.program << ": " << e.error << "\n";
    }
  }
  if (json) {
    std::cout << nlohmann::json({{"rows", rows},
                                 {"median_ratio", median(ratios)},
                                 {"median_compiled_step_us", median(compiled_us)}})
                     .dump(2)
              << "\n";
  } else {
    fmt::print("median over {} programs: compiled/interp {:.1f}x, compiled step {:.2f} us (render included)\n",
               ratios.size(), median(ratios), median(compiled_us));
  }
  return failures ? 1 : 0;
}

int cmd_difftest(const std::vector<std::string>& args, const DiffOptions& o) {
  auto files = expand_programs(args);
  if (files.empty()) {
    std::cerr << "autumn difftest: no programs given\n";
    return 1;
  }
  size_t steps = 0, episodes = 0, errored = 0;
  int failures = 0;
  for (const auto& f : files) {
    auto program = load_or_report(f.string(), std::nullopt);
    if (!program) {
      ++failures;
      fmt::print("FAILED {}: the program does not load\n", f.string());
      continue;
    }
    DiffResult r = diff_engines(program, o);
    steps += r.steps;
    episodes += r.episodes;
    errored += r.errored;
    if (!r.divergence.empty()) {
      ++failures;
      fmt::print("DIVERGED {}: {}\n", f.string(), r.divergence);
    }
  }
  fmt::print("{} programs, {} episodes ({} ended in the same runtime error), {} steps compared ({} vs {}): {} diverged\n",
             files.size(), episodes, errored, steps, o.engine_a, o.engine_b, failures);
  return failures ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"autumn: run Autumn programs and check them against the reference interpreter's traces"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show help for every subcommand");

  RunOptions run;
  auto* run_cmd = app.add_subcommand("run", "Run a program and print its frames");
  run_cmd->add_option("PROGRAM", run.program, "Autumn program (.au or .sexp)")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--seed", run.seed, "Interpreter seed (the benchmark's default is 0)")->default_val(0);
  auto* acts = run_cmd->add_option("--actions", run.actions,
                                   "Comma-separated actions: noop, left, right, up, down, click X Y");
  run_cmd->add_option("--actions-file", run.actions_file, "File with one action per line ('#' comments)")
      ->excludes(acts);
  run_cmd->add_option("--steps", run.steps, "Number of steps (missing actions are noop)")->check(CLI::NonNegativeNumber);
  run_cmd->add_option("--trigger", run.trigger, "Change-detection condition, without outer parentheses");
  run_cmd->add_flag("--json", run.json, "Print one JSON trace (the golden-trace format) instead of text");
  run_cmd->add_option("--engine", run.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");

  std::string check_program, check_traces_path, check_engine = "interp";
  bool check_quiet = false;
  auto* check_cmd = app.add_subcommand("check", "Replay golden traces and compare every frame");
  check_cmd->add_option("PROGRAM", check_program, "Autumn program")->required()->check(CLI::ExistingFile);
  check_cmd->add_option("TRACES", check_traces_path, "Trace file (JSON)")->required()->check(CLI::ExistingFile);
  check_cmd->add_option("--engine", check_engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");
  check_cmd->add_flag("--quiet", check_quiet, "Only print the summary lines");

  std::string survey_dir, survey_engine = "interp";
  int survey_steps = 100;
  uint64_t survey_seed = 0;
  auto* survey_cmd = app.add_subcommand("survey", "Run every program in a folder under a random policy and tabulate");
  survey_cmd->add_option("DIR", survey_dir, "Folder of .au/.sexp programs")->required();
  survey_cmd->add_option("--steps", survey_steps, "Steps per program")->default_val(100)->check(CLI::NonNegativeNumber);
  survey_cmd->add_option("--seed", survey_seed, "Seed for the programs and the random policy")->default_val(0);
  survey_cmd->add_option("--engine", survey_engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");

  std::vector<std::string> bench_programs;
  size_t bench_steps = 1000;
  uint64_t bench_seed = 0;
  bool bench_json = false;
  auto* bench_cmd = app.add_subcommand("bench", "Interpreter vs compiled engine: steps/s with and without render, clone cost");
  bench_cmd->add_option("PROGRAMS", bench_programs, "Program files or folders")->required();
  bench_cmd->add_option("--steps", bench_steps, "Steps per program")->default_val(1000);
  bench_cmd->add_option("--seed", bench_seed, "Seed for the programs and the action policy")->default_val(0);
  bench_cmd->add_flag("--json", bench_json, "Print JSON");
  std::string bench_only;
  bench_cmd->add_option("--only", bench_only, "Run one engine only (for profiling)")->check(CLI::IsMember(engine_names()));

  std::vector<std::string> diff_programs;
  DiffOptions diff;
  auto* diff_cmd = app.add_subcommand("difftest", "Differential test of two engines under random actions");
  diff_cmd->add_option("PROGRAMS", diff_programs, "Program files or folders")->required();
  diff_cmd->add_option("--seeds", diff.seeds, "Episodes (seeds) per program")->default_val(8);
  diff_cmd->add_option("--steps", diff.steps, "Steps per episode")->default_val(200);
  diff_cmd->add_option("--first-seed", diff.first_seed, "First seed")->default_val(0);
  diff_cmd->add_option("--engine", diff.engine_b, "Engine compared with interp")
      ->check(CLI::IsMember(engine_names()))->default_val("compiled");

  std::string limits_spec;
  for (CLI::App* cmd : {run_cmd, check_cmd, survey_cmd, diff_cmd}) add_limits_option(cmd, limits_spec);

  autumn::agent::add_agent_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (!limits_spec.empty()) {
    std::string why;
    auto parsed = limits::parse(limits_spec, &why);
    if (!parsed) {
      std::cerr << "autumn: --limits: " << why << "\n";
      return 2;
    }
    g_limits = *parsed;
    diff.limits = *parsed;
  }
  if (*run_cmd) return cmd_run(run);
  if (*check_cmd) return cmd_check(check_program, check_traces_path, check_engine, check_quiet);
  if (*survey_cmd) return cmd_survey(survey_dir, survey_steps, survey_seed, survey_engine);
  if (*bench_cmd) return cmd_bench(bench_programs, bench_steps, bench_seed, bench_json, bench_only);
  if (*diff_cmd) return cmd_difftest(diff_programs, diff);
  if (int rc = autumn::agent::run_agent_command(app); rc >= 0) return rc;
  return 2;
}
