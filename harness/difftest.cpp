// difftest — see difftest.hpp. An episode is compared after its reset and after
// every step; the first disagreement ends the run. One disagreement is checked
// once more before it is reported: the one the per-step budgets allow
// (runtime/limits.hpp). The interpreter counts more against "calls" and "cells"
// in a step than specialised code does, so under the same budget it may stop in
// a step the compiled engine finishes, or both may stop in one step at different
// constructs. The episode is then replayed on both engines with those two
// budgets raised (kBudgetRaise); if they agree at that step there, the engines
// differed only in where the budget caught them: the episode is counted as
// ended on a budget, not as a divergence. The compiled engine stopping where
// the interpreter runs on is never allowed, and is reported.
#include "harness/difftest.hpp"

#include <algorithm>
#include <limits>
#include <vector>

#include "harness/engine.hpp"
#include "harness/policy.hpp"

namespace autumn {

namespace {

// How much the re-run raises the per-step budgets. The interpreter's count of a
// step is a small multiple of the compiled engine's (it adds object fields,
// Positions, list literals and copies; it makes a call per element a loop
// visits): ajl_master_s_logic's step 1,184 of seed 90,001 stops the interpreter
// at cells=10M and runs at 20M, frame for frame the compiled engine's.
constexpr int64_t kBudgetRaise = 4;

Limits raised_step_budgets(Limits l) {
  auto raise = [](int64_t v) { return v > std::numeric_limits<int64_t>::max() / kBudgetRaise ? v : v * kBudgetRaise; };
  l.calls = raise(l.calls);
  l.cells = raise(l.cells);
  return l;
}

// Two environments at the same point of an episode (`ok`: the last reset or
// step succeeded). "" when they agree; else what differs. `both_failed`: they
// agree that the episode ended, with the same error.
std::string disagreement(const DiffOptions& o, Environment& a, bool oka, Environment& b, bool okb, bool& both_failed) {
  both_failed = false;
  if (oka != okb)
    return o.engine_a + (oka ? " ran on" : " failed (" + a.error() + ")") + " but " + o.engine_b +
           (okb ? " ran on" : " failed (" + b.error() + ")");
  if (!oka) {
    if (a.error() != b.error())
      return "both failed, with different errors:\n  " + o.engine_a + ": " + a.error() + "\n  " + o.engine_b + ": " +
             b.error();
    both_failed = true;
    return "";
  }
  if (frame_rows(a.frame(), a.palette()) != frame_rows(b.frame(), b.palette())) return "frames differ";
  if (a.triggered() != b.triggered()) return "trigger values differ";
  if (a.covered_on_clause_count() != b.covered_on_clause_count()) return "on-clause coverage differs";
  return "";
}

// A new environment of `engine` through `seed`'s reset and `actions`, under
// `limits`; `ok` as the last of them returned (false once one failed).
std::unique_ptr<Environment> replay(const std::string& engine, const std::shared_ptr<const Program>& program,
                                    const Limits& limits, uint64_t seed, const std::vector<Action>& actions,
                                    bool& ok) {
  std::string why;
  auto env = make_environment(engine, program, &why);
  if (!env) return nullptr;
  env->set_limits(limits);
  ok = env->reset(seed);
  for (size_t i = 0; ok && i < actions.size(); ++i) ok = env->step(actions[i]);
  return env;
}

// Whether a disagreement after `actions` of `seed`'s episode is one the
// per-step budgets allow: engine_a (the interpreter) stopped, and with the
// budgets raised both engines agree at that point.
bool budget_allows(const std::shared_ptr<const Program>& program, const DiffOptions& o, uint64_t seed,
                   const std::vector<Action>& actions, bool oka) {
  // engine_b ran on, or failed with another error: either is within the allowance.
  if (o.engine_a != "interp" || oka || o.engine_b == o.engine_a) return false;
  const Limits raised = raised_step_budgets(o.limits);
  bool ra = false, rb = false, both_failed = false;
  auto a = replay(o.engine_a, program, raised, seed, actions, ra);
  auto b = a ? replay(o.engine_b, program, raised, seed, actions, rb) : nullptr;
  return b && disagreement(o, *a, ra, *b, rb, both_failed).empty();
}

}  // namespace

DiffResult diff_engines(const std::shared_ptr<const Program>& program, const DiffOptions& o) {
  DiffResult r;
  std::string why;
  auto a = make_environment(o.engine_a, program, &why);
  auto b = a ? make_environment(o.engine_b, program, &why) : nullptr;
  if (!a || !b) {
    r.setup_failed = true;
    r.divergence = why;
    return r;
  }
  a->set_limits(o.limits);
  b->set_limits(o.limits);
  for (int k = 0; k < o.seeds && r.divergence.empty(); ++k) {
    const uint64_t seed = o.first_seed + static_cast<uint64_t>(k);
    ++r.episodes;
    bool oka = a->reset(seed), okb = b->reset(seed);
    std::vector<Action> actions;
    // Whether the episode goes on after this point; records how it ended otherwise.
    auto compare = [&] {
      bool both_failed = false;
      const std::string what = disagreement(o, *a, oka, *b, okb, both_failed);
      if (what.empty() && !both_failed) return true;
      std::string at = "seed " + std::to_string(seed) + (actions.empty() ? ", after reset" : ", step " + std::to_string(actions.size()));
      if (!actions.empty()) {
        std::string listed;
        for (const Action& act : actions) listed += (listed.empty() ? "" : ",") + format_action(act);
        at += " (actions: " + listed + ")";
      }
      if (both_failed) {
        ++r.errored;
        if (r.first_error.empty()) r.first_error = at + ": " + a->error();
      } else if (budget_allows(program, o, seed, actions, oka)) {
        ++r.budget_ended;
        if (r.first_budget.empty())
          r.first_budget = at + " (with the per-step budgets, calls and cells, raised " + std::to_string(kBudgetRaise) +
                           "x, both engines agree there): " + what;
      } else {
        r.divergence = at + ": " + what;
      }
      return false;
    };
    if (!compare()) continue;
    RandomPolicy policy(seed * 7919 + 17);
    for (int i = 0; i < o.steps; ++i) {
      actions.push_back(policy.next(a->frame()));
      oka = a->step(actions.back());
      okb = b->step(actions.back());
      ++r.steps;
      if (!compare()) break;
    }
  }
  return r;
}

}  // namespace autumn
