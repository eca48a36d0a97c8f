// commands — the subcommands of `autumn`, one file each (harness/cli/*_cmd.cpp).
//
// add_X_command registers X's options on `app` and returns it with its run
// function; the agent's commands (solve, make-task, eval, bench-agent) come from
// harness/agent/agent_commands.hpp.
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

}  // namespace autumn::cli
