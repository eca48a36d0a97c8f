// pass_moves — the last use of a list or object moves it instead of copying.
//
// When a variable holding a value that owns memory (a list, an object with a
// cell list, a sum) is used for the last time as the value of a store or a
// push, and no loop repeats that use without its declaration, the use becomes
// std::move:
//
//   std::vector<C1_Water> t5; ... s.g_water = std::move(t5);
//
// References (Binds) and loop elements name other places and are never moved
// from. Test: tests/lowering_test.cpp (PassMoves).
#include "compiler/lower/passes.hpp"

#include <map>

#include "compiler/lower/ir_walk.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

bool owns_memory(TypeP t) {
  return t->k == TK::List || t->k == TK::Sum || t->k == TK::Obj;
}

// Whether `v`'s use at position `at` is its last and no loop repeats it.
bool last_use(const Walk& w, const Var* v, int at) {
  auto u = w.uses.find(v);
  if (u == w.uses.end()) return false;
  for (int p : u->second)
    if (p > at) return false;
  auto d = w.declared.find(v);
  if (d == w.declared.end()) return false;
  for (const Walk::Loop& l : w.loops)
    if (at >= l.begin && at <= l.end && !(d->second >= l.begin && d->second <= l.end)) return false;
  return true;
}

bool movable(const Var* v, const std::map<const Var*, const Stmt*>& intro) {
  auto it = intro.find(v);
  return it != intro.end() && (it->second->k == SK::Decl || it->second->k == SK::Let) && owns_memory(v->type);
}

}  // namespace

void move_last_uses(Module& m) {
  std::vector<bool> stores_state(m.functions.size(), false);
  for (const auto& f : m.functions) {
    Walk w = walk_function(*f, stores_state);
    std::map<const Var*, const Stmt*> intro;
    for (const Stmt* s : w.at)
      if (s->var) intro[s->var] = s;
    for (const Stmt* cs : w.at) {
      Stmt* s = const_cast<Stmt*>(cs);
      const int at = w.position.at(cs);
      if ((s->k == SK::Set || s->k == SK::Push) && s->b->op == Op::Local && movable(s->b->var, intro) &&
          last_use(w, s->b->var, at)) {
        s->move_value = true;
        s->b->var->moved = true;
        continue;
      }
      // A new value built from variables at their last use takes them over.
      Node* value = s->k == SK::Let || s->k == SK::Decl ? s->a : s->k == SK::Set || s->k == SK::Push ? s->b : nullptr;
      if (!value || (value->op != Op::MakeObj && value->op != Op::MakeList && value->op != Op::MakeSum)) continue;
      for (size_t i = 0; i < value->a.size() && i < 32; ++i) {
        const Node* k = value->a[i];
        if (k->op != Op::Local || !movable(k->var, intro) || !last_use(w, k->var, at)) continue;
        int occurrences = 0;
        for (const Node* o : value->a) occurrences += o->op == Op::Local && o->var == k->var;
        if (occurrences != 1) continue;
        s->move_operands |= 1u << i;
        k->var->moved = true;
      }
    }
  }
}

}  // namespace autumn::lower
