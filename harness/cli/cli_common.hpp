// cli_common — what the `autumn` subcommands share.
//
// Each subcommand lives in its own file as an options struct, a register
// function (its options and --help) and a run function returning the exit
// status; add_*_command() ties the three together into a Subcommand that main()
// dispatches on. This header holds the pieces several of them use: exit codes,
// loading a program with its warnings, building an engine, reading actions
// (progress lines on stderr are harness/progress.hpp).
//
// Exit codes, everywhere: 0 done; 1 the program, the input or a task failed (a
// check mismatched, an engine could not be built, no answer was found); 2 the
// command line itself was wrong.
#pragma once
#include <CLI/CLI.hpp>

#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "harness/progress.hpp"
#include "runtime/environment.hpp"

namespace autumn::cli {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

// --Werror, set on the top-level command: warnings of the loaded programs become errors.
bool& warnings_are_errors();

// Loads a program and prints its warnings (file:line:col: warning: ...); on a
// compile error (or a warning under --Werror) prints it and returns null.
std::shared_ptr<const Program> load_or_report(const std::string& path, const std::optional<std::string>& trigger,
                                              std::string* why = nullptr);

// --limits KEY=N,... (runtime/limits.hpp) on a subcommand; the text goes to
// limits_spec() and parse_limits_option() turns it into episode_limits() once the
// command line is parsed (false after printing why).
void add_limits_option(CLI::App* cmd);
bool parse_limits_option();
const Limits& episode_limits();
// episode_limits() as JSON ({"call_depth": ..., "list_length", "objects", "cells", "calls"}): a setting
// of the runs a sharded command's merge compares (shard_options.hpp).
nlohmann::json episode_limits_json();

// What the compiled engine does when the program's module is not built yet.
enum class FirstUse {
  kInterpreterMeanwhile,  // the interpreter serves the first steps while it compiles (run, render, survey)
  kWaitForModule,         // the command waits for it: a check of an engine checks that engine (check)
};
// An environment of `engine` for one episode under episode_limits(), or null after printing why
// (harness/module_cache.hpp: make_compiled_episode_environment, make_compiled_environment).
std::unique_ptr<Environment> make_env(const std::string& command, const std::string& engine,
                                      std::shared_ptr<const Program> program,
                                      FirstUse first_use = FirstUse::kInterpreterMeanwhile);

// --actions text or an --actions-file (one action a line, '#' comments), padded
// with noop to `steps` when steps >= 0. Null after printing a one-line reason.
std::optional<std::vector<Action>> read_actions(const std::string& command, const std::string& text,
                                                const std::string& file, int steps);
// Warns (on stderr) about clicks outside a grid of `grid` cells a side: the
// program receives them, but they land on no cell.
void warn_clicks_outside(const std::string& command, const std::vector<Action>& actions, int grid);

}  // namespace autumn::cli
