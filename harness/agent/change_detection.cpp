#include "harness/agent/change_detection.hpp"

#include <fmt/core.h>

#include <cmath>
#include <random>
#include <unordered_map>

#include "harness/agent/click_model.hpp"
#include "harness/agent/particles.hpp"
#include "harness/agent/smc.hpp"

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

namespace {

// The agent's model of the ORIGINAL program: the exact stated-seed episode while
// it explains every observation, then sequential Monte Carlo over an unknown
// seed (smc.hpp), filtered afresh over the whole history when it first takes
// over and once more whenever all its samples die, before a change is declared.
class Model {
 public:
  Model(const Task& task, const SolveOptions& opts, ThreadPool& pool, const Environment& probe, CdResult& r)
      : task_(task), opts_(opts), pool_(pool), probe_(probe), r_(r), exact_(probe.clone()) {}

  // Advances the model by `action` (none: the initial frame) and says whether
  // it can still produce the observed frame.
  bool explains(const std::optional<Action>& action, const TaskFrame& frame, int size) {
    if (action) history_.push_back({*action, frame, size});
    else first_ = {Action::noop(), frame, size};
    if (exact_) {
      bool ok = !action || exact_->step(*action);
      ++exact_steps_;
      if (ok && matches(*exact_, frame, size)) return true;
      exact_.reset();
      r_.exact_consistent = false;
      if (r_.deterministic) return false;
      return explain_afresh();
    }
    if (smc_ && smc_->step(*action, keep_for(frame, size))) return note(*smc_), true;
    return explain_afresh();
  }
  const Environment& predictor() const { return exact_ ? *exact_ : *smc_->samples().front().env; }
  uint64_t env_steps() const { return exact_steps_ + smc_steps_ + (smc_ ? smc_->env_steps() : 0); }

 private:
  struct Seen {
    Action action;
    TaskFrame frame;
    int size;
  };
  bool matches(const Environment& e, const TaskFrame& frame, int size) const {
    return e.frame().size == size && task_frame(e.frame(), e.palette(), task_.colours) == frame;
  }
  static FramePredicate keep_for(const TaskFrame& frame, int size) {
    return [&frame, size](const TaskFrame& f, int sz) { return sz == size && f == frame; };
  }
  void note(const SmcSet& s) {
    r_.smc_ess_min = r_.smc_ess_min < 0 ? s.ess_min() : std::min(r_.smc_ess_min, s.ess_min());
    r_.peak_particles = std::max(r_.peak_particles, s.peak());
  }
  // A new filter over the whole history; false (and no filter) when it dies.
  bool explain_afresh() {
    if (smc_) smc_steps_ += smc_->env_steps();
    ++r_.smc_restarts;
    smc_ = std::make_unique<SmcSet>(pool_, task_.colours, std::max<uint64_t>(opts_.rollouts, 1),
                                    opts_.seed + r_.smc_restarts);
    bool ok = smc_->start(probe_, keep_for(first_.frame, first_.size));
    for (size_t t = 0; ok && t < history_.size(); ++t)
      ok = smc_->step(history_[t].action, keep_for(history_[t].frame, history_[t].size));
    if (ok) return note(*smc_), true;
    smc_steps_ += smc_->env_steps();
    smc_.reset();
    return false;
  }

  const Task& task_;
  const SolveOptions& opts_;
  ThreadPool& pool_;
  const Environment& probe_;
  CdResult& r_;
  std::unique_ptr<Environment> exact_;  // the stated-seed episode, while it explains everything
  std::unique_ptr<SmcSet> smc_;         // afterwards: the filter, while it keeps samples
  Seen first_;
  std::vector<Seen> history_;           // every observation after the first, with its action
  uint64_t exact_steps_ = 0, smc_steps_ = 0;
};

// How the agent acts: "random" draws any action; "novelty" predicts each
// candidate (the moves, noop, and one click, or four where clicks aim at
// positions) on the current model and takes the one whose predicted frame was
// seen least, then the least-used kind of action, then one at random.
class Explorer {
 public:
  Explorer(const Task& task, const SolveOptions& opts, ThreadPool& pool, int grid, ClickUse clicks)
      : task_(task), opts_(opts), pool_(pool), grid_(grid), clicks_(clicks), rng_(opts.seed ^ 0x9e3779b97f4a7c15ull) {}
  void saw(const TaskFrame& f) { ++visits_[frame_digest(f)]; }
  void took(const Action& a) { ++kind_uses_[static_cast<int>(a.kind)]; }
  uint64_t prediction_steps() const { return prediction_steps_; }

  Action choose(const Model& model) {
    if (opts_.policy == "random") return random_action(rng_, grid_, 4);
    std::vector<Action> cands = {Action::noop(), {Action::Kind::Left}, {Action::Kind::Right}, {Action::Kind::Up},
                                 {Action::Kind::Down}};
    int n_clicks = clicks_ == ClickUse::Position ? 4 : 1;
    for (int i = 0; i < n_clicks; ++i)
      cands.push_back(Action::click(static_cast<int>(rng_() % grid_), static_cast<int>(rng_() % grid_)));
    const std::vector<uint64_t> score = predicted_visits(model.predictor(), cands);
    uint64_t best = *std::min_element(score.begin(), score.end());
    uint64_t fewest = UINT64_MAX;
    for (size_t i = 0; i < cands.size(); ++i)
      if (score[i] == best) fewest = std::min(fewest, kind_uses_[static_cast<int>(cands[i].kind)]);
    std::vector<size_t> ties;
    for (size_t i = 0; i < cands.size(); ++i)
      if (score[i] == best && kind_uses_[static_cast<int>(cands[i].kind)] == fewest) ties.push_back(i);
    return cands[ties[rng_() % ties.size()]];
  }

 private:
  // Per candidate, how often its predicted frame was seen (UINT64_MAX: the
  // prediction failed). Never touch one environment from two threads: the
  // clones are made on the caller first.
  std::vector<uint64_t> predicted_visits(const Environment& predictor, const std::vector<Action>& cands) {
    std::vector<std::unique_ptr<Environment>> clones;
    for (size_t i = 0; i < cands.size(); ++i) clones.push_back(predictor.clone());
    std::vector<uint64_t> score(cands.size(), UINT64_MAX);
    pool_.parallel_for(cands.size(), [&](size_t i) {
      Environment* e = clones[i].get();
      if (!e->step(cands[i])) return;
      auto it = visits_.find(frame_digest(task_frame(e->frame(), e->palette(), task_.colours)));
      score[i] = it == visits_.end() ? 0 : it->second;
    });
    prediction_steps_ += cands.size();
    return score;
  }

  const Task& task_;
  const SolveOptions& opts_;
  ThreadPool& pool_;
  const int grid_;
  const ClickUse clicks_;
  std::mt19937_64 rng_;
  std::unordered_map<uint64_t, uint64_t> visits_;  // frame digest -> times observed
  uint64_t kind_uses_[6] = {0, 0, 0, 0, 0, 0};     // actions taken, per kind
  uint64_t prediction_steps_ = 0;
};

// The score against the changed program's trigger condition: t* is the first
// state (after step k) where it holds; `cond` has the states 0..steps-1 and up
// to two noop steps on a clone add `steps` and `steps + 1`.
void score_against_trigger(const Environment& env, std::vector<char>& cond, CdResult& r) {
  int need = r.detected ? *r.detected + 1 : r.steps;
  auto cont = env.clone();
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

}  // namespace

CdResult solve_cd(const Task& task, const SolveOptions& opts, ThreadPool& pool) {
  if (task.type != TaskType::ChangeDetection) throw TaskError(task.file.string() + ": not a change-detection task");
  Stopwatch clock;
  CdResult r;
  r.policy = opts.policy;
  if (std::string why = unknown_name("policy", opts.policy, policy_names()); !why.empty()) throw TaskError(why);
  std::optional<std::string> trigger;
  r.world_seed = task.env_seed;
  if (opts.answers) {
    Answers answers = load_answers(*opts.answers);
    trigger = answers.condition;
    if (answers.seed) r.world_seed = *answers.seed;
  }
  if (trigger) r.trigger = *trigger;

  auto original = load_program_checked(task_program_path(task, opts, task.program));
  auto changed = load_program_checked(task_program_path(task, opts, task.wrong_program), trigger);
  ClickUse clicks = analyse_click_use(*original);
  auto env = make_env_checked(opts.engine, changed);
  if (!env->reset(r.world_seed)) throw TaskError(task.wrong_program + ": " + env->error());
  const int grid = env->frame().size;

  std::vector<char> cond;  // cond[k]: trigger condition on the state after step k
  TaskFrame observed = task_frame(env->frame(), env->palette(), task.colours);
  int observed_size = grid;

  auto probe = make_env_checked(opts.engine, original);
  if (!probe->reset(task.env_seed)) throw TaskError(task.program + ": " + probe->error());
  r.deterministic = probe->deterministic();
  r.particles = r.deterministic ? 1 : std::max<uint64_t>(opts.rollouts, 1);
  Model model(task, opts, pool, *probe, r);
  if (!model.explains(std::nullopt, observed, observed_size)) r.detected = 0;

  Explorer explorer(task, opts, pool, grid, clicks);
  explorer.saw(observed);

  for (int t = 1; t <= opts.max_steps && !r.detected; ++t) {
    Action a = explorer.choose(model);
    if (!env->step(a)) {
      r.env_error = env->error();
      break;
    }
    r.actions.push_back(a);
    explorer.took(a);
    r.steps = t;
    if (trigger) cond.push_back(env->triggered());
    observed = task_frame(env->frame(), env->palette(), task.colours);
    observed_size = env->frame().size;
    explorer.saw(observed);
    if (!model.explains(a, observed, observed_size)) r.detected = t;
  }

  if (trigger) score_against_trigger(*env, cond, r);
  r.env_steps = model.env_steps() + explorer.prediction_steps();
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
  j["world_seed"] = r.world_seed;
  j["exact_consistent"] = r.exact_consistent;
  j["smc_ess_min"] = r.smc_ess_min < 0 ? nlohmann::json(nullptr) : nlohmann::json(r.smc_ess_min);
  j["smc_restarts"] = r.smc_restarts;
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
  if (r.deterministic)
    s += "original program: deterministic, one exact episode\n";
  else
    s += fmt::format("original program: stochastic; stated-seed episode {}; {} Monte Carlo filter(s) of {} samples, "
                     "effective particles >= {:.1f}, peak {} distinct states\n",
                     r.exact_consistent ? "explained everything" : "contradicted", r.smc_restarts, r.particles,
                     std::max(0.0, r.smc_ess_min), r.peak_particles);
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
