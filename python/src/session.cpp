#include "python/src/session.hpp"

#include <cstring>
#include <functional>

#include "compiler/emit/emit_module.hpp"
#include "compiler/parse/parser.hpp"
#include "compiler/read/sexpr.hpp"

namespace autumn::py {

Session::Session(std::shared_ptr<const Program> program, uint64_t seed, const std::string& engine, bool compilable)
    : program_(std::move(program)), seed_(seed), compilable_(compilable), mode_(engine) {
  if (engine != "auto" && engine != "compiled" && engine != "interp")
    throw std::invalid_argument("unknown engine '" + engine + "' (expected auto, compiled or interp)");
  if (engine == "compiled" && !compilable)
    throw std::invalid_argument("the compiled engine is built with the bundled standard library; "
                                "this program was given another one (use engine='interp' or 'auto')");
  if (engine == "interp" || !compilable) ce_dead_ = true;
  else prototype_ = request_compiled(program_);
  if (engine == "compiled") {
    std::shared_ptr<const Prototype> p = prototype_.get();
    if (!p->env) throw std::runtime_error("the compiled engine cannot serve " + program_->file.name + ": " + p->why);
  }
  attach_compiled_if_ready();
  if (!ce_) check_interp(interp());
}

Session::Session(const Session& o)
    : program_(o.program_),
      seed_(o.seed_),
      compilable_(o.compilable_),
      mode_(o.mode_),
      prototype_(o.prototype_),
      log_(o.log_),
      snippets_(o.snippets_),
      failed_(o.failed_),
      error_(o.error_),
      ce_(o.ce_ ? o.ce_->clone() : nullptr),
      ce_dead_(o.ce_dead_),
      ce_pos_(o.ce_pos_),
      ce_ahead_(o.ce_ahead_),
      ce_input_(o.ce_input_),
      spec_(o.spec_ && o.spec_at_ != SIZE_MAX ? o.spec_->clone() : nullptr),
      spec_at_(spec_ ? o.spec_at_ : SIZE_MAX),
      it_(o.it_ ? std::make_unique<InterpTrack>(*o.it_) : nullptr) {}

// ---------------------------------------------------------------------------
// The log and the compiled track

void Session::append(HostOp op) {
  log_.push_back(op);
  attach_compiled_if_ready();
  sync_compiled();
}

void Session::attach_compiled_if_ready() {
  if (ce_ || ce_dead_ || !is_ready(prototype_)) return;
  std::shared_ptr<const Prototype> p = prototype_.get();
  std::unique_ptr<Environment> env = p->env ? instantiate(*p) : nullptr;
  if (env) env->record_render(true);  // render_all() from the compiled track (where the module can)
  if (!env || !env->reset(seed_)) {
    // A start-up failure is reported by the interpreter, which knows whether it
    // came from start or from the host render reset adds.
    ce_dead_ = true;
    return;
  }
  ce_ = std::move(env);
  ce_pos_ = 0;
  ce_ahead_ = true;
  ce_input_.reset();
  spec_at_ = SIZE_MAX;
  sync_compiled();
  probe_pending();
}

void Session::kill_compiled() {
  ce_dead_ = true;
  ce_.reset();
  spec_.reset();
  spec_at_ = SIZE_MAX;
}

// Consumes every log entry whose effect on the compiled environment is decided.
void Session::sync_compiled() {
  const bool random = program_->uses_random;
  while (ce_ && ce_pos_ < log_.size()) {
    const HostOp& op = log_[ce_pos_];
    switch (op.kind) {
      case HostOp::Press:
        if (ce_input_ && ce_input_->kind != op.input.kind) return kill_compiled();  // two inputs in one step
        ce_input_ = op.input;
        break;
      case HostOp::Render:
        if (ce_ahead_) ce_ahead_ = false;
        else if (random) return kill_compiled();  // an extra render may draw random numbers
        break;
      case HostOp::Reseed:
        if (random && (ce_ahead_ || !ce_->reseed_random(op.arg))) return kill_compiled();
        break;
      case HostOp::Eval:
        if (op.effect) return kill_compiled();
        break;
      case HostOp::Exec: return kill_compiled();
      case HostOp::Step:
        if (!step_compiled(ce_pos_)) return;
        break;
    }
    ++ce_pos_;
  }
}

// The step at log_[at]: with its render when one follows before the next step,
// without when another step comes first, undecided (false) at the end of the log.
bool Session::step_compiled(size_t at) {
  const bool random = program_->uses_random;
  if (ce_ahead_ && random) {  // it rendered where the reference did not
    kill_compiled();
    return false;
  }
  bool render = false, decided = false, reseeded = false;
  for (size_t j = at + 1; j < log_.size() && !decided; ++j) {
    const HostOp::Kind k = log_[j].kind;
    if (k == HostOp::Step || k == HostOp::Render) {
      decided = true;
      render = k == HostOp::Render;
    }
    if (k == HostOp::Reseed) reseeded = true;
  }
  if (!decided) return false;
  if (render && reseeded && random) {
    kill_compiled();
    return false;
  }
  const Action in = ce_input_.value_or(Action::noop());
  ce_input_.reset();
  bool ok;
  if (render && spec_ && spec_at_ == at) {
    std::swap(ce_, spec_);
    ok = !ce_->failed();
  } else {
    ok = render ? ce_->step(in) : ce_->advance(in);
  }
  spec_at_ = SIZE_MAX;
  ce_ahead_ = render;
  if (!ok) fail(ce_->error());
  return true;
}

// Runs the pending step ahead on a copy, with a render: a step error surfaces
// now, at step(), and the copy is the next state if a render follows.
void Session::probe_pending() {
  if (!ce_ || ce_pos_ >= log_.size() || log_[ce_pos_].kind != HostOp::Step) return;
  const Action in = ce_input_.value_or(Action::noop());
  if (!spec_ || !spec_->copy_from(*ce_)) spec_ = ce_->clone();
  spec_at_ = ce_pos_;
  if (spec_->step(in)) return;
  std::unique_ptr<Environment> probe = ce_->clone();
  if (!probe->advance(in)) fail(probe->error());
  // Only the render failed: that is reported by the render that meets it.
}

// The compiled environment in the state the log describes (pending inputs and
// renders aside), or null when only the interpreter can tell.
const Environment* Session::compiled_now() {
  if (!ce_) return nullptr;
  if (ce_pos_ == log_.size()) return ce_.get();
  if (spec_at_ != ce_pos_) return nullptr;
  for (size_t j = ce_pos_ + 1; j < log_.size(); ++j)
    if (log_[j].kind != HostOp::Press && !(log_[j].kind == HostOp::Eval && !log_[j].effect)) return nullptr;
  return spec_.get();
}

// ---------------------------------------------------------------------------
// The interpreter track

InterpTrack& Session::interp() {
  if (!it_) it_ = std::make_unique<InterpTrack>(program_, seed_);
  it_->catch_up(log_, *snippets_);
  check_interp(*it_);
  return *it_;
}

void Session::check_interp(InterpTrack& t) {
  if (t.failed()) fail(t.error());
}

void Session::fail(const std::string& message) {
  failed_ = true;
  error_ = message;
  throw SessionError(message);
}

void Session::check_alive() const {
  if (failed_) throw SessionError(error_);
}

// ---------------------------------------------------------------------------
// Host calls

void Session::press(const Action& a) {
  HostOp op;
  op.kind = HostOp::Press;
  op.input = a;
  append(op);
}

void Session::step() {
  check_alive();
  HostOp op;
  op.kind = HostOp::Step;
  append(op);
  if (ce_) probe_pending();
  else interp();  // the interpreter serves alone: step now, so errors surface here
}

std::string Session::render_all() {
  check_alive();
  HostOp op;
  op.kind = HostOp::Render;
  append(op);
  std::string json;
  if (ce_ && ce_pos_ == log_.size() && ce_->render_json(&json)) return json;
  return interp().render_json();
}

void Session::render_frame(Frame& frame, Palette& palette) {
  check_alive();
  HostOp op;
  op.kind = HostOp::Render;
  append(op);
  if (ce_ && ce_pos_ == log_.size()) {
    frame = ce_->frame();
    palette = ce_->palette();
    return;
  }
  InterpTrack& t = interp();
  if (t.grid_size() <= 0 || t.grid_size() > 4096)
    fail(program_->file.name + ": runtime error: GRID_SIZE " + std::to_string(t.grid_size()) + " cannot be painted");
  t.paint(frame, palette);
}

bool Session::trigger_state() {
  check_alive();
  if (const Environment* e = compiled_now()) return e->triggered();
  return interp().interpreter().triggered();
}

int Session::on_clause_count() {
  check_alive();
  if (const Environment* e = compiled_now()) return e->on_clause_count();
  return interp().interpreter().on_clause_count();
}

int Session::covered_on_clause_count() {
  check_alive();
  if (const Environment* e = compiled_now()) return e->covered_on_clause_count();
  return interp().interpreter().covered_on_clause_count();
}

std::string Session::background() {
  check_alive();
  return interp().interpreter().background();
}

int Session::frame_rate() {
  check_alive();
  int r = interp().interpreter().frame_rate();
  if (r < 0) throw std::runtime_error("FRAME_RATE is not a Number (the reference interpreter crashes here)");
  return r;
}

void Session::reseed(uint64_t seed) {
  HostOp op;
  op.kind = HostOp::Reseed;
  op.arg = seed;
  append(op);
}

uint64_t Session::state_hash() {
  check_alive();
  if (const Environment* e = compiled_now()) return e->state_hash();
  return interp().interpreter().state_hash();
}

std::string Session::engine() const { return ce_ ? "compiled" : "interp"; }

}  // namespace autumn::py
