#include "harness/agent/plan_beam.hpp"

#include <fmt/core.h>

#include <absl/container/flat_hash_set.h>

#include <algorithm>
#include <numeric>

namespace autumn::agent {

namespace {

class Beam {
 public:
  Beam(PlanProblem& p, const std::vector<Action>& actions, const BeamSpec& spec)
      : p_(p), actions_(actions), width_(spec.width), at_horizon_(spec.at_horizon), max_len_(spec.max_len),
        limit_(spec.limit), scorers_(p.pool().size()) {}
  SearchOutcome run();

 private:
  struct Member {
    std::unique_ptr<Environment> env;
    int64_t node;
  };
  struct Succ {
    std::unique_ptr<Environment> env;
    uint64_t hash = 0;
    Future future;
    bool ok = false;  // false: the step failed or the state was already seen
  };

  void expand_one(std::unique_ptr<Environment> e, size_t a, int noops, FutureScorer& scorer, Succ& out) const;
  std::vector<Action> path(int64_t node) const;
  SearchOutcome stop(const std::string& why);

  PlanProblem& p_;
  const std::vector<Action>& actions_;
  const size_t width_;
  const bool at_horizon_;  // score at step max_len_ exactly, not at the best step
  const int max_len_;  // plans are at most this long: look-aheads end there too
  const Limit limit_;
  std::vector<FutureScorer> scorers_;  // one per pool thread
  absl::flat_hash_set<uint64_t> seen_;
  std::vector<Node> nodes_;
  SearchOutcome out_;
};

// Steps `e` by action `a` and scores it by its noop future (FutureScorer):
// settled, at most `noops` steps, or with at_horizon_ after exactly `noops`.
// Reads seen_ only.
void Beam::expand_one(std::unique_ptr<Environment> e, size_t a, int noops, FutureScorer& scorer, Succ& out) const {
  if (!e->step(actions_[a])) return;
  out.hash = e->state_hash();
  if (seen_.count(out.hash)) return;
  out.future = scorer.score(p_, *e, noops, at_horizon_, false);
  out.env = std::move(e);
  out.ok = true;
}

std::vector<Action> Beam::path(int64_t node) const { return path_to(nodes_, actions_, node); }

SearchOutcome Beam::stop(const std::string& why) {
  out_.note = why;
  out_.distinct = seen_.size();
  return std::move(out_);
}

SearchOutcome Beam::run() {
  const size_t A = actions_.size();
  nodes_ = {{-1, -1, 0}};
  seen_ = {p_.root().state_hash()};
  std::vector<Member> layer;
  layer.push_back({p_.root().clone(), 0});
  for (int depth = 0; depth < max_len_ && !layer.empty(); ++depth) {
    const int noops = at_horizon_ ? max_len_ - depth - 1 : std::min(2 * p_.grid(), max_len_ - depth - 1);
    if (out_.nodes >= limit_.nodes) return stop(fmt::format("beam {} ({} actions): node budget spent at depth {}", width_, A, depth));
    if (limit_.out_of_time()) {
      out_.timed_out = limit_.clock->out_of_time();
      return stop(fmt::format("beam {}: {}", width_, limit_.time_note()));
    }
    // Every member's successors, in beam order then action order.
    std::vector<std::unique_ptr<Environment>> clones;
    clones.reserve(layer.size() * A);
    for (Member& m : layer) {
      for (size_t a = 0; a + 1 < A; ++a) clones.push_back(m.env->clone());
      clones.push_back(std::move(m.env));
    }
    std::vector<Succ> succ(clones.size());
    p_.pool().parallel_for_worker(clones.size(), [&](size_t i, unsigned w) {
      expand_one(std::move(clones[i]), i % A, noops, scorers_[w], succ[i]);
    });
    out_.nodes += succ.size();
    for (const Succ& s : succ) out_.lookahead_steps += s.future.steps;
    // A goal on the way: the first in generation order with the fewest steps.
    int64_t best_goal = -1;
    for (size_t i = 0; i < succ.size(); ++i)
      if (succ[i].ok && succ[i].future.goal_noops >= 0 &&
          (best_goal < 0 || succ[i].future.goal_noops < succ[static_cast<size_t>(best_goal)].future.goal_noops))
        best_goal = static_cast<int64_t>(i);
    if (best_goal >= 0) {
      const Succ& s = succ[static_cast<size_t>(best_goal)];
      out_.found = true;
      out_.plan = path(layer[static_cast<size_t>(best_goal) / A].node);
      out_.plan.push_back(actions_[static_cast<size_t>(best_goal) % A]);
      out_.plan.insert(out_.plan.end(), static_cast<size_t>(s.future.goal_noops), Action::noop());
      return stop("");
    }
    std::vector<size_t> order(succ.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
      if (succ[x].ok != succ[y].ok) return succ[x].ok;
      return succ[x].future.key < succ[y].future.key;
    });
    std::vector<Member> next;
    absl::flat_hash_set<uint64_t> looks;
    for (size_t i : order) {
      Succ& s = succ[i];
      if (!s.ok || next.size() >= width_) break;
      if (!seen_.insert(s.hash).second || !looks.insert(s.future.digest).second) continue;
      nodes_.push_back({layer[i / A].node, static_cast<int32_t>(i % A), depth + 1});
      next.push_back({std::move(s.env), static_cast<int64_t>(nodes_.size()) - 1});
    }
    p_.pool().parallel_for(succ.size(), [&](size_t i) { succ[i].env.reset(); });
    layer = std::move(next);
  }
  return stop(fmt::format("beam {}: no plan of length <= {}", width_, max_len_));
}

}  // namespace

SearchOutcome beam(PlanProblem& problem, const std::vector<Action>& actions, const BeamSpec& spec) {
  return Beam(problem, actions, spec).run();
}

}  // namespace autumn::agent
