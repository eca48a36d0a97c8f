// pass_budget_locals — a loop that charges the budget as it runs keeps the counts in a local.
//
// The step's two budget counts (elements its loops visit, cells its constructs
// build: docs/design.md "Limits") live in the state's core. A filter charges
// each element it keeps as it keeps it; through the core, each charge's load
// waited on the last one's store, and g++ cannot keep the count in a register
// across the loop's calls (a push's growth path, the failure). Such a loop
// takes the counts into a plain local before it runs and gives them back after:
//
//   { const auto& x_list = l;                        { Budget budget = budget_of(s.core);
//     charge_loop(s.core, 7, ...);                     const auto& x_list = l;
//     for (const P& x : x_list)                  =>    charge_loop(budget, 7, ...);
//       if (...) { charge_built(s.core, 7, 1);         for (const P& x : x_list)
//                  kept.push_back(x); } }                if (...) { charge_built(budget, 7, 1); ... }
//                                                      give_back(s.core, budget); }
//
// The same charges against the same limits, in the same order, with the same
// failures. A loop qualifies when its body charges (a ChargeBuilt, or a loop
// inside that charges its length), calls no module function that may charge
// (those charge the core), and has no return (it would skip give_back). Only the
// outermost such loop is marked: loops inside it charge its local. A failure
// throws out of the step, whose counts are then never read (the next entry
// starts them afresh), so nothing gives them back on that path.
// Test: tests/lowering_test.cpp (IrPasses.LoopsChargingAsTheyRunKeepTheCountsLocal),
// tests/ir/keep_budgets_local.ir.
#include "compiler/lower/ir_walk.hpp"
#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

void mark(Block& b, const std::vector<bool>& charging) {
  for (Stmt* s : b) {
    if ((s->k == SK::ForEach && !s->move_value) || s->k == SK::ForRange) {
      const BudgetUse u = budget_use(s->body, charging);
      if (u.charges && !u.calls_charging && !u.returns) {
        s->local_budget = true;
        continue;  // the loops inside charge this one's local
      }
    }
    mark(s->body, charging);
    mark(s->other, charging);
    for (auto& [k, c] : s->cases) mark(c, charging);
  }
}

}  // namespace

void keep_budgets_local(Module& m) {
  const std::vector<bool> charging = functions_charging(m.functions);
  for (auto& f : m.functions)
    if (f) mark(f->body, charging);
}

}  // namespace autumn::lower
