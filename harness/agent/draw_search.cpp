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

// The draws one script forces, shared by a descent and an explanation.
// Invariant: values.size() <= kMaxDraws; drawn = the draws the last run made,
// bounds[0..drawn) their bounds.
struct DrawVector {
  explicit DrawVector(uint64_t seed) : rng(seed), bounds(kMaxDraws) { base_seed = rng(); }
  // The script for the next run: the current values, the count from zero.
  autumn_draw_script& arm() {
    script = autumn_draw_script{values.data(), values.size(), bounds.data(), bounds.size(), 0};
    return script;
  }
  void ran() { drawn = std::min<size_t>(script.drawn, kMaxDraws); }
  // Random values for draws the last run made beyond those already fixed.
  void extend() {
    while (values.size() < drawn) values.push_back(static_cast<int64_t>(rng() % bounds[values.size()]));
  }

  std::mt19937_64 rng;
  uint64_t base_seed = 0;  // the seed runs reset or reseed with (unforced draws)
  autumn_draw_script script{};
  std::vector<int64_t> values;
  std::vector<uint64_t> bounds;
  size_t drawn = 0;
};

// Cells of `frame` that disagree with the observation's unmasked cells; kFailed
// when the sizes differ.
int64_t disagreeing(const TaskFrame& frame, const Grid& obs) {
  if (frame.size() != obs.cells.size()) return kFailed;
  int64_t n = 0;
  for (size_t i = 0; i < frame.size(); ++i) n += obs.cells[i] != 0 && obs.cells[i] != frame[i];
  return n;
}

class Descent {
 public:
  // `trial` runs the start-up or step under the script it is given and returns
  // the environment after it, nullptr when the episode failed.
  Descent(Trial trial, const ColourTable& colours, const Grid& obs, uint64_t seed)
      : trial_(std::move(trial)), colours_(colours), first_(obs), d_(seed) {}

  // An agreeing start state, or nullptr.
  std::unique_ptr<Environment> run() {
    int64_t score = evaluate();
    if (score == kFailed) return nullptr;
    d_.extend();  // every draw the start-up made is forced from here on
    score = evaluate();
    for (int sweep = 0; sweep < kMaxSweeps && score > 0; ++sweep) {
      int64_t before = score;
      for (size_t k = 0; k < d_.values.size() && score > 0; ++k) score = improve({k}, score);
      if (score == before)
        for (size_t k = 0; k + 1 < d_.values.size() && score == before; ++k) score = improve({k, k + 1}, score);
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
    ++resets_;
    env_ = trial_(d_.arm(), d_.base_seed);
    if (!env_) return kFailed;
    d_.ran();
    frames_.map(env_->frame(), env_->palette(), colours_, frame_);
    return disagreeing(frame_, first_);
  }

  // Values to try for draw k (all of them up to kMaxValues, else a sample).
  std::vector<int64_t> candidates(size_t k, uint64_t cap) {
    const uint64_t bound = k < d_.drawn ? d_.bounds[k] : 1;
    std::vector<int64_t> out;
    if (bound <= cap) {
      for (uint64_t v = 0; v < bound; ++v) out.push_back(static_cast<int64_t>(v));
    } else {
      for (uint64_t i = 0; i < cap; ++i) out.push_back(static_cast<int64_t>(d_.rng() % bound));
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
    std::vector<int64_t>& values = d_.values;
    for (size_t i = 0; i < ks.size(); ++i) best[i] = current[i] = values[ks[i]];
    int64_t best_score = score;
    std::vector<size_t> at(ks.size(), 0);
    while (true) {
      for (size_t i = 0; i < ks.size(); ++i) values[ks[i]] = options[i][at[i]];
      bool same = true;
      for (size_t i = 0; i < ks.size(); ++i) same = same && values[ks[i]] == current[i];
      if (!same) {
        int64_t s = evaluate();
        if (s < best_score) {
          best_score = s;
          for (size_t i = 0; i < ks.size(); ++i) best[i] = values[ks[i]];
        }
      }
      size_t i = 0;  // next combination (odometer)
      while (i < ks.size() && ++at[i] == options[i].size()) at[i++] = 0;
      if (i == ks.size()) break;
    }
    for (size_t i = 0; i < ks.size(); ++i) values[ks[i]] = best[i];
    int64_t now = evaluate();  // the bounds of the kept values
    d_.extend();
    return now;
  }

  Trial trial_;
  const ColourTable& colours_;
  const Grid& first_;  // the observation
  DrawVector d_;
  std::unique_ptr<Environment> env_;  // after the last trial
  FrameColours frames_;
  TaskFrame frame_;
  uint64_t resets_ = 0;
};

// The episode-wide explanation: one script over reset() and every step.
class Explainer {
 public:
  Explainer(const Environment& model, const ColourTable& colours, const std::vector<Observation>& obs, uint64_t seed)
      : model_(model), colours_(colours), obs_(obs), d_(seed) {}

  std::optional<DrawExplanation> run() {
    for (size_t t = 0; t < obs_.size(); ++t) {
      int64_t score = evaluate(t);
      if (score == kFailed) return std::nullopt;
      const size_t from = d_.values.size();
      d_.extend();
      score = evaluate(t);
      // The step's own draws first; then every draw, as a hidden earlier draw
      // (a rocket's burst height) may be what this frame shows first.
      for (size_t lo : {from, size_t{0}})
        for (int sweep = 0; sweep < kMaxSweeps && score > 0 && runs_ <= kMaxRuns; ++sweep) {
          const int64_t before = score;
          for (size_t k = lo; k < d_.values.size() && score > 0; ++k) score = improve(k, t, score);
          if (score == before) break;
        }
      if (score != 0 || runs_ > kMaxRuns) return std::nullopt;
    }
    DrawExplanation e;
    const size_t last = obs_.size() - 1;
    if (evaluate(last) != 0) return std::nullopt;
    d_.values.resize(std::min(d_.values.size(), d_.drawn));
    e.values = d_.values;
    e.bounds.assign(d_.bounds.begin(), d_.bounds.begin() + static_cast<std::ptrdiff_t>(d_.values.size()));
    for (size_t k = 0; k < d_.values.size(); ++k) {
      bool pinned = e.bounds[k] <= kMaxValues;  // a larger bound is only sampled: never counted as pinned
      const int64_t keep = d_.values[k];
      for (int64_t a = 0; pinned && a < static_cast<int64_t>(e.bounds[k]); ++a) {
        if (a == keep) continue;
        d_.values[k] = a;
        if (evaluate(last) == 0) pinned = false;
      }
      d_.values[k] = keep;
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
    ++runs_;
    auto env = model_.clone();
    ++steps_;
    if (!env->set_draw_script(&d_.arm()) || !env->reset(d_.base_seed)) return kFailed;
    int64_t n = 0;
    for (size_t t = 0; t <= upto; ++t) {
      if (t > 0) {
        ++steps_;
        if (!obs_[t].action || !env->step(*obs_[t].action)) return kFailed;
      }
      frames_.map(env->frame(), env->palette(), colours_, frame_);
      const int64_t d = disagreeing(frame_, obs_[t].grid);
      if (d == kFailed) return kFailed;
      n += d;
    }
    d_.ran();
    return n;
  }

  int64_t improve(size_t k, size_t upto, int64_t score) {
    const uint64_t bound = d_.bounds[k];
    const int64_t keep = d_.values[k];
    int64_t best = score, best_v = keep;
    for (uint64_t i = 0; i < std::min(bound, kMaxValues); ++i) {
      const int64_t a = bound <= kMaxValues ? static_cast<int64_t>(i) : static_cast<int64_t>(d_.rng() % bound);
      if (a == keep) continue;
      d_.values[k] = a;
      const int64_t s = evaluate(upto);
      if (s < best) best = s, best_v = a;
    }
    d_.values[k] = best_v;
    const int64_t now = evaluate(upto);
    d_.extend();
    return now;
  }

  const Environment& model_;
  const ColourTable& colours_;
  const std::vector<Observation>& obs_;
  DrawVector d_;
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
