// interruptible — Ctrl-C during a long interpreted step (runtime/interrupt.hpp).
//
// Python runs its SIGINT handler only between bytecodes, so a step inside the
// extension would finish before KeyboardInterrupt is raised (a minute, for a step
// near the calls budget). Around the calls that step, the interpreter's poll asks
// Python for pending signals (PyErr_CheckSignals: the handler runs and raises);
// a raised exception ends the step as a runtime error, and the call then raises
// it in place of its result. Only with the GIL held: the poll answers false on a
// thread without it (VecEnv's workers).
#pragma once
#include <pybind11/pybind11.h>

#include "runtime/interrupt.hpp"

namespace autumn::py {

inline bool poll_python_signals() { return PyGILState_Check() && PyErr_CheckSignals() != 0; }

// Raises what a poll left pending (KeyboardInterrupt), if anything.
inline void raise_if_interrupted() {
  if (PyErr_Occurred()) throw pybind11::error_already_set();
}

// f() with the poll installed; its result, or the pending exception raised.
template <class F>
decltype(auto) interruptible(F&& f) {
  try {
    InterruptPollScope scope(&poll_python_signals);
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      raise_if_interrupted();
    } else {
      decltype(auto) r = f();
      raise_if_interrupted();
      return r;
    }
  } catch (const pybind11::error_already_set&) {
    throw;
  } catch (...) {
    raise_if_interrupted();  // the step's own error is the interrupt's consequence
    throw;
  }
}

}  // namespace autumn::py
