// particles — a weighted set of environment episodes advanced in lock-step.
//
// Each particle is one live episode (its own Environment) standing for `weight`
// rollouts. step() advances every particle by one action on the thread pool,
// drops those whose new frame a predicate rejects (or whose program failed), and
// then merges particles with equal state_hash() and equal frame into the first of
// them, adding the weights: equal states have identical futures, so a merged set
// gives exactly the tallies the unmerged one would. Nothing is ever replayed.
//
// Seed groups: a seed lives only in the random generator's state, so episodes
// that have drawn no random number yet differ in nothing else. When the first
// seed's reset draws nothing, one particle stands for all seeds: its env runs
// the first seed and `pending` lists the others (each is "this env, reseeded").
// A step that draws nothing keeps the group; one that draws splits it: every
// pending seed is run from a copy of the pre-step state, reseeded. Stochastic
// programs that draw rarely (food that appears when eaten) then cost one
// rollout until the first draw instead of N.
//
// Order is part of the contract: the particle order, which one a merge keeps
// (the earliest), and where a split group's seeds go (right after it, in
// pending order) are fixed by the seeds alone; predicates see frames in parallel
// but decisions are applied in index order — so results never depend on the
// number of threads.
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
  uint64_t weight = 1;         // rollouts it stands for, pending seeds included
  std::vector<uint64_t> pending;  // seed group: seeds that are env reseeded (see above)
  uint64_t hash = 0;
  TaskFrame frame;             // colour-table ids of env->frame()
  FrameColours colour_map;     // maps env's frames into `frame`
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
  // Seed groups are on by default; off, every seed is its own particle from the
  // start (the reference the tests compare groups with).
  void set_seed_groups(bool on) { seed_groups_ = on; }
  size_t peak() const { return peak_; }

 private:
  // p.frame from p.env->frame(), without a per-step allocation.
  void observe(Particle& p) const { p.colour_map.map(p.env->frame(), p.env->palette(), colours_, p.frame); }
  // Steps p and judges it: true when it lives (hash and frame set).
  bool advance(Particle& p, const Action& action, const FramePredicate& keep) const;
  void merge();

  ThreadPool& pool_;
  const ColourTable& colours_;
  std::vector<Particle> particles_;
  absl::flat_hash_map<uint64_t, size_t> head_;  // merge(): hash -> last kept particle with it
  std::vector<size_t> chain_;                   // merge(): kept particle -> previous one with its hash
  uint64_t env_steps_ = 0;
  bool seed_groups_ = true;
  size_t peak_ = 0;
};

// `count` interpreter seeds for rollouts: `first` (the environment's own seed,
// the benchmark's default 0 unless the task says otherwise), then 32-bit values
// from mt19937_64(seed) (the interpreter keeps 32 bits).
std::vector<uint64_t> rollout_seeds(uint64_t seed, uint64_t count, uint64_t first);

}  // namespace autumn::agent
