#include "harness/agent/solve_pictures.hpp"

#include "harness/episode.hpp"
#include "harness/render_images.hpp"

namespace autumn::agent {
namespace {

constexpr DrawOptions kDraw{16, true};
constexpr int kDelayMs = 300;

// A task grid: colour ids through the task's table, id 0 (masked) slate grey.
Picture picture_of_grid(const Grid& g, const ColourTable& colours) {
  Picture p;
  p.width = g.width;
  p.height = g.height;
  for (int16_t id : g.cells) p.rgb.push_back(id == 0 ? kMaskRgb : cell_rgb(colours.name(id)));
  return p;
}

// Frame i captioned "start" or "i: action" (and "(the last)" on the final one).
std::vector<Image> episode_images(const EpisodeFrames& ep) {
  std::vector<Image> images;
  for (size_t i = 0; i < ep.frames.size(); ++i) {
    std::string caption = i == 0 ? "start" : std::to_string(i) + ": " + format_action(ep.actions[i - 1]);
    images.push_back(captioned(draw(picture_of_rows(ep.frames[i]), kDraw), caption));
  }
  return images;
}

EpisodeFrames replay(const std::string& program_name, const Task& task, const SolveOptions& opts,
                     const std::optional<std::string>& trigger, const std::vector<Action>& actions) {
  auto program = load_program_checked(task_program_path(task, opts, program_name), trigger);
  auto env = make_env_checked(opts.engine, program);
  return run_episode(*env, task.env_seed, actions);
}

std::string out_path(const fs::path& dir, const Task& task, const std::string& suffix) {
  fs::create_directories(dir);
  return (dir / (task.name + suffix)).string();
}

}  // namespace

std::vector<std::string> render_plan(const Task& task, const SolveOptions& opts, const PlanResult& r, const fs::path& dir) {
  if (!r.found) return {};
  const EpisodeFrames ep = replay(task.program, task, opts, std::nullopt, r.plan);
  std::vector<Image> frames = episode_images(ep);
  Grid goal = task.goal;
  for (size_t i = 0; i < goal.cells.size(); ++i)
    if (!task.mask.cells[i]) goal.cells[i] = 0;
  const std::string gif = out_path(dir, task, "_plan.gif"), png = out_path(dir, task, "_plan.png");
  write_gif(gif, frames, kDelayMs);
  frames.push_back(captioned(draw(picture_of_grid(goal, task.colours), kDraw), "goal (grey: any colour)"));
  write_png(png, tile(frames, static_cast<int>(std::min<size_t>(frames.size(), 8))));
  return {gif, png};
}

std::vector<std::string> render_mfp(const Task& task, const MfpResult& r, const fs::path& dir) {
  std::vector<Image> observed;
  for (size_t i = 0; i < task.observations.size(); ++i)
    observed.push_back(captioned(draw(picture_of_grid(task.observations[i].grid, task.colours), kDraw),
                                 "observation " + std::to_string(i + 1) + " of " +
                                     std::to_string(task.observations.size())));
  const std::string gif = out_path(dir, task, "_observations.gif");
  write_gif(gif, observed, kDelayMs);
  if (r.choice < 0) return {gif};
  Grid answered = task.observations.back().grid;
  const Grid& choice = task.choices[static_cast<size_t>(r.choice)];
  for (int y = 0; y < choice.height; ++y)
    for (int x = 0; x < choice.width; ++x)
      answered.cells[static_cast<size_t>(task.masked.y + y) * answered.width + task.masked.x + x] = choice.at(x, y);
  const std::string png = out_path(dir, task, "_answer.png");
  write_png(png, tile({captioned(draw(picture_of_grid(task.observations.back().grid, task.colours), kDraw),
                                 "last frame (grey: masked)"),
                        captioned(draw(picture_of_grid(answered, task.colours), kDraw),
                                  "answer: choice " + std::to_string(r.choice))},
                       2, 8));
  return {gif, png};
}

std::vector<std::string> render_cd(const Task& task, const SolveOptions& opts, const CdResult& r, const fs::path& dir) {
  const EpisodeFrames ep = replay(task.wrong_program, task, opts, std::nullopt, r.actions);
  if (ep.frames.empty()) return {};
  const std::string gif = out_path(dir, task, "_detection.gif");
  write_gif(gif, episode_images(ep), kDelayMs);
  return {gif};
}

}  // namespace autumn::agent
