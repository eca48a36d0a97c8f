// pass_loop_budget — loops that cannot be long charge nothing.
//
// Specialised code charges every loop's length against the step's budget before
// it runs (charge_loop, docs/design.md "Limits"), so that nested loops over long
// lists end with a located error instead of running for hours. A loop over a
// list that is declared right there and filled by a few pushes in straight-line
// code (the cells of one object, rendered to ask whether it was clicked or
// touches another) has at most that many elements; charging it costs as much as
// walking it. Such a loop, of at most kShort elements, is not charged: the loop
// around it is, so the work it adds is at most kShort times what is charged.
//
//   std::vector<Elem>& r = s.scratch.v.b2;  r.clear();      std::vector<Elem>& r = ...;  r.clear();
//   r.push_back(Elem{...});                              =>  r.push_back(Elem{...});
//   { const auto& e_list = r;                                { const auto& e_list = r;
//     charge_loop(s.core, 7, int64_t(e_list.size()));          for (const Elem& e : e_list) ...
//     for (const Elem& e : e_list) ...
//
// Known length: the Decl's initial list (none, or a literal list of k items)
// plus one per Push into it before the loop, where no push sits in a loop
// nested after the Decl, and nothing else writes or reads the list in between
// (a render call filling it, an append, a copy). A range with literal bounds
// counts its span. Test: tests/lowering_test.cpp (IrPasses.ShortLoopsAreNotCharged).
//
// A loop that may stop early (a break of its own: `any`, and `in` and the
// collision helpers through it) is charged one per element as it visits it,
// not its whole length before: the interpreter makes a call per element it
// visits, and a charge up front stopped a step the interpreter finishes
// (tests/lowering/early_exit_budget.au).
#include "compiler/lower/ir_walk.hpp"
#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

constexpr int64_t kShort = 16;

// Whether position q lies in a loop that starts after position d.
bool repeated_after(const Walk& w, int d, int q) {
  for (const Walk::Loop& l : w.loops)
    if (l.begin > d && l.begin < q && q <= l.end) return true;
  return false;
}

// The most elements the list of the ForEach at position p can hold, or -1.
int64_t known_length(const Walk& w, const Stmt& loop, int p) {
  if (!loop.a || loop.a->op != Op::Local) return -1;
  const Var* v = loop.a->var;
  const auto d_it = w.declared.find(v);
  if (d_it == w.declared.end()) return -1;
  const int d = d_it->second;
  const Stmt& decl = *w.at[d];
  if (decl.k != SK::Decl || d >= p) return -1;
  int64_t n = 0;
  if (decl.a) {
    if (decl.a->op != Op::MakeList) return -1;
    n = static_cast<int64_t>(decl.a->a.size());
  }
  if (const auto u = w.uses.find(v); u != w.uses.end())
    for (int q : u->second)
      if (q > d && q < p) return -1;  // read, or filled by a call, before the loop
  if (const auto st = w.stores.find(Root{v, -1}); st != w.stores.end())
    for (int q : st->second) {
      if (q <= d) continue;
      if (q >= p || w.at[q]->k != SK::Push || repeated_after(w, d, q)) return -1;
      ++n;
    }
  return n;
}

// Whether `b` holds a break of the loop whose body it is (not of a loop nested in it).
bool breaks_out(const Block& b) {
  for (const Stmt* s : b) {
    if (s->k == SK::Break) return true;
    if (s->k == SK::ForEach || s->k == SK::ForRange) continue;
    if (breaks_out(s->body) || breaks_out(s->other)) return true;
    for (const auto& [k, c] : s->cases)
      if (breaks_out(c)) return true;
  }
  return false;
}

void spare(const Walk& w, Block& b) {
  for (Stmt* s : b) {
    if ((s->k == SK::ForEach || s->k == SK::ForRange) && breaks_out(s->body)) s->charge_each = true;
    if (s->k == SK::ForEach) {
      const int64_t n = known_length(w, *s, w.position.at(s));
      if (n >= 0 && n <= kShort) s->charged = false;
    } else if (s->k == SK::ForRange && s->a && s->b && s->a->op == Op::Lit && s->b->op == Op::Lit) {
      if (s->b->imm - s->a->imm <= kShort) s->charged = false;
    }
    spare(w, s->body);
    spare(w, s->other);
    for (auto& [k, c] : s->cases) spare(w, c);
  }
}

}  // namespace

void spare_short_loops(Module& m) {
  const std::vector<bool> none(m.functions.size(), false);
  for (auto& f : m.functions) {
    const Walk w = walk_function(*f, none);
    spare(w, f->body);
  }
}

}  // namespace autumn::lower
