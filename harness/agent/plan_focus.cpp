#include "harness/agent/plan_focus.hpp"

#include <algorithm>

namespace autumn::agent {

std::vector<Action> near_clicks(const PlanProblem& p, const std::vector<Action>& all,
                                const std::vector<uint32_t>& cells, int r, bool box) {
  const int n = p.grid();
  std::vector<uint8_t> near(static_cast<size_t>(n) * n, 0);
  auto mark = [&](int x0, int y0, int x1, int y1) {
    for (int y = std::max(0, y0 - r); y <= std::min(n - 1, y1 + r); ++y)
      for (int x = std::max(0, x0 - r); x <= std::min(n - 1, x1 + r); ++x) near[static_cast<size_t>(y) * n + x] = 1;
  };
  int bx0 = n, by0 = n, bx1 = -1, by1 = -1;
  for (uint32_t i : cells) {
    const int x = static_cast<int>(i) % n, y = static_cast<int>(i) / n;
    if (box) bx0 = std::min(bx0, x), by0 = std::min(by0, y), bx1 = std::max(bx1, x), by1 = std::max(by1, y);
    else mark(x, y, x, y);
  }
  if (box && bx1 >= 0) mark(bx0, by0, bx1, by1);
  std::vector<Action> out;
  for (const Action& a : all)
    if (a.kind != Action::Kind::Click ||
        (a.x >= 0 && a.y >= 0 && a.x < n && a.y < n && near[static_cast<size_t>(a.y) * n + a.x]))
      out.push_back(a);
  return out;
}

std::vector<Action> clicks_of(const std::vector<Action>& all) {
  std::vector<Action> clicks;
  for (const Action& a : all)
    if (a.kind == Action::Kind::Click) clicks.push_back(a);
  return clicks;
}

namespace {

// The non-click actions of `all` and its clicks k (in order) with keep[k].
std::vector<Action> keep_clicks(const std::vector<Action>& all, const std::vector<uint8_t>& keep) {
  std::vector<Action> out;
  size_t k = 0;
  for (const Action& a : all)
    if (a.kind != Action::Kind::Click || keep[k++]) out.push_back(a);
  return out;
}

}  // namespace

std::vector<Action> reaching_clicks(PlanProblem& p, const std::vector<Action>& all, const std::vector<uint32_t>& cells) {
  const int steps = std::max(1, 2 * p.grid());
  std::vector<TaskFrame> baseline;
  {
    auto e = p.root().clone();
    for (int t = 0; t < steps && e->step(Action::noop()); ++t) baseline.push_back(p.frame_of(*e));
  }
  const std::vector<Action> clicks = clicks_of(all);
  std::vector<uint8_t> reaches(clicks.size(), 0);
  on_clones(p.pool(), p.root(), clicks.size(), [&](Environment& e, size_t k, unsigned) {
    for (size_t t = 0; t < baseline.size() && !reaches[k]; ++t) {
      if (!e.step(t == 0 ? clicks[k] : Action::noop())) break;
      const TaskFrame f = p.frame_of(e);
      for (uint32_t c : cells)
        if (c < f.size() && f[c] != baseline[t][c]) reaches[k] = 1;
    }
  });
  return keep_clicks(all, reaches);
}

std::vector<Action> hidden_clicks(PlanProblem& p, const std::vector<Action>& all, const std::vector<uint32_t>& cells,
                                  size_t max) {
  if (cells.empty()) return {};
  const int n = p.grid();
  const Action probe = Action::click(static_cast<int>(cells[0]) % n, static_cast<int>(cells[0]) / n);
  // The probe after a noop, and after each click that shows nothing.
  auto quiet = p.root().clone();
  if (!quiet->step(Action::noop())) return {};
  const TaskFrame quiet_frame = p.frame_of(*quiet);
  if (!quiet->step(probe)) return {};
  const uint64_t quiet_probe = frame_digest(p.frame_of(*quiet));
  const std::vector<Action> clicks = clicks_of(all);
  std::vector<uint64_t> kind(clicks.size(), quiet_probe);  // quiet_probe: not a mode click
  on_clones(p.pool(), p.root(), clicks.size(), [&](Environment& e, size_t k, unsigned) {
    if (e.step(clicks[k]) && p.frame_of(e) == quiet_frame && e.step(probe)) kind[k] = frame_digest(p.frame_of(e));
  });
  std::vector<uint64_t> kinds;
  std::vector<uint8_t> keep(clicks.size(), 0);
  for (size_t k = 0; k < clicks.size(); ++k) {
    if (kind[k] == quiet_probe || std::find(kinds.begin(), kinds.end(), kind[k]) != kinds.end()) continue;
    kinds.push_back(kind[k]);
    keep[k] = 1;
  }
  if (kinds.size() > max) return {};
  std::vector<Action> out;
  for (const Action& a : keep_clicks(all, keep))
    if (a.kind == Action::Kind::Click) out.push_back(a);
  return out;
}

std::vector<Action> unite(const std::vector<Action>& all, const std::vector<Action>& a, const std::vector<Action>& b) {
  std::vector<Action> out;
  size_t i = 0, j = 0;
  for (const Action& x : all) {
    bool in = false;
    if (i < a.size() && a[i] == x) ++i, in = true;
    if (j < b.size() && b[j] == x) ++j, in = true;
    if (in) out.push_back(x);
  }
  return out;
}

}  // namespace autumn::agent
