// random_baseline — rollouts of the uniform random policy (see random_baseline.hpp).
//
// One prototype environment is reset once; every rollout is a clone of it (the
// same world, the same seed; clones made on the calling thread, a batch at a
// time), driven by its own generator. Per-rollout outcomes
// go to slots and are summed in rollout order afterwards.
#include "harness/agent/random_baseline.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "harness/agent/eval.hpp"
#include "harness/agent/plan_problem.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

namespace {

// splitmix64: rollout r's generator seed, well apart from rollout r + 1's.
uint64_t random_rollout_seed(uint64_t seed, uint64_t r) {
  uint64_t z = seed * 0x9E3779B97F4A7C15ull + r + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

struct RandomOutcome {
  bool success = false;
  bool error = false;
  int steps = 0;        // of the success
  uint64_t env_steps = 0;
};

// Whether the environment's state is a success (the goal, or the trigger seen).
using RolloutTest = std::function<bool(const Environment&)>;

// One rollout: clones the prototype and steps up to `steps` times, testing the
// state before the first step (t = 0) when `test_initial`, and after each step.
RandomOutcome random_rollout(std::unique_ptr<Environment> env, uint64_t seed, int grid, int steps, bool test_initial,
                             const RolloutTest& test) {
  RandomOutcome out;
  std::mt19937_64 rng(seed);
  if (test_initial && test(*env)) return {true, false, 0, 0};
  for (int t = 1; t <= steps; ++t) {
    ++out.env_steps;
    if (!env->step(uniform_action(rng, grid))) {
      out.error = true;
      return out;
    }
    if (test(*env)) {
      out.success = true;
      out.steps = t;
      return out;
    }
  }
  return out;
}

void summarise_rollouts(RandomResult& r, const std::vector<RandomOutcome>& outcomes) {
  double steps = 0;
  for (const RandomOutcome& o : outcomes) {
    r.successes += o.success;
    r.errors += o.error;
    r.env_steps += o.env_steps;
    if (o.success) steps += o.steps;
  }
  r.rollouts = outcomes.size();
  const double p = r.rollouts ? static_cast<double>(r.successes) / static_cast<double>(r.rollouts) : 0.0;
  r.score = p;
  r.stderr_of_score = r.rollouts ? std::sqrt(p * (1 - p) / static_cast<double>(r.rollouts)) : 0.0;
  if (r.successes) r.mean_steps = steps / static_cast<double>(r.successes);
}

std::unique_ptr<Environment> random_world(const Task& task, const RandomOptions& o, const std::string& name,
                                   const std::optional<std::string>& trigger, uint64_t seed) {
  SolveOptions so;
  so.engine = o.engine;
  so.programs_dir = o.programs_dir;
  auto env = make_env_checked(o.engine, load_program_checked(task_program_path(task, so, name), trigger));
  if (!env->reset(seed)) throw TaskError(name + ": " + env->error());
  return env;
}

}  // namespace

Action uniform_action(std::mt19937_64& rng, int grid) {
  switch (rng() % 6) {
    case 0: {
      const int x = static_cast<int>(rng() % static_cast<uint64_t>(grid));
      return Action::click(x, static_cast<int>(rng() % static_cast<uint64_t>(grid)));
    }
    case 1: return Action{Action::Kind::Up};
    case 2: return Action{Action::Kind::Down};
    case 3: return Action{Action::Kind::Left};
    case 4: return Action{Action::Kind::Right};
    default: return Action::noop();
  }
}

RandomResult random_baseline(const Task& task, const RandomOptions& o, ThreadPool& pool) {
  const Stopwatch watch;
  RandomResult r;
  r.type = task.type;
  std::optional<Answers> answers;
  if (std::optional<fs::path> file = find_answers(task)) answers = load_answers(*file);
  if (task.type == TaskType::MaskedFramePrediction) {
    r.choices = static_cast<int>(task.choices.size());
    // Scored as eval scores the other agents: only a task with a known answer.
    if (task.answer || (answers && answers->correct_idx)) r.score = r.choices ? 1.0 / r.choices : 0.0;
    else r.note = "no correct_idx to score against";
    r.seconds = watch.seconds();
    return r;
  }
  r.world_seed = answers && answers->seed ? *answers->seed : task.env_seed;
  const bool cd = task.type == TaskType::ChangeDetection;
  std::unique_ptr<Environment> proto;
  std::optional<Goal> goal;
  if (cd) {
    if (!answers || !answers->condition) {
      r.note = "no trigger condition (an answers file with \"condition\") to estimate";
      r.seconds = watch.seconds();
      return r;
    }
    r.trigger = *answers->condition;
    proto = random_world(task, o, task.wrong_program, r.trigger, r.world_seed);
  } else {
    proto = random_world(task, o, task.program, std::nullopt, r.world_seed);
    goal.emplace(task);
  }
  // triggered() after step t + 1 is the condition on state t: change detection
  // takes one step more, tests no initial state, and counts one step less.
  const int steps = cd ? o.timeout + 1 : o.timeout;
  std::vector<FrameColours> colours(pool.size() + 1);
  const int grid = proto->frame().size;
  std::vector<RandomOutcome> outcomes(o.rollouts);
  // The rollouts' environments are cloned here, on one thread, a batch at a
  // time: clone() is not safe concurrently on the interpreter's environments
  // (they share structure with their source).
  const size_t batch = std::max<size_t>(64, 8 * static_cast<size_t>(pool.size()));
  for (size_t first = 0; first < o.rollouts; first += batch) {
    const size_t n = std::min<size_t>(batch, o.rollouts - first);
    std::vector<std::unique_ptr<Environment>> envs;
    for (size_t k = 0; k < n; ++k) envs.push_back(proto->clone());
    pool.parallel_for_worker(n, [&](size_t k, unsigned worker) {
      const size_t i = first + k;
      const RolloutTest success = [&, worker](const Environment& e) {
        return cd ? e.triggered() : goal->reached(e, colours[worker]);
      };
      outcomes[i] = random_rollout(std::move(envs[k]), random_rollout_seed(o.seed, i), grid, steps, !cd, success);
      if (cd && outcomes[i].success) --outcomes[i].steps;
    });
  }
  summarise_rollouts(r, outcomes);
  r.seconds = watch.seconds();
  return r;
}

nlohmann::json random_json(const RandomResult& r) {
  auto opt = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  nlohmann::json j = {{"type", short_name(r.type)},
                      {"score", opt(r.score)},
                      {"stderr", r.stderr_of_score},
                      {"rollouts", r.rollouts},
                      {"successes", r.successes},
                      {"mean_steps", opt(r.mean_steps)},
                      {"errors", r.errors},
                      {"env_steps", r.env_steps},
                      {"world_seed", r.world_seed},
                      {"seconds", r.seconds}};
  if (r.type == TaskType::MaskedFramePrediction) {
    j["choices"] = r.choices;
    j["chance"] = r.choices ? 1.0 / r.choices : 0.0;
  }
  if (!r.trigger.empty()) j["trigger"] = r.trigger;
  if (!r.note.empty()) j["note"] = r.note;
  return j;
}

std::vector<RandomUnit> random_units(const std::vector<std::string>& paths) {
  std::vector<RandomUnit> units;
  for (const std::string& p : paths) {
    if (fs::is_directory(p)) {
      for (const fs::path& f : find_tasks(p)) units.push_back({f, fs::relative(f, p).string()});
    } else {
      units.push_back({p, p});
    }
  }
  return units;
}

std::vector<RandomRow> run_random_units(const std::vector<RandomUnit>& units, const RandomOptions& o, ThreadPool& pool,
                                        const std::function<void(size_t, size_t, const std::string&)>& progress) {
  std::vector<RandomRow> rows;
  for (size_t i = 0; i < units.size(); ++i) {
    if (progress) progress(i, units.size(), units[i].name);
    RandomRow row;
    row.task = units[i].name;
    row.type = "?";
    try {
      const Task task = load_task(units[i].file);
      row.type = short_name(task.type);
      row.result = random_baseline(task, o, pool);
    } catch (const std::exception& e) {
      row.error = e.what();
    }
    rows.push_back(std::move(row));
  }
  if (progress) progress(units.size(), units.size(), "");
  return rows;
}

std::vector<RandomRow> run_random_baseline(const std::vector<std::string>& paths, const RandomOptions& o,
                                           ThreadPool& pool,
                                           const std::function<void(size_t, size_t, const std::string&)>& progress) {
  return run_random_units(random_units(paths), o, pool, progress);
}

std::string random_table(const std::vector<RandomRow>& rows) {
  std::string out = fmt::format("{:<44} {:<8} {:>15} {:>9} {:>10} {:>8}\n", "task", "type", "score (+- se)",
                                "successes", "mean steps", "seconds");
  struct Sum {
    int tasks = 0, scored = 0, errors = 0;
    double score = 0;
  };
  std::map<std::string, Sum> by_type;
  for (const RandomRow& r : rows) {
    Sum& t = by_type[r.type];
    ++t.tasks;
    if (!r.error.empty()) {
      ++t.errors;
      out += fmt::format("{:<44} {:<8} error: {}\n", r.task, r.type, r.error);
      continue;
    }
    const RandomResult& x = r.result;
    const std::string score = x.score ? fmt::format("{:.3f} +- {:.3f}", *x.score, x.stderr_of_score) : "-";
    const std::string successes = x.type == TaskType::MaskedFramePrediction
                                      ? fmt::format("1/{}", x.choices)
                                      : fmt::format("{}/{}", x.successes, x.rollouts);
    const std::string steps = x.mean_steps ? fmt::format("{:.1f}", *x.mean_steps) : "-";
    out += fmt::format("{:<44} {:<8} {:>15} {:>9} {:>10} {:>8.2f}{}\n", r.task, r.type, score, successes, steps,
                       x.seconds, x.note.empty() ? "" : "  (" + x.note + ")");
    if (x.score) {
      ++t.scored;
      t.score += *x.score;
    }
  }
  out += fmt::format("\n{:<10} {:>6} {:>7} {:>7} {:>11}\n", "type", "tasks", "scored", "errors", "mean score");
  for (const auto& [type, t] : by_type)
    out += fmt::format("{:<10} {:>6} {:>7} {:>7} {:>11}\n", type, t.tasks, t.scored, t.errors,
                       t.scored ? fmt::format("{:.3f}", t.score / t.scored) : "-");
  return out;
}

nlohmann::json random_report_json(const std::vector<RandomRow>& rows, const RandomOptions& o,
                                  const std::vector<std::string>& paths) {
  nlohmann::json tasks = nlohmann::json::array();
  for (const RandomRow& r : rows) {
    nlohmann::json j;
    if (r.error.empty()) {
      j = random_json(r.result);
    } else {
      j = {{"type", r.type}, {"score", nullptr}, {"error", r.error}};
    }
    j["task"] = r.task;
    tasks.push_back(j);
  }
  nlohmann::json agent = {{"name", "random"},
                          {"policy", "uniform over click, up, down, left, right, noop; clicks on a uniform cell"},
                          {"rollouts", o.rollouts},
                          {"timeout", o.timeout},
                          {"seed", o.seed},
                          {"engine", o.engine}};
  if (!o.programs_dir.empty()) agent["programs"] = o.programs_dir.string();
  return {{"agent", agent}, {"task_set", paths}, {"tasks", tasks}};
}

RandomRow random_row_from_json(const nlohmann::json& j) {
  auto opt = [&](const char* key) {
    return j.at(key).is_null() ? std::optional<double>() : std::optional<double>(j.at(key).get<double>());
  };
  RandomRow row;
  row.task = j.at("task").get<std::string>();
  row.type = j.at("type").get<std::string>();
  if (j.contains("error")) {
    row.error = j.at("error").get<std::string>();
    return row;
  }
  RandomResult& r = row.result;
  r.type = row.type == "mfp" ? TaskType::MaskedFramePrediction
           : row.type == "cd" ? TaskType::ChangeDetection
                              : TaskType::Planning;
  r.score = opt("score");
  r.stderr_of_score = j.at("stderr").get<double>();
  r.rollouts = j.at("rollouts").get<uint64_t>();
  r.successes = j.at("successes").get<uint64_t>();
  r.mean_steps = opt("mean_steps");
  r.errors = j.at("errors").get<uint64_t>();
  r.env_steps = j.at("env_steps").get<uint64_t>();
  r.world_seed = j.at("world_seed").get<uint64_t>();
  r.seconds = j.at("seconds").get<double>();
  r.choices = j.value("choices", 0);
  r.trigger = j.value("trigger", "");
  r.note = j.value("note", "");
  return row;
}

}  // namespace autumn::agent
