// planning — find actions that bring the environment's frame to the goal on the mask.
//
// The environment starts from reset(task seed) (default 0, the benchmark's). For a
// stochastic program this is the privileged oracle of the AutumnBench paper: the
// planner simulates with the environment's own seed, and says so in its report.
//
// bfs: breadth-first search over the full action set (click_model.hpp: noop,
// four arrows, clicks — merged when the program provably cannot tell click
// positions apart), deduplicating states by state_hash(). Each layer is expanded
// in chunks on the thread pool: a thread copies the parent into a scratch
// environment per action (copy_from), steps and hashes, and keeps only states not
// seen before, as snapshots (save_state) — or as environments, up to keep_states,
// for engines without snapshots (the rest are replayed from the root). The seen
// set is sharded by hash so duplicates are settled in parallel; the winner of a
// duplicate, the first goal and the next layer's order are fixed by (shard,
// parent, action), never by the thread count, so neither is the plan. The first
// goal found is at the shallowest depth: a shortest plan. Limits: --depth,
// --nodes, --time-limit.
//
// best-first: greedy best-first search, same action set and state dedup, each
// node's successors generated in parallel; depth limit max_plan. Priority: the
// distance to the goal on the mask — cells whose "is background" differs first
// (the goal's most common masked colour is its background), then all differing
// cells — at its best on the successor's noop future: the successor itself and
// the frames it passes while left alone (noops until the frame stops changing,
// at most 2*GRID_SIZE; a goal frame on the way ends the search). Things that
// fall or slide count where they come to rest, things that keep moving (a global
// velocity, endless gravity) where they pass the goal. Ties: fewer steps, then
// first generated. A first pass also prunes successors whose frame and settled
// frame were both already generated (hidden-state variants that look alike would
// otherwise flood the plateaus); if it fails, a second pass runs
// without that pruning. The plan is then shortened by dropping single actions
// while the goal stays reached. Not guaranteed shortest. Open nodes keep their
// environments up to keep_states; the others are replayed from the root.
//
// auto (default): bfs with a quarter of the node budget, then best-first with
// the rest. When clicks are told apart by position (a click on every cell, so
// full layers beyond the first are unaffordable), bfs first runs one layer over
// the full action set, then focused stages with clicks only near the cells where
// the goal differs from the initial frame (within 0 cells; clicks whose effect
// reaches those cells under noops; within 1, 3 cells) and then within the mask's
// bounding box, an eighth of the node budget and of the time left each; then
// best-first over the clicks near (within 1) or reaching the changes, then over
// the full action set. A focused plan is the
// shortest among focused plans; it is proven shortest only when it is at most
// one action longer than the deepest full layer searched.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

struct PlanResult {
  bool found = false;
  std::vector<Action> plan;
  std::string method;           // "bfs", "bfs, clicks within ..." or "best-first" (which search found the plan)
  bool shortest = false;        // the plan is provably shortest (bfs found it)
  std::string note;             // why a search stopped
  int bfs_depth_done = 0;       // BFS layers fully explored
  uint64_t nodes = 0;           // successor states generated (one environment step each)
  uint64_t lookahead_steps = 0; // best-first: noop steps of the settling look-ahead
  uint64_t distinct = 0;        // distinct states seen
  size_t actions = 0;           // size of the action set
  std::string click_use;
  bool stochastic = false;
  uint64_t env_seed = 0;
  bool verified = false;        // the plan replays on a fresh environment to the goal
  double seconds = 0;           // the whole solve: loading, set-up, search, verification
  double search_seconds = 0;    // the searches alone (what nodes/s figures of the search use)
  bool exhausted = false;       // a search saw every reachable state within its limits
  bool timed_out = false;       // the time limit stopped a search
};

PlanResult solve_planning(const Task& task, const SolveOptions& opts, ThreadPool& pool);
// Replays `plan` from reset(task seed); true when some frame on the way (the
// initial one included) matches the goal on the mask.
bool plan_reaches_goal(const Task& task, const SolveOptions& opts, const std::vector<Action>& plan);
nlohmann::json planning_json(const PlanResult& r);
std::string planning_summary(const PlanResult& r);

}  // namespace autumn::agent
