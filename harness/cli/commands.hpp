// commands — the subcommands of `autumn`, one file each (harness/cli/*_cmd.cpp).
//
// add_X_command registers X's options on `app` and returns it with its run
// function. Each file holds an options struct, a register function and a run
// function; the agent's commands (solve, make-task, eval, baseline random,
// bench-agent) share harness/cli/agent_options.hpp.
#pragma once
#include "harness/cli/cli_common.hpp"

namespace autumn::cli {

Subcommand add_run_command(CLI::App& app);
Subcommand add_render_command(CLI::App& app);
Subcommand add_check_command(CLI::App& app);
Subcommand add_survey_command(CLI::App& app);
Subcommand add_bench_command(CLI::App& app);
Subcommand add_difftest_command(CLI::App& app);
Subcommand add_play_command(CLI::App& app);
Subcommand add_solve_command(CLI::App& app);
Subcommand add_make_task_command(CLI::App& app);
Subcommand add_eval_command(CLI::App& app);
Subcommand add_baseline_command(CLI::App& app);  // `baseline random`
Subcommand add_bench_agent_command(CLI::App& app);

}  // namespace autumn::cli
