#include "harness/agent/plan_local.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <random>

#include "harness/agent/plan_focus.hpp"

namespace autumn::agent {

namespace {

// One edit of a plan (see the header).
struct Edit {
  enum class Kind { Replace, Insert, Delete, Swap } kind = Kind::Replace;
  size_t at = 0;
  Action action;
};

class Local {
 public:
  Local(PlanProblem& p, const std::vector<Action>& actions, const LocalSpec& spec)
      : p_(p), spec_(spec), L_(static_cast<size_t>(std::max(2, spec.length))), clicks_(clicks_of(actions)),
        rng_(spec.seed * 0x9E3779B97F4A7C15ull + 0x10CA1), scorers_(p.pool().size()) {
    for (const Action& a : actions)
      if (a.kind != Action::Kind::Click) moves_.push_back(a);
  }
  SearchOutcome run(std::vector<Action>* best);

 private:
  bool spent() const { return out_.nodes >= spec_.limit.nodes || spec_.limit.out_of_time(); }
  Edit draw();
  std::vector<Action> apply(const std::vector<Action>& plan, const Edit& e) const;
  // Steps `e` through plan[from..]; best_[from] carries the ranks before.
  TailRun roll(Environment& e, const std::vector<Action>& plan, size_t from, FutureScorer& scorer) const;
  bool adopt(std::vector<Action> plan, size_t from);
  void found(const std::vector<Action>& plan, int goal_at);

  PlanProblem& p_;
  const LocalSpec spec_;
  const size_t L_;
  std::vector<Action> moves_, clicks_;
  std::mt19937_64 rng_;
  std::vector<FutureScorer> scorers_;  // one per pool thread
  SearchOutcome out_;
  // The plan being edited, the state before each of its steps (trail_[t]
  // before plan_[t]), and best_[t] the best rank on the frames before step t
  // (the start's frame included). Invariant: trail_ and best_ are those of plan_.
  std::vector<Action> plan_;
  std::vector<std::unique_ptr<Environment>> trail_;
  std::vector<int64_t> best_;
  int64_t score_ = kNoRank;
};

Edit Local::draw() {
  Edit e;
  e.kind = static_cast<Edit::Kind>(rng_() % 4);
  e.at = rng_() % (e.kind == Edit::Kind::Swap ? L_ - 1 : L_);
  const bool click = !clicks_.empty() && (moves_.empty() || rng_() % 2 == 0);
  e.action = click ? clicks_[rng_() % clicks_.size()] : moves_[rng_() % moves_.size()];
  return e;
}

std::vector<Action> Local::apply(const std::vector<Action>& plan, const Edit& e) const {
  std::vector<Action> out = plan;
  const auto at = out.begin() + static_cast<std::ptrdiff_t>(e.at);
  switch (e.kind) {
    case Edit::Kind::Replace: *at = e.action; break;
    case Edit::Kind::Insert: out.insert(at, e.action), out.pop_back(); break;
    case Edit::Kind::Delete: out.erase(at), out.push_back(Action::noop()); break;
    case Edit::Kind::Swap: std::swap(*at, *(at + 1)); break;
  }
  return out;
}

// A plan's score (plan_problem.hpp): the rank at its best frame, the kept
// prefix's best (best_[from]) included.
TailRun Local::roll(Environment& e, const std::vector<Action>& plan, size_t from, FutureScorer& scorer) const {
  return run_tail(p_, e, plan, from, scorer, RankAt::Best, true, best_[from]);
}

// Makes `plan` (equal to plan_ before step `from`) the plan being edited;
// false (nothing changed) when one of its steps fails.
bool Local::adopt(std::vector<Action> plan, size_t from) {
  std::vector<std::unique_ptr<Environment>> tail;
  std::vector<int64_t> best{best_[from]};
  FutureScorer& scorer = scorers_[0];
  for (size_t t = from; t < L_; ++t) {
    auto next = (t == from ? *trail_[from] : *tail.back()).clone();
    ++out_.nodes;
    if (!next->step(plan[t])) return false;
    best.push_back(std::min(best.back(), scorer.score(p_, *next, 0, true, true).key));
    tail.push_back(std::move(next));
  }
  plan_ = std::move(plan);
  trail_.resize(from + 1);
  best_.resize(from + 1);
  for (size_t k = 0; k < tail.size(); ++k) {
    trail_.push_back(std::move(tail[k]));
    best_.push_back(best[k + 1]);
  }
  score_ = best_.back();
  return true;
}

void Local::found(const std::vector<Action>& plan, int goal_at) {
  out_.found = true;
  out_.plan.assign(plan.begin(), plan.begin() + goal_at);
}

SearchOutcome Local::run(std::vector<Action>* best) {
  trail_.push_back(p_.root().clone());
  best_.push_back(scorers_[0].score(p_, p_.root(), 0, true, true).key);
  if (!adopt(std::vector<Action>(L_, Action::noop()), 0)) {
    out_.note = "local search: waiting fails a step";
    return std::move(out_);
  }
  std::vector<Action> best_plan = plan_;
  int64_t best_score = score_;
  int stale = 0;
  uint64_t restarts = 0;
  bool offered = false;  // best_plan has been offered (spec_.offer)
  auto offer = [&] {
    if (!spec_.offer || offered) return false;
    offered = true;
    return spec_.offer(best_plan);
  };
  bool taken = false;
  while (!spent()) {
    std::vector<Edit> edits(spec_.batch);
    for (Edit& e : edits) e = draw();
    std::vector<std::vector<Action>> plans(edits.size());
    std::vector<std::unique_ptr<Environment>> envs(edits.size());
    for (size_t k = 0; k < edits.size(); ++k) {
      plans[k] = apply(plan_, edits[k]);
      envs[k] = trail_[edits[k].at]->clone();
    }
    std::vector<TailRun> scores(edits.size());
    p_.pool().parallel_for_worker(edits.size(), [&](size_t k, unsigned w) {
      scores[k] = roll(*envs[k], plans[k], edits[k].at, scorers_[w]);
      envs[k].reset();
    });
    for (size_t k = 0; k < edits.size(); ++k) out_.nodes += L_ - edits[k].at;
    size_t pick = edits.size();
    for (size_t k = 0; k < edits.size(); ++k) {
      if (scores[k].goal_at >= 0) {
        found(plans[k], scores[k].goal_at);
        return std::move(out_);
      }
      if (scores[k].rank != kNoRank && scores[k].rank <= score_ && plans[k] != plan_ &&
          (pick == edits.size() || scores[k].rank < scores[pick].rank))
        pick = k;
    }
    if (pick < edits.size()) adopt(std::move(plans[pick]), edits[pick].at);  // scored, so its steps succeed
    if (score_ < best_score) {
      best_score = score_, best_plan = plan_, stale = 0, offered = false;
      continue;
    }
    if (++stale < spec_.patience) continue;
    if ((taken = offer())) break;
    // A restart: the best plan, shaken by a few edits.
    std::vector<Action> kicked = best_plan;
    for (int n = 0; n < 3; ++n) kicked = apply(kicked, draw());
    if (!adopt(std::move(kicked), 0)) adopt(best_plan, 0);
    stale = 0;
    ++restarts;
  }
  if (!taken) taken = offer();
  out_.timed_out = !taken && spec_.limit.clock->out_of_time();
  out_.note = fmt::format("local search over plans of {} ({} restarts): {}", L_, restarts,
                          taken                                ? "a plan offered was completed"
                          : out_.nodes >= spec_.limit.nodes ? "node budget spent"
                                                               : spec_.limit.time_note());
  if (best) *best = std::move(best_plan);
  return std::move(out_);
}

}  // namespace

SearchOutcome local_search(PlanProblem& problem, const std::vector<Action>& actions, const LocalSpec& spec,
                           std::vector<Action>* best) {
  return Local(problem, actions, spec).run(best);
}

}  // namespace autumn::agent
