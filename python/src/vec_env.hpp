// vec_env — batched environments stepped in C++ threads (autumnc.VecEnv, autumnc.Env).
//
// Slots hold one Environment each (clones of the engine's prototype) and write
// their observations straight into caller-owned buffers: obs [N, H, W] uint8
// colour ids (colours.hpp), rewards float32 [N], terminated / truncated bool [N].
// step() splits the slots into one contiguous range per thread; a slot's result
// depends only on its own actions, so results never depend on the thread count.
// Actions are integers: 0 noop, 1 left, 2 right, 3 up, 4 down, 5 + y*W + x a
// click. A slot whose episode ended (a runtime error: terminated; the step
// limit: truncated) is reset by its next step, which ignores the action (the
// Gymnasium "next step" autoreset). Episode k of slot i runs with seed
// base + i + k*N. Reward: 1.0 on steps where the program's trigger condition
// held, else 0.0 (Autumn programs define no reward). Nothing here touches
// Python: the binding (bindings.cpp) owns the buffers and releases the GIL.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "harness/agent/thread_pool.hpp"
#include "python/src/colours.hpp"
#include "runtime/environment.hpp"

namespace autumn::py {

struct Buffers {
  uint8_t* obs = nullptr;  // N * H * W
  float* rewards = nullptr;
  bool* terminated = nullptr;
  bool* truncated = nullptr;
};

// Decodes an integer action on a W-wide grid; false when out of range.
bool decode_action(int64_t a, int grid, Action* out);

// How a batched call is stopped (Ctrl-C, runtime/interrupt.hpp). `check` runs
// on the calling thread only (in its own steps' interpreter polls, and about
// every 20 ms while it waits for the workers) and says whether the host wants
// to stop; once it has said so, `stop` makes every thread's interpreter poll
// answer true, so their long steps fail at once, and no further slot starts.
// The batch is then half stepped: the host asks for a reset.
struct Interrupt {
  std::function<bool()> check;
  std::atomic<bool> stop{false};
};

struct Slot {
  std::unique_ptr<Environment> env;
  PaletteMap colours;
  uint64_t episode = 0;
  uint32_t steps = 0;
  bool done = false;
  std::string error;  // why the episode ended, if by an error
};

class SlotSet {
 public:
  SlotSet(const Environment& prototype, size_t n, uint64_t base_seed, uint32_t max_steps, unsigned threads);
  size_t size() const { return slots_.size(); }
  int grid() const { return grid_; }
  unsigned threads() const { return pool_.size(); }
  // Resets every slot (episode 0 of `base_seed`) and writes obs.
  void reset_all(uint64_t base_seed, const Buffers& out, Interrupt* interrupt = nullptr);
  // actions: N integers. Throws std::invalid_argument for an invalid action (nothing stepped).
  void step(const int64_t* actions, const Buffers& out, Interrupt* interrupt = nullptr);
  Slot& slot(size_t i) { return slots_.at(i); }
  void write_obs(size_t i, const Buffers& out);  // throws std::runtime_error on a grid-size change

 private:
  void reset_slot(size_t i);
  // body(0..chunks-1) on the pool (one chunk: on this thread), each chunk with
  // the interrupt's poll installed.
  void run_chunks(size_t chunks, const std::function<void(size_t)>& body, Interrupt* interrupt);
  void step_slot(size_t i, const Action& a, const Buffers& out);

  std::vector<Slot> slots_;
  uint64_t base_seed_;
  uint32_t max_steps_;  // 0: no limit
  int grid_ = 0;
  agent::ThreadPool pool_;
};

}  // namespace autumn::py
