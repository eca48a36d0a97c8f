#include "harness/agent/make_task.hpp"

#include <fmt/core.h>

#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include <map>

#include "compiler/read/output.hpp"
#include "harness/agent/particles.hpp"
#include "harness/agent/smc.hpp"
#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

using nlohmann::json;

namespace {

struct Episode {
  std::vector<Action> actions;
  std::vector<Frame> frames;  // frames[0] after reset, frames[t] after action t
  Palette palette;            // the final palette covers every frame
};

// Runs `steps` random actions. An action under which the program fails is taken
// back (the step runs on a copy) and another one drawn, up to 20 times per step;
// nullopt (with the last error in `error`) when no action goes through. Programs
// that never fail draw exactly the actions they always did.
std::optional<Episode> random_episode(Environment& env, uint64_t env_seed, int steps, std::mt19937_64& rng,
                                      std::string* error = nullptr) {
  Episode ep;
  if (!env.reset(env_seed)) throw TaskError(env.error());
  int grid = env.frame().size;
  ep.frames.push_back(env.frame());
  std::unique_ptr<Environment> cur = env.clone();
  for (int t = 0; t < steps; ++t) {
    bool stepped = false;
    for (int tries = 0; tries < 20 && !stepped; ++tries) {
      Action a = random_action(rng, grid, 5);
      auto next = cur->clone();
      if (!next->step(a)) {
        if (error) *error = next->error();
        continue;
      }
      cur = std::move(next);
      ep.actions.push_back(a);
      ep.frames.push_back(cur->frame());
      stepped = true;
    }
    if (!stepped) return std::nullopt;
  }
  ep.palette = cur->palette();
  return ep;
}

// Makes every colour the episode's frames show a table colour (or fails). Only
// painted colours count: a compiled module's palette also names the program's
// other string literals ("origin" in the stdlib's move helpers).
void cover_colours(const Episode& ep, const std::string& program, bool extend, ColourTable& colours, bool& extended) {
  // In order of first appearance (frames in order, cells row-major), so that
  // both engines extend the table alike.
  std::vector<bool> seen(ep.palette.size());
  std::vector<uint16_t> painted;
  for (const Frame& f : ep.frames)
    for (uint16_t c : f.cells)
      if (!seen[c]) seen[c] = true, painted.push_back(c);
  for (uint16_t i : painted) {
    const std::string& name = ep.palette.name(i);
    if (colours.find(name) >= 0) continue;
    if (!extend)
      throw TaskError(fmt::format("colour '{}' of program '{}' is not in the colour table{} (--extend-colours adds it)",
                                  name, program, colours.source().empty() ? "" : " " + colours.source().string()));
    colours.add(name);
    extended = true;
  }
}

Grid masked(const TaskFrame& f, int size, const std::optional<Rect>& hide) {
  Grid g;
  g.width = g.height = size;
  g.cells.assign(f.begin(), f.end());
  if (hide)
    for (int y = hide->y; y < hide->y + hide->h; ++y)
      for (int x = hide->x; x < hide->x + hide->w; ++x) g.cells[static_cast<size_t>(y) * size + x] = 0;
  return g;
}

// Random candidate rectangles, best first: content that changed since the start
// and since the frame before the masked ones scores, distinct colours break ties.
std::vector<Rect> ranked_rectangles(const std::vector<TaskFrame>& frames, int size, int recent, std::mt19937_64& rng) {
  const TaskFrame& last = frames.back();
  int max_side = std::max(2, std::min(6, size / 2));
  std::vector<std::pair<int, Rect>> scored;
  for (int c = 0; c < 200; ++c) {
    Rect r;
    r.w = 2 + static_cast<int>(rng() % (max_side - 1));
    r.h = 2 + static_cast<int>(rng() % (max_side - 1));
    r.w = std::min(r.w, size), r.h = std::min(r.h, size);
    r.x = static_cast<int>(rng() % (size - r.w + 1));
    r.y = static_cast<int>(rng() % (size - r.h + 1));
    int score = 0;
    std::set<int16_t> distinct;
    for (int y = r.y; y < r.y + r.h; ++y)
      for (int x = r.x; x < r.x + r.w; ++x) {
        size_t i = static_cast<size_t>(y) * size + x;
        score += (last[i] != frames[0][i]) + 2 * (last[i] != frames[recent][i]);
        distinct.insert(last[i]);
      }
    scored.push_back({score * 4 + static_cast<int>(distinct.size()), r});
  }
  // Stable: among equal scores the earlier draw first (as the single best always was).
  std::stable_sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Rect> out;
  for (const auto& [score, r] : scored) out.push_back(r);
  return out;
}

// Masked-region contents -> samples showing them.
using Outcomes = std::map<std::vector<int16_t>, uint64_t>;
constexpr size_t kRectangles = 32;  // best-ranked rectangles tried

// What a blind solver could infer: sequential Monte Carlo over an unknown seed
// (smc.hpp) conditioned on the task's frames before `first_masked` (shared by
// every rectangle: nullptr when the filter finds no explanation)...
std::unique_ptr<SmcSet> unmasked_prefix(const Environment& model, const Episode& ep, const std::vector<TaskFrame>& frames,
                                        int size, int first_masked, uint64_t seed, uint64_t samples, ThreadPool& pool,
                                        const ColourTable& colours) {
  auto smc = std::make_unique<SmcSet>(pool, colours, samples, seed ^ 0xb1d5eedull, /*max_growth=*/8);
  Grid obs;
  FramePredicate keep = [&obs](const TaskFrame& f, int sz) { return consistent(f, sz, obs); };
  for (int t = 0; t < first_masked; ++t) {
    obs = masked(frames[t], size, std::nullopt);
    if (!(t == 0 ? smc->start(model, keep) : smc->step(ep.actions[t - 1], keep))) return nullptr;
  }
  return smc;
}

// ...then on the masked frames with `hide` masked: the final masked contents of
// its samples, or nullopt when nothing explains them.
std::optional<Outcomes> posterior_outcomes(const SmcSet& prefix, const Episode& ep, const std::vector<TaskFrame>& frames,
                                           int size, const Rect& hide, int first_masked) {
  std::unique_ptr<SmcSet> smc = prefix.fork();
  Grid obs;
  FramePredicate keep = [&obs](const TaskFrame& f, int sz) { return consistent(f, sz, obs); };
  for (size_t t = first_masked; t < frames.size(); ++t) {
    obs = masked(frames[t], size, hide);
    if (!smc->step(ep.actions[t - 1], keep)) return std::nullopt;
  }
  Outcomes out;
  for (const SmcSample& s : smc->samples()) out[crop(s.frame, size, hide).cells] += s.count;
  return out;
}

json base_task(const char* type, const MakeTaskOptions& opts) {
  return {{"type", type}, {"program", opts.program.stem().string()}};
}

json base_answers(const MakeTaskOptions& opts) {
  return {{"seed", opts.env_seed},
          {"generator", {{"tool", "autumn make-task"}, {"seed", opts.seed}, {"steps", opts.steps}}}};
}

// The masked rectangle and its answer, and the grids no distractor may equal:
// the answer and what other rollouts show there (`batch`), and for a stochastic
// program what the blind solver's posterior expects there.
struct MaskChoice {
  Rect rect;
  Grid answer;
  std::set<std::vector<int16_t>> taken;
};

MaskChoice choose_mask(const MakeTaskOptions& opts, const Environment& env, const Episode& ep,
                       const std::vector<TaskFrame>& frames, int first_masked, const ParticleSet& batch,
                       std::mt19937_64& rng, ThreadPool& pool, const ColourTable& colours) {
  const int size = ep.frames[0].size, K = opts.steps;
  // Among random candidates, the ones whose content changed most.
  const int recent = std::max(0, K - std::max(1, opts.masked_frames));
  std::vector<Rect> candidates = ranked_rectangles(frames, size, recent, rng);
  MaskChoice m{candidates.front(), crop(frames.back(), size, candidates.front()), {}};
  m.taken = {m.answer.cells};
  if (!env.deterministic()) {
    // A blind solver sees the observations, not the seed: prefer a rectangle whose
    // hidden content they make predictable (see the header).
    double best_share = 0;
    std::unique_ptr<SmcSet> prefix =
        first_masked > 0
            ? unmasked_prefix(env, ep, frames, size, first_masked, opts.seed, opts.posterior_samples, pool, colours)
            : nullptr;
    for (size_t c = 0; prefix && c < candidates.size() && c < kRectangles && best_share < 0.5; ++c) {
      std::optional<Outcomes> out = posterior_outcomes(*prefix, ep, frames, size, candidates[c], first_masked);
      if (!out) continue;
      const Grid a = crop(frames.back(), size, candidates[c]);
      auto it = out->find(a.cells);
      double share = it == out->end() ? 0.0 : static_cast<double>(it->second) / opts.posterior_samples;
      if (share <= best_share) continue;
      best_share = share, m.rect = candidates[c], m.answer = a;
      m.taken = {m.answer.cells};
      for (const auto& [cells, n] : *out) m.taken.insert(cells);
    }
  }
  for (const Particle& p : batch.particles()) m.taken.insert(crop(p.frame, size, m.rect).cells);
  return m;
}

// The colours a distractor's edits draw from: those of the episode, at least two.
std::vector<int16_t> edit_palette(const std::vector<TaskFrame>& frames, const ColourTable& colours) {
  std::vector<int16_t> ids;
  for (const TaskFrame& f : frames)
    for (int16_t c : f)
      if (std::find(ids.begin(), ids.end(), c) == ids.end()) ids.push_back(c);
  std::sort(ids.begin(), ids.end());
  if (ids.size() < 2)
    for (int id = 1; id < colours.table_size() && ids.size() < 2; ++id)
      if (colours.in_table(id) && id != ids[0]) ids.push_back(static_cast<int16_t>(id));
  return ids;
}

// Five distractors, none in `taken`: the rectangle in earlier frames and shifted
// a little in the last, then the answer with one to three cells recoloured.
std::vector<Grid> distractors_for(const std::vector<TaskFrame>& frames, int size, int K, const MaskChoice& m,
                                  const ColourTable& colours, std::mt19937_64& rng) {
  std::set<std::vector<int16_t>> taken = m.taken;
  std::vector<Grid> pool_grids;
  for (int t = K - 1; t >= 0; --t) pool_grids.push_back(crop(frames[t], size, m.rect));
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      Rect s = m.rect;
      s.x += dx, s.y += dy;
      if ((dx || dy) && s.x >= 0 && s.y >= 0 && s.x + s.w <= size && s.y + s.h <= size)
        pool_grids.push_back(crop(frames.back(), size, s));
    }
  std::shuffle(pool_grids.begin(), pool_grids.end(), rng);
  const std::vector<int16_t> palette_ids = edit_palette(frames, colours);
  std::vector<Grid> distractors;
  auto consider = [&](const Grid& g) {
    if (distractors.size() < 5 && taken.insert(g.cells).second) distractors.push_back(g);
  };
  for (const Grid& g : pool_grids) consider(g);
  for (int tries = 0; distractors.size() < 5 && tries < 10000; ++tries) {
    Grid g = m.answer;
    int changes = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < changes; ++k) {
      size_t i = rng() % g.cells.size();
      int16_t c = palette_ids[rng() % palette_ids.size()];
      if (c == g.cells[i]) c = palette_ids[(std::find(palette_ids.begin(), palette_ids.end(), c) - palette_ids.begin() + 1) % palette_ids.size()];
      g.cells[i] = c;
    }
    consider(g);
  }
  if (distractors.size() < 5) throw TaskError("could not build five distinct distractors");
  return distractors;
}

// The observations: each frame, the rectangle hidden from `first_masked` on.
json mfp_observations(const std::vector<TaskFrame>& frames, int size, int K, const Episode& ep, int first_masked,
                      const Rect& rect) {
  json observations = json::array();
  for (int t = 0; t <= K; ++t) {
    std::optional<Rect> hide;
    if (t >= first_masked) hide = rect;
    json o = {{"masked_grid", masked(frames[t], size, hide).to_json()}};
    if (t > 0) o = {{"action", action_to_json(ep.actions[t - 1])}, {"masked_grid", o["masked_grid"]}};
    observations.push_back(o);
  }
  return observations;
}

MadeTask make_mfp(const MakeTaskOptions& opts, std::shared_ptr<const Program> program, ThreadPool& pool,
                  ColourTable colours) {
  MadeTask made;
  std::mt19937_64 rng(opts.seed);
  auto env = make_env_checked(opts.engine, program);
  std::optional<Episode> ep;
  std::string error;
  for (int attempt = 0; attempt < 20 && !ep; ++attempt)
    ep = random_episode(*env, opts.env_seed, opts.steps, rng, &error);
  if (!ep) throw TaskError(fmt::format("program '{}' fails under every random action sequence tried: {}",
                                       opts.program.stem().string(), error));
  cover_colours(*ep, opts.program.stem().string(), opts.extend_colours, colours, made.colours_extended);
  const int size = ep->frames[0].size;
  const int K = opts.steps;
  std::vector<TaskFrame> frames;
  for (const Frame& f : ep->frames) frames.push_back(task_frame(f, ep->palette, colours));

  // The outcomes a batch of rollouts (other seeds, same actions) produce.
  ParticleSet batch(pool, colours);
  std::vector<uint64_t> seeds = rollout_seeds(opts.seed, std::max<uint64_t>(opts.batch, 1), opts.env_seed);
  FramePredicate all = [](const TaskFrame&, int) { return true; };
  batch.start([&] { return env->clone(); }, seeds, env->deterministic(), all);
  for (const Action& a : ep->actions) batch.step(a, all);

  const int first_masked = K - std::max(1, std::min(opts.masked_frames, K + 1)) + 1;
  const MaskChoice mask = choose_mask(opts, *env, *ep, frames, first_masked, batch, rng, pool, colours);
  const std::vector<Grid> distractors = distractors_for(frames, size, K, mask, colours, rng);
  int answer_index = static_cast<int>(rng() % 6);
  json choices = json::array();
  for (int i = 0, d = 0; i < 6; ++i) choices.push_back(i == answer_index ? mask.answer.to_json() : distractors[d++].to_json());
  made.task = base_task("masked_frame_prediction", opts);
  made.task["observations"] = mfp_observations(frames, size, K, *ep, first_masked, mask.rect);
  made.task["choices"] = choices;
  made.answers = base_answers(opts);
  made.answers["correct_idx"] = answer_index;
  made.colours = colours;
  return made;
}

MadeTask make_planning(const MakeTaskOptions& opts, std::shared_ptr<const Program> program, ColourTable colours) {
  MadeTask made;
  std::mt19937_64 rng(opts.seed);
  auto env = make_env_checked(opts.engine, program);
  std::string error;
  // Puzzles that react only to rare inputs (a peg, then the right hole) need many
  // draws; a draw costs K steps.
  const int attempts = 2000;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    std::optional<Episode> ep = random_episode(*env, opts.env_seed, opts.steps, rng, &error);
    if (!ep) continue;
    const Frame& first = ep->frames.front();
    const Frame& goal = ep->frames.back();
    const int size = goal.size;
    if (first.size != size) continue;
    int x0 = size, y0 = size, x1 = -1, y1 = -1;
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x)
        if (ep->palette.name(first.at(x, y)) != ep->palette.name(goal.at(x, y)))
          x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    if (x1 < 0) continue;  // nothing changed: try another sequence
    cover_colours(*ep, opts.program.stem().string(), opts.extend_colours, colours, made.colours_extended);
    x0 = std::max(0, x0 - 1), y0 = std::max(0, y0 - 1), x1 = std::min(size - 1, x1 + 1), y1 = std::min(size - 1, y1 + 1);
    Grid mask;
    mask.width = mask.height = size;
    mask.cells.assign(static_cast<size_t>(size) * size, 0);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) mask.cells[static_cast<size_t>(y) * size + x] = 1;
    Grid goal_grid = masked(task_frame(goal, ep->palette, colours), size, std::nullopt);
    json plan = json::array();
    for (const Action& a : ep->actions) plan.push_back(action_to_json(a));
    made.task = base_task("planning", opts);
    made.task["goal"] = goal_grid.to_json();
    made.task["mask"] = mask.to_json();
    made.answers = base_answers(opts);
    made.answers["reference_plan"] = plan;
    made.colours = colours;
    // The prompt is blind to the seed: a solver simulates seed 0 (solve's
    // assumption), another world than this one when the program draws.
    if (opts.env_seed != 0 && !env->deterministic())
      made.warnings.push_back(fmt::format(
          "warning: {} draws random numbers and this planning task was made with --env-seed {}, which only its "
          "answers file records: a solver simulates seed 0, another world, where this goal may be unreachable "
          "(eval judges plans in the task's own world)",
          opts.program.filename().string(), opts.env_seed));
    return made;
  }
  throw TaskError(fmt::format("no random {}-step action sequence ({} tried) changes the frame of program '{}'{}",
                              opts.steps, attempts, opts.program.stem().string(),
                              error.empty() ? "" : "; some actions made it fail: " + error));
}

bool is_grid(const json& j) {
  return j.is_array() && !j.empty() && j[0].is_array() &&
         std::all_of(j.begin(), j.end(), [](const json& r) {
           return r.is_array() && std::all_of(r.begin(), r.end(), [](const json& c) { return c.is_number(); });
         });
}

void format_value(const json& j, int indent, std::string& out) {
  std::string pad(indent, ' '), inner(indent + 2, ' ');
  if (is_grid(j)) {
    out += "[\n";
    for (size_t i = 0; i < j.size(); ++i) out += inner + j[i].dump() + (i + 1 < j.size() ? ",\n" : "\n");
    out += pad + "]";
  } else if (j.is_object() && !j.empty()) {
    // Task keys in reading order; anything else after them, alphabetically.
    static const std::vector<std::string> order = {"type",  "program", "wrong_program", "seed", "observations",
                                                   "action", "masked_grid", "choices", "answer", "goal",
                                                   "mask", "correct_idx", "reference_plan", "condition", "t_star", "generator"};
    std::vector<std::string> keys;
    for (const auto& k : order)
      if (j.contains(k)) keys.push_back(k);
    for (auto it = j.begin(); it != j.end(); ++it)
      if (std::find(order.begin(), order.end(), it.key()) == order.end()) keys.push_back(it.key());
    out += "{\n";
    for (size_t i = 0; i < keys.size(); ++i) {
      out += inner + json(keys[i]).dump() + ": ";
      format_value(j.at(keys[i]), indent + 2, out);
      out += i + 1 < keys.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (j.is_array() && !j.empty() && (j[0].is_object() || is_grid(j[0]))) {
    out += "[\n";
    for (size_t i = 0; i < j.size(); ++i) {
      out += inner;
      format_value(j[i], indent + 2, out);
      out += i + 1 < j.size() ? ",\n" : "\n";
    }
    out += pad + "]";
  } else {
    out += j.dump();
  }
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

void write_all(const fs::path& p, const std::string& text) {
  if (std::string why = write_file(p, text); !why.empty()) throw TaskError(why);
}

}  // namespace

std::string format_task_json(const json& j) {
  std::string out;
  format_value(j, 0, out);
  return out + "\n";
}

MadeTask make_task(const MakeTaskOptions& in, ThreadPool& pool) {
  MakeTaskOptions opts = in;
  if (opts.kind == "cd") throw TaskError("change-detection tasks are made by make_cd() (make_cd.hpp)");
  if (opts.kind != "mfp" && opts.kind != "planning") throw TaskError("unknown task kind '" + opts.kind + "' (mfp, planning, cd)");
  if (opts.steps < 0) opts.steps = opts.kind == "mfp" ? 20 : 4;
  if (opts.kind == "mfp" && opts.steps < 1) throw TaskError("an MFP task needs --steps >= 1");
  if (opts.kind == "planning" && opts.steps < 1) throw TaskError("a planning task needs --steps >= 1");
  auto program = load_program_checked(opts.program);
  ColourTable colours = opts.out.empty() ? ColourTable() : ColourTable::for_task(opts.out);
  MadeTask made = opts.kind == "mfp" ? make_mfp(opts, program, pool, colours) : make_planning(opts, program, colours);
  made.answers["generator"]["steps"] = opts.steps;
  return made;
}

std::vector<std::string> write_task(const MadeTask& made, const MakeTaskOptions& opts) {
  std::vector<std::string> notes;
  std::string text = format_task_json(made.task);
  if (opts.out.empty()) {
    fmt::print("{}", text);
    if (made.colours_extended) notes.push_back("colours were added to the table; without --out the table is not written");
    if (opts.answers_out.empty()) {
      notes.push_back("the answers (seed, answer) are not kept without --out or --answers");
    } else {
      write_all(opts.answers_out, format_task_json(made.answers));
      notes.push_back("wrote the answers " + opts.answers_out.string());
    }
    return notes;
  }
  fs::path out = opts.out;
  fs::path dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  fs::create_directories(dir);
  write_all(out, text);
  notes.push_back("wrote " + out.string());
  fs::path root = dir.filename() == "prompts" ? dir.parent_path() : dir;
  if (root.empty()) root = ".";
  fs::path answers = opts.answers_out;
  if (answers.empty())
    answers = dir.filename() == "prompts" ? root / "answers" / (out.stem().string() + ".json")
                                          : dir / (out.stem().string() + ".answers.json");
  if (!answers.parent_path().empty()) fs::create_directories(answers.parent_path());
  write_all(answers, format_task_json(made.answers));
  notes.push_back("wrote the answers " + answers.string());
  if (dir.filename() == "prompts") {
    fs::path programs = root / "programs";
    fs::create_directories(programs);
    fs::path copy = programs / opts.program.filename();
    std::string source = read_all(opts.program);
    if (!fs::exists(copy)) {
      write_all(copy, source);
      notes.push_back("copied the program to " + copy.string());
    } else if (read_all(copy) != source) {
      throw TaskError(copy.string() + " exists and differs from " + opts.program.string() + "; not overwriting");
    }
  }
  fs::path dict = root / "color_dict.yaml";
  if (made.colours_extended || (!made.colours.source().empty() && !fs::exists(dict))) {
    write_all(dict, made.colours.to_yaml());
    notes.push_back("wrote the colour table " + dict.string());
  }
  return notes;
}

}  // namespace autumn::agent
