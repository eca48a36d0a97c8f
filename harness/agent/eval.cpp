#include "harness/agent/eval.hpp"

#include <fmt/core.h>

#include "harness/agent/change_detection.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"

namespace autumn::agent {

std::vector<fs::path> find_tasks(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw TaskError("'" + dir.string() + "' is not a directory");
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && looks_like_task(e.path())) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

EvalRow eval_task(const fs::path& file, const fs::path& root, const SolveOptions& base, ThreadPool& pool) {
  EvalRow row;
  row.task = fs::relative(file, root).string();
  row.type = "?";
  std::optional<Stopwatch> clock;
  try {
    Task task = load_task(file);
    row.type = short_name(task.type);
    SolveOptions opts = base;
    if (task.type == TaskType::ChangeDetection) opts.answers = default_answers_file(task);
    row.compile_seconds = prepare_modules(task, opts);
    clock.emplace();
    switch (task.type) {
      case TaskType::MaskedFramePrediction: {
        MfpResult r = solve_mfp(task, opts, pool);
        if (task.answer) row.score = r.choice == *task.answer ? 1.0 : 0.0;
        row.throughput = per_second(static_cast<double>(r.rollouts), r.seconds);
        row.unit = "rollouts/s";
        row.detail = r.choice >= 0 ? fmt::format("choice {} ({}/{} accepted)", r.choice, r.counts[r.choice], r.accepted)
                                   : std::string("no choice supported");
        if (task.answer) row.detail += fmt::format(", answer {}", *task.answer);
        row.result = mfp_json(r);
        break;
      }
      case TaskType::ChangeDetection: {
        CdResult r = solve_cd(task, opts, pool);
        row.score = r.score;
        row.throughput = per_second(static_cast<double>(r.env_steps), r.seconds);
        row.unit = "steps/s";
        row.detail = r.detected ? fmt::format("detected at step {}", *r.detected)
                                : fmt::format("no change in {} steps", r.steps);
        if (r.t_star) row.detail += fmt::format(", t* = {}", *r.t_star);
        row.result = cd_json(r);
        break;
      }
      case TaskType::Planning: {
        PlanResult r = solve_planning(task, opts, pool);
        row.score = r.found && r.verified ? 1.0 : 0.0;
        row.throughput = per_second(static_cast<double>(r.nodes), r.seconds);
        row.unit = "nodes/s";
        row.detail = r.found ? fmt::format("plan of {} ({}{})", r.plan.size(), r.method, r.shortest ? ", shortest" : "")
                             : std::string("no plan");
        row.result = planning_json(r);
        break;
      }
    }
  } catch (const std::exception& e) {
    row.error = e.what();
  }
  row.seconds = clock ? clock->seconds() : 0;
  return row;
}

std::vector<EvalRow> run_eval(const fs::path& dir, const SolveOptions& opts, ThreadPool& pool,
                              const std::function<void(size_t, size_t, const std::string&)>& progress) {
  std::vector<fs::path> files = find_tasks(dir);
  std::vector<EvalRow> rows;
  for (size_t i = 0; i < files.size(); ++i) {
    if (progress) progress(i, files.size(), fs::relative(files[i], dir).string());
    rows.push_back(eval_task(files[i], dir, opts, pool));
  }
  if (progress) progress(files.size(), files.size(), "");
  return rows;
}

namespace {

std::string score_text(const EvalRow& r) {
  if (!r.error.empty()) return "error";
  return r.score ? fmt::format("{:.3f}", *r.score) : "-";
}

struct Totals {
  double score = 0, seconds = 0, compile_seconds = 0;
  size_t scored = 0, errors = 0;
};

Totals totals(const std::vector<EvalRow>& rows) {
  Totals t;
  for (const auto& r : rows) {
    t.seconds += r.seconds;
    t.compile_seconds += r.compile_seconds;
    if (!r.error.empty()) ++t.errors;
    else if (r.score) t.score += *r.score, ++t.scored;
  }
  return t;
}

}  // namespace

std::string eval_table(const std::vector<EvalRow>& rows) {
  size_t w = 4;
  for (const auto& r : rows) w = std::max(w, r.task.size());
  std::string s = fmt::format("{:<{}}  {:<8} {:>7} {:>9} {:>12} {:<10}  {}\n", "task", w, "type", "score", "time s",
                              "throughput", "unit", "detail");
  for (const auto& r : rows)
    s += fmt::format("{:<{}}  {:<8} {:>7} {:>9.3f} {:>12.0f} {:<10}  {}\n", r.task, w, r.type, score_text(r), r.seconds,
                     r.throughput, r.unit.empty() ? "-" : r.unit, r.error.empty() ? r.detail : r.error);
  const Totals t = totals(rows);
  s += fmt::format("{} tasks, {} scored, total score {:.3f}{}, {} errors, {:.3f} s{}\n", rows.size(), t.scored, t.score,
                   t.scored ? fmt::format(" (mean {:.3f})", t.score / t.scored) : std::string(), t.errors, t.seconds,
                   t.compile_seconds > 0 ? fmt::format(" (and {:.1f} s compiling modules, not counted)", t.compile_seconds)
                                         : std::string());
  return s;
}

nlohmann::json eval_json(const std::vector<EvalRow>& rows) {
  nlohmann::json tasks = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json j = {{"task", r.task},
                        {"type", r.type},
                        {"score", r.score ? nlohmann::json(*r.score) : nlohmann::json(nullptr)},
                        {"seconds", r.seconds},
                        {"compile_seconds", r.compile_seconds},
                        {"throughput", r.throughput},
                        {"unit", r.unit},
                        {"detail", r.detail}};
    if (!r.error.empty()) j["error"] = r.error;
    else j["result"] = r.result;
    tasks.push_back(j);
  }
  const Totals t = totals(rows);
  return {{"tasks", tasks},
          {"totals",
           {{"tasks", rows.size()},
            {"scored", t.scored},
            {"score", t.score},
            {"mean_score", t.scored ? nlohmann::json(t.score / t.scored) : nlohmann::json(nullptr)},
            {"errors", t.errors},
            {"seconds", t.seconds},
            {"compile_seconds", t.compile_seconds}}}};
}

}  // namespace autumn::agent
