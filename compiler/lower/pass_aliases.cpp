// pass_aliases — a reference to a local variable is the variable.
//
// The specialiser names every read of a mutable local with a Bind. Once
// pass_refs has found that no store to the variable can intervene (the Bind
// stays a reference), the name is only an alias: its uses read the variable
// itself. Replacing them lets pass_moves see the variable's true last use:
//
//   std::vector<CellV> l_tail; ...              std::vector<CellV> l_tail; ...
//   const std::vector<CellV>& v9 = l_tail;  ->  C0_Snake o = C0_Snake{..., std::move(l_tail), ...};
//   C0_Snake o = C0_Snake{..., v9, ...};
//
// Binds of state slots stay (a global is never moved from). The Bind itself is
// left in place, unused. Test: tests/lowering_test.cpp (IrPasses).
#include <functional>
#include <map>

#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

void collect(const Block& b, std::map<Var*, Var*>& alias) {
  for (Stmt* s : b) {
    if (s->k == SK::Bind && s->var->is_ref && s->a->op == Op::Local && s->a->var->mut) alias[s->var] = s->a->var;
    collect(s->body, alias);
    collect(s->other, alias);
    for (auto& [k, c] : s->cases) collect(c, alias);
  }
}

Var* resolve(Var* v, const std::map<Var*, Var*>& alias) {
  for (auto it = alias.find(v); it != alias.end(); it = alias.find(v)) v = it->second;
  return v;
}

}  // namespace

void resolve_aliases(Module& m) {
  std::map<Var*, Var*> alias;
  for (const auto& f : m.functions) collect(f->body, alias);
  if (alias.empty()) return;
  for (Node& n : m.arena.nodes)
    if (n.op == Op::Local) {
      Var* v = resolve(n.var, alias);
      if (v != n.var) {
        n.var = v;
        n.type = v->type;
      }
    }
}

}  // namespace autumn::lower
