// plan_shorten — make a found plan shorter without proving anything.
//
// Three passes, each keeping the plan a plan (it reaches the goal on the search
// model, checked by replay):
//  cut:      end the plan at its first goal frame;
//  drop:     remove single actions, last to first, while the goal stays
//            reached; repeat while that helps;
//  shortcut: from each state s_i on the plan, a bounded BFS (plan_bfs.hpp) looks
//            for a later state s_j (by state hash) or a goal state reachable in d
//            steps with i + d < j; the segment is replaced and the search goes on
//            from the same place. d grows from 1 while the BFS stays within a
//            per-state node share (the action count to the power d), so wide
//            action sets search shallow and narrow ones deep.
// Every pass keeps the plan when nothing shorter is found; the node budget and
// the clock bound the shortcut pass. Under the "moves" cost only cut and drop run
// (neither adds a move; a shortcut could).
#pragma once
#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

struct ShortenStats {
  size_t before = 0, after = 0;
  int shortcuts = 0;
  uint64_t nodes = 0;
};

std::vector<Action> shorten_plan(PlanProblem& problem, std::vector<Action> plan, const std::vector<Action>& actions,
                                 const Limit& limit, bool keep_moves, ShortenStats& stats);

}  // namespace autumn::agent
