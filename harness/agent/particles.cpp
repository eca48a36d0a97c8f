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

void ParticleSet::observe(Particle& p) const {
  const Palette& palette = p.env->palette();
  if (p.ids.size() != palette.size()) p.ids = colour_ids(palette, colours_);
  const std::vector<uint16_t>& cells = p.env->frame().cells;
  p.frame.resize(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) p.frame[i] = p.ids[cells[i]];
}

void ParticleSet::start(const std::function<std::unique_ptr<Environment>()>& make,
                        const std::vector<uint64_t>& seeds, bool deterministic, const FramePredicate& keep) {
  particles_.clear();
  if (seeds.empty()) return;
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
  pool_.parallel_for(n, [&](size_t i) {
    Particle& p = particles_[i];
    if (!p.env->step(action)) return;
    observe(p);
    if (!keep(p.frame, p.env->frame().size)) return;
    p.hash = p.env->state_hash();
    alive[i] = 1;
  });
  env_steps_ += n;
  size_t out = 0;
  for (size_t i = 0; i < n; ++i)
    if (alive[i]) {
      if (out != i) particles_[out] = std::move(particles_[i]);
      ++out;
    }
  particles_.resize(out);
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
        particles_[k].weight += particles_[i].weight;
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
