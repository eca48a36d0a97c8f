// difftest — differential testing of two engines on one program.
//
// Both engines run the same seeds and the same (randomly chosen, reproducible)
// actions; after every step the frames, the trigger value, the coverage count and
// the success of the step must agree, and when both fail, their error messages.
// The first divergence is reported. A disagreement the per-step budgets allow
// (the interpreter stopped by "calls" or "cells" in a step, and the two agree
// there once those are raised: runtime/limits.hpp) ends its episode as
// budget_ended instead (difftest.cpp).
#pragma once
#include <cstdint>
#include <string>

#include "compiler/analyse/program.hpp"
#include "runtime/limits.hpp"

namespace autumn {

struct DiffOptions {
  std::string engine_a = "interp";
  std::string engine_b = "compiled";
  int seeds = 8;
  int steps = 200;
  uint64_t first_seed = 0;
  Limits limits;  // both engines run under these
};

struct DiffResult {
  size_t episodes = 0;
  size_t steps = 0;             // steps compared (both engines)
  size_t errored = 0;           // episodes that ended in the same runtime error on both engines
  std::string first_error;      // the error of the first such episode
  size_t budget_ended = 0;      // episodes ended where only the budgets' allowance told the engines apart
  std::string first_budget;     // where the first such episode ended, and how
  bool setup_failed = false;    // an engine could not be built
  std::string divergence;       // empty when the engines agreed everywhere
};

DiffResult diff_engines(const std::shared_ptr<const Program>& program, const DiffOptions& options);

}  // namespace autumn
