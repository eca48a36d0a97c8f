// plan_shorten — make a found plan shorter without proving anything.
//
// Four passes, each keeping the plan a plan (it reaches the goal on the search
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
//  relocate: a click moves into a waiting step: for a click at step j and a
//            noop at step i, the plan without step j and with a click at step
//            i, trying every click position (a click made while things move
//            must land elsewhere to end in the same place); the first
//            position in action order that reaches the goal wins, and the pass
//            repeats (then drop) while it shortens. Cost per (i, j): the clicks
//            times the plan's length in steps. Example (gravity_3, blobs moving
//            with the velocity the arrows set): left, noop, noop, right,
//            click 33 20, click 7 22, click 14 24, click 22 28 becomes
//            left, click, click, right, click, click in two relocations.
// Every pass keeps the plan when nothing shorter is found; the node budget and
// the clock bound the shortcut pass, and a quarter of what is left of them the
// relocate pass. Under the "moves" cost only
// cut, drop and relocate run (none adds a move; a shortcut could).
#pragma once
#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

struct ShortenStats {
  size_t before = 0, after = 0;
  int shortcuts = 0;
  int relocated = 0;  // clicks moved into a waiting step
  uint64_t nodes = 0;
};

std::vector<Action> shorten_plan(PlanProblem& problem, std::vector<Action> plan, const std::vector<Action>& actions,
                                 const Limit& limit, bool keep_moves, ShortenStats& stats);

}  // namespace autumn::agent
