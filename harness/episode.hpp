// episode — one episode under the host protocol, frame by frame.
//
// reset(seed), then one step (and host render) per action; after each frame the
// callback sees it in the trace format (rows of colour names), so commands can
// stream frames as they come (run) or keep them (render, solve --render). A
// runtime error ends the episode: the frames so far stay, and `error` says why.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "runtime/action.hpp"
#include "runtime/environment.hpp"

namespace autumn {

struct EpisodeFrames {
  int grid = 0;                                  // GRID_SIZE after reset (0 if start-up failed)
  std::vector<std::vector<std::string>> frames;  // frames[0] after reset, frames[i] after action i
  std::vector<Action> actions;                   // the actions that ran
  std::vector<bool> triggers;                    // after each action
  std::string error;                             // empty when every action ran
  bool ok() const { return error.empty(); }
};

// on_frame(index, label, rows): label is "start" or the action's text form.
using FrameCallback = std::function<void(size_t, const std::string&, const std::vector<std::string>&)>;

EpisodeFrames run_episode(Environment& env, uint64_t seed, const std::vector<Action>& actions,
                          const FrameCallback& on_frame = {});

}  // namespace autumn
