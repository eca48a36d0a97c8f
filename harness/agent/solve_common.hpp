// solve_common — options and shared helpers of the three task solvers.
#pragma once
#include <chrono>
#include <cstdint>
#include <optional>
#include <random>
#include <string>

#include "harness/agent/task_file.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

struct SolveOptions {
  std::string engine = "interp";
  fs::path programs_dir;      // empty: default_programs_dir(task file)
  uint64_t rollouts = 10000;  // MFP rollouts; CD particles for stochastic programs
  uint64_t seed = 0;          // the agent's own randomness (rollout seeds, policy)
  bool seed_inversion = true;  // MFP, stochastic programs: try seed_inversion.hpp before the filter
  // change detection
  std::optional<fs::path> answers;  // trigger condition used only to score
  int max_steps = 200;
  std::string policy = "novelty";   // novelty | random
  // planning
  int depth = 12;                   // BFS cost limit
  uint64_t nodes = 30000000;
  std::string search = "auto";      // auto | bfs | best-first
  std::string cost = "steps";       // steps: every action costs 1; moves: noop (waiting) is free
  int max_plan = 200;               // best-first depth limit
  uint64_t keep_states = 10000;     // search environments kept in memory when the engine has no
                                    // snapshots (save_state); others are replayed
  double time_limit = 0;            // planning: seconds for all searches of a solve (0: none)
};

// The program file a task names, from opts.programs_dir or the task's default.
fs::path task_program_path(const Task& task, const SolveOptions& opts, const std::string& name);

// Builds the task's compiled modules (its program, and for change detection the
// wrong program with the answers' trigger) before a solver's clock starts, so
// compile time is never counted as solve time; returns the seconds spent
// compiling (0 for other engines or when every module is cached). A module that
// cannot be built is left for the solver, which reports why.
double prepare_modules(const Task& task, const SolveOptions& opts);
// The programs whose modules prepare_modules builds (whatever the engine): what
// autumnc.distributed compiles once and ships to its workers.
std::vector<std::shared_ptr<const Program>> task_module_programs(const Task& task, const SolveOptions& opts);

class Stopwatch {
 public:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

inline double per_second(double count, double seconds) { return seconds > 0 ? count / seconds : 0.0; }

// A uniformly random action on a `grid`-sized grid: noop with probability 2/10,
// an arrow with `arrows`/10 (split evenly), else a click on a uniform cell.
// Change detection's random policy uses arrows = 4, make-task's episodes 5; the
// draws from `rng` are part of what a seed means, so neither may change.
Action random_action(std::mt19937_64& rng, int grid, int arrows);

}  // namespace autumn::agent
