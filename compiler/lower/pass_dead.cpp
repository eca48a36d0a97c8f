// pass_dead — names nobody reads are not computed.
//
// The specialiser names values eagerly (every operand gets a temporary or a
// Bind), and later passes make some of those names unused (pass_aliases
// replaces references by their variables; concat of a list literal appends the
// parts directly). A Let or Bind whose variable is never used and whose value
// has no effect is removed, repeatedly, so the list literal that fed it goes too:
//
//   const std::vector<std::vector<CellV>> t5 = {t3, t4};   // removed: t5 unused
//
// Values with effects (helper calls that draw, store or may fail, function
// calls) are kept. Test: tests/lowering_test.cpp (IrPasses).
#include <functional>
#include <map>

#include "compiler/lower/ir_walk.hpp"
#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

void count_uses(const Node* n, std::map<const Var*, int>& uses) {
  if (!n) return;
  if (n->op == Op::Local) ++uses[n->var];
  for (const Node* k : n->a) count_uses(k, uses);
}

void count_block(const Block& b, std::map<const Var*, int>& uses) {
  for (const Stmt* s : b) {
    count_uses(s->a, uses);
    count_uses(s->b, uses);
    count_block(s->body, uses);
    count_block(s->other, uses);
    for (const auto& [k, c] : s->cases) count_block(c, uses);
  }
}

// Removes dead Let/Bind statements from `b`; true if it removed any.
bool sweep(Block& b, const std::map<const Var*, int>& uses) {
  bool removed = false;
  for (size_t i = 0; i < b.size();) {
    Stmt* s = b[i];
    const bool in_body = sweep(s->body, uses);  // both blocks are swept, whatever the first found
    const bool in_other = sweep(s->other, uses);
    removed = removed || in_body || in_other;
    for (auto& [k, c] : s->cases) removed |= sweep(c, uses);
    const bool dead = (s->k == SK::Let || s->k == SK::Bind) && !uses.count(s->var) && pure(s->a);
    if (dead) {
      b.erase(b.begin() + static_cast<long>(i));
      removed = true;
    } else {
      ++i;
    }
  }
  return removed;
}

}  // namespace

void remove_dead_names(Module& m) {
  for (const auto& f : m.functions)
    for (;;) {
      std::map<const Var*, int> uses;
      count_block(f->body, uses);
      if (!sweep(f->body, uses)) break;
    }
}

}  // namespace autumn::lower
