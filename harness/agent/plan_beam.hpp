// plan_beam — layered beam search, for goals that hold at one moment only.
//
// Best-first compares states of different depths, so when the world runs on
// its own clock (snow falls, water rises, sparks fly) it happily sets the
// scene first and then waits for the world to catch up: a plan twice as long
// as needed, and shortening cannot cut it, because the goal frame exists only
// at the step the world reaches it. Here every candidate is compared with the
// others of its own depth: layer t+1 is the `width` best successors of layer
// t, each scored by its noop future (as best-first scores: the best distance
// on the successor's frame and on the frames of up to 2*GRID_SIZE noops after
// it), so a prefix is judged by the goal it could still meet if the agent
// stopped acting now, at the step that meets it best. A goal frame on the
// way ends the search with that prefix and its noops.
//
// With `at_horizon` the score is the distance at one fixed step, max_len: the
// goal of a world that runs on its own clock exists at (about) one moment, and
// a prefix is judged by whether the world it leaves matches the goal then —
// setting the scene early and waiting scores nothing for it. The planner tries
// horizons in increasing order (each a search of its own, cheap when short),
// so the first plan found is also short.
//
// Layer t keeps states distinct by state hash and, among look-alikes, by frame
// and noop-future digest (hidden-state variants would fill the beam). Ties:
// generation order (beam order, then action order), so results do not depend
// on --threads. Not shortest: the planner shortens what this finds. The
// planner runs settled beams at widths 8 and 32, and horizon beams about 2,048
// successors wide a layer (at least 8 states), while its share lasts.
#pragma once
#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

struct BeamSpec {
  size_t width = 8;
  int max_len = 0;          // plans of at most this many actions; look-aheads end there too
  bool at_horizon = false;  // score each candidate by its frame at step max_len exactly
  Limit limit;
};

SearchOutcome beam(PlanProblem& problem, const std::vector<Action>& actions, const BeamSpec& spec);

}  // namespace autumn::agent
