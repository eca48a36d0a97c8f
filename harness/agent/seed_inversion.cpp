// seed_inversion — see seed_inversion.hpp: the forward enumeration of one
// pinned draw's states, the walk forward through the others, the walk back.
#include "harness/agent/seed_inversion.hpp"

#include <algorithm>
#include <cmath>

#include "runtime/rng.hpp"

namespace autumn::agent {

namespace {

constexpr uint64_t kModulus = WrappedMinstd::kModulus;  // 2^31 - 1
constexpr uint64_t kMultiplier = WrappedMinstd::kMultiplier;
constexpr uint64_t kChunks = 256;

uint32_t advance(uint32_t s) { return WrappedMinstd::advance(s); }

// 48271^-1 mod 2^32 (Newton's iteration: each step doubles the correct bits).
uint32_t inverse_multiplier() {
  uint32_t x = static_cast<uint32_t>(kMultiplier);
  for (int i = 0; i < 5; ++i) x *= 2u - static_cast<uint32_t>(kMultiplier) * x;
  return x;
}

// States p with advance(p) == s; `any_state` false restricts them to states a
// draw can leave (below 2^31 - 1).
void preimages(uint32_t s, bool any_state, std::vector<uint32_t>& out) {
  static const uint32_t inv = inverse_multiplier();
  for (uint64_t y = s; y < (uint64_t{1} << 32); y += kModulus) {
    uint32_t p = static_cast<uint32_t>(y) * inv;
    if (any_state || p < kModulus) out.push_back(p);
  }
}

// The stream from `seed` gives the pinned values.
bool agrees(uint32_t seed, const DrawExplanation& e) {
  uint32_t s = seed;
  for (size_t k = 0; k < e.values.size(); ++k) {
    s = advance(s);
    if (e.pinned[k] && static_cast<int64_t>(s % e.bounds[k]) != e.values[k]) return false;
  }
  return true;
}

}  // namespace

SeedInversion invert_start_draws(ThreadPool& pool, const DrawExplanation& e, size_t cap) {
  SeedInversion out;
  size_t first = e.values.size();
  for (size_t k = 0; k < e.values.size(); ++k) {
    if (!e.pinned[k]) continue;
    out.pinned_bits += std::log2(static_cast<double>(e.bounds[k]));
    first = std::min(first, k);
  }
  if (first == e.values.size()) {
    out.complete = false;  // nothing pinned: every seed agrees
    return out;
  }
  const uint64_t b = e.bounds[first], v = static_cast<uint64_t>(e.values[first]);
  const uint64_t count = v < kModulus ? (kModulus - 1 - v) / b + 1 : 0;  // states v + j*b below 2^31 - 1
  std::vector<std::vector<uint32_t>> found(kChunks);
  pool.parallel_for(kChunks, [&](size_t c) {
    const uint64_t begin = count * c / kChunks, end = count * (c + 1) / kChunks;
    std::vector<uint32_t> back, next;
    for (uint64_t j = begin; j < end; ++j) {
      const uint32_t at = static_cast<uint32_t>(v + j * b);  // the state the first pinned draw left
      uint32_t s = at;
      bool ok = true;
      for (size_t k = first + 1; ok && k < e.values.size(); ++k) {
        s = advance(s);
        ok = !e.pinned[k] || static_cast<int64_t>(s % e.bounds[k]) == e.values[k];
      }
      if (!ok) continue;
      // Back from the state after draw `first` to the seeds: first + 1 steps.
      back.assign(1, at);
      for (size_t step = 0; step <= first; ++step) {
        next.clear();
        const bool to_seed = step == first;
        for (uint32_t x : back) preimages(x, to_seed, next);
        back.swap(next);
      }
      for (uint32_t seed : back)
        if (agrees(seed, e)) found[c].push_back(seed);
      if (found[c].size() > cap) return;
    }
  });
  for (auto& f : found) out.seeds.insert(out.seeds.end(), f.begin(), f.end());
  std::sort(out.seeds.begin(), out.seeds.end());
  out.seeds.erase(std::unique(out.seeds.begin(), out.seeds.end()), out.seeds.end());
  if (out.seeds.size() > cap) {
    out.seeds.resize(cap);
    out.complete = false;
  }
  return out;
}

}  // namespace autumn::agent
