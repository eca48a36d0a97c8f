// pass_refs — a name for a place: a reference when nothing can change the place
// while the name is in use, else a copy.
//
// The specialiser names every read of a global or a variable with a Bind. Most
// are only read before any store to their place, so they can stay references
// and the read costs nothing (a global list read by reference instead of copied
// was most of a step's allocations). A Bind becomes a copy when a store to its
// place (or a call of a function that stores state) may run between the Bind and
// a later use of it or of a name bound from it, counting a loop's repetition:
//
//   const std::vector<C1_Water>& t4 = s.g_water;   // stays a reference:
//   for (const C1_Water& x : t4) ...                //   water is stored only after
//   s.g_water = std::move(out);
//
//   const C2_Cloud& t9 = s.g_cloud;                // becomes a copy: the store
//   s.g_cloud = t12;                                //   runs before the last use
//   ... t9.origin ...
// Test: tests/lowering_test.cpp (PassRefs).
#include "compiler/lower/passes.hpp"

#include <algorithm>

#include "compiler/lower/ir_walk.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

// Variables bound (by Bind) from `v`, transitively, with v itself.
std::vector<const Var*> names_of(const Var* v, const std::map<const Var*, std::vector<const Var*>>& bound_from) {
  std::vector<const Var*> out{v};
  for (size_t i = 0; i < out.size(); ++i)
    if (auto it = bound_from.find(out[i]); it != bound_from.end())
      for (const Var* w : it->second) out.push_back(w);
  return out;
}

// The places a Bind names: its root, or both of a Select's (prev: the snapshot or the global).
std::vector<Root> roots_of(const Node* n) {
  if (n->op == Op::Select) return {root_of(n->a[1]), root_of(n->a[2])};
  return {root_of(n)};
}

bool must_copy(const Walk& w, int at, const std::vector<Root>& roots, const std::vector<int>& uses) {
  std::vector<int> stores;
  for (const Root& root : roots) {
    if (auto it = w.stores.find(root); it != w.stores.end()) stores.insert(stores.end(), it->second.begin(), it->second.end());
    if (root.slot >= 0) stores.insert(stores.end(), w.opaque_stores.begin(), w.opaque_stores.end());
  }
  for (int s : stores) {
    if (s <= at) continue;
    for (int u : uses)
      if (u > s) return true;
  }
  // A loop that begins after the Bind repeats: a store anywhere in it comes
  // before the uses of the next round.
  for (const Walk::Loop& l : w.loops) {
    if (l.begin <= at) continue;
    bool store_in = false, use_in = false;
    for (int s : stores) store_in |= s >= l.begin && s <= l.end;
    for (int u : uses) use_in |= u >= l.begin && u <= l.end;
    if (store_in && use_in) return true;
  }
  return false;
}

}  // namespace

void settle_references(Module& m) {
  std::vector<bool> stores_state;
  for (const auto& f : m.functions) stores_state.push_back(function_stores_state(*f));
  for (const auto& f : m.functions) {
    Walk w = walk_function(*f, stores_state);
    std::map<const Var*, std::vector<const Var*>> bound_from;
    for (const Stmt* s : w.at)
      if (s->k == SK::Bind && s->a->op == Op::Local) bound_from[s->a->var].push_back(s->var);
    for (const Stmt* s : w.at) {
      if (s->k != SK::Bind) continue;
      std::vector<Root> roots = roots_of(s->a);
      std::vector<int> uses;
      for (const Var* v : names_of(s->var, bound_from))
        if (auto it = w.uses.find(v); it != w.uses.end()) uses.insert(uses.end(), it->second.begin(), it->second.end());
      s->var->is_ref = !must_copy(w, w.position.at(s), roots, uses);
    }
  }
}

}  // namespace autumn::lower
