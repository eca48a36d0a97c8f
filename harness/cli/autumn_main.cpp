// autumn — the command-line front door: run programs, draw them, check them
// against golden traces, compare engines, and (harness/agent) solve and make
// AutumnBench tasks. One binary, one subcommand per job, each in its own file
// (harness/cli/*_cmd.cpp); every subcommand has --help.
//
// Exit codes: 0 success; 1 the program, input or task failed (including a check
// that mismatched and a solve that found no answer); 2 bad command-line usage.
// Commands over many programs report a bad one in its row and go on. --limits
// sets the episodes' budget (runtime/limits.hpp).
#include <CLI/CLI.hpp>

#include "compiler/read/output.hpp"
#include "harness/cli/commands.hpp"
#include "harness/module_cache.hpp"

int main(int argc, char** argv) {
  using namespace autumn::cli;
  CLI::App app{"autumn: run, draw and check Autumn programs; compare engines; solve AutumnBench tasks"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show help for every subcommand");
  app.set_version_flag("--version", "autumn " AUTUMNC_VERSION, "Print the version and exit");
  app.add_flag("--Werror", warnings_are_errors(), "Treat the programs' warnings as errors");
  app.fallthrough();  // --Werror after the subcommand too (`autumn run prog.au --Werror`)
  std::vector<Subcommand> commands = {
      add_run_command(app),      add_render_command(app),    add_check_command(app),     add_survey_command(app),
      add_bench_command(app),    add_difftest_command(app),  add_play_command(app),      add_solve_command(app),
      add_make_task_command(app), add_eval_command(app),     add_baseline_command(app),  add_bench_agent_command(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  if (!parse_limits_option()) return kExitUsage;
  int rc = -1;
  for (const Subcommand& c : commands)
    if (c.app->parsed()) rc = c.run();
  if (rc < 0) rc = kExitUsage;
  // Before static destruction: a module emitted in the background must not
  // outlive the statics it reads (module_cache.hpp).
  autumn::finish_module_emits();
  return autumn::finish_stdout("autumn", rc);
}
