#include "python/src/vec_env.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "runtime/interrupt.hpp"

namespace autumn::py {

constexpr size_t kSlotsPerThread = 32;

namespace {

// The batch being stepped on this thread, for the interpreter's poll
// (InterruptPoll takes no argument), and whether this is the calling thread.
thread_local Interrupt* t_interrupt = nullptr;
thread_local bool t_caller = false;

bool stop_requested(Interrupt* in) {
  if (in->stop.load(std::memory_order_relaxed)) return true;
  if (in->check && in->check()) in->stop.store(true);
  return in->stop.load(std::memory_order_relaxed);
}

bool slot_poll() {
  Interrupt* in = t_interrupt;
  if (!in) return false;
  return t_caller ? stop_requested(in) : in->stop.load(std::memory_order_relaxed);
}

// Installed around a chunk of slots on each thread (nothing without an Interrupt).
class ChunkPoll {
 public:
  ChunkPoll(Interrupt* in, std::thread::id caller)
      : saved_(t_interrupt), saved_caller_(t_caller), scope_(in ? &slot_poll : interrupt_poll()) {
    t_interrupt = in;
    t_caller = std::this_thread::get_id() == caller;
  }
  ~ChunkPoll() {
    t_interrupt = saved_;
    t_caller = saved_caller_;
  }
  ChunkPoll(const ChunkPoll&) = delete;
  ChunkPoll& operator=(const ChunkPoll&) = delete;

 private:
  Interrupt* saved_;
  bool saved_caller_;
  InterruptPollScope scope_;
};

bool stopped(const Interrupt* in) { return in && in->stop.load(std::memory_order_relaxed); }

}  // namespace

void SlotSet::run_chunks(size_t chunks, const std::function<void(size_t)>& body, Interrupt* interrupt) {
  const std::thread::id caller = std::this_thread::get_id();
  auto polled = [&](size_t chunk) {
    ChunkPoll poll(interrupt, caller);
    body(chunk);
  };
  if (chunks == 1) polled(0);
  else if (!interrupt) pool_.parallel_for(chunks, polled);
  else pool_.parallel_for(chunks, polled, [interrupt] { stop_requested(interrupt); });
}

bool decode_action(int64_t a, int grid, Action* out) {
  if (a < 0 || a >= 5 + static_cast<int64_t>(grid) * grid) return false;
  if (a < 5) {
    out->kind = static_cast<Action::Kind>(a);  // Noop, Left, Right, Up, Down
    return true;
  }
  *out = Action::click(static_cast<int>((a - 5) % grid), static_cast<int>((a - 5) / grid));
  return true;
}

SlotSet::SlotSet(const Environment& prototype, size_t n, uint64_t base_seed, uint32_t max_steps, unsigned threads)
    : base_seed_(base_seed), max_steps_(max_steps), pool_(threads) {
  slots_.resize(n);
  for (Slot& s : slots_) s.env = prototype.clone();
  slots_[0].env->reset(base_seed);
  grid_ = slots_[0].env->frame().size;
  if (grid_ <= 0) throw std::runtime_error("the program does not start: " + slots_[0].env->error());
}

void SlotSet::reset_slot(size_t i) {
  Slot& s = slots_[i];
  const uint64_t seed = base_seed_ + i + s.episode * slots_.size();
  s.steps = 0;
  s.error.clear();
  s.done = !s.env->reset(seed);
  if (s.done) s.error = s.env->error();
}

void SlotSet::write_obs(size_t i, const Buffers& out) {
  Slot& s = slots_[i];
  const size_t cells = static_cast<size_t>(grid_) * grid_;
  uint8_t* row = out.obs + i * cells;
  if (s.env->failed()) return;  // the last good observation stays
  const Frame& f = s.env->frame();
  if (f.size != grid_)
    throw std::runtime_error("GRID_SIZE changed from " + std::to_string(grid_) + " to " + std::to_string(f.size) +
                             "; batched observations need a fixed grid");
  s.colours.paint(f, s.env->palette(), row);
}

void SlotSet::reset_all(uint64_t base_seed, const Buffers& out, Interrupt* interrupt) {
  base_seed_ = base_seed;
  std::vector<std::string> errors(slots_.size());
  run_chunks(pool_.size(), [&](size_t chunk) {
    const size_t n = slots_.size(), per = (n + pool_.size() - 1) / pool_.size();
    for (size_t i = chunk * per; i < std::min(n, (chunk + 1) * per) && !stopped(interrupt); ++i) {
      slots_[i].episode = 0;
      reset_slot(i);
      std::memset(out.obs + i * grid_ * grid_, 0, static_cast<size_t>(grid_) * grid_);
      try {
        write_obs(i, out);
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
      out.rewards[i] = 0;
      out.terminated[i] = slots_[i].done;
      out.truncated[i] = false;
    }
  }, interrupt);
  for (const auto& e : errors)
    if (!e.empty()) throw std::runtime_error(e);
}

void SlotSet::step_slot(size_t i, const Action& a, const Buffers& out) {
  Slot& s = slots_[i];
  out.rewards[i] = 0;
  out.terminated[i] = out.truncated[i] = false;
  if (s.done) {  // autoreset: this step starts the next episode
    ++s.episode;
    reset_slot(i);
    out.terminated[i] = s.done;
    write_obs(i, out);
    return;
  }
  if (!s.env->step(a)) {
    s.done = true;
    s.error = s.env->error();
    out.terminated[i] = true;
    return;
  }
  ++s.steps;
  out.rewards[i] = s.env->triggered() ? 1.0f : 0.0f;
  if (max_steps_ && s.steps >= max_steps_) s.done = out.truncated[i] = true;
  write_obs(i, out);
}

void SlotSet::step(const int64_t* actions, const Buffers& out, Interrupt* interrupt) {
  const size_t n = slots_.size();
  std::vector<Action> decoded(n);
  for (size_t i = 0; i < n; ++i)
    if (!decode_action(actions[i], grid_, &decoded[i]))
      throw std::invalid_argument("action " + std::to_string(actions[i]) + " of environment " + std::to_string(i) +
                                  " is not in 0.." + std::to_string(4 + grid_ * grid_) +
                                  " (0 noop, 1-4 left/right/up/down, 5 + y*W + x click)");
  // Waking the workers costs more than a few slots' steps: small batches run here.
  const size_t chunks = std::min<size_t>(pool_.size(), (n + kSlotsPerThread - 1) / kSlotsPerThread);
  std::vector<std::string> errors(chunks);
  auto body = [&](size_t chunk) {
    const size_t per = (n + chunks - 1) / chunks;
    try {
      for (size_t i = chunk * per; i < std::min(n, (chunk + 1) * per) && !stopped(interrupt); ++i)
        step_slot(i, decoded[i], out);
    } catch (const std::exception& e) {
      errors[chunk] = e.what();
    }
  };
  run_chunks(chunks, body, interrupt);
  for (const auto& e : errors)
    if (!e.empty()) throw std::runtime_error(e);
}

}  // namespace autumn::py
