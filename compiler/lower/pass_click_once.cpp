// pass_click_once — a loop that defines the click global on every element defines it once, before.
//
// `(clicked obj)` defines the global `click` from the pending click each time it
// is evaluated (spec_builtins_state: define_click), so `(removeObj xs (--> o
// (clicked o)))` stores the same two values for every element of xs. Those
// stores sit in the hottest loop of a click and keep g++ from holding anything
// of the state in registers across it (a store to a bool or an int of the state
// may alias the elements being copied): a third of gameOfLife's click step.
// Where they lead the loop's body, guarded by an input flag only, they are done
// once before the loop, under the flag and only if the list has an element:
//
//   for_each o in xs                              if and(not(empty(xs)), input_flag(0))
//     decl clicked = 0                              set slot d_click = 1
//     if input_flag(0)                   =>        let t = click_pos
//       set slot d_click = 1                        set global g_click = t
//       let t = click_pos                         for_each o in xs
//       set global g_click = t                      decl clicked = 0
//       ...compare o's cells with the click...      if input_flag(0)
//                                                     ...compare...
//
// The same stores, of the same values (a literal or the click's position: the
// step changes neither), happen in the same runs: the flag does not change
// during a step, the list is read the same before the loop as in it, and no
// statement before them in the body reads or writes their slots. Nothing else
// in the loop may read or store those slots or call a function that stores
// state. A click position with an identity (a fresh uid each time) is not a
// literal and stays. Test: tests/lowering_test.cpp (IrPasses.ClickDefinedInALoopIsDefinedOnce),
// tests/lowering/click_once.au (both engines), tests/ir/define_click_once.ir.
#include <set>

#include "compiler/lower/ir_walk.hpp"
#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

bool is_click_pos(const Node* n) { return n && n->op == Op::Call && n->helper == Helper::ClickPos && n->a.empty(); }
bool is_input_flag(const Node* n) {
  return n && n->op == Op::Call && n->helper == Helper::InputFlag && n->a.size() == 1 && n->a[0]->op == Op::Lit;
}
class ClickOnce {
 public:
  ClickOnce(Module& m, const std::vector<bool>& stores_state) : m_(m), stores_state_(stores_state) {}

  void block(Block& b) {
    for (size_t i = 0; i < b.size(); ++i) {
      Stmt* s = b[i];
      if (s->k == SK::ForEach && !s->move_value && hoist(b, i)) ++i;  // past the loop, now at i + 1
      Stmt* at = b[i];
      block(at->body);
      block(at->other);
      for (auto& [k, c] : at->cases) block(c);
    }
  }

 private:
  // The run of stores leading the flag's branch: sets of literals or the
  // click's position (directly, or through a let of it in the run).
  static size_t leading_stores(const Block& b, std::set<const Var*>& lets, std::set<int>& slots) {
    size_t n = 0;
    for (; n < b.size(); ++n) {
      const Stmt* s = b[n];
      if (s->k == SK::Let && is_click_pos(s->a)) {
        lets.insert(s->var);
        continue;
      }
      if (s->k != SK::Set || s->move_operands || s->move_value) break;
      if (!s->a || (s->a->op != Op::Slot && s->a->op != Op::Global)) break;
      const Node* v = s->b;
      if (!(v->op == Op::Lit || is_click_pos(v) || (v->op == Op::Local && lets.count(v->var)))) break;
      slots.insert(s->a->slot);
    }
    return n;
  }

  // Whether anything in `b` (but the statements of `skip`) touches `slots`,
  // uses a variable of `lets`, or calls a function that stores state.
  bool touched(const Block& b, const std::set<int>& slots, const std::set<const Var*>& lets,
               const std::set<const Stmt*>& skip) const {
    for (const Stmt* s : b) {
      if (skip.count(s)) continue;
      if (touches(s->a, slots, lets) || touches(s->b, slots, lets)) return true;
      if (s->var && lets.count(s->var)) return true;
      if (touched(s->body, slots, lets, skip) || touched(s->other, slots, lets, skip)) return true;
      for (const auto& [k, c] : s->cases)
        if (touched(c, slots, lets, skip)) return true;
    }
    return false;
  }
  bool touches(const Node* n, const std::set<int>& slots, const std::set<const Var*>& lets) const {
    if (!n) return false;
    if ((n->op == Op::Slot || n->op == Op::Global) && slots.count(n->slot)) return true;
    if (n->op == Op::Local && lets.count(n->var)) return true;
    if (n->op == Op::FnCall && (n->index < 0 || static_cast<size_t>(n->index) >= stores_state_.size() ||
                                stores_state_[n->index]))
      return true;
    for (const Node* k : n->a)
      if (touches(k, slots, lets)) return true;
    return false;
  }

  bool hoist(Block& outer, size_t at) {
    Stmt* loop = outer[at];
    if (!pure(loop->a)) return false;  // read again before the loop
    // The body's lead: comments and declarations that read no state, then the flag's branch.
    size_t k = 0;
    for (; k < loop->body.size(); ++k) {
      const Stmt* s = loop->body[k];
      const bool lead = s->k == SK::Comment || ((s->k == SK::Decl || s->k == SK::Let) && (!s->a || s->a->op == Op::Lit));
      if (!lead) break;
    }
    if (k == loop->body.size()) return false;
    Stmt* branch = loop->body[k];
    if (branch->k != SK::If || !is_input_flag(branch->a)) return false;
    std::set<const Var*> lets;
    std::set<int> slots;
    const size_t n = leading_stores(branch->body, lets, slots);
    if (slots.empty()) return false;
    const std::set<const Stmt*> run(branch->body.begin(), branch->body.begin() + static_cast<long>(n));
    if (touched(loop->body, slots, lets, run)) return false;
    // if and(not(empty(list)), flag): the run, moved out of the loop.
    Stmt* once = stmt(SK::If);
    once->a = node(Op::And, m_.types.bool_(),
                   {node(Op::Not, m_.types.bool_(), {node(Op::Empty, m_.types.bool_(), {copy(loop->a)})}),
                    copy(branch->a)});
    once->body.assign(branch->body.begin(), branch->body.begin() + static_cast<long>(n));
    branch->body.erase(branch->body.begin(), branch->body.begin() + static_cast<long>(n));
    outer.insert(outer.begin() + static_cast<long>(at), once);
    return true;
  }

  Node* node(Op op, TypeP t, std::vector<Node*> a) {
    m_.arena.nodes.emplace_back();
    Node* n = &m_.arena.nodes.back();
    n->op = op;
    n->type = t;
    n->a = std::move(a);
    return n;
  }
  Node* copy(const Node* n) {
    m_.arena.nodes.emplace_back(*n);
    Node* c = &m_.arena.nodes.back();
    for (Node*& k : c->a) k = copy(k);
    return c;
  }
  Stmt* stmt(SK k) {
    m_.arena.stmts.emplace_back();
    Stmt* s = &m_.arena.stmts.back();
    s->k = k;
    return s;
  }

  Module& m_;
  const std::vector<bool>& stores_state_;
};

}  // namespace

void define_click_once(Module& m) {
  std::vector<bool> stores_state;
  for (const auto& f : m.functions) stores_state.push_back(f && function_stores_state(*f));
  ClickOnce pass(m, stores_state);
  for (auto& f : m.functions)
    if (f) pass.block(f->body);
}

}  // namespace autumn::lower
