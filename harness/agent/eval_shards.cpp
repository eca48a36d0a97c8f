// eval_shards — the slices of an evaluation and their merge (eval_shards.hpp).
#include "harness/agent/eval_shards.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

namespace autumn::agent {

Shard parse_shard(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("--shard '" + text + "': " + why + " (expected K/N, 1 <= K <= N, as in 2/8)");
  };
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw bad("no '/'");
  const auto number = [&](const std::string& part) {
    if (part.empty() || part.size() > 6 || !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; }))
      throw bad("'" + part + "' is not a whole number");
    return std::stoi(part);
  };
  Shard s;
  s.index = number(text.substr(0, slash));
  s.count = number(text.substr(slash + 1));
  if (s.count < 1 || s.count > 100000) throw bad("N must be from 1 to 100000");
  if (s.index < 1 || s.index > s.count) throw bad("K must be from 1 to N");
  return s;
}

std::vector<fs::path> select_shard(const std::vector<fs::path>& files, const Shard& s) {
  std::vector<fs::path> out;
  for (size_t i = static_cast<size_t>(s.index - 1); i < files.size(); i += static_cast<size_t>(s.count))
    out.push_back(files[i]);
  return out;
}

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

namespace {

struct ShardInfo {
  int index, count;
  size_t tasks;
};

ShardInfo shard_info(const nlohmann::json& report, const std::string& name) {
  if (!report.is_object() || !report.contains("tasks") || !report.contains("agent") || !report.contains("task_set"))
    throw std::runtime_error(name + ": not the JSON of `autumn eval` (no tasks, agent or task_set)");
  if (!report.contains("shard"))
    throw std::runtime_error(name + ": not a shard (it has no \"shard\"; run `autumn eval DIR --shard K/N --json-out FILE`)");
  const auto& s = report.at("shard");
  return {s.at("index").get<int>(), s.at("count").get<int>(), s.at("tasks").get<size_t>()};
}

}  // namespace

nlohmann::json merge_shard_reports(const std::vector<nlohmann::json>& reports, const std::vector<std::string>& names,
                                   std::vector<EvalRow>& rows) {
  if (reports.empty()) throw std::runtime_error("no shard files to merge");
  std::map<int, std::string> seen;  // index -> file
  const ShardInfo first = shard_info(reports[0], names[0]);
  size_t row_count = 0;
  for (size_t i = 0; i < reports.size(); ++i) {
    const ShardInfo s = shard_info(reports[i], names[i]);
    if (s.count != first.count || s.tasks != first.tasks)
      throw std::runtime_error(names[i] + ": shard " + std::to_string(s.index) + "/" + std::to_string(s.count) +
                               " of " + std::to_string(s.tasks) + " tasks is not of the same run as " + names[0] +
                               " (" + std::to_string(first.index) + "/" + std::to_string(first.count) + " of " +
                               std::to_string(first.tasks) + ")");
    if (reports[i].at("agent") != reports[0].at("agent"))
      throw std::runtime_error(names[i] + ": its agent settings differ from " + names[0] + "'s");
    if (reports[i].at("task_set") != reports[0].at("task_set"))
      throw std::runtime_error(names[i] + ": its task set " + reports[i].at("task_set").dump() + " is not " +
                               names[0] + "'s " + reports[0].at("task_set").dump());
    if (auto [at, fresh] = seen.emplace(s.index, names[i]); !fresh)
      throw std::runtime_error(names[i] + ": shard " + std::to_string(s.index) + " is also " + at->second);
    row_count += reports[i].at("tasks").size();
  }
  if (static_cast<int>(seen.size()) != first.count) {
    std::string missing;
    for (int k = 1; k <= first.count && missing.size() < 200; ++k)
      if (!seen.count(k)) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
    throw std::runtime_error("shards missing: " + missing + " (of " + std::to_string(first.count) + ")");
  }
  if (row_count != first.tasks)
    throw std::runtime_error("the shards hold " + std::to_string(row_count) + " tasks, the run had " +
                             std::to_string(first.tasks));
  rows.clear();
  for (const auto& r : reports)
    for (const auto& t : r.at("tasks")) rows.push_back(eval_row_from_json(t));
  // find_tasks() order: sorted by path under one root, so by the relative path.
  std::sort(rows.begin(), rows.end(), [](const EvalRow& a, const EvalRow& b) { return fs::path(a.task) < fs::path(b.task); });
  nlohmann::json merged = eval_json(rows);
  merged["agent"] = reports[0].at("agent");
  merged["task_set"] = reports[0].at("task_set");
  return merged;
}

}  // namespace autumn::agent
