// smc — sequential Monte Carlo over a stochastic program's unknown randomness.
//
// A blind task does not say which seed its environment ran with, and for a long
// stochastic trajectory almost no seed drawn at random reproduces every observed
// frame: rejection over whole episodes dies. SmcSet filters instead, observation
// by observation. It holds a population of N samples, stored as distinct states
// with counts (equal state_hash() and frame merged: equal states have equal
// futures). Each step advances every sample by the action with FRESH randomness
// (a clone of its state, reseed_random() with a seed drawn from the filter's own
// generator, then step()), keeps the children whose frame the predicate accepts,
// merges them, and resamples the survivors back to N (systematic resampling).
// A step under which no child survives is retried with 8, then 64 children per
// sample (an unlikely observation is not an impossible one; a caller may allow
// fewer with max_growth, 1 for none); only then does it
// report that nothing explains the observation, leaving the population as it was.
//
// A sample's step that draws no random number (random_draws() unchanged) would
// give the same child under every seed, so one child stands for all of that
// sample's children: programs that draw rarely cost one step per distinct state.
//
// Figures: accepted(t) is the fraction of proposed children that survived step t;
// log_likelihood() sums log accepted(t), the standard SMC estimate of the
// probability of the observations under an unknown seed; ess(t) = accepted(t)*N
// is the effective number of particles the step kept, ess_min() its minimum.
//
// Determinism: seeds are drawn from the generator in sample order before any
// work runs, children are judged in parallel but merged in index order, so the
// result depends only on the seed, never on the number of threads. Children are
// made in chunks, so memory holds the population plus one chunk.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "harness/agent/draw_search.hpp"
#include "harness/agent/particles.hpp"
#include "harness/agent/task_file.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

struct SmcSample {
  std::unique_ptr<Environment> env;
  uint64_t count = 0;  // samples of the population this state stands for
  uint64_t hash = 0;
  TaskFrame frame;
};

class SmcSet {
 public:
  SmcSet(ThreadPool& pool, const ColourTable& colours, uint64_t n, uint64_t seed, uint64_t max_growth = 64);

  // N fresh episodes: clones of `model` reset with fresh seeds, filtered by `keep`.
  // When no seed's start-up is kept and the first observation is given, the
  // start states come from a search over the draws themselves (draw_search.hpp):
  // the population is split evenly over the distinct states it finds, and the
  // first observation's likelihood is taken as 1 / (2 x the start-ups proposed),
  // a bound, since none of them agreed.
  bool start(const Environment& model, const FramePredicate& keep, const Grid* first = nullptr);
  // Advances every sample by `action`; false when no child explains the frame.
  // With the observation given, a step no child explains falls back on the draw
  // search from the heaviest samples, as start() does.
  bool step(const Action& action, const FramePredicate& keep, const Grid* obs = nullptr);

  // An independent copy (every sample's environment cloned, the same generator
  // state): filters that share a prefix of observations run it once.
  std::unique_ptr<SmcSet> fork() const;

  const std::vector<SmcSample>& samples() const { return samples_; }
  uint64_t size() const { return n_; }
  double log_likelihood() const { return log_likelihood_; }
  double ess_min() const { return ess_min_; }
  uint64_t env_steps() const { return env_steps_; }
  uint64_t retries() const { return retries_; }  // steps that needed 8 or 64 children per sample
  size_t peak() const { return peak_; }
  const DrawSearchStats& draw_search() const { return draw_search_; }  // starts 0: not used

 private:
  // One child operation: reset(seed) for start, reseed_random(seed) + step otherwise.
  using Op = std::function<bool(Environment&, uint64_t seed)>;
  struct Parent {
    const Environment* env;
    uint64_t children;
  };
  bool propagate(const std::vector<Parent>& parents, const Op& op, const FramePredicate& keep, uint64_t mult,
                 bool from_reset);
  void adopt(std::unique_ptr<Environment> env, TaskFrame frame, uint64_t count);
  std::unique_ptr<Environment> copy_of(const Environment& parent);
  void give_spare(std::unique_ptr<Environment> env);
  bool adopt_found(std::vector<std::unique_ptr<Environment>> states, const FramePredicate& keep, uint64_t proposed);
  void resample();

  ThreadPool& pool_;
  const ColourTable& colours_;
  const uint64_t n_;
  const uint64_t max_growth_;  // most children per sample a step may try (1, 8 or 64)
  std::mt19937_64 rng_;
  // The population. Invariant between calls: distinct (hash, frame), counts sum to n_.
  std::vector<SmcSample> samples_;
  // Survivors of the step being built (merged as they arrive), and their index.
  std::vector<SmcSample> next_;
  absl::flat_hash_map<uint64_t, std::vector<size_t>> index_;
  double log_likelihood_ = 0, ess_min_ = -1;
  uint64_t env_steps_ = 0, retries_ = 0;
  size_t peak_ = 0;
  uint64_t proposed_ = 0;  // children proposed by the last propagate()
  // Environments of dead children and of replaced samples, reused (copy_from)
  // for the next children instead of cloning: a clone's allocations were
  // 40% of a stochastic MFP query. Their contents are never read. Taken and
  // given back on the calling thread only.
  std::vector<std::unique_ptr<Environment>> spare_;
  bool reuse_ = true;  // false once an environment refused copy_from: the engine has none (the interpreter)
  DrawSearchStats draw_search_;
};

}  // namespace autumn::agent
