// autumn solve — one AutumnBench task (masked-frame prediction, change
// detection or planning) answered by the simulator agent (harness/agent): the
// answer as text or JSON, pictures of it with --render, exit 1 without an answer.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/agent/change_detection.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"
#include "harness/agent/solve_pictures.hpp"
#include "harness/agent/task_file.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/progress.hpp"

namespace autumn::cli {
namespace {

using namespace autumn::agent;

struct SolveCommand {
  SolveOptions search;
  std::string task_file, programs_dir, answers_file, render_dir;
  std::string protocol = "default";
  unsigned threads = 0;
  bool json = false;
};

void register_solve(CLI::App* cmd, SolveCommand& o) {
  cmd->add_option("TASK", o.task_file, "Task file (JSON)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--programs", o.programs_dir, "Folder of the task's programs (default: programs/ beside the task's folder)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--answers", o.answers_file, "Answers file, read only to report and score: MFP correct_idx, change detection's condition and world seed")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--json", o.json, "Print one JSON object");
  cmd->add_option("--render", o.render_dir,
                      "Write pictures of the answer into DIR: the plan (GIF and PNG), the chosen MFP answer, "
                      "the change-detection episode");
  add_search_options(cmd, o.search, o.threads);
  add_protocol_option(cmd, o.protocol);

}

// Clicks outside the task's grid reach the program but land on no cell: say so.
void warn_clicks_outside(const Task& task) {
  const int grid = task.type == TaskType::MaskedFramePrediction ? task.observations[0].grid.width
                   : task.type == TaskType::Planning           ? task.goal.width
                                                                : 0;
  std::vector<Action> actions = task.reference_plan;
  for (const Observation& o : task.observations)
    if (o.action) actions.push_back(*o.action);
  for (const Action& a : actions)
    if (grid > 0 && a.kind == Action::Kind::Click && (a.x < 0 || a.y < 0 || a.x >= grid || a.y >= grid))
      std::cerr << "autumn solve: warning: " << task.file.filename().string() << ": " << format_action(a)
                << " is outside the " << grid << "x" << grid << " grid; the program still receives it\n";
}

int run_solve(const CLI::App* cmd, const SolveCommand& c) {
  try {
    SolveOptions o = c.search;
    apply_protocol(cmd, c.protocol, o);
    if (!c.programs_dir.empty()) o.programs_dir = c.programs_dir;
    if (!c.answers_file.empty()) o.answers = c.answers_file;
    Task task = load_task(c.task_file);
    warn_clicks_outside(task);
    ThreadPool pool(c.threads);
    nlohmann::json out = {{"task", c.task_file}, {"type", type_name(task.type)}, {"program", task.program}};
    out["compile_seconds"] = prepare_modules(task, o);
    std::string text;
    bool answered = false;
    std::vector<std::string> pictures;
    Heartbeat heartbeat("autumn solve: " + task.name);
    switch (task.type) {
      case TaskType::MaskedFramePrediction: {
        MfpResult r = solve_mfp(task, o, pool);
        out["result"] = mfp_json(r);
        text = mfp_summary(r);
        answered = r.choice >= 0;
        if (!c.render_dir.empty()) pictures = render_mfp(task, r, c.render_dir);
        break;
      }
      case TaskType::ChangeDetection: {
        out["wrong_program"] = task.wrong_program;
        CdResult r = solve_cd(task, o, pool);
        out["result"] = cd_json(r);
        text = cd_summary(r);
        answered = r.detected.has_value();
        if (!c.render_dir.empty()) pictures = render_cd(task, o, r, c.render_dir);
        break;
      }
      case TaskType::Planning: {
        PlanResult r = solve_planning(task, o, pool);
        out["result"] = planning_json(r);
        text = planning_summary(r);
        answered = r.found;
        if (!c.render_dir.empty()) pictures = render_plan(task, o, r, c.render_dir);
        break;
      }
    }
    for (const std::string& p : pictures) std::cerr << "autumn solve: wrote " << p << "\n";
    out["threads"] = pool.size();
    if (c.json) {
      std::cout << out.dump() << "\n";
    } else {
      fmt::print("task: {} ({}, program {}, {} threads)\n{}", c.task_file, type_name(task.type), task.program,
                 pool.size(), text);
    }
    if (!answered) std::cerr << "autumn solve: no answer found (exit status 1)\n";
    return answered ? 0 : 1;
  } catch (const std::exception& e) {
    return command_failed("solve", e.what());
  }
}

}  // namespace

Subcommand add_solve_command(CLI::App& app) {
  auto o = std::make_shared<SolveCommand>();
  CLI::App* cmd = app.add_subcommand("solve", "Solve an AutumnBench task (MFP, change detection or planning)");
  register_solve(cmd, *o);
  return {cmd, [cmd, o] { return run_solve(cmd, *o); }};
}

}  // namespace autumn::cli
