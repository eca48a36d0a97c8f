// autumn make-task — an MFP, planning or change-detection task generated for a
// program (harness/agent/make_task, make_cd): the prompt, its answers and, under
// prompts/, the program copied beside them.
#include <CLI/CLI.hpp>

#include <iostream>

#include "harness/agent/make_cd.hpp"
#include "harness/agent/make_task.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/engine.hpp"

namespace autumn::cli {
namespace {

using namespace autumn::agent;

struct MakeCommand {
  MakeTaskOptions task;
  std::string program, out;
};

void register_make(CLI::App* cmd, MakeCommand& o) {
  cmd->add_option("KIND", o.task.kind, "mfp, planning or cd")
      ->required()
      ->check(CLI::IsMember({"mfp", "planning", "cd"}));
  cmd->add_option("PROGRAM", o.program, "Autumn program (.au or .sexp)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--seed", o.task.seed, "Seed of the generator (actions, mask, distractors)")
      ->default_val(0)
      ->check(cli::seed_number());
  cmd->add_option("--steps", o.task.steps, "Actions in the task (default: mfp 20, planning 4); cd: the clock value K "
                                                 "the change starts at (default: seeded in 6..20)")
      ->check(cli::int_count(1));
  cmd->add_option("--out", o.out, "Output task file (default: stdout); under prompts/ the program is copied "
                                          "to the sibling programs/ and the answers go to the sibling answers/ "
                                          "(cd: required, and the changed program goes to programs/ too)");
  cmd->add_option("--answers", o.task.answers_out,
                     "Answers file (seed, correct_idx / reference_plan) (default: answers/TASK.json beside prompts/, "
                     "else TASK.answers.json beside the task)");
  cmd->add_option("--env-seed", o.task.env_seed, "Interpreter seed of the environment")
      ->default_val(0)
      ->check(cli::seed_number());
  cmd->add_option("--batch", o.task.batch, "MFP: rollouts whose outcomes no distractor may equal")
      ->default_val(200)
      ->check(cli::big_count(1));
  cmd->add_option("--posterior-samples", o.task.posterior_samples,
                     "MFP, stochastic programs: samples of the blind solver's posterior that choose the rectangle")
      ->default_val(1000)
      ->check(cli::big_count(1));
  cmd->add_option("--masked-frames", o.task.masked_frames, "MFP: final frames that hide the rectangle")
      ->default_val(3)
      ->check(cli::int_count(1));
  cmd->add_flag("--extend-colours", o.task.extend_colours,
                   "Append colours missing from the colour table (and write the table next to the task)");
  cmd->add_option("--engine", o.task.engine, "Execution engine")
      ->check(CLI::IsMember(engine_names()))
      ->default_val("compiled");

}

int run_make(const MakeCommand& c) {
  try {
    MakeTaskOptions o = c.task;
    o.program = c.program;
    if (!c.out.empty()) o.out = c.out;
    if (o.kind == "cd") {
      if (o.out.empty()) return command_failed("make-task", "cd needs --out DIR/prompts/NAME_cd.json");
      for (const auto& note : write_cd(make_cd(o), o)) std::cerr << note << "\n";
      return 0;
    }
    ThreadPool pool(0);
    MadeTask made = make_task(o, pool);
    for (const auto& w : made.warnings) std::cerr << "autumn make-task: " << w << "\n";
    for (const auto& note : write_task(made, o)) std::cerr << note << "\n";
    return 0;
  } catch (const std::exception& e) {
    return command_failed("make-task", e.what());
  }
}

}  // namespace

Subcommand add_make_task_command(CLI::App& app) {
  auto o = std::make_shared<MakeCommand>();
  CLI::App* cmd = app.add_subcommand("make-task", "Generate an MFP, planning or change-detection task for a program");
  register_make(cmd, *o);
  return {cmd, [o] { return run_make(*o); }};
}

}  // namespace autumn::cli
