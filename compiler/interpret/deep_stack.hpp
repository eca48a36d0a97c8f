// deep_stack — the interpreter evaluates on a stack sized for its limits.
//
// Evaluation is a recursive tree walk, and the call-depth limit (runtime/limits)
// allows 10,000 nested calls by default, each several C++ frames: more than a
// thread's usual 8 MiB. Rather than rewrite the walk, every entry into the
// interpreter (start, step, render, the host API) runs on a per-thread stack of
// kDeepStackBytes, reserved once per thread and committed only as it is touched
// (less, down to kMinDeepStackBytes, when the address space is limited; below
// that a one-line reason)
// (a ucontext fiber: same thread, so thread-locals and exceptions behave;
// AddressSanitizer is told about each switch). Re-entry while already on it runs
// directly. The depth counters, not the stack, decide where evaluation stops, so
// results never depend on the thread or the build; as a last resort
// stack_exhausted() reports a nearly full stack, which the interpreter turns into
// its ordinary nesting error instead of overflowing.
#pragma once
#include <cstddef>
#include <exception>
#include <type_traits>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AUTUMN_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define AUTUMN_ASAN 1
#endif

namespace autumn::interp {

constexpr size_t kDeepStackBytes = size_t{1} << 30;     // reserved, not committed
constexpr size_t kMinDeepStackBytes = size_t{32} << 20;  // the least taken when less can be reserved
constexpr size_t kStackReserve = size_t{256} << 10;  // what stack_exhausted() keeps free

// Runs fn(arg) on this thread's deep stack (directly when already there).
// Exceptions thrown by fn are rethrown to the caller.
void run_on_deep_stack(void (*fn)(void*), void* arg);

template <class F>
void on_deep_stack(F&& f) {
  using Fn = std::remove_reference_t<F>;
  run_on_deep_stack([](void* p) { (*static_cast<Fn*>(p))(); }, const_cast<void*>(static_cast<const void*>(&f)));
}

// Call in every catch handler on the deep stack before rethrowing or going on.
// AddressSanitizer cleans the frames an exception unwinds only when the stack
// in use is under 64 MiB deep; deeper, their poison stays, and the next frames
// written there (the rethrow's own) are reported as bugs that are not there.
// This clears from the caller's frame down to the deepest point noted since the
// last call (note_stack_depth), and a window below it; a no-op without ASan.
void forget_unwound_frames();

// Notes how deep the stack has gone (eval() calls it on every frame); a no-op
// without ASan.
#ifdef AUTUMN_ASAN
extern thread_local const char* tls_deepest;
inline void note_stack_depth() {
  char here;
  if (!tls_deepest || &here < tls_deepest) tls_deepest = &here;
}
#else
inline void note_stack_depth() {}
#endif

// The lowest usable address of the stack the caller runs on (for the
// interpreter's cheap check), or null when unknown.
const char* stack_floor();
inline bool stack_exhausted(const char* floor) {
  char here;
  return floor && &here < floor;
}

}  // namespace autumn::interp
