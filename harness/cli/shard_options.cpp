// shard_options — --shard, --merge and --json-out of the many-unit commands (shard_options.hpp).
#include "harness/cli/shard_options.hpp"

#include <set>

#include "compiler/read/output.hpp"
#include "harness/cli/agent_options.hpp"
#include "harness/cli/cli_common.hpp"

namespace autumn::cli {

void add_shard_options(CLI::App* cmd, ShardOptions& o, CLI::Option* inputs, const std::string& units,
                       const std::string& order) {
  cmd->add_option("--json-out", o.json_out, "Also write the JSON object to FILE (the table still prints)")
      ->type_name("FILE");
  CLI::Option* shard = cmd->add_option("--shard", o.shard,
                                       "Run only slice K of N of the " + units + ": those whose index in " + order +
                                           " is K-1 modulo N, for a batch scheduler's array job; its JSON "
                                           "(--json-out) says which slice (docs/scale.md)")
                           ->type_name("K/N");
  cmd->add_option("--merge", o.merge,
                  "Put the N shards' JSON files (--json-out of each --shard run) back together: the table and JSON "
                  "of one run over all the " + units + "; with no " + inputs->get_name() +
                      " and no run options, only --json and --json-out")
      ->type_name("SHARD.json ...")
      ->excludes(inputs)
      ->excludes(shard)
      ->check(CLI::ExistingFile);
}

namespace {

// The reason the options do not go together, or "".
std::string usage_problem(const CLI::App* cmd, const ShardOptions& o, bool has_inputs) {
  if (o.merging()) {
    static const std::set<std::string> kMergeOptions = {"--merge", "--json", "--json-out", "--help"};
    for (const CLI::Option* opt : cmd->get_options())
      if (opt->count() > 0 && !kMergeOptions.count(opt->get_name()))
        return "--merge takes its settings from the shards; " + opt->get_name() + " is an option of a run";
    return "";
  }
  if (!has_inputs) {
    std::string inputs;
    for (const CLI::Option* opt : cmd->get_options())
      if (opt->get_positional()) inputs = opt->get_name();
    return inputs + " is required, or --merge SHARD.json ...";
  }
  if (!o.shard.empty()) {
    try {
      parse_shard(o.shard);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
  }
  return "";
}

}  // namespace

int check_shard_options(const std::string& command, const CLI::App* cmd, const ShardOptions& o, bool has_inputs) {
  if (std::string why = usage_problem(cmd, o, has_inputs); !why.empty()) {
    command_failed(command, why);
    return kExitUsage;
  }
  // Checked before the (long) run, so a bad path fails at once.
  if (!o.json_out.empty() && !can_write(o.json_out)) return command_failed(command, "cannot write " + o.json_out);
  return 0;
}

Shard chosen_shard(const ShardOptions& o) { return o.shard.empty() ? Shard{} : parse_shard(o.shard); }

MergedShards merge_shard_files(const ShardOptions& o, const ShardFormat& format) {
  return merge_shards(read_json_files(o.merge), o.merge, format);
}

std::string write_json_out(const ShardOptions& o, const nlohmann::json& report) {
  if (o.json_out.empty()) return "";
  return write_file(o.json_out, report.dump(1) + "\n");
}

}  // namespace autumn::cli
