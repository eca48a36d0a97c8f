#include "harness/agent/particles.hpp"

#include <random>
#include <unordered_map>

namespace autumn::agent {

std::vector<uint64_t> rollout_seeds(uint64_t seed, uint64_t count, uint64_t first) {
  std::vector<uint64_t> out;
  out.reserve(count);
  std::mt19937_64 rng(seed);
  for (uint64_t i = 0; i < count; ++i) out.push_back(i == 0 ? first : (rng() & 0xffffffffull));
  return out;
}

bool ParticleSet::advance(Particle& p, const Action& action, const FramePredicate& keep) const {
  if (!p.env->step(action)) return false;
  observe(p);
  if (!keep(p.frame, p.env->frame().size)) return false;
  p.hash = p.env->state_hash();
  return true;
}

void ParticleSet::start(const std::function<std::unique_ptr<Environment>()>& make,
                        const std::vector<uint64_t>& seeds, bool deterministic, const FramePredicate& keep) {
  particles_.clear();
  if (seeds.empty()) return;
  if (seed_groups_ && !deterministic && seeds.size() > 1) {
    // A seed group, when the first seed's start-up draws no random number.
    Particle p;
    p.env = make();
    ++env_steps_;
    if (p.env->reset(seeds[0]) && p.env->random_draws() == 0) {
      observe(p);
      if (keep(p.frame, p.env->frame().size)) {
        p.hash = p.env->state_hash();
        p.pending.assign(seeds.begin() + 1, seeds.end());
        p.weight = seeds.size();
        particles_.push_back(std::move(p));
      }
      peak_ = std::max(peak_, particles_.size());
      return;
    }
  }
  size_t n = deterministic ? 1 : seeds.size();
  std::vector<Particle> ps(n);
  std::vector<char> alive(n, 0);
  // Environments are built on the caller: make() may share non-thread-safe state.
  for (size_t i = 0; i < n; ++i) {
    ps[i].env = make();
    ps[i].weight = deterministic ? seeds.size() : 1;
  }
  pool_.parallel_for(n, [&](size_t i) {
    Particle& p = ps[i];
    if (!p.env->reset(seeds[i])) return;
    observe(p);
    if (!keep(p.frame, p.env->frame().size)) return;
    p.hash = p.env->state_hash();
    alive[i] = 1;
  });
  env_steps_ += n;
  for (size_t i = 0; i < n; ++i)
    if (alive[i]) particles_.push_back(std::move(ps[i]));
  merge();
  peak_ = std::max(peak_, particles_.size());
}

void ParticleSet::step(const Action& action, const FramePredicate& keep) {
  size_t n = particles_.size();
  std::vector<char> alive(n, 0);
  // Seed groups keep their pre-step state, to split from if the step draws.
  std::vector<std::unique_ptr<Environment>> before(n);
  std::vector<char> drew(n, 0);
  pool_.parallel_for(n, [&](size_t i) {
    Particle& p = particles_[i];
    int64_t draws = -1;
    if (!p.pending.empty()) {
      before[i] = p.env->clone();
      draws = p.env->random_draws();
    }
    alive[i] = advance(p, action, keep);
    if (!p.pending.empty()) drew[i] = draws < 0 || p.env->random_draws() != draws;
  });
  env_steps_ += n;
  // Split the groups whose step drew: each pending seed from the pre-step state,
  // reseeded (clones made here, one thread: clone() is not safe concurrently on
  // one environment), stepped in parallel, placed right after its group.
  std::vector<Particle> split;
  std::vector<size_t> split_from;  // group index of each split particle
  for (size_t i = 0; i < n; ++i) {
    if (!drew[i]) {
      if (!alive[i]) particles_[i].pending.clear();  // the whole group dies alike
      continue;
    }
    Particle& g = particles_[i];
    for (uint64_t seed : g.pending) {
      Particle q;
      q.env = before[i]->clone();
      if (!q.env->reseed_random(seed)) throw TaskError("reseeding a rollout failed: " + q.env->error());
      split.push_back(std::move(q));
      split_from.push_back(i);
    }
    g.weight -= g.pending.size();
    g.pending.clear();
  }
  before.clear();
  std::vector<char> split_alive(split.size(), 0);
  pool_.parallel_for(split.size(), [&](size_t k) { split_alive[k] = advance(split[k], action, keep); });
  env_steps_ += split.size();
  std::vector<Particle> next;
  next.reserve(n + split.size());
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    if (alive[i]) next.push_back(std::move(particles_[i]));
    for (; k < split.size() && split_from[k] == i; ++k)
      if (split_alive[k]) next.push_back(std::move(split[k]));
  }
  particles_ = std::move(next);
  merge();
  peak_ = std::max(peak_, particles_.size());
}

void ParticleSet::merge() {
  if (particles_.size() <= 1) return;
  head_.clear();
  chain_.clear();
  size_t out = 0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    auto [it, fresh] = head_.try_emplace(particles_[i].hash, SIZE_MAX);
    bool merged = false;
    for (size_t k = it->second; k != SIZE_MAX && !merged; k = chain_[k])
      if (particles_[k].frame == particles_[i].frame) {
        // Equal states: i's pending seeds are k's env reseeded just as well.
        particles_[k].weight += particles_[i].weight;
        particles_[k].pending.insert(particles_[k].pending.end(), particles_[i].pending.begin(),
                                     particles_[i].pending.end());
        merged = true;
      }
    if (merged) continue;
    if (out != i) particles_[out] = std::move(particles_[i]);
    chain_.push_back(it->second);
    it->second = out++;
  }
  particles_.resize(out);
}

}  // namespace autumn::agent
