// interpreted_env — the interpreter behind the common Environment interface.
//
// reset() runs the reference's host sequence: start (which renders once
// internally) and then the host's own render_all(), a second render that matters
// because deferred cell colours may draw random numbers at every render.
// Limits and the source name given by the host apply from the next reset on
// (and to clones). A failed episode's clone is failed too and shares nothing.
#pragma once
#include <memory>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/interpret/interpreter.hpp"
#include "runtime/environment.hpp"

namespace autumn {

class InterpretedEnvironment : public Environment {
 public:
  explicit InterpretedEnvironment(std::shared_ptr<const Program> program);
  bool reset(uint64_t seed) override;
  bool step(const Action& action) override;
  bool advance(const Action& action) override;
  const Frame& frame() const override { return frame_; }
  const Palette& palette() const override { return palette_; }
  bool triggered() const override { return triggered_; }
  int on_clause_count() const override;
  int covered_on_clause_count() const override;
  bool failed() const override { return failed_; }
  const std::string& error() const override { return error_; }
  std::unique_ptr<Environment> clone() const override;
  uint64_t state_hash() const override;
  bool deterministic() const override { return !program_->uses_random; }
  int64_t random_draws() const override {
    return interp_ && !failed_ ? static_cast<int64_t>(interp_->rng().draws()) : -1;
  }
  bool reseed_random(uint64_t seed) override {
    if (!interp_ || failed_) return false;
    interp_->rng().reseed(seed);
    return true;
  }
  bool set_draw_script(autumn_draw_script* script) override {
    script_ = script;
    if (interp_) interp_->rng().set_script(script);
    return true;
  }
  void set_source_name(const std::string& path) override;
  void set_relocation(std::shared_ptr<const Relocation> r) override;
  void set_limits(const Limits& limits) override;

 private:
  template <class F>
  bool guarded(F&& f);
  void paint(int size);  // the frame from the host render's cells_ (size checked by the interpreter)
  const std::string& name() const;  // the program's path in messages

  std::shared_ptr<const Program> program_;
  std::unique_ptr<interp::Interpreter> interp_;
  std::string source_name_;  // empty: the program's own file name
  std::shared_ptr<const Relocation> relocation_;
  Limits limits_;
  autumn_draw_script* script_ = nullptr;  // given to every interpreter reset() makes; clones start without
  std::vector<interp::RenderedCell> cells_;
  Palette palette_;
  Frame frame_;
  bool triggered_ = false;
  bool failed_ = true;
  std::string error_ = "not started";
};

}  // namespace autumn
