// shard_options — what the commands over many units (eval, baseline random,
// bench, bench-agent, survey, difftest) share to run in slices on a batch
// scheduler: --shard K/N (one slice; its JSON says which), --merge SHARD.json...
// (the slices back into the whole run's report) and --json-out FILE (the JSON
// a shard is merged from). The rule and the merge's checks are
// harness/shards.hpp; each command builds its rows, totals and table from the
// merged rows as it does from its own. --merge takes no units and no run
// options (they are the shards'), --shard needs the units: both refused with a
// one-line reason, exit status 2.
#pragma once
#include <CLI/CLI.hpp>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/shards.hpp"

namespace autumn::cli {

struct ShardOptions {
  std::string shard;               // K/N: this slice of the units
  std::vector<std::string> merge;  // shard JSON files to put back together
  std::string json_out;            // also write the JSON here (the table still prints)
  bool merging() const { return !merge.empty(); }
};

// --json-out, --shard and --merge on `cmd`. `inputs` is the command's positional option, required
// unless --merge (check_shard_options says so); `units` names what it lists
// ("folder's tasks", "programs") and `order` the whole run's order of them, in
// the help.
void add_shard_options(CLI::App* cmd, ShardOptions& o, CLI::Option* inputs, const std::string& units,
                       const std::string& order);

// After parsing, before the run: 0 when the options go together; else prints
// "autumn COMMAND: reason" (one line) and returns the exit status: 2 for
// options that do not go together (no inputs and no --merge, --merge with a
// run option such as --steps, a bad --shard), 1 for an unwritable --json-out.
int check_shard_options(const std::string& command, const CLI::App* cmd, const ShardOptions& o, bool has_inputs);

// The slice of --shard (the whole run without it).
Shard chosen_shard(const ShardOptions& o);

// --merge's files read and merged (shards.hpp); throws std::runtime_error with a one-line reason.
MergedShards merge_shard_files(const ShardOptions& o, const ShardFormat& format);

// Writes `report` to --json-out when given; "" or why not.
std::string write_json_out(const ShardOptions& o, const nlohmann::json& report);

}  // namespace autumn::cli
