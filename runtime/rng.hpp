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
#pragma once
#include <cstdint>

namespace autumn {

class WrappedMinstd {
 public:
  WrappedMinstd() = default;
  explicit WrappedMinstd(uint64_t seed) { reseed(seed); }
  void reseed(uint64_t seed) { state_ = static_cast<uint32_t>(seed); }
  uint64_t next(uint64_t bound) {
    if (bound == 0) return 0;
    ++draws_;
    state_ = static_cast<uint32_t>(48271u * state_) % 2147483647u;
    return state_ % bound;
  }
  uint32_t state() const { return state_; }
  void set_state(uint32_t s) { state_ = s; }
  uint64_t draws() const { return draws_; }

 private:
  uint32_t state_ = 0;
  uint64_t draws_ = 0;
};

}  // namespace autumn
