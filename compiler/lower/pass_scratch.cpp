// pass_scratch — lists rebuilt every time their code runs keep their storage.
//
// A list declared empty (a map's result, a render's output, range) whose value
// never leaves its block — it is only filled, iterated, measured (its length
// checked against the budget) or indexed —
// can live in a buffer of the state that is cleared instead of freed, so a step
// allocates nothing for it after the first:
//
//   std::vector<Elem>& t7 = s.scratch.v.b3;  t7.clear();   // instead of
//   std::vector<Elem> t7;                                  // (a fresh vector)
//
// A list escapes when it is stored (in a variable, a global, another list, an
// object), returned, or named by another binding. The same Decl cannot run
// again while its list is in use: every inlined call site has its own Decl, and
// there is no recursion. Test: tests/lowering_test.cpp (PassScratch).
#include <functional>
#include <map>
#include <set>

#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

// Records every variable that occurs in `n` where its value could be kept.
void escapes(const Node* n, std::set<const Var*>& out) {
  if (!n) return;
  switch (n->op) {
    case Op::Local: out.insert(n->var); return;
    case Op::Size:
    case Op::Empty:
    case Op::Index:
    case Op::Front:
    case Op::Back:
      // Reading: the list itself stays (an element copied out is not the list).
      for (size_t i = 1; i < n->a.size(); ++i) escapes(n->a[i], out);
      if (n->a[0]->op != Op::Local) escapes(n->a[0], out);
      return;
    case Op::Call:
      if (n->helper == Helper::Reserve || n->helper == Helper::Clear || n->helper == Helper::Append ||
          n->helper == Helper::OrderKeys || n->helper == Helper::DrawnKeys ||  // fill their lists
          n->helper == Helper::CheckLength || n->helper == Helper::ChargeBuilt) {  // the checks measure their lists
        for (const Node* k : n->a)
          if (k->op != Op::Local) escapes(k, out);
        return;
      }
      break;
    case Op::FnCall:  // render functions fill their last argument
      for (size_t i = 0; i < n->a.size(); ++i)
        if (!(i + 1 == n->a.size() && n->a[i]->op == Op::Local)) escapes(n->a[i], out);
      return;
    default:
      break;
  }
  for (const Node* k : n->a) escapes(k, out);
}

void scan(const Block& b, std::set<const Var*>& escaped, std::vector<Var*>& candidates,
          std::map<const Var*, const Var*>& alias_of) {
  for (Stmt* s : b) {
    switch (s->k) {
      case SK::Bind:  // another name for the same list: its uses count as the list's
        if (s->a->op == Op::Local) alias_of[s->var] = s->a->var;
        else escapes(s->a, escaped);
        break;
      case SK::Decl:
        if (!s->a && s->var->type->k == TK::List) candidates.push_back(s->var);
        escapes(s->a, escaped);
        break;
      case SK::Push:
        if (s->a->op != Op::Local) escapes(s->a, escaped);
        escapes(s->b, escaped);
        break;
      case SK::Set:
        // Assigning into the list copies into its storage. The list assigned
        // escapes, unless this is its last use: then it is swapped into place
        // (the place's old storage becomes the buffer).
        if (s->a->op != Op::Local) escapes(s->a, escaped);
        if (!(s->move_value && s->b->op == Op::Local)) escapes(s->b, escaped);
        break;
      case SK::ForEach:
        if (s->a->op != Op::Local) escapes(s->a, escaped);
        break;
      default:
        escapes(s->a, escaped);
        escapes(s->b, escaped);
        break;
    }
    scan(s->body, escaped, candidates, alias_of);
    scan(s->other, escaped, candidates, alias_of);
    for (auto& [k, c] : s->cases) scan(c, escaped, candidates, alias_of);
  }
}

}  // namespace

void reuse_buffers(Module& m) {
  for (const auto& f : m.functions) {
    std::set<const Var*> escaped;
    std::vector<Var*> candidates;
    std::map<const Var*, const Var*> alias_of;
    scan(f->body, escaped, candidates, alias_of);
    for (const auto& [alias, source] : alias_of)
      if (escaped.count(alias)) {
        const Var* v = source;
        while (v) {
          escaped.insert(v);
          auto it = alias_of.find(v);
          v = it == alias_of.end() ? nullptr : it->second;
        }
      }
    for (Var* v : candidates) v->scratch = !escaped.count(v) && v->type->elem;
  }
}

}  // namespace autumn::lower
