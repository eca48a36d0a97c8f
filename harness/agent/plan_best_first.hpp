// plan_best_first — greedy best-first search, for goals beyond BFS's reach.
//
// Same action sets and state deduplication as BFS; each node's successors are
// generated in parallel; the depth limit is max_plan. Priority: the goal
// distance (Goal::distance, shape before colour) at its best on the successor's
// noop future — the successor itself and the frames it passes while left alone
// (noops until the frame stops changing, at most 2*GRID_SIZE; a goal frame on the
// way ends the search). Things that fall or slide count where they come to rest,
// things that keep moving (a global velocity, endless gravity) where they pass
// the goal, instead of leaving long plateaus. Ties: fewer steps, then first
// generated. With `prune_frames`, successors whose frame and settled frame were
// both already generated are dropped too (hidden-state variants that look alike
// would otherwise flood the plateaus); the planner runs a second pass without
// that pruning when the first fails. With `travel`, Goal::distance's travel
// breaks ties between equal counts (objects drawn towards their goal squares);
// it helps where objects must be walked across plateaus and misleads elsewhere
// (a particle whose colour is nearer is not the one that will land), so the
// planner runs it as a pass of its own. Not shortest: plan_shorten.hpp follows.
// Open nodes keep their environments up to keep_states; the others are replayed
// from the root. Deterministic: successors are merged in action order.
#pragma once
#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

SearchOutcome best_first(PlanProblem& problem, const std::vector<Action>& actions, bool prune_frames, bool travel,
                         const Limit& limit);

}  // namespace autumn::agent
