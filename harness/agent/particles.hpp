// particles — a weighted set of environment episodes advanced in lock-step.
//
// Each particle is one live episode (its own Environment) standing for `weight`
// rollouts. step() advances every particle by one action on the thread pool,
// drops those whose new frame a predicate rejects (or whose program failed), and
// then merges particles with equal state_hash() and equal frame into the first of
// them, adding the weights: equal states have identical futures, so a merged set
// gives exactly the tallies the unmerged one would. Nothing is ever replayed.
//
// Order is part of the contract: particles stay sorted by the index of the seed
// that created them, merging keeps the earliest, and predicates see frames in
// parallel but decisions are applied in index order — so results never depend on
// the number of threads.
#pragma once
#include <cstdint>
#include <absl/container/flat_hash_map.h>

#include <functional>
#include <memory>
#include <vector>

#include "harness/agent/task_file.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

struct Particle {
  std::unique_ptr<Environment> env;
  uint64_t weight = 1;
  uint64_t hash = 0;
  TaskFrame frame;             // colour-table ids of env->frame()
  std::vector<int16_t> ids;    // palette id -> colour-table id (the palette only grows)
};

using FramePredicate = std::function<bool(const TaskFrame& frame, int size)>;

class ParticleSet {
 public:
  ParticleSet(ThreadPool& pool, const ColourTable& colours) : pool_(pool), colours_(colours) {}

  // One particle per seed, each a fresh environment from `make` reset with that
  // seed and filtered by `keep`; when `deterministic`, only the first seed is run
  // and it stands for all of them.
  void start(const std::function<std::unique_ptr<Environment>()>& make, const std::vector<uint64_t>& seeds,
             bool deterministic, const FramePredicate& keep);
  void step(const Action& action, const FramePredicate& keep);

  std::vector<Particle>& particles() { return particles_; }
  const std::vector<Particle>& particles() const { return particles_; }
  bool empty() const { return particles_.empty(); }
  uint64_t env_steps() const { return env_steps_; }  // resets and steps actually run
  size_t peak() const { return peak_; }

 private:
  void observe(Particle& p) const;  // p.frame from p.env->frame(), without a per-step allocation
  void merge();

  ThreadPool& pool_;
  const ColourTable& colours_;
  std::vector<Particle> particles_;
  absl::flat_hash_map<uint64_t, size_t> head_;  // merge(): hash -> last kept particle with it
  std::vector<size_t> chain_;                   // merge(): kept particle -> previous one with its hash
  uint64_t env_steps_ = 0;
  size_t peak_ = 0;
};

// `count` interpreter seeds for rollouts: `first` (the environment's own seed,
// the benchmark's default 0 unless the task says otherwise), then 32-bit values
// from mt19937_64(seed) (the interpreter keeps 32 bits).
std::vector<uint64_t> rollout_seeds(uint64_t seed, uint64_t count, uint64_t first);

}  // namespace autumn::agent
