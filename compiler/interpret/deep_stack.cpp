// deep_stack — one lazily reserved fiber stack per thread (deep_stack.hpp).
//
// The fiber is made once per thread and never ends: each run_on_deep_stack
// switches into its loop, which runs the job and switches back (two context
// switches, one signal-mask call each). Only the pages the evaluation touches
// are committed.
#include "compiler/interpret/deep_stack.hpp"

#include <pthread.h>
#include <sys/mman.h>
#include <ucontext.h>

#include <cerrno>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

#ifdef AUTUMN_ASAN
#include <sanitizer/asan_interface.h>
#include <sanitizer/common_interface_defs.h>
#endif

namespace autumn::interp {
namespace {

struct DeepStack {
  char* base = nullptr;  // lowest address of the mapping (a guard page first)
  size_t size = 0;       // bytes mapped at base: kDeepStackBytes, or less under an address-space limit
  bool started = false;  // the fiber waits in loop()
  bool active = false;   // this thread runs on it now
  ucontext_t fiber{}, caller{};
  void (*fn)(void*) = nullptr;
  void* arg = nullptr;
  std::exception_ptr error;
  // For AddressSanitizer: the stack we came from, and each side's fake stack.
  const void* caller_bottom = nullptr;
  size_t caller_size = 0;
  void* fiber_fake = nullptr;

  ~DeepStack() {
    if (base) munmap(base, size);  // the suspended fiber owns nothing else
  }
  void start();
};

thread_local DeepStack tls_stack;

// The fiber's body: runs one job per switch in, then switches back out.
void loop() {
  DeepStack& d = tls_stack;
  for (;;) {
#ifdef AUTUMN_ASAN
    __sanitizer_finish_switch_fiber(d.fiber_fake, &d.caller_bottom, &d.caller_size);
#endif
    try {
      d.fn(d.arg);
    } catch (...) {
      forget_unwound_frames();
      d.error = std::current_exception();
    }
#ifdef AUTUMN_ASAN
    __sanitizer_start_switch_fiber(&d.fiber_fake, d.caller_bottom, d.caller_size);
#endif
    swapcontext(&d.fiber, &d.caller);
  }
}

void DeepStack::start() {
  // Reserved, not committed; an address-space limit (ulimit -v) can refuse the
  // full size, so halve down to kMinDeepStackBytes: the depth counters still
  // decide where evaluation stops, and past a smaller stack's end
  // stack_exhausted() gives the nesting error instead of a crash.
  void* p = MAP_FAILED;
  int err = 0;
  for (size = kDeepStackBytes; size >= kMinDeepStackBytes; size /= 2) {
    p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE | MAP_STACK, -1, 0);
    if (p != MAP_FAILED) break;
    err = errno;
  }
  if (p == MAP_FAILED) {
    size = 0;
    throw std::runtime_error("cannot reserve the interpreter's stack (" + std::to_string(kMinDeepStackBytes >> 20) +
                             " MiB of address space, at least): " + std::strerror(err) +
                             " (is the address space limited, as by ulimit -v?)");
  }
  base = static_cast<char*>(p);
  mprotect(base, 4096, PROT_NONE);  // an overflow faults instead of writing below
  getcontext(&fiber);
  fiber.uc_stack.ss_sp = base;
  fiber.uc_stack.ss_size = size;
  fiber.uc_link = nullptr;
  makecontext(&fiber, loop, 0);
  started = true;
}

// The current thread's stack bounds (a thread that is not the deep stack).
const char* thread_stack_floor() {
  thread_local const char* floor = [] {
    pthread_attr_t attr;
    void* addr = nullptr;
    size_t size = 0;
    if (pthread_getattr_np(pthread_self(), &attr) != 0) return static_cast<const char*>(nullptr);
    pthread_attr_getstack(&attr, &addr, &size);
    pthread_attr_destroy(&attr);
    return size > 2 * kStackReserve ? static_cast<const char*>(addr) + kStackReserve : nullptr;
  }();
  return floor;
}

}  // namespace

void run_on_deep_stack(void (*fn)(void*), void* arg) {
  DeepStack& d = tls_stack;
  if (d.active) return fn(arg);
  if (!d.started) d.start();
  d.fn = fn;
  d.arg = arg;
  d.error = nullptr;
  d.active = true;
#ifdef AUTUMN_ASAN
  void* fake_stack = nullptr;
  __sanitizer_start_switch_fiber(&fake_stack, d.base, d.size);
#endif
  swapcontext(&d.caller, &d.fiber);
#ifdef AUTUMN_ASAN
  __sanitizer_finish_switch_fiber(fake_stack, nullptr, nullptr);
#endif
  d.active = false;
  if (d.error) std::rethrow_exception(std::exchange(d.error, nullptr));
}

#ifdef AUTUMN_ASAN
thread_local const char* tls_deepest = nullptr;
#endif

void forget_unwound_frames() {
#ifdef AUTUMN_ASAN
  // The unwound frames lie between the deepest point eval() noted and here,
  // give or take the frames below the deepest eval() (builtins, the throw's
  // own): a window below covers those.
  constexpr size_t kWindow = size_t{64} << 10;
  const DeepStack& d = tls_stack;
  char here;
  char* top = &here;
  const char* deepest = tls_deepest && tls_deepest < top ? tls_deepest : top;
  tls_deepest = top;
  if (!d.active) return;
  char* low = const_cast<char*>(deepest);
  low = low - (d.base + 4096) > static_cast<std::ptrdiff_t>(kWindow) ? low - kWindow : d.base + 4096;
  __asan_unpoison_memory_region(low, static_cast<size_t>(top - low));
#endif
}

const char* stack_floor() {
  const DeepStack& d = tls_stack;
  if (d.active) return d.base + kStackReserve;
  return thread_stack_floor();
}

}  // namespace autumn::interp
