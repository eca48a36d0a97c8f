// eval_shards — `autumn eval --shard K/N` and `autumn eval --merge`: one
// evaluation cut into N deterministic slices for a batch scheduler (a Slurm
// array, docs/scale.md), and the slices' JSON put back together.
//
// Shard K of N (K from 1) takes the tasks whose index in find_tasks()'s sorted
// order is K-1 modulo N: every task in exactly one shard, the task types mixed
// in each. Its JSON is eval's, with "shard": {"index": K, "count": N, "tasks":
// the folder's task count}. The merge checks that the files are the N shards of
// one run (same task set, same agent settings, each index once, every task
// present) and returns the report a single run prints: the rows in path order,
// the totals recomputed. Tests: tests/eval_shards_test.cpp.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/agent/eval.hpp"

namespace autumn::agent {

struct Shard {
  int index = 1;  // 1..count
  int count = 1;
  bool whole() const { return count == 1; }
};

// "K/N" with 1 <= K <= N <= 100000; throws std::invalid_argument with a one-line reason.
Shard parse_shard(const std::string& text);

// The files of shard `s` (files in find_tasks() order).
std::vector<fs::path> select_shard(const std::vector<fs::path>& files, const Shard& s);

// The inverse of eval_json()'s task rows.
EvalRow eval_row_from_json(const nlohmann::json& row);

// The N shard reports (parsed JSON, in any order) as one report, and its rows;
// throws std::runtime_error naming the file (`names`, parallel to `reports`)
// and the reason when they are not the shards of one run.
nlohmann::json merge_shard_reports(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                                   std::vector<EvalRow>& rows);

}  // namespace autumn::agent
