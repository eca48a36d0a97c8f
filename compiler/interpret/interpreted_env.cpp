#include "compiler/interpret/interpreted_env.hpp"

#include <new>

#include "runtime/diagnostic.hpp"

namespace autumn {

InterpretedEnvironment::InterpretedEnvironment(std::shared_ptr<const Program> program)
    : program_(std::move(program)) {}

template <class F>
bool InterpretedEnvironment::guarded(F&& f) {
  try {
    f();
    return true;
  } catch (const interp::RuntimeError& e) {
    error_ = interp_->describe(e);
  } catch (const std::bad_alloc&) {
    error_ = diagnostic_prefix(name(), 0, 0, "runtime error") + "out of memory";
  } catch (const std::exception& e) {
    error_ = diagnostic_prefix(name(), 0, 0, "runtime error") + shown(e.what());
  }
  failed_ = true;
  return false;
}

void InterpretedEnvironment::paint(int size) {
  uint16_t bg = palette_.id(lower_ascii(interp_->background()));
  frame_.size = size;
  frame_.cells.assign(static_cast<size_t>(size) * size, bg);
  for (const auto& c : cells_) {
    if (c.x < 0 || c.y < 0 || c.x >= size || c.y >= size) continue;
    const std::string& q = *c.color;  // quoted
    std::string_view name = q.size() >= 2 ? std::string_view(q).substr(1, q.size() - 2) : std::string_view(q);
    frame_.cells[static_cast<size_t>(c.y) * size + c.x] = palette_.id(lower_ascii(name));
  }
  triggered_ = interp_->triggered();
}

const std::string& InterpretedEnvironment::name() const {
  return source_name_.empty() ? program_->file.name : source_name_;
}

void InterpretedEnvironment::set_source_name(const std::string& path) {
  source_name_ = path;
  if (interp_) interp_->set_source_name(path);
}

void InterpretedEnvironment::set_relocation(std::shared_ptr<const Relocation> r) {
  relocation_ = std::move(r);
  if (interp_) interp_->set_relocation(relocation_);
}

void InterpretedEnvironment::set_limits(const Limits& limits) {
  limits_ = limits;
  if (interp_) interp_->set_limits(limits);
}

bool InterpretedEnvironment::reset(uint64_t seed) {
  interp_ = std::make_unique<interp::Interpreter>(program_);
  interp_->set_source_name(source_name_);
  interp_->set_relocation(relocation_);
  interp_->set_limits(limits_);
  interp_->rng().set_script(script_);
  failed_ = false;
  error_.clear();
  triggered_ = false;
  return guarded([&] { paint(interp_->start_and_render(seed, &cells_)); });
}

bool InterpretedEnvironment::step(const Action& action) {
  if (failed_) return false;
  return guarded([&] { paint(interp_->step_and_render(action, &cells_)); });
}

std::unique_ptr<Environment> InterpretedEnvironment::clone() const {
  auto copy = std::make_unique<InterpretedEnvironment>(program_);
  if (interp_ && !failed_) copy->interp_ = interp_->clone();  // a failed state may be half-updated
  copy->source_name_ = source_name_;
  copy->relocation_ = relocation_;
  copy->limits_ = limits_;
  copy->palette_ = palette_;
  copy->frame_ = frame_;
  copy->triggered_ = triggered_;
  copy->failed_ = failed_;
  copy->error_ = error_;
  return copy;
}

uint64_t InterpretedEnvironment::state_hash() const {
  if (!interp_ || failed_) return 0;
  return interp_->state_hash();
}

bool InterpretedEnvironment::advance(const Action& action) {
  if (failed_) return false;
  return guarded([&] { interp_->step(action); });
}

int InterpretedEnvironment::on_clause_count() const { return interp_ ? interp_->on_clause_count() : 0; }
int InterpretedEnvironment::covered_on_clause_count() const {
  return interp_ ? interp_->covered_on_clause_count() : 0;
}

}  // namespace autumn
