#include "harness/agent/plan_shorten.hpp"

#include <cmath>

#include "harness/agent/plan_bfs.hpp"
#include "harness/agent/plan_focus.hpp"

namespace autumn::agent {

namespace {

// Ends the plan at its first goal frame (the plan is unchanged when it never gets there).
std::vector<Action> cut(const PlanProblem& p, std::vector<Action> plan) {
  const int k = p.first_goal(plan);
  if (k >= 0) plan.resize(static_cast<size_t>(k));
  return plan;
}

std::vector<Action> drop_single(const PlanProblem& p, std::vector<Action> plan) {
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t i = plan.size(); i-- > 0;) {
      if (i >= plan.size()) continue;
      std::vector<Action> cand = plan;
      cand.erase(cand.begin() + static_cast<std::ptrdiff_t>(i));
      const int k = p.first_goal(cand);
      if (k < 0) continue;
      cand.resize(static_cast<size_t>(k));
      plan = std::move(cand);
      changed = true;
    }
  }
  return plan;
}

// The states along the plan (index i: after i actions) and their hashes.
struct Trail {
  std::vector<std::unique_ptr<Environment>> states;
  std::vector<uint64_t> hashes;
};

Trail trail_of(const PlanProblem& p, const std::vector<Action>& plan) {
  Trail t;
  t.states.push_back(p.root().clone());
  for (const Action& a : plan) {
    auto e = t.states.back()->clone();
    if (!e->step(a)) break;
    t.states.push_back(std::move(e));
  }
  for (const auto& e : t.states) t.hashes.push_back(e->state_hash());
  return t;
}

// One shortcut from state i: the replacement segment and the index it rejoins
// (plan.size() for the goal), or nothing.
bool shortcut_from(PlanProblem& p, const Trail& t, size_t i, const std::vector<Action>& actions, const Limit& limit,
                   std::vector<Action>& segment, size_t& rejoin, ShortenStats& stats) {
  const size_t n = t.states.size() - 1;
  const double per_state = 200000;
  for (int d = 1; i + static_cast<size_t>(d) + 1 <= n; ++d) {
    if (std::pow(static_cast<double>(actions.size()), d) > per_state || stats.nodes >= limit.nodes ||
        limit.out_of_time())
      return false;
    absl::flat_hash_map<uint64_t, int> targets;
    for (size_t j = i + static_cast<size_t>(d) + 1; j <= n; ++j) targets.emplace(t.hashes[j], static_cast<int>(j));
    BfsSpec spec;
    spec.actions = actions;
    spec.max_cost = d;
    spec.limit = limit;
    spec.limit.nodes = limit.nodes - stats.nodes;
    spec.start = t.states[i].get();
    spec.targets = &targets;
    BfsOutcome o = bfs(p, spec);
    stats.nodes += o.nodes;
    if (o.found && (o.target < 0 || static_cast<size_t>(o.target) > i + o.plan.size())) {
      segment = o.plan;
      rejoin = o.target < 0 ? n : static_cast<size_t>(o.target);
      return true;
    }
  }
  return false;
}

std::vector<Action> shortcuts(PlanProblem& p, std::vector<Action> plan, const std::vector<Action>& actions,
                              const Limit& limit, ShortenStats& stats) {
  for (size_t i = 0; i + 1 < plan.size(); ++i) {
    Trail t = trail_of(p, plan);
    std::vector<Action> segment;
    size_t rejoin = 0;
    if (!shortcut_from(p, t, i, actions, limit, segment, rejoin, stats)) continue;
    std::vector<Action> next(plan.begin(), plan.begin() + static_cast<std::ptrdiff_t>(i));
    next.insert(next.end(), segment.begin(), segment.end());
    next.insert(next.end(), plan.begin() + static_cast<std::ptrdiff_t>(rejoin), plan.end());
    if (p.first_goal(next) < 0) continue;  // a hash collision, never seen; keep the plan
    plan = cut(p, std::move(next));
    ++stats.shortcuts;
    if (i > 0) --i;  // the new segment may open another shortcut from here
  }
  return plan;
}

// Relocation: the plan without its click at step j and with click c in the
// noop slot i. `base` is the state just before slot i in that plan, `suffix`
// the actions after slot i.
// Tries every click of `clicks` from `base` in parallel and returns the index
// (in `clicks`) of the first in order whose replay reaches the goal, with the
// number of the candidate's actions up to its first goal frame in `length`.
int first_relocation(PlanProblem& p, const Environment& base, const std::vector<Action>& clicks,
                     const std::vector<Action>& suffix, std::vector<FrameColours>& colours, int& length,
                     ShortenStats& stats) {
  std::vector<int> goal_at(clicks.size(), -1);
  on_clones(p.pool(), base, clicks.size(), [&](Environment& e, size_t k, unsigned w) {
    if (!e.step(clicks[k])) return;
    for (size_t t = 0;; ++t) {
      if (p.goal().reached(e, colours[w])) {
        goal_at[k] = static_cast<int>(t);
        return;
      }
      if (t == suffix.size() || !e.step(suffix[t])) return;
    }
  });
  stats.nodes += clicks.size() * (suffix.size() + 1);
  for (size_t k = 0; k < clicks.size(); ++k)
    if (goal_at[k] >= 0) {
      length = goal_at[k] + 1;  // the click, then goal_at[k] suffix actions
      return static_cast<int>(k);
    }
  return -1;
}

// One relocation that shortens the plan by at least one action, or false.
bool relocate_once(PlanProblem& p, std::vector<Action>& plan, const std::vector<Action>& clicks, const Limit& limit,
                   ShortenStats& stats) {
  std::vector<FrameColours> colours(p.pool().size());
  const Trail t = trail_of(p, plan);
  if (t.states.size() != plan.size() + 1) return false;
  for (size_t j = plan.size(); j-- > 0;) {
    if (plan[j].kind != Action::Kind::Click) continue;
    for (size_t i = 0; i < plan.size(); ++i) {
      if (plan[i].kind != Action::Kind::Noop) continue;
      if (stats.nodes >= limit.nodes || limit.out_of_time()) return false;
      // The candidate: plan without step j, slot i holding the click.
      std::vector<Action> prefix, suffix;
      for (size_t s = 0; s < plan.size(); ++s) {
        if (s == j || s == i) continue;
        (s < i ? prefix : suffix).push_back(plan[s]);
      }
      // The state before slot i: the trail's where the plans agree, then stepped.
      const size_t common = std::min(i, j);
      auto base = t.states[common]->clone();
      bool usable = true;  // no failed step, no goal on the way (dropping step j alone: drop_single's case)
      for (size_t s = common; s < prefix.size() && usable; ++s)
        usable = base->step(prefix[s]) && !p.goal().reached(p.frame_of(*base));
      if (!usable) continue;
      int length = 0;
      const int k = first_relocation(p, *base, clicks, suffix, colours, length, stats);
      if (k < 0) continue;
      prefix.push_back(clicks[static_cast<size_t>(k)]);
      prefix.insert(prefix.end(), suffix.begin(), suffix.begin() + (length - 1));
      if (prefix.size() >= plan.size() || p.first_goal(prefix) != static_cast<int>(prefix.size())) continue;
      plan = std::move(prefix);
      ++stats.relocated;
      return true;
    }
  }
  return false;
}

}  // namespace

std::vector<Action> shorten_plan(PlanProblem& problem, std::vector<Action> plan, const std::vector<Action>& actions,
                                 const Limit& limit, bool keep_moves, ShortenStats& stats) {
  stats.before = plan.size();
  plan = drop_single(problem, cut(problem, std::move(plan)));
  if (!keep_moves) plan = drop_single(problem, shortcuts(problem, std::move(plan), actions, limit, stats));
  const std::vector<Action> clicks = clicks_of(problem.actions());
  // Relocation gets a quarter of what is left, so the stages after shortening
  // (the horizon beam) keep their turn.
  // relocate_once compares the whole shortening's node count with it.
  Limit quarter = limit.fraction(0.25, stats.nodes);
  quarter.nodes += stats.nodes;
  if (!clicks.empty())
    while (relocate_once(problem, plan, clicks, quarter, stats)) plan = drop_single(problem, std::move(plan));
  stats.after = plan.size();
  return plan;
}

}  // namespace autumn::agent
