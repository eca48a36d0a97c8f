#include "harness/bench.hpp"

#include <chrono>

#include "harness/engine.hpp"
#include "harness/policy.hpp"

namespace autumn {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Steps per second over the action sequence, replayed from `start` until at
// least kMinSeconds have passed (a fast engine runs 300 steps in microseconds,
// too short to time once). `step` is Environment::step or ::advance.
constexpr double kMinSeconds = 0.2;
template <class Step>
double rate(const Environment& start, const std::vector<Action>& actions, Step step, size_t* done_first) {
  size_t steps = 0;
  double elapsed = 0;
  for (int rep = 0; rep == 0 || elapsed < kMinSeconds; ++rep) {
    auto env = start.clone();
    auto t0 = Clock::now();
    size_t done = 0;
    for (const Action& a : actions) {
      if (!step(*env, a)) break;
      ++done;
    }
    elapsed += seconds_since(t0);
    steps += done;
    if (rep == 0 && done_first) *done_first = done;
    if (done == 0) break;
  }
  return elapsed > 0 ? steps / elapsed : 0;
}

}  // namespace

BenchRow bench_program(const std::string& name, const std::shared_ptr<const Program>& program,
                       const std::vector<std::string>& engines, size_t steps, uint64_t seed) {
  BenchRow row;
  row.program = name;
  // One action sequence for all engines, chosen by the policy on the first engine's frames.
  std::vector<Action> actions;
  for (const std::string& engine : engines) {
    EngineFigures f;
    std::string why;
    auto env = make_environment(engine, program, &why);
    if (!env) {
      f.error = why;
      row.engines.push_back(f);
      continue;
    }
    if (!env->reset(seed)) {
      f.error = env->error();
      row.engines.push_back(f);
      continue;
    }
    row.grid = env->frame().size;
    if (actions.empty()) {
      auto probe = env->clone();
      RandomPolicy policy(seed + 101);
      for (size_t i = 0; i < steps; ++i) {
        Action a = policy.next(probe->frame());
        if (!probe->step(a)) break;
        actions.push_back(a);
      }
    }
    auto start_state = env->clone();
    size_t done = 0;
    // With render (the protocol), then without.
    f.steps_per_s = rate(*start_state, actions, [](Environment& e, const Action& a) { return e.step(a); }, &done);
    f.steps_per_s_no_render =
        rate(*start_state, actions, [](Environment& e, const Action& a) { return e.advance(a); }, nullptr);
    f.steps = done;
    for (size_t i = 0; i < done; ++i) env->step(actions[i]);
    // Clone cost, on the final state of the protocol run.
    const int clones = 200;
    auto t0 = Clock::now();
    for (int i = 0; i < clones; ++i) {
      auto c = env->clone();
      (void)c;
    }
    f.clone_ns = seconds_since(t0) * 1e9 / clones;
    f.ok = done == actions.size();
    if (!f.ok) f.error = env->error();
    row.engines.push_back(f);
  }
  return row;
}

}  // namespace autumn
