// interrupt — the per-thread poll of interrupt.hpp.
#include "runtime/interrupt.hpp"

namespace autumn {
namespace {

thread_local InterruptPoll current_poll = nullptr;  // the innermost scope's, on this thread

}  // namespace

InterruptPoll interrupt_poll() { return current_poll; }

InterruptPollScope::InterruptPollScope(InterruptPoll poll) : previous_(current_poll) { current_poll = poll; }

InterruptPollScope::~InterruptPollScope() { current_poll = previous_; }

std::string interrupted_error() { return "interrupted (the host asked the step to stop)"; }

}  // namespace autumn
