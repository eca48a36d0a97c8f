// autumn run — run a program and print its frames (text, or one JSON trace that
// `autumn check` reads).
#include <fmt/core.h>

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/engine.hpp"
#include "harness/episode.hpp"
#include "harness/warm_env.hpp"

namespace autumn::cli {
namespace {

struct RunOptions {
  std::string program;
  uint64_t seed = 0;
  std::string actions;
  std::string actions_file;
  int steps = -1;
  std::string trigger;
  bool json = false;
  std::string engine = "interp";
  bool verbose = false;
};

void register_run(CLI::App* cmd, RunOptions& o) {
  cmd->add_option("PROGRAM", o.program, "Autumn program (.au or .sexp)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--seed", o.seed, "Interpreter seed (the benchmark's default is 0)")->default_val(0)->check(seed_number());
  auto* acts = cmd->add_option("--actions", o.actions, "Comma-separated actions: noop, left, right, up, down, click X Y");
  cmd->add_option("--actions-file", o.actions_file, "File with one action per line ('#' comments)")->excludes(acts);
  cmd->add_option("--steps", o.steps, "Number of steps (missing actions are noop)")->check(int_count());
  cmd->add_option("--trigger", o.trigger, "Change-detection condition, without outer parentheses");
  cmd->add_flag("--json", o.json, "Print one JSON trace (the golden-trace format) instead of text");
  cmd->add_option("--engine", o.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");
  cmd->add_flag("-v,--verbose", o.verbose, "Say on stderr which engine ran the episode (the compiled engine's first use of a program runs the interpreter while its module compiles)");
}

// What `-v` prints: the engine that ran, and for a warm start which steps each served.
std::string engine_line(const RunOptions& o, const Environment& env) {
  if (auto* warm = dynamic_cast<const WarmingEnvironment*>(&env)) return warm->served_by();
  return o.engine;
}

nlohmann::json trace_json(const RunOptions& o, const EpisodeFrames& ep, const std::optional<std::string>& trigger) {
  nlohmann::json actions = nlohmann::json::array();
  for (const Action& a : ep.actions) actions.push_back(format_action(a));
  nlohmann::json trace = {{"seed", o.seed}, {"actions", actions}, {"frames", ep.frames}};
  if (trigger) trace["trigger"] = ep.triggers;
  nlohmann::json out = {{"program", std::filesystem::path(o.program).stem().string()},
                        {"grid_size", ep.grid},
                        {"traces", nlohmann::json::array({trace})}};
  if (trigger) out["triggering_condition"] = *trigger;
  if (!ep.ok()) out["error"] = ep.error;
  return out;
}

int run_run(const RunOptions& o) {
  auto actions = read_actions("run", o.actions, o.actions_file, o.steps);
  if (!actions) return kExitUsage;  // the flags' value, not the program: a usage error
  std::optional<std::string> trigger;
  if (!o.trigger.empty()) trigger = o.trigger;
  auto program = load_or_report(o.program, trigger);
  if (!program) return kExitFailed;
  auto env = make_env("run", o.engine, program);
  if (!env) return kExitFailed;
  auto print = [&](size_t index, const std::string& label, const std::vector<std::string>& rows) {
    if (o.json) return;
    if (index == 0) warn_clicks_outside("run", *actions, env->frame().size);
    fmt::print("# frame {} ({})\n", index, label);
    for (const auto& r : rows) fmt::print("{}\n", r);
    if (trigger && index > 0) fmt::print("# trigger {}\n", env->triggered() ? "true" : "false");
    std::fflush(stdout);
  };
  EpisodeFrames ep = run_episode(*env, o.seed, *actions, print);
  if (o.verbose) std::cerr << "autumn run: engine: " << engine_line(o, *env) << "\n";
  if (o.json) {
    if (ep.grid) warn_clicks_outside("run", *actions, ep.grid);
    std::cout << trace_json(o, ep, trigger).dump() << "\n";
  }
  if (!ep.ok()) {
    std::cerr << ep.error << "\n";
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace

Subcommand add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Run a program and print its frames");
  register_run(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [o] { return run_run(*o); }};
}

}  // namespace autumn::cli
