// shards — a command over many units (tasks, programs) cut into N
// deterministic slices for a batch scheduler (a Slurm array, docs/scale.md),
// and the slices' JSON put back together into the report of one whole run.
// `autumn eval`, `baseline random`, `bench`, `bench-agent`, `survey` and
// `difftest` shard by this one rule; their options are harness/cli/shard_options.
//
// The slice: a command lists its units in the order a whole run takes them;
// shard K of N (K from 1) takes the units whose index in that list is K-1
// modulo N, in that order. Every unit is in exactly one shard, and neighbours
// (often alike: one program's tasks, one folder's programs) are spread over
// the shards, so they take similar times. No command seeds a unit by its
// position, so a unit's row is the same whichever shard ran it.
//
// A shard's JSON is the command's JSON with one more key, "shard": {"index": K,
// "count": N, UNITS: M} (UNITS the command's word for its units, "tasks" or
// "programs"; M the whole list's length) and, when some of the shard's units
// give no row (bench-agent's --grid leaves programs out), "skipped": their
// indices in the whole list.
//
// The merge checks that its files are the N shards of one run: each is the
// command's JSON (its rows and settings keys) with a "shard"; all have the
// same N and M and equal settings (compared as JSON, the first difference
// named); each index from 1 to N once; each shard holds its share of the M
// units. It returns the settings and the rows in the whole run's order (by the
// rule above: unit i is shard i mod N + 1's next row); the command recomputes
// its totals from them. Every refusal is one line naming the file.
// Tests: tests/shards_test.cpp, AgentEval.ShardsMergeToTheWholeRun.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace autumn {

struct Shard {
  int index = 1;  // 1..count
  int count = 1;
  bool whole() const { return count == 1; }
};

// "K/N" with 1 <= K <= N <= 100000; throws std::invalid_argument with a one-line reason.
Shard parse_shard(const std::string& text);

// The units of shard `s`, in the order of `units` (the whole run's).
template <class T>
std::vector<T> select_shard(const std::vector<T>& units, const Shard& s) {
  std::vector<T> out;
  for (size_t i = static_cast<size_t>(s.index - 1); i < units.size(); i += static_cast<size_t>(s.count))
    out.push_back(units[i]);
  return out;
}

// The index in the whole list of the shard's unit `i` (0-based).
size_t shard_unit_index(const Shard& s, size_t i);

// The "shard" member of a shard's JSON: `units` is the whole list's length,
// named `unit_key`; `skipped` the whole-list indices of its units without a row.
nlohmann::json shard_json(const Shard& s, const std::string& unit_key, size_t units,
                          const std::vector<size_t>& skipped = {});

// What a command's shard JSON holds.
struct ShardFormat {
  std::string command;                // "eval", "baseline random": named in the refusals
  std::string rows;                   // the key of its rows ("tasks", "programs", "rows")
  std::string units;                  // the key of the unit count in "shard" ("tasks", "programs")
  std::vector<std::string> settings;  // keys every shard of one run has, equal
};

struct MergedShards {
  nlohmann::json settings;  // an object: the settings keys, as every shard has them
  nlohmann::json rows;      // an array: the rows in the whole run's order
};

// The N shard reports (parsed JSON, in any order) of one run, put together;
// throws std::runtime_error naming the file (`names`, parallel to `reports`) and
// the reason when they are not the shards of one run.
MergedShards merge_shards(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                          const ShardFormat& format);

// The files, parsed; throws std::runtime_error "FILE: not JSON (...)".
std::vector<nlohmann::json> read_json_files(const std::vector<std::string>& files);

}  // namespace autumn
