// warm_env — an episode that starts on the interpreter while its module compiles.
//
// The compiled engine's first use of a program costs a C++ compile (about two
// seconds, docs/design.md "First runs"). A WarmingEnvironment answers at once: the
// interpreter runs reset and the first steps, and the environment remembers the
// seed and the actions. Before each reset and step it asks whether the module is
// ready; when it is, a compiled environment is reset with the same seed, replays
// the same actions (each with its host render, as the protocol does), and takes
// over if its frame, trigger value and on-clause coverage equal the
// interpreter's; otherwise (an engine disagreement, never expected) the
// interpreter keeps the episode and a warning says so. Both engines are exact, so
// callers see one episode either way.
//
// What cannot be replayed ends the chance to switch: advance() (no host render),
// reseed_random() and load_state(). clone() copies whichever engine is running
// and state_hash() is that engine's: this environment is meant for one episode
// driven step by step (run, render, check, survey), not for search.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "runtime/environment.hpp"

namespace autumn {

// Returns the compiled environment once it can be had, null while it cannot yet;
// sets *never (to the reason) when it never will be.
using CompiledSource = std::function<std::unique_ptr<Environment>(std::string* never)>;

class WarmingEnvironment : public Environment {
 public:
  WarmingEnvironment(std::shared_ptr<const Program> program, CompiledSource source);
  bool switched() const { return switched_; }
  // Which engine ran the episode, for `-v`: "compiled", "interp for steps 1-N
  // (the module was compiling), then compiled", or "interp (why)".
  std::string served_by() const;

  bool reset(uint64_t seed) override;
  bool step(const Action& action) override;
  bool advance(const Action& action) override;
  const Frame& frame() const override { return active_->frame(); }
  const Palette& palette() const override { return active_->palette(); }
  bool triggered() const override { return active_->triggered(); }
  int on_clause_count() const override { return active_->on_clause_count(); }
  int covered_on_clause_count() const override { return active_->covered_on_clause_count(); }
  bool failed() const override { return active_->failed(); }
  const std::string& error() const override { return active_->error(); }
  std::unique_ptr<Environment> clone() const override { return active_->clone(); }
  bool save_state(std::vector<uint8_t>& out) const override { return active_->save_state(out); }
  bool load_state(const uint8_t* data, size_t size) override;
  uint64_t state_hash() const override { return active_->state_hash(); }
  bool deterministic() const override { return active_->deterministic(); }
  int64_t random_draws() const override { return active_->random_draws(); }
  bool reseed_random(uint64_t seed) override;
  bool set_draw_script(autumn_draw_script* script) override;
  void set_source_name(const std::string& path) override;
  void set_limits(const Limits& limits) override;

 private:
  void try_switch();
  bool replays_to_here(Environment& compiled) const;

  std::shared_ptr<const Program> program_;
  CompiledSource source_;
  std::unique_ptr<Environment> active_;
  bool switched_ = false;
  size_t switched_after_ = 0;  // steps the interpreter had served when the module took over
  std::string never_;          // why the module will not serve ("" while it may)
  bool can_switch_ = true;
  bool started_ = false;
  uint64_t seed_ = 0;
  std::vector<Action> log_;
  std::string source_name_;
  std::optional<Limits> limits_;  // passed on to the compiled environment when it takes over
};

}  // namespace autumn
