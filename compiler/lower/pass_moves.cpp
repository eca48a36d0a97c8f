// pass_moves — the last use of a list or object moves it instead of copying.
//
// When a variable holding a value that owns memory (a list, an object with a
// cell list, a sum) is used for the last time as the value of a store or a
// push, and no loop repeats that use without its declaration, the use becomes
// std::move:
//
//   std::vector<C1_Water> t5; ... s.g_water = std::move(t5);
//
// A loop that only pushes each element of a list at its last use onto an
// empty list (addObj's copy of a list built in the step) moves the whole list
// instead, charged as the loop was:
//
//   for (const C0_Particle& x14 : kept4) added13.push_back(x14);   =>   std::swap(added13, kept4);
//
// References (Binds) and loop elements name other places and are never moved
// from. Tests: tests/lowering_test.cpp (PassMoves), tests/ir/move_whole_list.ir.
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

// Whether ForEach `loop`, at `at` in `b`, copies a list at its last use whole
// into a list declared empty just before it (Decl, then at most a reserve):
// its body is one push of the element, as it is, onto that list.
bool copies_whole(const Walk& w, const Block& b, size_t at, const std::map<const Var*, const Stmt*>& intro) {
  const Stmt* loop = b[at];
  if (loop->body.size() != 1 || loop->a->op != Op::Local || !movable(loop->a->var, intro)) return false;
  const Stmt* push = loop->body[0];
  if (push->k != SK::Push || push->a->op != Op::Local || push->b->op != Op::Local || push->b->var != loop->var) return false;
  const Var* out = push->a->var;
  const Var* from = loop->a->var;
  if (out == from || out->type != from->type) return false;
  size_t k = at;
  if (k > 0 && b[k - 1]->k == SK::Eval && b[k - 1]->a->op == Op::Call && b[k - 1]->a->helper == Helper::Reserve &&
      b[k - 1]->a->a[0]->op == Op::Local && b[k - 1]->a->a[0]->var == out)
    --k;
  if (k == 0 || b[k - 1]->k != SK::Decl || b[k - 1]->var != out || b[k - 1]->a) return false;
  // The loop reads the list to its end (Walk): no later use, and no loop
  // around this one that repeats it without its declaration.
  const int begin = w.position.at(loop);
  int end = begin;
  for (const Walk::Loop& l : w.loops)
    if (l.begin == begin) end = l.end;
  for (int p : w.uses.at(from))
    if (p > end) return false;
  const int declared = w.declared.at(from);
  for (const Walk::Loop& l : w.loops)
    if (l.begin < begin && end <= l.end && !(declared >= l.begin && declared <= l.end)) return false;
  return true;
}

void move_whole_lists(Block& b, const Walk& w, const std::map<const Var*, const Stmt*>& intro) {
  for (size_t i = 0; i < b.size(); ++i) {
    Stmt* s = b[i];
    if (s->k == SK::ForEach && copies_whole(w, b, i, intro)) {
      s->move_value = true;
      s->a->var->moved = true;
    }
    move_whole_lists(s->body, w, intro);
    move_whole_lists(s->other, w, intro);
    for (auto& [k, c] : s->cases) move_whole_lists(c, w, intro);
  }
}

}  // namespace

void move_last_uses(Module& m) {
  std::vector<bool> stores_state(m.functions.size(), false);
  for (const auto& f : m.functions) {
    Walk w = walk_function(*f, stores_state);
    std::map<const Var*, const Stmt*> intro;
    for (const Stmt* s : w.at)
      if (s->var) intro[s->var] = s;
    move_whole_lists(f->body, w, intro);
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
