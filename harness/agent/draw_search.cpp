// draw_search — see draw_search.hpp for the algorithm; this file is one
// descent (a draw vector, its score, single and paired moves) and the loop over
// starts.
#include "harness/agent/draw_search.hpp"

#include <algorithm>
#include <limits>
#include <functional>
#include <random>

namespace autumn::agent {

namespace {

constexpr int kMaxSweeps = 12;
constexpr uint64_t kMaxValues = 64;    // values tried for one draw (a sample above this)
constexpr uint64_t kMaxPair = 1024;    // value pairs tried for two adjacent draws
constexpr size_t kMaxDraws = 1 << 14;  // draws a script follows and records
constexpr int64_t kFailed = std::numeric_limits<int64_t>::max();

using Trial = std::function<std::unique_ptr<Environment>(autumn_draw_script& script, uint64_t seed)>;

class Descent {
 public:
  // `trial` runs the start-up or step under the script it is given and returns
  // the environment after it, nullptr when the episode failed.
  Descent(Trial trial, const ColourTable& colours, const Grid& obs, uint64_t seed)
      : trial_(std::move(trial)), colours_(colours), first_(obs), rng_(seed), bounds_(kMaxDraws) {
    base_seed_ = rng_();
  }

  // An agreeing start state, or nullptr.
  std::unique_ptr<Environment> run() {
    int64_t score = evaluate();
    if (score == kFailed) return nullptr;
    extend();  // every draw the start-up made is forced from here on
    score = evaluate();
    for (int sweep = 0; sweep < kMaxSweeps && score > 0; ++sweep) {
      int64_t before = score;
      for (size_t k = 0; k < values_.size() && score > 0; ++k) score = improve({k}, score);
      if (score == before)
        for (size_t k = 0; k + 1 < values_.size() && score == before; ++k) score = improve({k, k + 1}, score);
      if (score == before) break;
    }
    if (score != 0) return nullptr;
    env_->set_draw_script(nullptr);
    return std::move(env_);
  }

  uint64_t resets() const { return resets_; }

 private:
  // Mismatching cells of reset() under the current values (kFailed when the
  // start-up fails or the grid differs); refreshes the recorded bounds.
  int64_t evaluate() {
    script_.forced = values_.data();
    script_.forced_count = values_.size();
    script_.bounds = bounds_.data();
    script_.capacity = bounds_.size();
    script_.drawn = 0;
    ++resets_;
    env_ = trial_(script_, base_seed_);
    if (!env_) return kFailed;
    drawn_ = std::min<size_t>(script_.drawn, kMaxDraws);
    frames_.map(env_->frame(), env_->palette(), colours_, frame_);
    if (frame_.size() != first_.cells.size()) return kFailed;
    int64_t n = 0;
    for (size_t i = 0; i < frame_.size(); ++i) n += first_.cells[i] != 0 && first_.cells[i] != frame_[i];
    return n;
  }

  // Values for draws the last start-up made beyond those already fixed.
  void extend() {
    while (values_.size() < drawn_) values_.push_back(static_cast<int64_t>(rng_() % bounds_[values_.size()]));
  }

  // Values to try for draw k (all of them up to kMaxValues, else a sample).
  std::vector<int64_t> candidates(size_t k, uint64_t cap) {
    const uint64_t bound = k < drawn_ ? bounds_[k] : 1;
    std::vector<int64_t> out;
    if (bound <= cap) {
      for (uint64_t v = 0; v < bound; ++v) out.push_back(static_cast<int64_t>(v));
    } else {
      for (uint64_t i = 0; i < cap; ++i) out.push_back(static_cast<int64_t>(rng_() % bound));
    }
    return out;
  }

  // Tries every combination of values for the draws in `ks` (one or two
  // adjacent draws) and keeps the best; returns the new score.
  int64_t improve(std::vector<size_t> ks, int64_t score) {
    std::vector<std::vector<int64_t>> options;
    for (size_t k : ks) options.push_back(candidates(k, ks.size() == 1 ? kMaxValues : 32));
    if (ks.size() == 2 && options[0].size() * options[1].size() > kMaxPair) return score;
    std::vector<int64_t> best(ks.size()), current(ks.size());
    for (size_t i = 0; i < ks.size(); ++i) best[i] = current[i] = values_[ks[i]];
    int64_t best_score = score;
    std::vector<size_t> at(ks.size(), 0);
    while (true) {
      for (size_t i = 0; i < ks.size(); ++i) values_[ks[i]] = options[i][at[i]];
      bool same = true;
      for (size_t i = 0; i < ks.size(); ++i) same = same && values_[ks[i]] == current[i];
      if (!same) {
        int64_t s = evaluate();
        if (s < best_score) {
          best_score = s;
          for (size_t i = 0; i < ks.size(); ++i) best[i] = values_[ks[i]];
        }
      }
      size_t i = 0;  // next combination (odometer)
      while (i < ks.size() && ++at[i] == options[i].size()) at[i++] = 0;
      if (i == ks.size()) break;
    }
    for (size_t i = 0; i < ks.size(); ++i) values_[ks[i]] = best[i];
    int64_t now = evaluate();  // the bounds of the kept values
    extend();
    return now;
  }

  const ColourTable& colours_;
  const Grid& first_;  // the observation
  std::mt19937_64 rng_;
  uint64_t base_seed_ = 0;
  // The script the environment follows; values_ and bounds_ are its arrays.
  // Invariant: values_.size() <= kMaxDraws; drawn_ = draws of the last start-up.
  autumn_draw_script script_{};
  std::vector<int64_t> values_;
  std::vector<uint64_t> bounds_;
  size_t drawn_ = 0;
  Trial trial_;
  std::unique_ptr<Environment> env_;  // after the last trial
  FrameColours frames_;
  TaskFrame frame_;
  uint64_t resets_ = 0;
};

// The episode-wide explanation: one script over reset() and every step.
class Explainer {
 public:
  Explainer(const Environment& model, const ColourTable& colours, const std::vector<Observation>& obs, uint64_t seed)
      : model_(model), colours_(colours), obs_(obs), rng_(seed), bounds_(kMaxDraws) {
    base_seed_ = rng_();
  }

  std::optional<DrawExplanation> run() {
    std::vector<size_t> drawn_by(obs_.size());  // draws made up to and including observation t
    for (size_t t = 0; t < obs_.size(); ++t) {
      int64_t score = evaluate(t);
      if (score == kFailed) return std::nullopt;
      const size_t from = values_.size();
      extend();
      score = evaluate(t);
      // The step's own draws first; then every draw, as a hidden earlier draw
      // (a rocket's burst height) may be what this frame shows first.
      for (size_t lo : {from, size_t{0}})
        for (int sweep = 0; sweep < kMaxSweeps && score > 0 && runs_ <= kMaxRuns; ++sweep) {
          const int64_t before = score;
          for (size_t k = lo; k < values_.size() && score > 0; ++k) score = improve(k, t, score);
          if (score == before) break;
        }
      if (score != 0 || runs_ > kMaxRuns) return std::nullopt;
      drawn_by[t] = values_.size();
    }
    DrawExplanation e;
    const size_t last = obs_.size() - 1;
    if (evaluate(last) != 0) return std::nullopt;
    values_.resize(std::min(values_.size(), drawn_));
    e.values = values_;
    e.bounds.assign(bounds_.begin(), bounds_.begin() + static_cast<std::ptrdiff_t>(values_.size()));
    for (size_t k = 0; k < values_.size(); ++k) {
      bool pinned = e.bounds[k] <= kMaxValues;  // a larger bound is only sampled: never counted as pinned
      const int64_t keep = values_[k];
      for (int64_t a = 0; pinned && a < static_cast<int64_t>(e.bounds[k]); ++a) {
        if (a == keep) continue;
        values_[k] = a;
        if (evaluate(last) == 0) pinned = false;
      }
      values_[k] = keep;
      e.pinned.push_back(pinned);
      if (runs_ > kMaxRuns) return std::nullopt;
    }
    e.env_steps = steps_;
    return e;
  }

 private:
  static constexpr uint64_t kMaxRuns = 20000;  // episode replays one explanation may take

  // Disagreeing cells over observations 0..upto under the current values.
  int64_t evaluate(size_t upto) {
    script_ = autumn_draw_script{values_.data(), values_.size(), bounds_.data(), bounds_.size(), 0};
    ++runs_;
    auto env = model_.clone();
    ++steps_;
    if (!env->set_draw_script(&script_) || !env->reset(base_seed_)) return kFailed;
    int64_t n = 0;
    for (size_t t = 0; t <= upto; ++t) {
      if (t > 0) {
        ++steps_;
        if (!obs_[t].action || !env->step(*obs_[t].action)) return kFailed;
      }
      frames_.map(env->frame(), env->palette(), colours_, frame_);
      const Grid& g = obs_[t].grid;
      if (frame_.size() != g.cells.size()) return kFailed;
      for (size_t i = 0; i < frame_.size(); ++i) n += g.cells[i] != 0 && g.cells[i] != frame_[i];
    }
    drawn_ = std::min<size_t>(script_.drawn, kMaxDraws);
    return n;
  }

  void extend() {
    while (values_.size() < drawn_) values_.push_back(static_cast<int64_t>(rng_() % bounds_[values_.size()]));
  }

  int64_t improve(size_t k, size_t upto, int64_t score) {
    const uint64_t bound = bounds_[k];
    const int64_t keep = values_[k];
    int64_t best = score, best_v = keep;
    for (uint64_t i = 0; i < std::min(bound, kMaxValues); ++i) {
      const int64_t a = bound <= kMaxValues ? static_cast<int64_t>(i) : static_cast<int64_t>(rng_() % bound);
      if (a == keep) continue;
      values_[k] = a;
      const int64_t s = evaluate(upto);
      if (s < best) best = s, best_v = a;
    }
    values_[k] = best_v;
    const int64_t now = evaluate(upto);
    extend();
    return now;
  }

  const Environment& model_;
  const ColourTable& colours_;
  const std::vector<Observation>& obs_;
  std::mt19937_64 rng_;
  uint64_t base_seed_ = 0;
  // The script and its arrays. Invariant: values_.size() <= kMaxDraws; drawn_ =
  // the draws of the last replay.
  autumn_draw_script script_{};
  std::vector<int64_t> values_;
  std::vector<uint64_t> bounds_;
  size_t drawn_ = 0;
  FrameColours frames_;
  TaskFrame frame_;
  uint64_t runs_ = 0, steps_ = 0;
};

// Runs one descent per trial in parallel (trial i with the i-th seed drawn from
// `seed`) and keeps the distinct agreeing states in trial order.
std::vector<std::unique_ptr<Environment>> descend(ThreadPool& pool, const std::vector<Trial>& trials,
                                                  const ColourTable& colours, const Grid& obs, uint64_t seed,
                                                  DrawSearchStats& stats) {
  std::mt19937_64 seeds(seed ^ 0xd4a3c0de5eedull);
  std::vector<uint64_t> trial_seeds(trials.size());
  for (uint64_t& s : trial_seeds) s = seeds();
  std::vector<std::unique_ptr<Environment>> found(trials.size());
  std::vector<uint64_t> resets(trials.size(), 0);
  pool.parallel_for(trials.size(), [&](size_t i) {
    Descent d(trials[i], colours, obs, trial_seeds[i]);
    found[i] = d.run();
    resets[i] = d.resets();
  });
  std::vector<std::unique_ptr<Environment>> out;
  std::vector<uint64_t> hashes;
  for (size_t i = 0; i < found.size(); ++i) {
    stats.resets += resets[i];
    ++stats.starts;
    if (!found[i]) continue;
    ++stats.found;
    uint64_t h = found[i]->state_hash();
    if (std::find(hashes.begin(), hashes.end(), h) != hashes.end()) continue;
    hashes.push_back(h);
    out.push_back(std::move(found[i]));
  }
  return out;
}

}  // namespace

std::vector<std::unique_ptr<Environment>> search_start_draws(ThreadPool& pool, const Environment& model,
                                                             const ColourTable& colours, const Grid& first,
                                                             uint64_t seed, int starts, DrawSearchStats& stats) {
  Trial reset = [&model](autumn_draw_script& script, uint64_t s) -> std::unique_ptr<Environment> {
    auto e = model.clone();
    if (!e->set_draw_script(&script) || !e->reset(s)) return nullptr;
    return e;
  };
  return descend(pool, std::vector<Trial>(static_cast<size_t>(std::max(starts, 0)), reset), colours, first, seed,
                 stats);
}

std::optional<DrawExplanation> explain_episode_draws(const Environment& model, const ColourTable& colours,
                                                     const std::vector<Observation>& observations, uint64_t seed) {
  if (observations.empty()) return std::nullopt;
  return Explainer(model, colours, observations, seed).run();
}

std::vector<std::unique_ptr<Environment>> search_step_draws(ThreadPool& pool,
                                                            const std::vector<const Environment*>& parents,
                                                            const Action& action, const ColourTable& colours,
                                                            const Grid& obs, uint64_t seed, DrawSearchStats& stats) {
  std::vector<Trial> trials;
  for (const Environment* parent : parents)
    trials.push_back([parent, action](autumn_draw_script& script, uint64_t s) -> std::unique_ptr<Environment> {
      auto e = parent->clone();
      if (!e->reseed_random(s) || !e->set_draw_script(&script) || !e->step(action)) return nullptr;
      return e;
    });
  return descend(pool, trials, colours, obs, seed, stats);
}

}  // namespace autumn::agent
