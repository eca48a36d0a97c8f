#include "harness/warm_env.hpp"

#include <iostream>

#include "compiler/interpret/interpreted_env.hpp"

namespace autumn {

WarmingEnvironment::WarmingEnvironment(std::shared_ptr<const Program> program, CompiledSource source)
    : program_(std::move(program)),
      source_(std::move(source)),
      active_(std::make_unique<InterpretedEnvironment>(program_)) {}

bool WarmingEnvironment::replays_to_here(Environment& compiled) const {
  if (!compiled.reset(seed_)) return false;
  for (const Action& a : log_)
    if (!compiled.step(a)) return false;
  return frame_rows(compiled.frame(), compiled.palette()) == frame_rows(active_->frame(), active_->palette()) &&
         compiled.triggered() == active_->triggered() &&
         compiled.covered_on_clause_count() == active_->covered_on_clause_count();
}

void WarmingEnvironment::try_switch() {
  if (switched_ || !can_switch_) return;
  std::string never;
  std::unique_ptr<Environment> compiled = source_(&never);
  if (!never.empty()) {
    std::cerr << "autumn: warning: " << never << "\nautumn: the interpreter runs " << program_->file.name
              << " instead\n";
    can_switch_ = false;
    never_ = never;
  }
  if (!compiled) return;
  if (!source_name_.empty()) compiled->set_source_name(source_name_);
  if (limits_) compiled->set_limits(*limits_);
  if (started_ && active_->failed()) return;  // the episode is over; the next reset switches
  if (started_ && !replays_to_here(*compiled)) {
    std::cerr << "autumn: warning: the compiled module of " << program_->file.name << " disagrees with the "
              << "interpreter after " << log_.size() << " steps; the interpreter keeps the episode\n";
    can_switch_ = false;
    never_ = "the compiled module disagreed with the interpreter";
    return;
  }
  active_ = std::move(compiled);
  switched_ = true;
  switched_after_ = started_ ? log_.size() : 0;
}

std::string WarmingEnvironment::served_by() const {
  if (switched_ && switched_after_ == 0) return "compiled";
  if (switched_)
    return "interp for steps 1-" + std::to_string(switched_after_) + " (the module was compiling), then compiled";
  if (!never_.empty()) return "interp (" + never_ + ")";
  if (!can_switch_) return "interp (the episode used what only the interpreter replays: advance, load_state or reseeding)";
  return "interp (the module was still compiling; a later run uses it)";
}

bool WarmingEnvironment::reset(uint64_t seed) {
  if (!switched_ && can_switch_) {
    started_ = false;  // nothing to carry over: switch now if the module is ready
    try_switch();
  }
  started_ = true;
  seed_ = seed;
  log_.clear();
  if (switched_) switched_after_ = 0;  // a new episode, compiled from its start
  return active_->reset(seed);
}

bool WarmingEnvironment::step(const Action& action) {
  try_switch();
  if (!switched_) log_.push_back(action);
  return active_->step(action);
}

bool WarmingEnvironment::advance(const Action& action) {
  can_switch_ = false;
  return active_->advance(action);
}

bool WarmingEnvironment::load_state(const uint8_t* data, size_t size) {
  can_switch_ = false;
  return active_->load_state(data, size);
}

bool WarmingEnvironment::reseed_random(uint64_t seed) {
  can_switch_ = false;
  return active_->reseed_random(seed);
}

bool WarmingEnvironment::set_draw_script(autumn_draw_script* script) {
  can_switch_ = false;
  return active_->set_draw_script(script);
}

void WarmingEnvironment::set_source_name(const std::string& path) {
  source_name_ = path;
  active_->set_source_name(path);
}

void WarmingEnvironment::set_limits(const Limits& limits) {
  limits_ = limits;
  active_->set_limits(limits);
}

}  // namespace autumn
