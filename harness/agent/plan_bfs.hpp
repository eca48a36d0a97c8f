// plan_bfs — breadth-first search by cost layers: the planner's exact strategy.
//
// Layer k holds the states first reached at cost k. An action costs 1, or 0 when
// `free` says so (noop under the "moves" cost: waiting is free); the successors
// of a free action join the layer being expanded, the others the next one. With
// every action costing 1 this is plain BFS by depth; either way the first layer
// holding a goal state gives a cheapest plan (states are deduplicated by
// state_hash(), the first occurrence wins). `max_steps` caps a plan's length
// (free actions included: a clock that ticks forever would make a layer endless).
//
// Parallel, deterministic: each layer is expanded in chunks of parents, three
// phases per chunk:
//  expand: each parent is expanded by one thread; per action it copies the parent
//    into the thread's scratch environment (copy_from: no allocation), steps and
//    hashes. A state seen in an earlier chunk (the shared sets, read-only now) or
//    earlier in the same thread's share of this chunk is dropped on the spot; new
//    ones are tested, saved as a snapshot into the thread's byte buffer (or kept
//    as an environment when the engine has no snapshots, up to keep_states; the
//    rest are replayed from the start), and listed under their hash's shard.
//    A state is saved only if it may be expanded: not at the depth limit, and
//    not in the next layer when there is none (max_cost), when the node budget
//    ends before it, or, roughly, beyond the entries of it the budget reaches
//    (BfsOutcome::stored counts what was saved; a parent not saved is replayed).
//  dedup: per shard, the threads' lists are merged in (parent, action) order and
//    inserted into that shard's seen set: the first occurrence wins.
//  place: winners become nodes and frontier entries, shard by shard at offsets
//    fixed beforehand.
// Which state wins, the first hit (lowest (parent, action) among winners) and the
// frontier's order (shard, then (parent, action)) do not depend on the thread
// count, so neither does the plan.
//
// Hits: the goal, and (shortcut search, plan_shorten.hpp) states whose hash is in
// `targets`. A hit at the start state counts at cost 0.
#pragma once
#include <absl/container/flat_hash_map.h>

#include <atomic>

#include "harness/agent/plan_problem.hpp"

namespace autumn::agent {

struct BfsSpec {
  std::vector<Action> actions;
  std::vector<uint8_t> free;  // per action; empty: every action costs 1
  int max_cost = 12;
  int max_steps = 1 << 30;
  Limit limit;
  const Environment* start = nullptr;  // default: the problem's root
  bool goal = true;                    // stop at goal states
  const absl::flat_hash_map<uint64_t, int>* targets = nullptr;
};

struct BfsOutcome : SearchOutcome {
  int target = -1;  // the value of the target hit, when a target (not the goal) was hit
  int cost = 0;     // of the plan found
  uint64_t stored = 0;  // states kept for expansion (snapshots or environments), the root included
};

BfsOutcome bfs(PlanProblem& problem, const BfsSpec& spec);

// Tests only: store every state of the next layer while the budget reaches it
// at all, instead of those of the entries it can expand (plan_bfs.cpp,
// next_shards_to_store), to show that the two searches are the same.
extern std::atomic<bool> bfs_store_every_state_for_testing;

// Tests only: the workers searches keep for the next search (plan_bfs.cpp,
// take_workers), and dropping them.
size_t bfs_kept_workers_for_testing();
void bfs_drop_kept_workers_for_testing();

}  // namespace autumn::agent
