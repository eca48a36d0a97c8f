#include "harness/agent/plan_fill.hpp"

#include <fmt/core.h>

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <numeric>

#include "harness/agent/plan_focus.hpp"

namespace autumn::agent {

namespace {

constexpr int kLookAhead = 2;  // noop steps behind a layer's tie-break

struct Skeleton {
  std::unique_ptr<Environment> env;  // the state after `plan` (in the layer; null in skeletons()' result)
  std::vector<Action> plan;
  int noops = 0;
  int64_t rank = kNoRank;
};

class Fill {
 public:
  Fill(PlanProblem& p, const std::vector<Action>& actions, const FillSpec& spec)
      : p_(p), spec_(spec), clicks_(clicks_of(actions)), scorers_(p.pool().size()) {
    layer_.push_back({p.root().clone(), {}, 0, kNoRank});
    for (const Action& a : actions)
      if (a.kind != Action::Kind::Click) moves_.push_back(a);
  }
  SearchOutcome run();
  SearchOutcome run_one(std::vector<Action> skeleton);

 private:
  bool spent() const { return out_.nodes >= spec_.limit.nodes || spec_.limit.out_of_time(); }
  std::vector<Skeleton> skeletons(int horizon);
  bool fill(std::vector<Action> plan, int64_t rank, bool every_step);
  TailRun roll(Environment& e, const std::vector<Action>& plan, size_t from, FutureScorer& scorer) const;
  void found(std::vector<Action> plan, int goal_at) {
    plan.resize(static_cast<size_t>(goal_at));
    out_.found = true;
    out_.plan = std::move(plan);
  }

  PlanProblem& p_;
  const FillSpec spec_;
  std::vector<Action> moves_, clicks_;
  std::vector<FutureScorer> scorers_;  // one per pool thread
  SearchOutcome out_;
  // The skeleton layer: every kept non-click sequence of depth_ steps, with the
  // state after it. Horizons extend it; ranks are of its own frames, so a layer
  // does not depend on the horizon it serves.
  std::vector<Skeleton> layer_;
  int depth_ = 0;
};

// A rollout's outcome (plan_problem.hpp): the goal's rank at its last frame.
TailRun Fill::roll(Environment& e, const std::vector<Action>& plan, size_t from, FutureScorer& scorer) const {
  return run_tail(p_, e, plan, from, scorer, RankAt::Last, false);
}

// Extends the layer of non-click sequences to `horizon` steps (one per distinct
// state; the best `layer_width` by rank when there are more) and returns the best
// `skeletons` of it, plans and ranks only. Sets out_.found when a layer shows
// the goal.
std::vector<Skeleton> Fill::skeletons(int horizon) {
  const size_t A = moves_.size();
  std::vector<Skeleton>& layer = layer_;
  for (; depth_ < horizon && !layer.empty(); ++depth_) {
    if (spent()) return {};
    std::vector<Skeleton> succ(layer.size() * A);
    for (size_t i = 0; i < succ.size(); ++i) {
      const Skeleton& m = layer[i / A];
      succ[i].env = i % A + 1 < A ? m.env->clone() : std::move(layer[i / A].env);
      succ[i].plan = m.plan;
      succ[i].plan.push_back(moves_[i % A]);
      succ[i].noops = m.noops + (moves_[i % A].kind == Action::Kind::Noop);
    }
    std::vector<uint64_t> hash(succ.size(), 0);
    std::vector<int> goal(succ.size(), -1);
    p_.pool().parallel_for_worker(succ.size(), [&](size_t i, unsigned w) {
      Skeleton& s = succ[i];
      const TailRun r = roll(*s.env, s.plan, s.plan.size() - 1, scorers_[w]);
      s.rank = r.rank;
      goal[i] = r.goal_at;
      if (r.rank != kNoRank || r.goal_at >= 0) hash[i] = s.env->state_hash();
    });
    out_.nodes += succ.size();
    for (size_t i = 0; i < succ.size(); ++i)
      if (goal[i] >= 0) {
        found(succ[i].plan, goal[i]);
        return {};
      }
    // One skeleton per state: the first generated, or a later one with more noops.
    std::vector<Skeleton> next;
    absl::flat_hash_map<uint64_t, size_t> index;
    for (size_t i = 0; i < succ.size(); ++i) {
      if (succ[i].rank == kNoRank) continue;
      const auto [it, fresh] = index.emplace(hash[i], next.size());
      if (fresh) next.push_back(std::move(succ[i]));
      else if (succ[i].noops > next[it->second].noops) next[it->second] = std::move(succ[i]);
    }
    if (next.size() > spec_.layer_width) {
      // Ties on the frame are broken by the frame two waits later, with travel
      // (plan_problem.hpp): an arrow often shows only a step after it (a
      // velocity that moves things next step), and then as a thing nearer its
      // goal cell.
      std::vector<int64_t> ahead(next.size(), 0);
      p_.pool().parallel_for_worker(next.size(), [&](size_t i, unsigned w) {
        ahead[i] = scorers_[w].score(p_, *next[i].env, kLookAhead, true, true).key;
      });
      out_.lookahead_steps += next.size() * kLookAhead;
      std::vector<size_t> keep(next.size());
      std::iota(keep.begin(), keep.end(), size_t{0});
      std::stable_sort(keep.begin(), keep.end(), [&](size_t x, size_t y) {
        return next[x].rank != next[y].rank ? next[x].rank < next[y].rank : ahead[x] < ahead[y];
      });
      keep.resize(spec_.layer_width);
      std::sort(keep.begin(), keep.end());
      std::vector<Skeleton> kept;
      kept.reserve(keep.size());
      for (size_t i : keep) kept.push_back(std::move(next[i]));
      next = std::move(kept);
    }
    layer = std::move(next);
  }
  if (depth_ < horizon) return {};  // every sequence failed a step
  std::vector<size_t> order(layer.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
    if (layer[x].rank != layer[y].rank) return layer[x].rank < layer[y].rank;
    return layer[x].noops > layer[y].noops;
  });
  std::vector<Skeleton> best;
  for (size_t i : order) {
    if (best.size() >= spec_.skeletons) break;
    if (layer[i].noops == 0) continue;
    best.push_back({nullptr, layer[i].plan, layer[i].noops, layer[i].rank});
  }
  return best;
}

// Fills `plan`'s slots with clicks (see the header): its noops, or with
// `every_step` all its steps; true when a plan reaches the goal (out_ holds it).
bool Fill::fill(std::vector<Action> plan, int64_t rank, bool every_step) {
  const size_t C = clicks_.size();
  for (int round = 0; round < 3 && !spent(); ++round) {
    // The states before each step of the plan (and after the last).
    std::vector<std::unique_ptr<Environment>> trail;
    trail.push_back(p_.root().clone());
    for (size_t t = 0; t < plan.size(); ++t) {
      trail.push_back(trail.back()->clone());
      if (!trail.back()->step(plan[t])) return false;
    }
    std::vector<size_t> slots;
    for (size_t i = 0; i < plan.size(); ++i)
      if (plan[i].kind == Action::Kind::Noop || (every_step && plan[i].kind != Action::Kind::Click)) slots.push_back(i);
    if (slots.empty()) return false;
    // Every click in every slot, rolled out in parallel.
    std::vector<TailRun> result(slots.size() * C);
    for (size_t k = 0; k < slots.size() && !spent(); ++k) {
      const size_t slot = slots[k];
      on_clones(p_.pool(), *trail[slot], C, [&](Environment& e, size_t c, unsigned w) {
        std::vector<Action> tail(plan.begin() + static_cast<std::ptrdiff_t>(slot), plan.end());
        tail[0] = clicks_[c];
        TailRun r = roll(e, tail, 0, scorers_[w]);
        if (r.goal_at >= 0) r.goal_at += static_cast<int>(slot);
        result[k * C + c] = r;
      });
      out_.nodes += C * (plan.size() - slot);
    }
    // A goal on the way: the shortest, then the first in (slot, click) order.
    int64_t best_goal = -1;
    for (size_t i = 0; i < result.size(); ++i)
      if (result[i].goal_at >= 0 &&
          (best_goal < 0 || result[i].goal_at < result[static_cast<size_t>(best_goal)].goal_at))
        best_goal = static_cast<int64_t>(i);
    if (best_goal >= 0) {
      const size_t i = static_cast<size_t>(best_goal);
      plan[slots[i / C]] = clicks_[i % C];
      found(std::move(plan), result[i].goal_at);
      return true;
    }
    // The improving pairs, best first; each taken if its slot is free and the
    // whole plan still improves.
    std::vector<size_t> better;
    for (size_t i = 0; i < result.size(); ++i)
      if (result[i].rank < rank) better.push_back(i);
    if (better.empty()) return false;
    std::stable_sort(better.begin(), better.end(), [&](size_t x, size_t y) { return result[x].rank < result[y].rank; });
    std::vector<uint8_t> used(slots.size(), 0);
    bool improved = false;
    FutureScorer& scorer = scorers_[0];
    for (size_t n = 0; n < better.size() && n < 256 && !spent(); ++n) {
      const size_t i = better[n];
      if (used[i / C]) continue;
      std::vector<Action> trial = plan;
      trial[slots[i / C]] = clicks_[i % C];
      auto e = p_.root().clone();
      const TailRun r = roll(*e, trial, 0, scorer);
      out_.nodes += trial.size();
      if (r.goal_at >= 0) {
        found(std::move(trial), r.goal_at);
        return true;
      }
      if (r.rank >= rank) continue;
      plan = std::move(trial);
      rank = r.rank;
      used[i / C] = 1;
      improved = true;
    }
    if (!improved) return false;
  }
  return false;
}

SearchOutcome Fill::run() {
  if (moves_.empty() || clicks_.empty()) {
    out_.note = "fill: no clicks or no other actions";
    return std::move(out_);
  }
  int horizon = std::max(1, spec_.first_horizon);
  for (; horizon <= spec_.last_horizon && !spent(); ++horizon) {
    std::vector<Skeleton> best = skeletons(horizon);
    if (out_.found) return std::move(out_);
    for (Skeleton& s : best) {
      if (spent()) break;
      if (fill(std::move(s.plan), s.rank, false)) return std::move(out_);
    }
    if (!spent()) out_.depth_done = horizon;
  }
  out_.timed_out = spec_.limit.clock->out_of_time();
  out_.note = horizon > spec_.first_horizon
                  ? fmt::format("fill at horizons {}..{}: no plan", spec_.first_horizon, horizon - 1)
                  : "fill: " + spec_.limit.time_note();
  return std::move(out_);
}

SearchOutcome Fill::run_one(std::vector<Action> skeleton) {
  if (clicks_.empty() || skeleton.empty()) {
    out_.note = "fill: no clicks or no skeleton";
    return std::move(out_);
  }
  auto e = p_.root().clone();
  const TailRun r = roll(*e, skeleton, 0, scorers_[0]);
  out_.nodes += skeleton.size();
  if (r.goal_at >= 0) found(skeleton, r.goal_at);
  else if (r.rank != kNoRank) fill(std::move(skeleton), r.rank, true);
  if (!out_.found) out_.note = "fill: no clicks in the skeleton's steps reach the goal";
  return std::move(out_);
}

}  // namespace

SearchOutcome fill_skeleton(PlanProblem& problem, const std::vector<Action>& actions,
                            const std::vector<Action>& skeleton, const Limit& limit) {
  FillSpec spec;
  spec.limit = limit;
  return Fill(problem, actions, spec).run_one(skeleton);
}

SearchOutcome fill_search(PlanProblem& problem, const std::vector<Action>& actions, const FillSpec& spec) {
  return Fill(problem, actions, spec).run();
}

}  // namespace autumn::agent
