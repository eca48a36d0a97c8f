#include "harness/agent/plan_shorten.hpp"

#include <cmath>

#include "harness/agent/plan_bfs.hpp"

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

}  // namespace

std::vector<Action> shorten_plan(PlanProblem& problem, std::vector<Action> plan, const std::vector<Action>& actions,
                                 const Limit& limit, bool keep_moves, ShortenStats& stats) {
  stats.before = plan.size();
  plan = drop_single(problem, cut(problem, std::move(plan)));
  if (!keep_moves) plan = drop_single(problem, shortcuts(problem, std::move(plan), actions, limit, stats));
  stats.after = plan.size();
  return plan;
}

}  // namespace autumn::agent
