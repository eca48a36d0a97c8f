// rng — the reference interpreter's random generator, bit for bit.
//
// A minstd-style generator whose product 48271*state is computed in 32-bit
// unsigned arithmetic and so wraps *before* the modulo by 2^31-1: this is not the
// textbook minstd sequence, and seed 0 stays 0 forever (every draw returns 0).
// The only consumers are uniformChoice and randomPositions; next(0) returns 0
// without advancing. draws() counts the real draws (bound > 0): it is not part of
// the state (not hashed, not in snapshots) and only its change across a step
// means anything — the particle filter uses it to tell whether a step read the
// generator at all.
//
// A draw script (module_abi.h: autumn_draw_script) lets a caller choose what
// draws return — the agent's search for random numbers that reproduce an
// observed frame. It belongs to the generator it was set on: a copy of the
// generator (a clone of the environment) starts without one, and assigning a
// generator's state to another (reset, copy_from) keeps the target's script.
// The generator advances as usual under a script, so unforced draws are the
// seed's.
#pragma once
#include <cstdint>

#include "runtime/module_abi.h"

namespace autumn {

class WrappedMinstd {
 public:
  WrappedMinstd() = default;
  explicit WrappedMinstd(uint64_t seed) { reseed(seed); }
  WrappedMinstd(const WrappedMinstd& o) : state_(o.state_), draws_(o.draws_) {}
  WrappedMinstd& operator=(const WrappedMinstd& o) {
    state_ = o.state_;
    draws_ = o.draws_;
    return *this;
  }
  void reseed(uint64_t seed) { state_ = static_cast<uint32_t>(seed); }
  // The generator's one rule: the state after a draw from state `s` (the
  // product wraps in 32 bits before the modulo). seed_inversion walks it too.
  static constexpr uint32_t kMultiplier = 48271u, kModulus = 2147483647u;
  static uint32_t advance(uint32_t s) { return static_cast<uint32_t>(kMultiplier * s) % kModulus; }
  uint64_t next(uint64_t bound) {
    if (bound == 0) return 0;
    ++draws_;
    state_ = advance(state_);
    if (script_) [[unlikely]]
      return scripted(state_ % bound, bound);
    return state_ % bound;
  }
  void set_script(autumn_draw_script* script) { script_ = script; }
  uint32_t state() const { return state_; }
  void set_state(uint32_t s) { state_ = s; }
  uint64_t draws() const { return draws_; }

 private:
  uint64_t scripted(uint64_t drawn, uint64_t bound) {
    const uint64_t k = script_->drawn++;
    if (k < script_->capacity) script_->bounds[k] = bound;
    if (k < script_->forced_count && script_->forced[k] >= 0) return static_cast<uint64_t>(script_->forced[k]) % bound;
    return drawn;
  }

  uint32_t state_ = 0;
  uint64_t draws_ = 0;
  autumn_draw_script* script_ = nullptr;  // not copied (see above)
};

}  // namespace autumn
