// change_detection — act in the changed environment and report the first step
// whose observation the original program cannot explain.
//
// The environment (the world) is the task's wrong_program (with the answers'
// trigger condition loaded when scoring, exactly as the benchmark runs it), reset
// with the answers' seed when an answers file is given, else the task's (default
// 0). The agent never reads that seed. Its model of the ORIGINAL program is the
// exact episode under the stated seed (the task's, else 0) while that explains
// every observation; a deterministic program then differs at the change. For a
// stochastic program, sequential Monte Carlo over an unknown seed (smc.hpp,
// --rollouts samples) takes over, filtered over the whole history, and is filtered
// afresh once more whenever all its samples die. The detection step is the first
// step no model explains (0 if the initial frame already differs).
//
// Policies: "random" — seeded noop/arrows/clicks; "novelty" (default) — for each
// candidate action (noop, the four arrows, one or more clicks) predict the next
// frame with the lowest-index particle and take the action whose predicted frame
// has been observed least often (ties: the kind of action used least so far, then
// the seeded RNG).
//
// Scoring (only with a trigger condition). After step N, triggered() reports the
// condition on the state BEFORE step N's updates (autumn-semantics §13). Here
// t* is the index of the first STATE on which the condition holds: the state after
// step t* (t* = 0 is the initial state), i.e. t* = N - 1 for the first step N whose
// triggered() is true. The changed program first differs in that state, so an
// observation can first differ at step t*. To learn the condition on the last
// states, the episode is continued on a clone with at most two noop steps; when it
// has not held by then, t* is later than detection + 1 and the score is 0.
// score(t) = 0 if t < t*-1; 1 if t in {t*-1, t*}; else 1.377 f(t) - 1.178 with
// f(t) = 1 / (1 - (t/t*) e^(-t/t*)) (for t* = 0 the limit f = 1).
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

struct CdResult {
  std::optional<int> detected;  // detection step, or none within max_steps
  int steps = 0;                // steps taken in the environment
  std::vector<Action> actions;
  std::string policy;
  bool deterministic = false;   // of the original program
  uint64_t particles = 0;       // samples of the Monte Carlo filter (stochastic programs)
  uint64_t world_seed = 0;      // the environment's seed (answers file, else the task's)
  bool exact_consistent = true; // the stated-seed episode explained every observation
  double smc_ess_min = -1;      // effective particles, minimum over the filters' steps (-1: no filter)
  int smc_restarts = 0;         // filters started over the whole history
  size_t peak_particles = 0;
  uint64_t env_steps = 0;       // particle + policy-prediction steps
  std::string env_error;        // the changed program failed (episode ended)
  std::string trigger;          // empty when not scored
  std::optional<int> t_star;
  std::optional<double> score;
  double seconds = 0;
};

double cd_score(int t, int t_star);
CdResult solve_cd(const Task& task, const SolveOptions& opts, ThreadPool& pool);
nlohmann::json cd_json(const CdResult& r);
std::string cd_summary(const CdResult& r);

}  // namespace autumn::agent
