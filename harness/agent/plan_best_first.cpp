#include "harness/agent/plan_best_first.hpp"

#include <fmt/core.h>

#include <absl/container/flat_hash_set.h>

#include <queue>

namespace autumn::agent {

namespace {

using HashSet = absl::flat_hash_set<uint64_t>;

class BestFirst {
 public:
  BestFirst(PlanProblem& p, const std::vector<Action>& actions, bool prune, bool travel, const Limit& limit)
      : p_(p), actions_(actions), prune_(prune), travel_(travel), limit_(limit), scorers_(p.pool().size()) {}
  SearchOutcome run();

 private:
  struct Succ {
    std::unique_ptr<Environment> env;
    uint64_t hash = 0;
    Future future;    // priority: future.key; frame pruning: future.digest
    bool ok = false;  // false: the step failed or the state was already seen
  };
  struct Open {
    int64_t h;
    int g;
    int64_t node;
    bool operator>(const Open& o) const {
      if (h != o.h) return h > o.h;
      if (g != o.g) return g > o.g;
      return node > o.node;
    }
  };

  void expand_one(std::unique_ptr<Environment> e, size_t a, FutureScorer& scorer, Succ& out) const;
  std::vector<Succ> successors(const Open& top);
  int64_t add_node(int64_t parent, size_t action, int depth, std::unique_ptr<Environment>& env);
  std::unique_ptr<Environment> parent_env(int64_t node);
  std::vector<Action> path(int64_t node) const;
  SearchOutcome stop(const std::string& why);
  void discard(std::vector<std::unique_ptr<Environment>>& trash);

  PlanProblem& p_;
  const std::vector<Action>& actions_;
  const bool prune_;
  const bool travel_;
  const Limit limit_;
  std::vector<FutureScorer> scorers_;  // one per pool thread
  HashSet seen_, seen_frames_;
  std::vector<Node> nodes_;
  std::vector<std::unique_ptr<Environment>> envs_;  // per node; null when not kept
  uint64_t stored_ = 0;
  SearchOutcome out_;
};

// The successor by action `a` of `e`, a fresh clone of its parent; not ok when
// its state is already in seen_ (read-only here). Clones are made by the caller:
// clone() is not safe to call concurrently on one environment. Its priority is
// its settled noop future (at most 2 * GRID_SIZE noops; FutureScorer), and the
// future's digest joins its frame hash, so a state whose future differs (a
// block in mid-air in another phase) is not pruned as a repeat of one that
// looks alike now.
void BestFirst::expand_one(std::unique_ptr<Environment> e, size_t a, FutureScorer& scorer, Succ& out) const {
  if (!e->step(actions_[a])) return;
  const uint64_t h = e->state_hash();
  if (seen_.count(h)) return;
  out.future = scorer.score(p_, *e, 2 * p_.grid(), false, travel_);
  out.hash = h;
  out.env = std::move(e);
  out.ok = true;
}

std::vector<BestFirst::Succ> BestFirst::successors(const Open& top) {
  const size_t A = actions_.size();
  std::unique_ptr<Environment> parent = parent_env(top.node);
  std::vector<std::unique_ptr<Environment>> clones;
  for (size_t a = 0; a + 1 < A; ++a) clones.push_back(parent->clone());
  clones.push_back(std::move(parent));
  std::vector<Succ> succ(A);
  p_.pool().parallel_for_worker(A, [&](size_t a, unsigned w) { expand_one(std::move(clones[a]), a, scorers_[w], succ[a]); });
  out_.nodes += A;
  return succ;
}

// Keeps `env` while under the keep_states cap (otherwise it stays with the caller).
int64_t BestFirst::add_node(int64_t parent, size_t action, int depth, std::unique_ptr<Environment>& env) {
  const int64_t id = static_cast<int64_t>(nodes_.size());
  nodes_.push_back({parent, static_cast<int32_t>(action), depth});
  if (env && stored_ < p_.opts().keep_states) {
    envs_.push_back(std::move(env));
    ++stored_;
  } else {
    envs_.emplace_back();
  }
  return id;
}

std::unique_ptr<Environment> BestFirst::parent_env(int64_t node) {
  if (envs_[node]) {
    --stored_;
    return std::move(envs_[node]);
  }
  auto e = p_.root().clone();
  for (const Action& a : path(node))
    if (!e->step(a)) throw TaskError("replaying a search path failed: " + e->error());
  return e;
}

std::vector<Action> BestFirst::path(int64_t node) const { return path_to(nodes_, actions_, node); }

SearchOutcome BestFirst::stop(const std::string& why) {
  out_.note = why;
  out_.distinct = seen_.size();
  envs_.clear();
  return std::move(out_);
}

// Destroys environments on the pool (freeing big object graphs is not cheap).
void BestFirst::discard(std::vector<std::unique_ptr<Environment>>& trash) {
  p_.pool().parallel_for(trash.size(), [&](size_t i) { trash[i].reset(); });
  trash.clear();
}

SearchOutcome BestFirst::run() {
  const Environment& root = p_.root();
  seen_ = {root.state_hash()};
  seen_frames_ = {frame_digest(p_.frame_of(root))};
  nodes_ = {{-1, -1, 0}};
  envs_.clear();
  envs_.push_back(root.clone());
  stored_ = 1;
  std::priority_queue<Open, std::vector<Open>, std::greater<Open>> open;
  open.push({0, 0, 0});
  const size_t A = actions_.size();
  while (!open.empty()) {
    if (out_.nodes >= limit_.nodes) return stop(fmt::format("best-first ({} actions): node budget spent", A));
    if (limit_.out_of_time()) {
      out_.timed_out = limit_.clock->out_of_time();
      return stop("best-first: " + limit_.time_note());
    }
    const Open top = open.top();
    open.pop();
    if (top.g >= p_.opts().max_plan) continue;
    std::vector<Succ> succ = successors(top);
    std::vector<std::unique_ptr<Environment>> trash;
    for (size_t a = 0; a < A; ++a) {
      Succ& s = succ[a];
      out_.lookahead_steps += s.future.steps;
      if (!s.ok || !seen_.insert(s.hash).second || (prune_ && !seen_frames_.insert(s.future.digest).second)) {
        if (s.env) trash.push_back(std::move(s.env));
        continue;
      }
      const int64_t id = add_node(top.node, a, top.g + 1, s.env);
      if (s.env) trash.push_back(std::move(s.env));
      if (s.future.goal_noops >= 0) {
        out_.found = true;
        out_.plan = path(id);
        out_.plan.insert(out_.plan.end(), static_cast<size_t>(s.future.goal_noops), Action::noop());
        return stop("");
      }
      open.push({s.future.key, top.g + 1, id});
    }
    discard(trash);
  }
  return stop(fmt::format("best-first: no plan of length <= {}", p_.opts().max_plan));
}

}  // namespace

SearchOutcome best_first(PlanProblem& problem, const std::vector<Action>& actions, bool prune_frames, bool travel,
                         const Limit& limit) {
  return BestFirst(problem, actions, prune_frames, travel, limit).run();
}

}  // namespace autumn::agent
