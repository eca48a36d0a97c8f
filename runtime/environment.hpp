// environment — the interface every Autumn environment implements, interpreted or
// compiled, and that every harness drives.
//
// Host protocol (the benchmark's): reset(seed) starts the program and renders;
// step(action) sets at most one input, runs one time step and renders again. The
// render after every step is part of the semantics: it refreshes the occupancy
// table read by isFreePos.
//
// clone() is an independent copy whose future is identical to the original's
// (same frames for the same actions), copy_from() the same into an existing one; state_hash() digests the whole hidden state
// (RNG included, identity numbers up to renaming) so that equal hashes mean equal
// futures, for deduplication. deterministic() is true when the program can never
// draw a random number, so states that differ only in RNG state are equivalent.
//
// A runtime error inside the program ends the episode: failed() becomes true,
// error() names the construct and its source location, and further steps are
// refused (they return false). Errors never escape as exceptions. Every episode
// runs under the limits of runtime/limits.hpp (set_limits; defaults otherwise).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/action.hpp"
#include "runtime/diagnostic.hpp"
#include "runtime/frame.hpp"
#include "runtime/limits.hpp"
#include "runtime/module_abi.h"

namespace autumn {

class Environment {
 public:
  virtual ~Environment() = default;
  // Starts a fresh episode. Returns false (and sets error()) if start-up failed.
  virtual bool reset(uint64_t seed) = 0;
  // One host step: input, step(), render. Returns false once the episode failed.
  virtual bool step(const Action& action) = 0;
  // A step *without* the host render, for benchmarks only: frame() goes stale and
  // the next step's isFreePos sees the old occupancy, so a run of advance() calls
  // is not the benchmark protocol.
  virtual bool advance(const Action& action) = 0;
  // The frame of the last host render.
  virtual const Frame& frame() const = 0;
  // frame().size and frame().cells[i] (i below size * size), which an engine may
  // answer without making the whole frame: a goal test that stops at its first
  // differing cell reads a few cells of each of millions of frames.
  virtual int frame_side() const { return frame().size; }
  virtual uint16_t frame_cell(size_t i) const { return frame().cells[i]; }
  // A palette naming every id frame_cell has returned: palette(), unless the
  // engine has one without making the frame.
  virtual const Palette& cell_palette() const { return palette(); }
  virtual const Palette& palette() const = 0;
  // SpecialConditionTriggered after the last step (false after reset).
  virtual bool triggered() const = 0;
  virtual int on_clause_count() const = 0;
  virtual int covered_on_clause_count() const = 0;
  virtual bool failed() const = 0;
  virtual const std::string& error() const = 0;
  virtual std::unique_ptr<Environment> clone() const = 0;
  // Makes this environment an exact copy of `other` (as clone() would), reusing
  // this one's buffers: the search's per-successor copy without an allocation.
  // Returns false, changing nothing, when `other` is not of the same kind (another
  // engine or program); callers then fall back to clone().
  virtual bool copy_from(const Environment& other) {
    (void)other;
    return false;
  }
  // Snapshots: save_state() appends a compact encoding of the state to `out`;
  // load_state() makes this environment continue exactly as the saved one would
  // (frame included). A snapshot is only for an environment of the same program
  // and engine. Environments that cannot encode their state return false from
  // save_state(); load_state() returns false for a corrupt snapshot too, with
  // error() saying why. Search keeps its open states this way: bytes, not objects.
  virtual bool save_state(std::vector<uint8_t>& out) const {
    (void)out;
    return false;
  }
  virtual bool load_state(const uint8_t* data, size_t size) {
    (void)data;
    (void)size;
    return false;
  }
  // The reference's render_all() JSON of the last host render (runtime/frame.hpp,
  // render_all_json), for environments that can record it: record_render(true)
  // keeps the elements of every later host render (false: not supported), and
  // render_json() gives the last recorded one (false when there is none).
  virtual bool record_render(bool on) {
    (void)on;
    return false;
  }
  virtual bool render_json(std::string* out) const {
    (void)out;
    return false;
  }
  virtual uint64_t state_hash() const = 0;
  virtual bool deterministic() const = 0;
  // Seed groups (the particle filter's): random_draws() counts the random numbers
  // drawn so far (-1: not supported); only its change across a step matters. The
  // generator's state is the only place a seed lives, so an environment reset
  // with seed A that has drawn nothing yet, given reseed_random(B), is exactly
  // the one reset(B) and the same actions would give. Returns false when not
  // supported or after a failure.
  virtual int64_t random_draws() const { return -1; }
  virtual bool reseed_random(uint64_t seed) {
    (void)seed;
    return false;
  }
  // Draw scripts (rng.hpp, module_abi.h): sets or (nullptr) clears the script
  // this environment's random draws follow, from the next draw on, resets
  // included; clones do not inherit it. False when not supported.
  virtual bool set_draw_script(autumn_draw_script* script) {
    (void)script;
    return false;
  }
  // The program's path for error messages ("path:line:col: runtime error: ...").
  virtual void set_source_name(const std::string& path) { (void)path; }
  // Program locations in error messages moved by `r` (runtime/diagnostic.hpp);
  // for a module that serves a text other than the one it was built from.
  virtual void set_relocation(std::shared_ptr<const Relocation> r) { (void)r; }
  // The episode's budget (runtime/limits.hpp), from the next reset() on; clones
  // keep it. Engines that do not enforce a limit ignore it.
  virtual void set_limits(const Limits& limits) { (void)limits; }
};

}  // namespace autumn
