#include "harness/episode.hpp"

namespace autumn {

EpisodeFrames run_episode(Environment& env, uint64_t seed, const std::vector<Action>& actions,
                          const FrameCallback& on_frame) {
  EpisodeFrames ep;
  auto keep = [&](const std::string& label) {
    ep.frames.push_back(frame_rows(env.frame(), env.palette()));
    if (on_frame) on_frame(ep.frames.size() - 1, label, ep.frames.back());
  };
  if (!env.reset(seed)) {
    ep.error = env.error();
    return ep;
  }
  ep.grid = env.frame().size;
  keep("start");
  for (const Action& a : actions) {
    if (!env.step(a)) {
      ep.error = env.error();
      break;
    }
    ep.actions.push_back(a);
    ep.triggers.push_back(env.triggered());
    keep(format_action(a));
  }
  return ep;
}

}  // namespace autumn
