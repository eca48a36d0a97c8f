// eval_shards — the slices of an evaluation and their merge (eval_shards.hpp).
#include "harness/agent/eval_shards.hpp"

namespace autumn::agent {

ShardFormat eval_shard_format() { return {"eval", "tasks", "tasks", {"agent", "task_set"}}; }

EvalRow eval_row_from_json(const nlohmann::json& j) {
  EvalRow r;
  r.task = j.at("task").get<std::string>();
  r.type = j.at("type").get<std::string>();
  if (!j.at("score").is_null()) r.score = j.at("score").get<double>();
  r.seconds = j.at("seconds").get<double>();
  r.compile_seconds = j.at("compile_seconds").get<double>();
  r.throughput = j.at("throughput").get<double>();
  r.unit = j.at("unit").get<std::string>();
  r.detail = j.at("detail").get<std::string>();
  r.answers = j.at("answers").get<bool>();
  r.stochastic = j.at("stochastic").get<bool>();
  r.answered = j.value("answered", true);
  if (j.contains("plan_length")) r.plan_length = j.at("plan_length").get<int>();
  if (j.contains("reference_length")) r.reference_length = j.at("reference_length").get<int>();
  if (j.contains("error")) r.error = j.at("error").get<std::string>();
  if (j.contains("result")) r.result = j.at("result");
  return r;
}

nlohmann::json merge_shard_reports(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                                   std::vector<EvalRow>& rows) {
  const MergedShards m = merge_shards(reports, names, eval_shard_format());
  rows.clear();
  for (const auto& t : m.rows) rows.push_back(eval_row_from_json(t));
  nlohmann::json merged = eval_json(rows);
  for (const auto& [key, value] : m.settings.items()) merged[key] = value;
  return merged;
}

}  // namespace autumn::agent
