// interrupt — how a host stops a long step (Ctrl-C in Python).
//
// A host that can be interrupted installs a poll on the thread that steps
// (InterruptPollScope); the interpreter calls it every kInterruptPollCalls
// function calls of the program, and when it answers true the step fails with
// interrupted_error() at the call, as a budget would. Nothing is polled when no
// host installed one. Compiled steps are not polled: the loop budget bounds
// them to well under a second (runtime/limits.hpp, "calls").
#pragma once
#include <cstdint>
#include <string>

namespace autumn {

using InterruptPoll = bool (*)();

// About every 10 ms of a busy interpreter.
constexpr int64_t kInterruptPollCalls = 1 << 16;

// The poll installed on this thread, or null.
InterruptPoll interrupt_poll();

// Installs `poll` on this thread for its lifetime, restoring the previous one.
class InterruptPollScope {
 public:
  explicit InterruptPollScope(InterruptPoll poll);
  ~InterruptPollScope();
  InterruptPollScope(const InterruptPollScope&) = delete;
  InterruptPollScope& operator=(const InterruptPollScope&) = delete;

 private:
  InterruptPoll previous_;
};

std::string interrupted_error();

}  // namespace autumn
