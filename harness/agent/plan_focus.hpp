// plan_focus — smaller click sets for programs that tell click positions apart.
//
// A click on every cell makes BFS layers hundreds of states wide; what a click
// changes is usually near it. These sets keep the non-click actions and only
// some clicks, in the full set's order:
//  near(cells, r):   clicks within Chebyshev distance r of one of `cells`
//                    (with `box`, of their bounding box);
//  reaching(cells):  clicks whose effect, from the root under noops, reaches one
//                    of `cells` within 2*GRID_SIZE steps (not only within the BFS
//                    depth: the stages after BFS wait): a frame differs from the
//                    noop baseline's there (a falling block lands, a fill spreads,
//                    a thrown rock breaks a bottle across the grid);
//  hidden(cells, max): mode clicks: clicks that change nothing on screen but
//                    change what a click on the first of `cells` then does (a
//                    mode button: the next clicks place another thing). One
//                    click per distinct probe result, none when there are more
//                    than `max` kinds; joined to every focused set, whose
//                    clicks may need a mode first. (The state alone cannot tell:
//                    a program that keeps the last click differs after every one.)
//  unite(a, b):      the actions of either.
// `cells` is normally Goal::differing(root frame): where the goal differs from
// the start. A plan over a focused set is the cheapest among such plans only.
#pragma once
#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

std::vector<Action> near_clicks(const PlanProblem& p, const std::vector<Action>& all,
                                const std::vector<uint32_t>& cells, int r, bool box);
std::vector<Action> reaching_clicks(PlanProblem& p, const std::vector<Action>& all, const std::vector<uint32_t>& cells);
std::vector<Action> hidden_clicks(PlanProblem& p, const std::vector<Action>& all, const std::vector<uint32_t>& cells,
                                  size_t max = 16);
// The clicks of `all`, in order.
std::vector<Action> clicks_of(const std::vector<Action>& all);
std::vector<Action> unite(const std::vector<Action>& all, const std::vector<Action>& a, const std::vector<Action>& b);

}  // namespace autumn::agent
