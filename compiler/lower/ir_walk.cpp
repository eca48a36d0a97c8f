// ir_walk — see ir_walk.hpp.
#include "compiler/lower/ir_walk.hpp"

#include <functional>

namespace autumn::lower::ir {

Root root_of(const Node* n) {
  switch (n->op) {
    case Op::Local: return Root{n->var, -1};
    case Op::Global:
    case Op::Slot: return Root{nullptr, n->slot};
    case Op::Member: return root_of(n->a[0]);
    default: return Root{};
  }
}

namespace {

bool is_place(const Root& r) { return r.var || r.slot >= 0; }

class Walker {
 public:
  Walker(Walk& w, const std::vector<bool>& stores_state) : w_(w), stores_state_(stores_state) {}

  void block(const Block& b) {
    for (const Stmt* s : b) stmt(*s);
  }

 private:
  void uses(const Node* n, int pos) {
    if (!n) return;
    if (n->op == Op::Local) w_.uses[n->var].push_back(pos);
    if (n->op == Op::FnCall && n->index >= 0 && n->index < static_cast<int>(stores_state_.size()) &&
        stores_state_[n->index])
      w_.opaque_stores.push_back(pos);
    if (n->op == Op::Call && (n->helper == Helper::Reserve || n->helper == Helper::Clear || n->helper == Helper::Append)) {
      store(n->a[0], pos);
      for (size_t i = 1; i < n->a.size(); ++i) uses(n->a[i], pos);
      return;
    }
    for (const Node* k : n->a) uses(k, pos);
  }
  void store(const Node* place, int pos) {
    Root r = root_of(place);
    if (is_place(r)) w_.stores[r].push_back(pos);
    // Index operands inside a place expression are reads.
    if (place->op == Op::Member) uses_inside_place(place->a[0], pos);
  }
  void uses_inside_place(const Node* n, int pos) {
    if (n->op == Op::Member) uses_inside_place(n->a[0], pos);
  }
  void stmt(const Stmt& s) {
    const int pos = w_.end++;
    w_.position[&s] = pos;
    w_.at.push_back(&s);
    if (s.var) w_.declared[s.var] = pos;
    switch (s.k) {
      case SK::Swap:
        store(s.a, pos);
        store(s.b, pos);
        uses(s.a, pos);
        uses(s.b, pos);
        break;
      case SK::Set:
      case SK::Push:
        store(s.a, pos);
        uses(s.b, pos);
        if (s.move_value) store(s.b, pos);  // moved from: its place changes too
        break;
      case SK::ForEach: {
        block(s.body);
        uses(s.a, w_.end - 1 > pos ? w_.end - 1 : pos);  // the list is read throughout the loop
        if (s.move_value) store(s.a, w_.end - 1 > pos ? w_.end - 1 : pos);  // and then moved from
        w_.loops.push_back(Walk::Loop{pos, w_.end - 1});
        return;
      }
      case SK::ForRange:
        uses(s.a, pos);
        uses(s.b, pos);
        block(s.body);
        w_.loops.push_back(Walk::Loop{pos, w_.end - 1});
        return;
      default:
        uses(s.a, pos);
        uses(s.b, pos);
        break;
    }
    block(s.body);
    block(s.other);
    for (const auto& [k, b] : s.cases) block(b);
  }

  Walk& w_;
  const std::vector<bool>& stores_state_;
};

}  // namespace

Walk walk_function(const Function& f, const std::vector<bool>& stores_state) {
  Walk w;
  Walker(w, stores_state).block(f.body);
  return w;
}

bool pure(const Node* n) {
  if (!n) return true;
  if (n->op == Op::Call || n->op == Op::FnCall) return false;
  for (const Node* k : n->a)
    if (!pure(k)) return false;
  return true;
}

bool function_stores_state(const Function& f) {
  bool found = false;
  std::function<void(const Block&)> rec = [&](const Block& b) {
    for (const Stmt* s : b) {
      if ((s->k == SK::Set || s->k == SK::Push) && root_of(s->a).slot >= 0) found = true;
      rec(s->body);
      rec(s->other);
      for (const auto& [k, c] : s->cases) rec(c);
    }
  };
  rec(f.body);
  return found;
}

namespace {

void budget_use_of(const Node* n, const std::vector<bool>& charging, BudgetUse& u) {
  if (!n) return;
  if (n->op == Op::Call && n->helper == Helper::ChargeBuilt) u.charges = true;
  if (n->op == Op::FnCall && n->index >= 0 && static_cast<size_t>(n->index) < charging.size() && charging[n->index])
    u.calls_charging = true;
  for (const Node* k : n->a) budget_use_of(k, charging, u);
}

void budget_use_of(const Block& b, const std::vector<bool>& charging, BudgetUse& u) {
  for (const Stmt* s : b) {
    if ((s->k == SK::ForEach || s->k == SK::ForRange) && s->charged) u.charges = true;
    if (s->local_budget) u.local = true;
    if (s->k == SK::Return) u.returns = true;
    budget_use_of(s->a, charging, u);
    budget_use_of(s->b, charging, u);
    budget_use_of(s->body, charging, u);
    budget_use_of(s->other, charging, u);
    for (const auto& [k, c] : s->cases) budget_use_of(c, charging, u);
  }
}

}  // namespace

BudgetUse budget_use(const Block& b, const std::vector<bool>& charging) {
  BudgetUse u;
  budget_use_of(b, charging, u);
  return u;
}

std::vector<bool> functions_charging(const std::vector<std::unique_ptr<Function>>& functions) {
  std::vector<bool> charging(functions.size(), false);
  for (bool changed = true; changed;) {  // until no function is found to charge through another
    changed = false;
    for (size_t i = 0; i < functions.size(); ++i) {
      if (charging[i] || !functions[i]) continue;
      const BudgetUse u = budget_use(functions[i]->body, charging);
      if (u.charges || u.calls_charging) charging[i] = changed = true;
    }
  }
  return charging;
}

}  // namespace autumn::lower::ir
