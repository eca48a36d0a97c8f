// ir_walk — a linear view of a function's statements for the IR passes.
//
// Numbers every statement in execution-text order (pre-order) and records, per
// variable, where it is used and, per place (a state slot or a variable), where
// it is stored; loops are recorded as position ranges. The passes (refs, moves,
// scratch) answer their questions on these tables instead of re-walking trees.
// Test: tests/lowering_test.cpp (IrPasses).
#pragma once
#include <map>
#include <memory>
#include <vector>

#include "compiler/lower/ir.hpp"

namespace autumn::lower::ir {

// The variable or state slot a place expression names (its root).
struct Root {
  const Var* var = nullptr;
  int slot = -1;
  bool operator<(const Root& o) const { return var != o.var ? var < o.var : slot < o.slot; }
  bool operator==(const Root& o) const { return var == o.var && slot == o.slot; }
};
Root root_of(const Node* n);  // var == nullptr && slot < 0: not a place

struct Walk {
  struct Loop {
    int begin, end;  // positions of the loop statement and of its last nested statement
  };
  std::map<const Var*, std::vector<int>> uses;      // positions reading the variable
  std::map<const Var*, int> declared;               // position of the introducing statement
  std::map<Root, std::vector<int>> stores;          // positions writing the place
  std::vector<int> opaque_stores;                   // calls of functions that store state
  std::vector<Loop> loops;
  std::map<const Stmt*, int> position;
  std::vector<const Stmt*> at;                      // by position
  int end = 0;
};

// `stores_state(f)`: whether calling module function f may store a state slot.
Walk walk_function(const Function& f, const std::vector<bool>& stores_state);

// Whether evaluating n has no effect and calls nothing (no helper, no module
// function): it may be dropped, or evaluated again with the same result.
bool pure(const Node* n);

// Whether function f stores any state slot (directly).
bool function_stores_state(const Function& f);

// What a block does with the step's budget counts (Core::visited, ::built),
// nested statements included.
struct BudgetUse {
  bool charges = false;        // a ChargeBuilt, or a loop that charges its length
  bool calls_charging = false; // a call of a module function that charges (charging[index])
  bool returns = false;        // a Return
  bool local = false;          // a loop that keeps the counts in a local (Stmt::local_budget)
};
BudgetUse budget_use(const Block& b, const std::vector<bool>& charging);
// Per module function: whether calling it may charge the budget (itself, or
// through the functions it calls; recursive functions included).
std::vector<bool> functions_charging(const std::vector<std::unique_ptr<Function>>& functions);

}  // namespace autumn::lower::ir
