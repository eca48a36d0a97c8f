#include "harness/agent/plan_problem.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <unordered_map>

namespace autumn::agent {

// ---------------------------------------------------------------------------- goal

Goal::Goal(const Task& task) : task_(task) {
  std::unordered_map<int16_t, int> counts;
  for (size_t i = 0; i < task.goal.cells.size(); ++i)
    if (task.mask.cells[i]) {
      ++counts[task.goal.cells[i]];
      mask_.push_back(static_cast<uint32_t>(i));
    }
  int best = -1;
  for (const auto& [c, n] : counts)
    if (n > best || (n == best && c < background_)) best = n, background_ = c;
  order_ = mask_;
}

bool Goal::reached(const TaskFrame& f) const {
  if (f.size() != task_.mask.cells.size()) return false;
  for (uint32_t i : order_)
    if (f[i] != task_.goal.cells[i]) return false;
  return true;
}

// Cell by cell (Environment::frame_cell): most frames differ at the first cells
// of order_, and a compiled engine then copies no frame. Reading a cell may name
// a colour, so the palette's mapping is asked after each read (cached by version).
bool Goal::reached(const Environment& e, FrameColours& colours) const {
  const size_t side = static_cast<size_t>(std::max(e.frame_side(), 0));
  if (side * side != task_.mask.cells.size()) return false;
  for (uint32_t i : order_) {
    const uint16_t id = e.frame_cell(i);
    if (colours.ids(e.cell_palette(), task_.colours)[id] != task_.goal.cells[i]) return false;
  }
  return true;
}

Goal::Dist Goal::distance(const TaskFrame& f, bool with_travel) const {
  Dist d;
  if (f.size() != task_.mask.cells.size()) return {cells() + 1, cells() + 1};  // GRID_SIZE changed
  for (uint32_t i : mask_) {
    const int16_t g = task_.goal.cells[i];
    if (g != f[i]) {
      ++d.colour;
      if ((g == background_) != (f[i] == background_)) ++d.shape;
    }
  }
  if (with_travel && d.colour > 0) d.travel = travel(f);
  return d;
}

// A differing cell's travel is its step distance (4-neighbour steps, no
// obstacles) to the nearest frame cell showing its goal colour, capped at
// travel_cap(). On an open grid that distance is the Manhattan distance to the
// nearest such cell, and it is never above (w - 1) + (h - 1), below the cap. So
// per wanted colour: when there are few targets and sources, the minimum over
// their pairs; else a two-pass city-block distance transform, which gives the
// same minimum for every cell at once (a breadth-first search would too, at
// several times the cost: this is the planner's hottest function in local
// search). Test: tests/agent_test.cpp (AgentPlanning.TravelIsTheStepDistance).
int64_t Goal::travel(const TaskFrame& f) const {
  const int w = task_.goal.width, h = task_.goal.height;
  struct Want {
    int16_t colour;
    std::vector<uint32_t> targets, sources;
  };
  thread_local std::vector<Want> wanted;
  thread_local std::vector<int> dist;
  size_t used = 0;  // wanted[0, used) are this call's; their vectors keep their capacity
  for (uint32_t i : mask_) {
    const int16_t g = task_.goal.cells[i];
    if (g == f[i] || g == background_) continue;
    size_t k = 0;
    while (k < used && wanted[k].colour != g) ++k;
    if (k == used) {
      if (used == wanted.size()) wanted.emplace_back();
      wanted[used].colour = g;
      wanted[used].targets.clear();
      wanted[used].sources.clear();
      ++used;
    }
    wanted[k].targets.push_back(i);
  }
  if (used == 0) return 0;
  for (uint32_t i = 0; i < f.size(); ++i)
    for (size_t k = 0; k < used; ++k)
      if (f[i] == wanted[k].colour) wanted[k].sources.push_back(i);
  int64_t total = 0;
  for (size_t k = 0; k < used; ++k) {
    const Want& want = wanted[k];
    if (want.sources.empty()) {
      total += static_cast<int64_t>(want.targets.size()) * travel_cap();
      continue;
    }
    if (want.targets.size() * want.sources.size() <= 4 * f.size()) {
      for (uint32_t t : want.targets) {
        const int tx = static_cast<int>(t % w), ty = static_cast<int>(t / w);
        int best = w + h;
        for (uint32_t s : want.sources)
          best = std::min(best, std::abs(static_cast<int>(s % w) - tx) + std::abs(static_cast<int>(s / w) - ty));
        total += best;
      }
      continue;
    }
    const int far = w + h;
    dist.assign(f.size(), far);
    for (uint32_t s : want.sources) dist[s] = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int& d = dist[static_cast<size_t>(y * w + x)];
        if (x > 0) d = std::min(d, dist[static_cast<size_t>(y * w + x - 1)] + 1);
        if (y > 0) d = std::min(d, dist[static_cast<size_t>((y - 1) * w + x)] + 1);
      }
    for (int y = h - 1; y >= 0; --y)
      for (int x = w - 1; x >= 0; --x) {
        int& d = dist[static_cast<size_t>(y * w + x)];
        if (x + 1 < w) d = std::min(d, dist[static_cast<size_t>(y * w + x + 1)] + 1);
        if (y + 1 < h) d = std::min(d, dist[static_cast<size_t>((y + 1) * w + x)] + 1);
      }
    for (uint32_t t : want.targets) total += dist[t];
  }
  return total;
}

std::vector<uint32_t> Goal::differing(const TaskFrame& f) const {
  std::vector<uint32_t> out;
  for (uint32_t i : mask_)
    if (i < f.size() && f[i] != task_.goal.cells[i]) out.push_back(i);
  return out;
}

void Goal::order_tests(const TaskFrame& first) {
  order_ = differing(first);
  std::vector<uint8_t> in(task_.mask.cells.size(), 0);
  for (uint32_t i : order_) in[i] = 1;
  for (uint32_t i : mask_)
    if (!in[i]) order_.push_back(i);
}

// ---------------------------------------------------------------------------- clock

Future FutureScorer::score(const PlanProblem& p, const Environment& e, int noops, bool at_end, bool travel) {
  const Goal& goal = p.goal();
  Future f;
  colours_.map(e.frame(), e.palette(), goal.colours(), prev_);
  Goal::Dist d = goal.distance(prev_, travel);
  f.key = goal.rank(d);
  f.digest = frame_digest(prev_);
  if (d.colour == 0) {
    f.goal_noops = 0;
    return f;
  }
  auto probe = noops > 0 ? e.clone() : nullptr;
  for (int k = 1; probe && k <= noops; ++k) {
    if (!probe->step(Action::noop())) break;
    ++f.steps;
    colours_.map(probe->frame(), probe->palette(), goal.colours(), frame_);
    d = goal.distance(frame_, travel);
    if (d.colour == 0) {
      f.goal_noops = k;
      f.key = 0;
      return f;
    }
    f.key = at_end ? goal.rank(d) : std::min(f.key, goal.rank(d));
    if (!at_end && frame_ == prev_) break;
    prev_.swap(frame_);  // keeps both buffers
  }
  f.digest = f.digest * 0x9E3779B97F4A7C15ull ^ frame_digest(prev_);
  return f;
}

std::vector<Action> path_to(std::span<const Node> nodes, const std::vector<Action>& actions, int64_t node) {
  std::vector<Action> plan;
  for (int64_t n = node; n > 0; n = nodes[n].parent) plan.push_back(actions[nodes[n].action]);
  std::reverse(plan.begin(), plan.end());
  return plan;
}

Limit Limit::fraction(double f, uint64_t spent) const {
  Limit l;
  l.clock = clock;
  l.nodes = static_cast<uint64_t>(static_cast<double>(nodes - std::min(nodes, spent)) * f);
  const double end = deadline > 0 ? deadline : clock->time_limit();
  l.deadline = deadline;
  if (end > 0 && f < 1) l.deadline = clock->seconds() + std::max(0.0, end - clock->seconds()) * f;
  return l;
}

std::string Limit::time_note() const {
  if (clock->out_of_time()) return fmt::format("time limit {} s reached", clock->time_limit());
  return "its share of the time limit spent";
}

// ---------------------------------------------------------------------------- problem


PlanProblem::PlanProblem(const Task& task, const SolveOptions& opts, ThreadPool& pool)
    : task_(task), opts_(opts), pool_(pool), goal_(task), clock_(opts.time_limit, opts.nodes) {
  const fs::path path = task_program_path(task, opts, task.program);
  auto program = load_program_checked(path);
  root_ = make_env_checked(opts.engine, program);
  if (!root_->reset(task.env_seed)) throw TaskError(task.program + ": " + root_->error());
  grid_ = root_->frame().size;
  if (grid_ != task.goal.width)
    throw TaskError(fmt::format("{}: goal is {}x{} but program '{}' has GRID_SIZE {}", task.file.filename().string(),
                                task.goal.width, task.goal.height, task.program, grid_));
  stochastic_ = !root_->deterministic();
  inputs_ = analyse_inputs(*program);
  actions_ = search_actions(inputs_, grid_);
  goal_.order_tests(frame_of(*root_));
  choose_model(program, path);
}

// Switches the root to the click-reset model when the analysis allows it and the
// model agrees with the program on random episodes.
void PlanProblem::choose_model(std::shared_ptr<const Program> program, const std::string& path) {
  std::optional<std::string> text = click_reset_model_text(*program, inputs_, &model_note_);
  if (!text) return;
  std::unique_ptr<Environment> model;
  try {
    model = make_env_checked(opts_.engine, load_program_checked_text(*text, path + " (click-reset model)"));
  } catch (const TaskError& e) {
    model_note_ = std::string("the click-reset model failed to load: ") + e.what();
    return;
  }
  if (!model->reset(task_.env_seed) || !models_agree(*root_, *model)) {
    model_note_ = "the click-reset model disagreed with the program on a random episode";
    return;
  }
  root_ = std::move(model);
  model_ = "click-reset model";
}

// Four random episodes of 24 steps (clicks on every other step): equal frames.
bool PlanProblem::models_agree(const Environment& a, const Environment& b) const {
  std::mt19937_64 rng(0x5eed);
  for (int episode = 0; episode < 4; ++episode) {
    auto x = a.clone(), y = b.clone();
    for (int t = 0; t < 24; ++t) {
      Action act = t % 2 ? Action::click(static_cast<int>(rng() % grid_), static_cast<int>(rng() % grid_))
                         : actions_[rng() % actions_.size()];
      const bool ok_x = x->step(act), ok_y = y->step(act);
      if (ok_x != ok_y) return false;
      if (!ok_x) break;
      if (frame_of(*x) != frame_of(*y)) return false;
    }
  }
  return true;
}

Limit PlanProblem::share(double fraction, uint64_t spent, double keep_time) const {
  Limit whole{&clock_, clock_.node_budget(), 0};
  if (keep_time > 0 && clock_.time_limit() > 0)
    whole.deadline = std::max(1e-9, clock_.time_limit() * (1 - keep_time));
  return whole.fraction(fraction, spent);
}

TailRun run_tail(const PlanProblem& p, Environment& e, const std::vector<Action>& plan, size_t from,
                 FutureScorer& scorer, RankAt at, bool travel, int64_t before) {
  TailRun r{before, -1};
  for (size_t t = from; t < plan.size(); ++t) {
    if (!e.step(plan[t])) return {};
    const Future f = scorer.score(p, e, 0, true, travel);
    if (f.goal_noops == 0) return {0, static_cast<int>(t + 1)};
    r.rank = at == RankAt::Last ? f.key : std::min(r.rank, f.key);
  }
  return r;
}

void on_clones(ThreadPool& pool, const Environment& base, size_t count,
               const std::function<void(Environment&, size_t, unsigned)>& each) {
  std::vector<std::unique_ptr<Environment>> envs;
  envs.reserve(count);
  for (size_t k = 0; k < count; ++k) envs.push_back(base.clone());
  pool.parallel_for_worker(count, [&](size_t k, unsigned w) {
    each(*envs[k], k, w);
    envs[k].reset();
  });
}

std::vector<TaskFrame> PlanProblem::replay_frames(const std::vector<Action>& plan, const Environment* start) const {
  auto e = (start ? *start : *root_).clone();
  std::vector<TaskFrame> frames = {frame_of(*e)};
  for (const Action& a : plan) {
    if (!e->step(a)) break;
    frames.push_back(frame_of(*e));
  }
  return frames;
}

int PlanProblem::first_goal(const std::vector<Action>& plan) const {
  std::vector<TaskFrame> frames = replay_frames(plan);
  for (size_t i = 0; i < frames.size(); ++i)
    if (goal_.reached(frames[i])) return static_cast<int>(i);
  return -1;
}

std::string plan_text(const std::vector<Action>& plan) {
  std::string s;
  for (size_t i = 0; i < plan.size(); ++i) s += (i ? ", " : "") + format_action(plan[i]);
  return s.empty() ? "(none needed)" : s;
}

size_t moves_of(const std::vector<Action>& plan) {
  size_t n = 0;
  for (const Action& a : plan) n += a.kind != Action::Kind::Noop;
  return n;
}

}  // namespace autumn::agent
