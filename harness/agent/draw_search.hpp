// draw_search — random numbers under which a program's start-up shows an
// observed frame.
//
// Some programs draw their whole first frame at random (breakout's gapped wall,
// color_flood's 63 tiles of five colours). The chance that a fresh seed
// reproduces such a frame is about 5^-63, so a filter that proposes start states
// from seeds (smc.hpp) finds none, however many it tries. The observation tells
// much more than accept/reject, though: how many cells disagree. This search
// works on the random numbers themselves (a draw script, runtime/rng.hpp): it
// fixes every draw of reset(), then changes one draw at a time to the value that
// leaves the fewest disagreeing cells (coordinate descent), sweeping until the
// frame agrees or a sweep changes nothing. A draw that picks one of two cells
// coordinates (x then y) may need both changed at once: when a sweep is stuck,
// adjacent draws are tried in pairs. Several starts from different random draw
// vectors give different explanations when the frame leaves part of the state
// hidden.
//
// Example: color_flood's start-up draws 63 colours (bound 5). From random values
// about 50 cells disagree; one sweep tries 63 x 4 values and ends with none.
//
// A step can draw a whole new layout too (color_flood deals a new board on
// `down`): the same descent then runs on the draws of one step from each of a
// few parent states.
//
// Deterministic: starts are seeded from `seed` in order and run in parallel,
// results are kept in start order. Tests: AgentDrawSearch.* in tests/agent_test.cpp.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "harness/agent/task_file.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

struct DrawSearchStats {
  uint64_t resets = 0;  // start-ups run
  int starts = 0;       // descents begun
  int found = 0;        // descents that reached an agreeing frame
};

// Distinct (by state_hash) start states, reset() under draw scripts, whose frame
// is consistent with `first`; empty when no descent reaches one or the
// environment does not support draw scripts. The states carry no script.
std::vector<std::unique_ptr<Environment>> search_start_draws(ThreadPool& pool, const Environment& model,
                                                             const ColourTable& colours, const Grid& first,
                                                             uint64_t seed, int starts, DrawSearchStats& stats);

// The same for one step: distinct states, each a parent stepped by `action`
// under a draw script (one descent per parent), whose frame is consistent with
// `obs`.
std::vector<std::unique_ptr<Environment>> search_step_draws(ThreadPool& pool,
                                                            const std::vector<const Environment*>& parents,
                                                            const Action& action, const ColourTable& colours,
                                                            const Grid& obs, uint64_t seed, DrawSearchStats& stats);

// One explanation of a whole observed episode, for seed inversion
// (seed_inversion.hpp): the values of every draw from reset() on, in order (one
// script spans the episode, as one generator stream does), their bounds, and
// which values the frames pin down (no other value of that draw alone keeps
// every frame agreeing). Built observation by observation: the draws a step
// adds are chosen by coordinate descent with the earlier ones fixed. nullopt
// when some observation is not explained or the work exceeds a budget of
// episode replays.
struct DrawExplanation {
  std::vector<int64_t> values;
  std::vector<uint64_t> bounds;
  std::vector<bool> pinned;
  uint64_t env_steps = 0;  // resets + steps run
};
std::optional<DrawExplanation> explain_episode_draws(const Environment& model, const ColourTable& colours,
                                                     const std::vector<Observation>& observations, uint64_t seed);

}  // namespace autumn::agent
