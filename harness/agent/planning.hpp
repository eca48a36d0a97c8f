// planning — find the fewest actions that bring the frame to the goal on the mask.
//
// The planner simulates the task's program from reset(seed) with the seed the
// task states, else 0 — the benchmark's; it never reads an answers file. A plan
// is open-loop, so for a stochastic program it holds for that seed only (the
// report says so).
//
// Cost: "steps" (default) counts every action; "moves" counts actions other than
// noop (waiting is free; the benchmark's optimal_actions_count for the public ice
// task counts this way). Plans are capped at max_plan steps either way.
//
// Strategies (one file each, each with its account): plan_bfs (exact, by cost
// layers), plan_beam (layered beam, scored by the settled future or at a fixed
// horizon), plan_best_first (greedy, for goals beyond BFS's reach), plan_shorten
// (cut, drop, shortcut and click-relocation passes on a found plan), plan_fill
// (the arrows first, then clicks into their waiting steps). They share plan_problem: the
// search model (clicks that change nothing merge with noop when `click` is
// step-local), the one goal test, the action set, the one clock.
//
// --search auto (default), in order, each stage on a share of what is left (the
// sequence is data: kAutoStages in planning.cpp, printed in docs/design.md):
//  1. BFS over the full action set (half the budget; a tenth when clicks are
//     told apart by position, whose layers are wide). A plan found here is
//     proven cheapest; otherwise no plan costs <= the layers searched
//     ("proven_bound").
//  2. Clicks told apart by position: BFS stages with clicks only near the cells
//     where the goal differs from the start (on them; clicks whose effect reaches
//     them under noops; within 1 and 3 cells; the goal region), each joined by
//     the mode clicks (clicks that show nothing but change what a later click
//     does: a tool button), an eighth of the budget each. A plan here is proven
//     cheapest when it costs at most proven_bound + 1.
//  3a. Cost "steps", clicks told apart by position, and arrows in the action
//     set: plan_fill (a quarter), horizons from proven_bound + 1 to 12, for
//     worlds whose arrows set a mode (a velocity) that placed things follow.
//  3. Cost "steps": BFS by moves (noop free) over the same actions, for goals
//     reached by a few actions and a long wait (things that fall, grow, drift).
//  4. Beam search scored by the settled future (a tenth), over clicks near or
//     reaching the changes when clicks are positional.
//  4a. Where 3a ran: plan_fill again (half), on the horizons after the last one
//     3a tried, up to --max-plan, for goals that are a late moment of a moving
//     world (snow piling up in one column while the clicks place rocks).
//  4b. Local search over whole plans of 32 actions (plan_local; 0.8 of what is
//     left), then of 64 except where 3a ran, then over plans one shorter than
//     the best found. Until 4b or 4c runs, the stages before keep back a node
//     reserve of 0.4 of the budget and half the time limit for them.
//  4c. Where 3a ran: a skeleton (local search over the non-click actions),
//     whose best skeletons are offered, as it goes, to plan_fill's
//     fill_skeleton, which puts clicks into their steps: a moving world's
//     moment plus things clicks placed.
//  5. Best-first (pruning look-alike states; then with travel breaking ties, so
//     objects are drawn towards their goal squares; then neither), over the
//     same clicks first, then all actions.
//  6. A plan from stages 3–5 is long when the goal exists at one moment that it
//     reached late (a world on its own clock): beam searches scored at a fixed
//     horizon, horizons from proven_bound + 1 up, replace it with the first
//     shorter plan they find.
// A plan from stages 3–6 (3a to 4c included) goes through plan_shorten; the result is replayed on the
// program itself (not the search model) to the goal: `verified`.
// --search paper (what --protocol paper selects) is the paper's simulator agent:
// BFS by steps over paper_action_set() to depth --depth, nothing else.
// --search bfs runs stage 1 alone with the whole budget, --search best-first stage
// 5 over all actions, --search beam stages 4 (on half) and 6, --search fill stage
// 3a with the whole budget, on horizons up to --max-plan, --search local and
// --search skeleton stages 4b and 4c with the whole budget.
// Results do not depend on --threads; only a time limit can make them depend on
// the machine.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

struct PlanResult {
  bool found = false;
  std::vector<Action> plan;
  std::string cost = "steps";   // what the search minimised
  std::string method;           // the stage that found the plan
  bool shortest = false;        // proven cheapest under `cost`
  int proven_bound = 0;         // no plan costs <= this (from full BFS layers); meaningful when !shortest
  std::string note;             // why stages stopped
  int bfs_depth_done = 0;       // full-action BFS layers completely searched
  uint64_t nodes = 0;           // successor states generated (environment steps), all stages
  uint64_t lookahead_steps = 0; // best-first: noop steps of the settling look-ahead
  uint64_t distinct = 0;        // distinct states seen, summed over stages
  size_t actions = 0;           // size of the full action set
  std::string click_use;
  std::string model;            // "program" or "click-reset model"
  std::string model_note;       // why the click-reset model was not used
  size_t found_length = 0;      // before shortening
  int shortcuts = 0;
  int relocated = 0;             // clicks moved into waiting steps by shortening
  bool stochastic = false;
  uint64_t env_seed = 0;
  bool verified = false;        // the plan replays on the program (fresh environment) to the goal
  double seconds = 0;           // the whole solve
  double search_seconds = 0;    // the searches alone (what nodes/s figures of the search use)
  bool exhausted = false;       // the full BFS saw every reachable state within its limits
  bool timed_out = false;       // the time limit stopped a search
};

PlanResult solve_planning(const Task& task, const SolveOptions& opts, ThreadPool& pool);
// The --search auto stages in order (what docs/design.md's table lists): a
// stage's name, when it applies, its share of what is left when it starts, and
// its role ("decisive": its plan ends the search; "search": once a plan is found
// only "polish" stages follow).
struct PlanStageRow {
  std::string name, when;
  double share;
  std::string role;
};
std::vector<PlanStageRow> auto_plan_stages();

// --search paper: the actions the paper's BFS tries from every state (breadth
// kPaperBreadth): noop, the four arrows, and clicks on distinct cells drawn
// uniformly with `seed` to make up the ten.
constexpr int kPaperBreadth = 10;
std::vector<Action> paper_action_set(int grid, uint64_t seed);
// Replays `plan` on the task's program from reset(task seed); true when some
// frame on the way (the initial one included) matches the goal on the mask.
bool plan_reaches_goal(const Task& task, const SolveOptions& opts, const std::vector<Action>& plan,
                       uint64_t env_seed);
inline bool plan_reaches_goal(const Task& task, const SolveOptions& opts, const std::vector<Action>& plan) {
  return plan_reaches_goal(task, opts, plan, task.env_seed);
}
nlohmann::json planning_json(const PlanResult& r);
std::string planning_summary(const PlanResult& r);

}  // namespace autumn::agent
