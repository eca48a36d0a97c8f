// seed_inversion — the seeds whose start-up draws are the ones a frame shows.
//
// A stochastic program's world runs one generator stream from its seed
// (runtime/rng.hpp: state' = (48271 * state mod 2^32) mod (2^31 - 1), a draw
// with bound b returns state' mod b). Fresh randomness per step (smc.hpp) is
// only an approximation of that: what a world drew at its start fixes its
// seed, and with it every later draw, hidden ones included (color_flood's
// masked tiles, fireworks' burst heights). Given the values the first frame
// pin down (draw_search.hpp: explain_episode_draws), this enumerates the whole
// seed space without running the program: every generator state after the
// first pinned draw that leaves that draw's value (v + j*b, so 1/b of them),
// walked forward through the other pinned draws, and the survivors walked back
// to the seeds that reach them (each step back has at most three preimages
// under the mod-2^32 product, as 48271 is odd and so invertible mod 2^32).
//
// Example: color_flood draws 56 tile colours (bound 5) at start-up; 36 of them
// visible pin 83 bits, so a 2^32 seed space leaves the true seed alone.
//
// Exactness: every seed returned reproduces the pinned values (checked by
// replaying the stream forward from it); whether it reproduces the frame is
// the caller's to check by running it. Deterministic for any thread count.
// Tests: AgentSeedInversion.* in tests/agent_test.cpp.
#pragma once
#include <cstdint>
#include <vector>

#include "harness/agent/draw_search.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

struct SeedInversion {
  std::vector<uint32_t> seeds;  // ascending
  bool complete = true;         // false: more than `cap` seeds matched (seeds holds the first cap)
  double pinned_bits = 0;       // sum of log2(bound) over the pinned draws
};

SeedInversion invert_start_draws(ThreadPool& pool, const DrawExplanation& e, size_t cap);

}  // namespace autumn::agent
