// eval_shards — `autumn eval --shard K/N` and `autumn eval --merge`: one
// evaluation cut into N deterministic slices for a batch scheduler (a Slurm
// array, docs/scale.md), and the slices' JSON put back together.
//
// The slice and the merge's checks are every sharded command's
// (harness/shards.hpp): shard K of N takes the tasks whose index in
// find_tasks()'s sorted order is K-1 modulo N, and its JSON is eval's with
// "shard": {"index": K, "count": N, "tasks": the folder's task count}. The
// settings every shard must share are "agent" and "task_set". The merge returns
// the report a single run prints: the rows in path order, the totals
// recomputed. Tests: tests/agent_test.cpp, AgentEval.ShardsMergeToTheWholeRun.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/agent/eval.hpp"
#include "harness/shards.hpp"

namespace autumn::agent {

// What eval's shard JSON holds (shards.hpp).
ShardFormat eval_shard_format();

// The inverse of eval_json()'s task rows.
EvalRow eval_row_from_json(const nlohmann::json& row);

// The N shard reports (parsed JSON, in any order) as one report, and its rows;
// throws std::runtime_error naming the file (`names`, parallel to `reports`)
// and the reason when they are not the shards of one run.
nlohmann::json merge_shard_reports(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                                   std::vector<EvalRow>& rows);

}  // namespace autumn::agent
