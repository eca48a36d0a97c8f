// plan_local — local search over whole plans, for goals that are one late
// moment of a busy world.
//
// The other strategies grow plans from the front and judge a prefix by what
// its future could still become; where many things must line up at one moment
// (ten plants, each sown so that it shows its stage at step 25; six apples
// caught and two missed), every prefix looks equally far from the goal and
// they search blind. This strategy edits a complete plan of `length` actions
// instead. A plan's score is the goal's rank (Goal::rank, with travel) at its
// best frame, the goal frame ending it. Each round draws `batch` edits from
// the seeded generator — replace one action, insert one (the last falls off),
// delete one (a noop is appended), swap two neighbours; a drawn action is a
// click or a move with even odds — scores them in parallel (each re-run from
// the kept state before the edit), and takes the first best if it scores no
// worse than the plan (so it also walks plateaus). After `patience` rounds
// without a new best it restarts from the best plan with a few random edits.
// Example (garden, seed 0: every unripe plant grows each sunny step): starting
// from 25 noops, the edits put one sowing click after another where the goal
// shows a plant at the stage that click's timing gives, and the ups where the
// goal's sun shows night. Edits are drawn and ranked on the calling thread, in
// draw order, so the result does not depend on --threads. Not shortest: the
// planner shortens what this finds.
// Test: tests/agent_test.cpp (AgentPlanning.LocalSearchLinesUpAMoment).
#pragma once
#include <functional>

#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

struct LocalSpec {
  int length = 32;       // actions in every plan searched
  size_t batch = 32;     // edits scored per round
  int patience = 40;     // rounds without a new best before a restart
  uint64_t seed = 0;     // the agent's --seed
  Limit limit;
  // When given: called with the best plan before each restart that follows a
  // new best, and with the last best when the limit ends the search (if not
  // offered before); true ends the search (a caller that completes plans and
  // has completed this one).
  std::function<bool(const std::vector<Action>&)> offer;
};

// `best`, when given: the best-ranked plan the search held (the starting
// noops at least), for a caller that completes it (the planner's skeleton
// stage, plan_fill.hpp's fill_skeleton).
SearchOutcome local_search(PlanProblem& problem, const std::vector<Action>& actions, const LocalSpec& spec,
                           std::vector<Action>* best = nullptr);

}  // namespace autumn::agent
