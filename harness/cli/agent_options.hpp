// agent_options — what the agent's subcommands (solve, make-task, eval,
// baseline random, bench-agent; harness/cli/*_cmd.cpp) share: the search
// options solve and eval both take, --protocol, the "autumn CMD: reason" line of
// a failure, the progress bar and the check that an output file can be written.
// The agent itself (harness/agent) knows nothing of the command line.
#pragma once
#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <string>

#include "harness/agent/solve_common.hpp"

namespace autumn::cli {

// --engine, --rollouts, --threads, --seed, the change-detection and planning
// options, into `o` and `threads`, with the CLI's defaults (autumnc.solve in
// Python states the same ones).
void add_search_options(CLI::App* cmd, agent::SolveOptions& o, unsigned& threads);
// --protocol default|paper; apply_protocol sets what "paper" chooses, except the
// options given on the command line (docs/baselines.md, "The paper's protocol").
void add_protocol_option(CLI::App* cmd, std::string& protocol);
void apply_protocol(const CLI::App* cmd, const std::string& protocol, agent::SolveOptions& o);
// "autumn CMD: why" (one line) on stderr; returns exit status 1.
int command_failed(const std::string& cmd, const std::string& why);
// A progress bar on stderr: redrawn in place on a terminal, a line per item otherwise.
std::function<void(size_t, size_t, const std::string&)> progress_bar();
// A file that exists and may be written, or a new one in a folder that may be.
bool can_write(const std::filesystem::path& p);

}  // namespace autumn::cli
