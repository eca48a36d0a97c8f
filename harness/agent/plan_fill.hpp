// plan_fill — the arrows first, then clicks into the waiting steps.
//
// Where the arrows set a mode that acts on everything (a velocity all blobs
// drift with) and clicks place things, the goal is a moment of a moving world:
// a click's thing ends where the later arrows carry it, so scoring a prefix by
// its noop future (beam, best-first) ranks the right click below the wrong one.
// This strategy splits the plan instead. For a horizon H:
//  1. skeletons: every sequence of H non-click actions (noop and the arrows of
//     the action set), layer by layer, one per distinct state (on a tie, the
//     one with more noops: each noop is a slot a click can take); a layer
//     wider than `layer_width` keeps its best by the goal's rank, ties broken
//     by the rank two noops later with travel (an arrow's effect often shows a
//     step late). One layer serves every horizon. Then the best `skeletons` at
//     layer H by rank, then more noops, then generation order;
//  2. fill: for each skeleton, every click of the action set is tried in
//     every noop slot, each a rollout to step H; the (slot, click)
//     pairs that bring the frame at H nearer the goal are then taken best
//     first, one per slot, each kept only if the whole plan still improves
//     (things placed by clicks rarely interact, so the gains mostly add up).
// A goal frame on the way ends the search with that prefix. Horizons run from
// `first_horizon` up while the limit lasts, so the first plan is also short.
// Example (gravity_3, blobs drift with the velocity the arrows set; the
// generator's 8 actions were click, left, right, up, up, left, click, click):
// at horizon 5 the skeleton up, left, noop, noop, noop brings the first blob to
// its goal cell, and the fill puts clicks 37 24, 8 24 and 29 27 in the three
// waiting steps. Deterministic: pairs are compared in (slot, click) order.
// Tests: tests/agent_test.cpp (AgentPlanning.FillPlacesClicksInADriftingWorld,
// AgentPlanning.FillKeepsTheBestSkeletonsWhenTheLayerIsFull,
// AgentPlanning.SkeletonStageFillsIdleMoves,
// AgentPlanning.SkeletonFillTakesMovesTheGoalDoesNotNeed).
#pragma once
#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

struct FillSpec {
  int first_horizon = 1;
  int last_horizon = 12;
  size_t skeletons = 8;       // skeletons filled per horizon
  size_t layer_width = 4096;  // distinct skeleton states kept per layer
  Limit limit;
};

// `actions`: the skeletons' moves are its non-click actions, the fill's clicks
// its clicks.
SearchOutcome fill_search(PlanProblem& problem, const std::vector<Action>& actions, const FillSpec& spec);

// Step 2 alone, on a skeleton found elsewhere (the planner's skeleton stage),
// judged at its last frame. Every step is a slot: a click may also take the
// place of a move, kept only if the whole plan improves, so moves that change
// nothing (an up at the fastest flow, a left at the wall) or nothing the goal
// shows give way to clicks, and the moves the goal needs keep their places.
SearchOutcome fill_skeleton(PlanProblem& problem, const std::vector<Action>& actions,
                            const std::vector<Action>& skeleton, const Limit& limit);

}  // namespace autumn::agent
