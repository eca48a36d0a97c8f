// autumn render — an episode as pictures: an animated GIF (one frame per step)
// or a PNG strip of the frames, in the benchmark's colours
// (harness/render_images.hpp). Same episode options as `autumn run`.
#include <iostream>

#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/engine.hpp"
#include "harness/episode.hpp"
#include "harness/render_images.hpp"

namespace autumn::cli {
namespace {

struct RenderOptions {
  std::string program;
  uint64_t seed = 0;
  std::string actions;
  std::string actions_file;
  int steps = -1;
  std::string out;
  int scale = 16;
  bool grid_lines = false;
  int delay_ms = 250;
  int columns = 8;
  std::string engine = "interp";
};

bool has_suffix(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void register_render(CLI::App* cmd, RenderOptions& o) {
  cmd->add_option("PROGRAM", o.program, "Autumn program (.au or .sexp)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--seed", o.seed, "Interpreter seed (the benchmark's default is 0)")->default_val(0)->check(seed_number());
  auto* acts = cmd->add_option("--actions", o.actions, "Comma-separated actions: noop, left, right, up, down, click X Y");
  cmd->add_option("--actions-file", o.actions_file, "File with one action per line ('#' comments)")->excludes(acts);
  cmd->add_option("--steps", o.steps, "Number of steps (missing actions are noop)")->check(int_count());
  cmd->add_option("--out", o.out, "FILE.gif (animated, one frame per step) or FILE.png (a strip of all frames)")
      ->required()
      ->check([](const std::string& p) {
        return has_suffix(p, ".gif") || has_suffix(p, ".png") ? "" : "--out must end in .gif or .png";
      });
  cmd->add_option("--scale", o.scale, "Pixels per cell side")->default_val(16)->check(CLI::Range(1, 256));
  cmd->add_flag("--grid-lines", o.grid_lines, "Draw a dark line between cells");
  cmd->add_option("--delay-ms", o.delay_ms, "GIF: time each frame is shown")->default_val(250)->check(CLI::Range(10, 60000));
  cmd->add_option("--columns", o.columns, "PNG: frames per row of the strip")->default_val(8)->check(CLI::Range(1, 1000));
  cmd->add_option("--engine", o.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");
}

// The pictures' pixels are held in memory (every frame, and for PNG the strip
// too): checked before any is drawn, so a large grid at a large --scale is a
// one-line reason rather than an out-of-memory abort.
constexpr int64_t kMaxPixels = int64_t{1} << 27;  // 134M pixels, about 400 MB of RGB
constexpr int64_t kMaxGifSide = 65535;             // the format's 16-bit width and height

std::string picture_size_error(const RenderOptions& o, int grid, size_t frames) {
  const int64_t side = int64_t{grid} * o.scale + (o.grid_lines ? 1 : 0);
  const bool gif = has_suffix(o.out, ".gif");
  const int64_t copies = gif ? 1 : 2;  // a PNG also holds the strip
  const std::string what = std::to_string(grid) + "x" + std::to_string(grid) + " grid at --scale " +
                           std::to_string(o.scale) + " makes " + std::to_string(side) + "x" + std::to_string(side) +
                           "-pixel frames";
  if (gif && side + kCaptionHeight > kMaxGifSide)
    return what + "; a GIF frame is at most " + std::to_string(kMaxGifSide) + " pixels a side (lower --scale)";
  if (side * (side + kCaptionHeight) > kMaxPixels / copies / static_cast<int64_t>(std::max<size_t>(frames, 1)))
    return what + ", " + std::to_string(frames) + " of them: more than " + std::to_string(kMaxPixels) +
           " pixels in all (lower --scale or --steps)";
  return {};
}

void write_pictures(const RenderOptions& o, const EpisodeFrames& ep) {
  if (std::string why = picture_size_error(o, ep.grid, ep.frames.size()); !why.empty()) throw std::runtime_error(why);
  std::vector<Image> images;
  for (size_t i = 0; i < ep.frames.size(); ++i)  // each frame captioned with the action that led to it
    images.push_back(captioned(draw(picture_of_rows(ep.frames[i]), {o.scale, o.grid_lines}),
                               i == 0 ? "start" : std::to_string(i) + ": " + format_action(ep.actions[i - 1])));
  if (has_suffix(o.out, ".gif")) write_gif(o.out, images, o.delay_ms);
  else write_png(o.out, tile(images, o.columns));
}

int run_render(const RenderOptions& o) {
  auto actions = read_actions("render", o.actions, o.actions_file, o.steps);
  if (!actions) return kExitUsage;  // the flags' value, not the program: a usage error
  auto program = load_or_report(o.program, std::nullopt);
  if (!program) return kExitFailed;
  auto env = make_env("render", o.engine, program);
  if (!env) return kExitFailed;
  // A grid whose every frame is too large is refused before the episode runs
  // (a 4096x4096 grid's frames as rows of colour names are 16M strings each).
  if (env->reset(o.seed))
    if (std::string why = picture_size_error(o, env->frame().size, 1); !why.empty()) {
      std::cerr << "autumn render: " << why << "\n";
      return kExitFailed;
    }
  EpisodeFrames ep = run_episode(*env, o.seed, *actions);
  if (ep.grid) warn_clicks_outside("render", *actions, ep.grid);
  if (!ep.frames.empty()) {
    try {
      write_pictures(o, ep);
    } catch (const std::exception& e) {
      std::cerr << "autumn render: " << e.what() << "\n";
      return kExitFailed;
    }
    std::cerr << "autumn render: wrote " << o.out << " (" << ep.frames.size() << " frame"
              << (ep.frames.size() == 1 ? "" : "s") << ", " << ep.grid << "x" << ep.grid << " cells)\n";
  }
  if (!ep.ok()) {
    std::cerr << ep.error << "\n";
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace

Subcommand add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Draw an episode: an animated GIF or a PNG strip of its frames");
  register_render(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [o] { return run_render(*o); }};
}

}  // namespace autumn::cli
