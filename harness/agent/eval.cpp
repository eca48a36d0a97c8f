#include "harness/agent/eval.hpp"

#include <fmt/core.h>

#include <functional>

#include "harness/agent/change_detection.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"
#include "harness/agent/solve_pictures.hpp"

namespace autumn::agent {

std::vector<fs::path> find_tasks(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw TaskError("'" + dir.string() + "' is not a directory");
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && meant_as_task(e.path())) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// A solved task's row: its figures, and how to draw the answer's pictures
// (called after the clock stops; `draw` keeps the result).
using Draw = std::function<std::vector<std::string>()>;

Draw fill_mfp(const Task& task, const SolveOptions& opts, ThreadPool& pool, const fs::path& pictures, EvalRow& row) {
  MfpResult r = solve_mfp(task, opts, pool);
  if (r.expected) row.score = r.choice == *r.expected ? 1.0 : 0.0;
  row.throughput = per_second(static_cast<double>(r.rollouts), r.seconds);
  row.unit = "rollouts/s";
  row.detail = r.choice >= 0 ? fmt::format("choice {} ({}/{} accepted)", r.choice, r.counts[r.choice], r.accepted)
                             : std::string("no choice supported");
  if (r.expected) row.detail += fmt::format(", answer {}", *r.expected);
  row.stochastic = !r.deterministic;
  row.result = mfp_json(r);
  return [&task, r = std::move(r), pictures] { return render_mfp(task, r, pictures); };
}

Draw fill_cd(const Task& task, const SolveOptions& opts, ThreadPool& pool, const fs::path& pictures, EvalRow& row) {
  CdResult r = solve_cd(task, opts, pool);
  row.score = r.score;
  row.throughput = per_second(static_cast<double>(r.env_steps), r.seconds);
  row.unit = "steps/s";
  row.detail = r.detected ? fmt::format("detected at step {}", *r.detected) : fmt::format("no change in {} steps", r.steps);
  if (r.t_star) row.detail += fmt::format(", t* = {}", *r.t_star);
  row.stochastic = !r.deterministic;
  row.result = cd_json(r);
  return [&task, &opts, r = std::move(r), pictures] { return render_cd(task, opts, r, pictures); };
}

Draw fill_planning(const Task& task, const SolveOptions& opts, ThreadPool& pool, const Answers& answers,
                   const fs::path& pictures, EvalRow& row) {
  PlanResult r = solve_planning(task, opts, pool);
  // Judged in the world the task was made in: the answers' seed.
  const bool reaches = r.found && (answers.seed && *answers.seed != task.env_seed
                                       ? plan_reaches_goal(task, opts, r.plan, *answers.seed)
                                       : r.verified);
  row.score = reaches ? 1.0 : 0.0;
  row.stochastic = r.stochastic;
  const std::vector<Action>& ref = answers.reference_plan.empty() ? task.reference_plan : answers.reference_plan;
  if (!ref.empty()) row.reference_length = static_cast<int>(ref.size());
  if (r.found) row.plan_length = static_cast<int>(r.plan.size());
  row.answered = r.found;
  row.throughput = per_second(static_cast<double>(r.nodes), r.seconds);
  row.unit = "nodes/s";
  row.detail = r.found ? fmt::format("plan of {} ({}{})", r.plan.size(), r.method, r.shortest ? ", shortest" : "")
                       : std::string("no plan");
  // Why a stochastic task can be out of reach: it was made in another world.
  if (!reaches && r.stochastic && answers.seed && *answers.seed != r.env_seed)
    row.detail += fmt::format(" (the task was made with env seed {}; the planner simulated seed {})", *answers.seed,
                              r.env_seed);
  if (row.reference_length) row.detail += fmt::format(", generator's K = {}", *row.reference_length);
  row.result = planning_json(r);
  return [&task, &opts, r = std::move(r), pictures] { return render_plan(task, opts, r, pictures); };
}

}  // namespace

EvalRow eval_task(const fs::path& file, const fs::path& root, const SolveOptions& base, ThreadPool& pool,
                  const fs::path& render_dir) {
  EvalRow row;
  row.task = fs::relative(file, root).string();
  row.type = "?";
  // A task's pictures go where it sits under the evaluated folder: two tasks of
  // one name in different folders never overwrite each other's.
  const fs::path pictures = render_dir.empty() ? fs::path() : render_dir / fs::path(row.task).parent_path();
  std::optional<Stopwatch> clock;  // runs from the solve's start
  bool solved = false;             // the solve returned: row.seconds is its time
  try {
    Task task = load_task(file);
    row.type = short_name(task.type);
    SolveOptions opts = base;
    opts.answers = find_answers(task);  // scoring only: the solvers never read it
    Answers answers;
    if (opts.answers) answers = load_answers(*opts.answers);
    row.answers = opts.answers.has_value();
    row.compile_seconds = prepare_modules(task, opts);
    clock.emplace();
    Draw draw;
    switch (task.type) {
      case TaskType::MaskedFramePrediction: draw = fill_mfp(task, opts, pool, pictures, row); break;
      case TaskType::ChangeDetection: draw = fill_cd(task, opts, pool, pictures, row); break;
      case TaskType::Planning: draw = fill_planning(task, opts, pool, answers, pictures, row); break;
    }
    row.seconds = clock->seconds();  // the solve's: pictures are drawn after the clock stops
    solved = true;
    if (!render_dir.empty()) row.pictures = draw();
    return row;
  } catch (const std::exception& e) {
    row.error = e.what();
  }
  if (!solved && clock) row.seconds = clock->seconds();  // the solve failed; a failed picture keeps the solve's time
  return row;
}

std::vector<EvalRow> run_eval(const fs::path& dir, const SolveOptions& opts, ThreadPool& pool,
                              const std::function<void(size_t, size_t, const std::string&)>& progress) {
  return run_eval_files(dir, find_tasks(dir), opts, pool, progress);
}

std::vector<EvalRow> run_eval_files(const fs::path& dir, const std::vector<fs::path>& files, const SolveOptions& opts,
                                    ThreadPool& pool,
                                    const std::function<void(size_t, size_t, const std::string&)>& progress,
                                    const fs::path& render_dir) {
  std::vector<EvalRow> rows;
  for (size_t i = 0; i < files.size(); ++i) {
    if (progress) progress(i, files.size(), fs::relative(files[i], dir).string());
    rows.push_back(eval_task(files[i], dir, opts, pool, render_dir));
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

std::string eval_type_table(const std::vector<EvalRow>& rows) {
  struct Group {
    size_t tasks = 0, errors = 0, scored = 0, with_k = 0, within_k = 0, plans = 0;
    double score = 0, seconds = 0, plan_len = 0, k_len = 0;
  };
  std::vector<std::pair<std::string, Group>> groups;
  auto group = [&](const std::string& name) -> Group& {
    for (auto& [n, g] : groups)
      if (n == name) return g;
    groups.push_back({name, Group{}});
    return groups.back().second;
  };
  for (const char* type : {"mfp", "cd", "planning"})
    for (const char* kind : {"deterministic", "stochastic"}) {
      std::string name = fmt::format("{} {}", type, kind);
      for (const auto& r : rows) {
        if (r.type != type || r.stochastic != (kind[0] == 's')) continue;
        Group& g = group(name);
        ++g.tasks;
        g.seconds += r.seconds;
        if (!r.error.empty()) ++g.errors;
        else if (r.score) ++g.scored, g.score += *r.score;
        if (r.reference_length) {
          ++g.with_k;
          if (r.plan_length && *r.plan_length <= *r.reference_length && r.score && *r.score > 0) ++g.within_k;
        }
        if (r.plan_length && r.reference_length) ++g.plans, g.plan_len += *r.plan_length, g.k_len += *r.reference_length;
      }
    }
  const size_t errored = std::count_if(rows.begin(), rows.end(), [](const EvalRow& r) { return r.type == "?"; });
  std::string s = fmt::format("{:<24} {:>5} {:>6} {:>6} {:>10} {:>12} {:>16} {:>9}\n", "type", "tasks", "errors",
                              "scored", "mean score", "plans <= K", "mean len / K", "time s");
  for (const auto& [name, g] : groups)
    s += fmt::format("{:<24} {:>5} {:>6} {:>6} {:>10} {:>12} {:>16} {:>9.1f}\n", name, g.tasks, g.errors, g.scored,
                     g.scored ? fmt::format("{:.3f}", g.score / g.scored) : "-",
                     g.with_k ? fmt::format("{}/{}", g.within_k, g.with_k) : "-",
                     g.plans ? fmt::format("{:.1f} / {:.1f}", g.plan_len / g.plans, g.k_len / g.plans) : "-",
                     g.seconds);
  if (errored) s += fmt::format("{:<24} {:>5} {:>6}\n", "unreadable", errored, errored);
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
                        {"detail", r.detail},
                        {"answers", r.answers},
                        {"stochastic", r.stochastic},
                        {"answered", r.answered}};
    if (r.plan_length) j["plan_length"] = *r.plan_length;
    if (r.reference_length) j["reference_length"] = *r.reference_length;
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

nlohmann::json eval_agent_json(const std::string& protocol, const SolveOptions& o) {
  return {{"name", protocol == "paper" ? "simulator (paper protocol)" : "simulator"},
          {"protocol", protocol},
          {"engine", o.engine},
          {"rollouts", o.rollouts},
          {"seed_inversion", o.seed_inversion},
          {"policy", o.policy},
          {"search", o.search},
          {"depth", o.depth},
          {"nodes", o.nodes},
          {"seed", o.seed},
          {"time_limit", o.time_limit}};
}

}  // namespace autumn::agent
