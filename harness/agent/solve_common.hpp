// solve_common — options and shared helpers of the three task solvers.
//
// The options' defaults and the names each string option takes are decided
// here once: the CLI (harness/cli/agent_options), the Python package
// (autumnc.solve, autumnc.distributed, through _core._solve_defaults) and the
// solvers' own refusals all read them.
#pragma once
#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

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

// The names the string options take (the first of each is its default where a
// user meets it).
const std::vector<std::string>& search_names();    // auto, bfs, best-first, beam, fill, local, skeleton, paper
const std::vector<std::string>& policy_names();    // novelty, random
const std::vector<std::string>& cost_names();      // steps, moves
const std::vector<std::string>& protocol_names();  // default, paper
// "" when `value` is one of `names`, else "unknown OPTION 'value' (a, b, ...)".
std::string unknown_name(const std::string& option, const std::string& value, const std::vector<std::string>& names);

// The options as `autumn solve` and autumnc.solve start from under `protocol`:
// "default" is SolveOptions{} on the compiled engine with a 120 s planning
// limit; "paper" the AutumnBench paper's simulator agent (10,000 samples
// without seed inversion, random exploration, BFS over ten actions to depth
// 10), which sets only rollouts, seed_inversion, policy, search and depth.
// Throws std::invalid_argument for another protocol.
SolveOptions protocol_options(const std::string& protocol);

// The options by their user-facing names (engine, rollouts, seed_inversion,
// policy, search, depth, seed, max_steps, nodes, cost, max_plan, keep_states,
// time_limit), and back: keys missing from `j` keep `base`'s value; "programs"
// and "answers" (strings, "" or null for none) set the folders.
nlohmann::json solve_options_json(const SolveOptions& o);
SolveOptions solve_options_from_json(const nlohmann::json& j, SolveOptions base);

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
