#include "harness/agent/change_detection.hpp"

#include <fmt/core.h>

#include <cmath>
#include <random>
#include <unordered_map>

#include "harness/agent/click_model.hpp"
#include "harness/agent/particles.hpp"

namespace autumn::agent {

double cd_score(int t, int t_star) {
  if (t < t_star - 1) return 0.0;
  if (t == t_star - 1 || t == t_star) return 1.0;
  double f = 1.0;
  if (t_star > 0) {
    double r = static_cast<double>(t) / t_star;
    f = 1.0 / (1.0 - r * std::exp(-r));
  }
  return 1.377 * f - 1.178;
}

CdResult solve_cd(const Task& task, const SolveOptions& opts, ThreadPool& pool) {
  if (task.type != TaskType::ChangeDetection) throw TaskError(task.file.string() + ": not a change-detection task");
  Stopwatch clock;
  CdResult r;
  r.policy = opts.policy;
  if (opts.policy != "novelty" && opts.policy != "random") throw TaskError("unknown policy '" + opts.policy + "'");
  std::optional<std::string> trigger;
  if (opts.answers) trigger = load_trigger_condition(*opts.answers);
  if (trigger) r.trigger = *trigger;

  auto original = load_program_checked(task_program_path(task, opts, task.program));
  auto changed = load_program_checked(task_program_path(task, opts, task.wrong_program), trigger);
  ClickUse clicks = analyse_click_use(*original);
  auto env = make_env_checked(opts.engine, changed);
  if (!env->reset(task.env_seed)) throw TaskError(task.wrong_program + ": " + env->error());
  const int grid = env->frame().size;

  std::vector<char> cond;  // cond[k]: trigger condition on the state after step k
  TaskFrame observed = task_frame(env->frame(), env->palette(), task.colours);
  int observed_size = grid;
  FramePredicate keep = [&](const TaskFrame& f, int size) { return size == observed_size && f == observed; };

  auto probe = make_env_checked(opts.engine, original);
  if (!probe->reset(0)) throw TaskError(task.program + ": " + probe->error());
  r.deterministic = probe->deterministic();
  std::vector<uint64_t> seeds = rollout_seeds(opts.seed, std::max<uint64_t>(opts.rollouts, 1), task.env_seed);
  r.particles = r.deterministic ? 1 : seeds.size();
  ParticleSet set(pool, task.colours);
  set.start([&] { return probe->clone(); }, seeds, r.deterministic, keep);
  if (set.empty()) r.detected = 0;

  std::mt19937_64 rng(opts.seed ^ 0x9e3779b97f4a7c15ull);
  std::unordered_map<uint64_t, uint64_t> visits;
  ++visits[frame_digest(observed)];
  uint64_t prediction_steps = 0;
  uint64_t kind_uses[6] = {0, 0, 0, 0, 0, 0};

  auto choose = [&]() -> Action {
    if (opts.policy == "random") return random_action(rng, grid, 4);
    std::vector<Action> cands = {Action::noop(), {Action::Kind::Left}, {Action::Kind::Right}, {Action::Kind::Up},
                                 {Action::Kind::Down}};
    int n_clicks = clicks == ClickUse::Position ? 4 : 1;
    for (int i = 0; i < n_clicks; ++i)
      cands.push_back(Action::click(static_cast<int>(rng() % grid), static_cast<int>(rng() % grid)));
    // Never touch one environment from two threads: clone on the caller first.
    const Environment& model = *set.particles().front().env;
    std::vector<std::unique_ptr<Environment>> clones;
    for (size_t i = 0; i < cands.size(); ++i) clones.push_back(model.clone());
    std::vector<uint64_t> score(cands.size(), UINT64_MAX);
    pool.parallel_for(cands.size(), [&](size_t i) {
      Environment* e = clones[i].get();
      if (!e->step(cands[i])) return;
      auto it = visits.find(frame_digest(task_frame(e->frame(), e->palette(), task.colours)));
      score[i] = it == visits.end() ? 0 : it->second;
    });
    prediction_steps += cands.size();
    // Least-visited predicted frame; then the least-used kind of action; then random.
    uint64_t best = *std::min_element(score.begin(), score.end());
    uint64_t fewest = UINT64_MAX;
    for (size_t i = 0; i < cands.size(); ++i)
      if (score[i] == best) fewest = std::min(fewest, kind_uses[static_cast<int>(cands[i].kind)]);
    std::vector<size_t> ties;
    for (size_t i = 0; i < cands.size(); ++i)
      if (score[i] == best && kind_uses[static_cast<int>(cands[i].kind)] == fewest) ties.push_back(i);
    return cands[ties[rng() % ties.size()]];
  };

  for (int t = 1; t <= opts.max_steps && !r.detected; ++t) {
    Action a = choose();
    if (!env->step(a)) {
      r.env_error = env->error();
      break;
    }
    r.actions.push_back(a);
    ++kind_uses[static_cast<int>(a.kind)];
    r.steps = t;
    if (trigger) cond.push_back(env->triggered());
    observed = task_frame(env->frame(), env->palette(), task.colours);
    observed_size = env->frame().size;
    ++visits[frame_digest(observed)];
    set.step(a, keep);
    if (set.empty()) r.detected = t;
  }

  if (trigger) {
    // Learn the condition on the states after the last steps: cond has states
    // 0..steps-1; up to two noop steps on a clone give `steps` and `steps + 1`.
    int need = r.detected ? *r.detected + 1 : r.steps;
    auto cont = env->clone();
    while (static_cast<int>(cond.size()) <= need && !cont->failed() && cont->step(Action::noop()))
      cond.push_back(cont->triggered());
    for (size_t k = 0; k < cond.size(); ++k)
      if (cond[k]) {
        r.t_star = static_cast<int>(k);
        break;
      }
    if (!r.detected) r.score = 0.0;
    else if (!r.t_star) r.score = 0.0;  // t* > detection + 1
    else r.score = cd_score(*r.detected, *r.t_star);
  }
  r.env_steps = set.env_steps() + prediction_steps;
  r.peak_particles = set.peak();
  r.seconds = clock.seconds();
  return r;
}

nlohmann::json cd_json(const CdResult& r) {
  nlohmann::json actions = nlohmann::json::array();
  for (const auto& a : r.actions) actions.push_back(format_action(a));
  nlohmann::json j = {{"detected", r.detected ? nlohmann::json(*r.detected) : nlohmann::json(nullptr)},
                      {"steps", r.steps},
                      {"actions", actions},
                      {"policy", r.policy},
                      {"deterministic", r.deterministic},
                      {"particles", r.particles},
                      {"peak_particles", r.peak_particles},
                      {"env_steps", r.env_steps},
                      {"seconds", r.seconds},
                      {"steps_per_second", per_second(static_cast<double>(r.env_steps), r.seconds)}};
  if (!r.env_error.empty()) j["env_error"] = r.env_error;
  if (!r.trigger.empty()) {
    j["t_star"] = r.t_star ? nlohmann::json(*r.t_star) : nlohmann::json(nullptr);
    j["score"] = r.score ? nlohmann::json(*r.score) : nlohmann::json(nullptr);
  }
  return j;
}

std::string cd_summary(const CdResult& r) {
  std::string s;
  if (r.detected) s += fmt::format("change detected at step {}\n", *r.detected);
  else s += fmt::format("no change detected in {} steps\n", r.steps);
  if (!r.env_error.empty()) s += fmt::format("the changed program failed: {}\n", r.env_error);
  std::string acts;
  for (size_t i = 0; i < r.actions.size(); ++i) acts += (i ? ", " : "") + format_action(r.actions[i]);
  s += fmt::format("actions ({} policy): {}\n", r.policy, acts.empty() ? "-" : acts);
  s += fmt::format("original program: {}, {} particle(s) at start, peak {}\n",
                   r.deterministic ? "deterministic" : "stochastic", r.particles, r.peak_particles);
  if (!r.trigger.empty()) {
    s += fmt::format("change condition first holds on the state after step {}\n",
                     r.t_star ? std::to_string(*r.t_star) : std::string("(not within the episode)"));
    s += fmt::format("score: {:.3f}\n", r.score.value_or(0.0));
  }
  s += fmt::format("time: {:.3f} s, {} environment steps ({:.0f} steps/s)\n", r.seconds, r.env_steps,
                   per_second(static_cast<double>(r.env_steps), r.seconds));
  return s;
}

}  // namespace autumn::agent
