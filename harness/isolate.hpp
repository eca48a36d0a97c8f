// isolate — one unit of a multi-program command run in a child process, so that
// a crash while testing one program (a signal, an abort, a stack overflow) is
// that program's failure and the command goes on with the next one.
//
// The child runs `work`, writes the text it returns (a JSON row) to a pipe and
// leaves with _exit(0): no exit handlers, no destructors of the parent's state,
// no flushing of buffers it inherited (the parent flushes its own before the
// fork). The caller must be single-threaded when it calls run_isolated: a child
// forked beside other threads may inherit a lock one of them held.
// Tested by tests/cli_test.cpp (DifftestGoesOnPastACrashingProgram).
#pragma once
#include <functional>
#include <string>

namespace autumn {

struct Isolated {
  bool finished = false;  // the child returned a result and exited normally
  std::string output;     // what `work` returned, when finished
  std::string death;      // otherwise how the child ended: "was killed by signal 11 (Segmentation fault)"
};

Isolated run_isolated(const std::function<std::string()>& work);

}  // namespace autumn
