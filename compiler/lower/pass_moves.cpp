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

#include "compiler/lower/ir_walk.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

bool owns_memory(TypeP t) {
  return t->k == TK::List || t->k == TK::Sum || t->k == TK::Obj;
}

}  // namespace

void move_last_uses(Module& m) {
  std::vector<bool> stores_state(m.functions.size(), false);
  for (const auto& f : m.functions) {
    Walk w = walk_function(*f, stores_state);
    std::map<const Var*, const Stmt*> intro;
    for (const Stmt* s : w.at)
      if (s->var) intro[s->var] = s;
    for (const Stmt* s : w.at) {
      if ((s->k != SK::Set && s->k != SK::Push) || s->b->op != Op::Local) continue;
      Var* v = s->b->var;
      auto it = intro.find(v);
      if (it == intro.end() || (it->second->k != SK::Decl && it->second->k != SK::Let)) continue;
      if (!owns_memory(v->type)) continue;
      const int at = w.position.at(s);
      const auto& uses = w.uses.at(v);
      bool later = false;
      for (int u : uses) later |= u > at;
      if (later) continue;
      const int decl = w.declared.at(v);
      bool repeated = false;
      for (const Walk::Loop& l : w.loops) repeated |= at >= l.begin && at <= l.end && !(decl >= l.begin && decl <= l.end);
      if (repeated) continue;
      const_cast<Stmt*>(s)->move_value = true;
      v->moved = true;
    }
  }
}

}  // namespace autumn::lower
