// ir_verify — the IR's invariants (see ir_verify.hpp).
#include "compiler/lower/ir_verify.hpp"

#include <set>

#include "compiler/lower/ir_print.hpp"
#include "compiler/lower/ir_walk.hpp"

namespace autumn::lower {

namespace {

using namespace ir;

// The operand count of an operation with a fixed one; -1: any.
int ir_arity(Op op) {
  switch (op) {
    case Op::Lit:
    case Op::Text:
    case Op::Local:
    case Op::Global:
    case Op::Slot:
    case Op::Shape: return 0;
    case Op::Member:
    case Op::Neg:
    case Op::Not:
    case Op::MakeSum:
    case Op::SumIs:
    case Op::SumGet:
    case Op::Size:
    case Op::Empty:
    case Op::Front:
    case Op::Back: return 1;
    case Op::Add:
    case Op::Sub:
    case Op::Mul:
    case Op::Div:
    case Op::Mod:
    case Op::Lt:
    case Op::Le:
    case Op::Gt:
    case Op::Ge:
    case Op::Eq:
    case Op::Ne:
    case Op::Index: return 2;
    case Op::Select: return 3;
    default: return -1;
  }
}

class IrVerifier {
 public:
  IrVerifier(const Module& m, std::vector<std::string>& problems) : m_(m), problems_(problems) {}

  void function(const Function& f) {
    f_ = &f;
    scopes_.assign(1, {});
    for (const Var* p : f.params) introduce(p, "a parameter");
    block(f.body);
  }

 private:
  void problem(const std::string& what) {
    if (problems_.size() < 50) problems_.push_back("function " + f_->name + ": " + what);
  }

  void introduce(const Var* v, const char* by) {
    if (!v) return problem(std::string(by) + " introduces no variable");
    if (!introduced_.insert(v).second) problem("v" + std::to_string(v->id) + " introduced twice (again by " + by + ")");
    scopes_.back().insert(v);
  }

  bool in_scope(const Var* v) const {
    for (const auto& s : scopes_)
      if (s.count(v)) return true;
    return false;
  }

  void node(const Node* n, const Stmt* at) {
    if (!n) return problem(std::string("a null operand in a ") + stmt_name(at));
    const int want = ir_arity(n->op);
    if (want >= 0 && static_cast<int>(n->a.size()) != want)
      problem("`" + print_node(n) + "` has " + std::to_string(n->a.size()) + " operand(s), wants " +
              std::to_string(want));
    if (!n->type && n->op != Op::Text && n->op != Op::Concat && n->op != Op::Call && n->op != Op::FnCall)
      problem("`" + print_node(n) + "` has no type");
    switch (n->op) {
      case Op::Local:
        if (!n->var) problem("a local with no variable");
        else if (!in_scope(n->var)) problem("v" + std::to_string(n->var->id) + " read out of its scope");
        break;
      case Op::Global:
      case Op::Slot:
        if (n->slot < 0 || static_cast<size_t>(n->slot) >= m_.slots.size())
          problem("slot " + std::to_string(n->slot) + " does not exist");
        break;
      case Op::MakeObj:
        if (n->index < 0 || static_cast<size_t>(n->index) >= m_.classes.size())
          problem("class " + std::to_string(n->index) + " does not exist");
        break;
      case Op::Shape:
        if (n->index < 0 || static_cast<size_t>(n->index) >= m_.classes.size() ||
            !m_.classes[n->index].shape_table || !m_.classes[n->index].static_shape)
          problem("`" + print_node(n) + "` names no printed table of cells");
        else if (!literal_cells(*m_.classes[n->index].static_shape))
          problem("`" + print_node(n) + "` names cells that are not all literal (x, y, colour)");
        else if (!at || at->k != SK::ForEach || at->a != n)
          problem("`" + print_node(n) + "` read by a " + stmt_name(at) + ", not as a loop's list");
        break;
      case Op::FnCall:
        if (n->index < 0 || static_cast<size_t>(n->index) >= m_.functions.size())
          problem("function #" + std::to_string(n->index) + " does not exist");
        break;
      default: break;
    }
    for (const Node* k : n->a) node(k, at);
  }

  void block(const Block& b) {
    scopes_.emplace_back();
    for (const Stmt* s : b) stmt(s);
    scopes_.pop_back();
  }

  void need(const Node* n, const Stmt* s, const char* what) {
    if (!n) problem(std::string("a ") + stmt_name(s) + " without its " + what);
    else node(n, s);
  }

  void site(const Stmt* s) {
    if (s->loc < 0 || static_cast<size_t>(s->loc) >= m_.locations.size())
      problem(std::string("a ") + stmt_name(s) + " names error site " + std::to_string(s->loc) + ", which does not exist");
  }

  void loop_body(const Stmt* s) {
    contexts_.push_back(SK::ForEach);
    block(s->body);
    contexts_.pop_back();
  }

  void stmt(const Stmt* s) {
    if (!s) return problem("a null statement");
    switch (s->k) {
      case SK::Let:
      case SK::Bind: need(s->a, s, "value"); introduce(s->var, stmt_name(s)); break;
      case SK::Decl:
        if (s->a) node(s->a, s);
        introduce(s->var, "a decl");
        break;
      case SK::Set:
      case SK::Push:
      case SK::Swap: need(s->a, s, "place"); need(s->b, s, "value"); break;
      case SK::Eval: need(s->a, s, "call"); break;
      case SK::If:
        need(s->a, s, "condition");
        block(s->body);
        block(s->other);
        break;
      case SK::ForEach:
      case SK::ForRange:
        need(s->a, s, s->k == SK::ForEach ? "list" : "low bound");
        if (s->k == SK::ForRange) need(s->b, s, "high bound");
        if (s->charged) site(s);
        if (s->charged && s->a && s->a->op == Op::Shape) problem("a loop over a table of cells charges the budget");
        if (s->k == SK::ForEach && s->move_value &&
            (s->body.size() != 1 || s->body[0]->k != SK::Push || !s->body[0]->b || s->body[0]->b->op != Op::Local ||
             s->body[0]->b->var != s->var || !s->a || s->a->op != Op::Local))
          problem("a loop that moves its list whole does more than push each element of a variable");
        if (s->local_budget) budget_local(s);
        scopes_.emplace_back();
        introduce(s->var, stmt_name(s));
        loop_body(s);
        scopes_.pop_back();
        break;
      case SK::Switch:
        need(s->a, s, "subject");
        contexts_.push_back(SK::Switch);
        for (const auto& c : s->cases) block(c.second);
        contexts_.pop_back();
        break;
      case SK::Block: block(s->body); break;
      case SK::Break:
        if (contexts_.empty()) problem("a break outside a loop");
        else if (contexts_.back() == SK::Switch) problem("a break inside a switch (it would leave the switch, not the loop)");
        break;
      case SK::Return:
        if (f_->ret && !s->a) problem("a return without the function's result");
        if (!f_->ret && s->a) problem("a return with a value from a function without a result");
        if (s->a) node(s->a, s);
        break;
      case SK::Fail:
        need(s->a, s, "message");
        site(s);
        break;
      case SK::Comment: break;
    }
  }

  // A loop keeping the budget's counts in a local: every charge inside it
  // must go to that local, and it must reach its end to give them back.
  void budget_local(const Stmt* s) {
    const BudgetUse u = budget_use(s->body, charging_);
    if (u.local) problem("a loop keeping the budget in a local holds another");
    if (u.calls_charging) problem("a loop keeping the budget in a local calls a function that charges the core");
    if (u.returns) problem("a loop keeping the budget in a local returns from inside");
    if (s->k == SK::ForEach && s->move_value) problem("a loop that moves its list whole keeps the budget in a local");
  }

  static const char* stmt_name(const Stmt* s) { return s ? stmt_kind_name(s->k) : "statement"; }

  // A node as ir_print shows it, cut short: enough to find it in a dump.
  std::string print_node(const Node* n) const {
    std::string t = lower::print_node(m_, n);
    return t.size() > 160 ? t.substr(0, 157) + "..." : t;
  }

  const Module& m_;
  std::vector<std::string>& problems_;
  const std::vector<bool> charging_ = functions_charging(m_.functions);
  const Function* f_ = nullptr;
  std::vector<std::set<const Var*>> scopes_;
  std::vector<SK> contexts_;  // enclosing loops (ForEach) and switches
  std::set<const Var*> introduced_;
};

}  // namespace

std::vector<std::string> verify_ir(const Module& m) {
  std::vector<std::string> problems;
  IrVerifier v(m, problems);
  for (const auto& f : m.functions)
    if (f) v.function(*f);
  return problems;
}

}  // namespace autumn::lower
