#include "harness/agent/click_model.hpp"

#include <unordered_map>
#include <unordered_set>

#include "compiler/read/sexpr.hpp"

namespace autumn::agent {

namespace {

// One walk over everything the program can evaluate: the click classification
// (ClickUse), the arrows read, and whether `click` is step-local (see the
// header). `guarded` means "a clicked test that must have held ran earlier in
// this step", so `click` holds this step's click.
class InputAnalysis {
 public:
  explicit InputAnalysis(const Program& p) : p_(p) {
    auto sym = [&](Builtin b) { return p.builtin_syms[static_cast<size_t>(b)]; };  // the table's names
    click_ = p.names.click;
    clicked_ = sym(Builtin::Clicked);
    prev_ = sym(Builtin::Prev);
    remove_ = sym(Builtin::RemoveObj);
    const Builtin arrows[4] = {Builtin::Left, Builtin::Right, Builtin::Up, Builtin::Down};
    for (int i = 0; i < 4; ++i) arrow_[i] = sym(arrows[i]);
    for (Builtin b : {Builtin::AllObjs, Builtin::Defined}) order_names_.insert(sym(b));
    for (const Stmt& s : p.stdlib_stmts)
      if (s.kind == StmtKind::Expr && s.expr && s.expr->kind == ExprKind::Assign)
        stdlib_defs_[s.expr->name].push_back(s.expr.get());
  }

  InputUse run() {
    for (const Stmt& s : p_.stmts) stmt(s);
    if (p_.trigger) expr(p_.trigger.get(), Ctx::Condition, false);
    while (!pending_.empty()) {
      Sym s = pending_.back();
      pending_.pop_back();
      for (const Expr* def : stdlib_defs_[s]) expr(def, Ctx::Other, false);
    }
    if (use_.clicks != ClickUse::None && use_.click_note.empty()) use_.click_step_local = true;
    return use_;
  }

 private:
  enum class Ctx { Condition, Callee0, CalleeArgs, Other };

  void sensitive() { use_.clicks = ClickUse::Position; }
  void not_local(const std::string& why) {
    if (use_.click_note.empty()) use_.click_note = why;
  }

  // True when `e` (a condition operand) can only be true after a clicked test
  // held, i.e. with this step's click pending and `click` just defined.
  bool implies_click(const Expr* e) const {
    if (!e) return false;
    if (e->kind == ExprKind::Var) return e->name == clicked_;
    if (e->kind == ExprKind::Call) return !e->kids.empty() && e->kids[0]->kind == ExprKind::Var &&
                                          e->kids[0]->name == clicked_ && e->kids.size() <= 2;
    if (e->kind == ExprKind::Logical) {
      bool l = implies_click(e->kids[0].get()), r = implies_click(e->kids[1].get());
      return e->is_or ? (l && r) : (l || r);
    }
    return false;
  }

  void stmt(const Stmt& s) {
    switch (s.kind) {
      case StmtKind::Object:
        for (const auto& f : s.fields)
          if (is_click_name(f.name)) sensitive(), not_local("a field is named click");
        if (s.cell_expr) expr(s.cell_expr.get(), Ctx::Other, false);
        if (s.constructor_body) expr(s.constructor_body.get(), Ctx::Other, false);
        break;
      case StmtKind::On:
        if (s.cond) expr(s.cond.get(), Ctx::Condition, false);
        if (s.body) expr(s.body.get(), Ctx::Other, implies_click(s.cond.get()));
        break;
      case StmtKind::Expr:
        if (s.expr) expr(s.expr.get(), Ctx::Other, false);
        break;
    }
  }

  bool is_click_name(Sym s) const { return s >= 0 && (s == click_ || s == clicked_); }

  void name(Sym s, Ctx ctx, bool guarded) {
    if (s < 0) return;
    for (int i = 0; i < 4; ++i)
      if (s == arrow_[i]) use_.arrows[i] = true;
    if (order_names_.count(s)) not_local("the program observes the global map's order (" + p_.name(s) + ")");
    if (s == click_) {
      sensitive();
      if (!guarded) not_local("click is read where no clicked test has held in the same step");
      return;
    }
    if (s == clicked_) {
      if (ctx == Ctx::Condition || ctx == Ctx::Callee0) {
        if (use_.clicks == ClickUse::None) use_.clicks = ClickUse::PositionFree;
      } else {
        sensitive();  // (clicked obj), or clicked passed around as a value
      }
      return;
    }
    if (seen_.insert(s).second && stdlib_defs_.count(s)) pending_.push_back(s);
  }

  void call(const Expr* e, bool guarded) {
    const Expr* callee = e->kids[0].get();
    if (callee->kind == ExprKind::Var && callee->name == prev_ && e->kids.size() > 1 &&
        e->kids[1]->kind == ExprKind::Var && e->kids[1]->name == click_)
      not_local("prev of click reads the last step's click");
    if (callee->kind == ExprKind::Var && callee->name == remove_ && e->kids.size() == 2)
      not_local("one-argument removeObj observes the global map's order");
    for (size_t i = 0; i < e->kids.size(); ++i) {
      const Expr* k = e->kids[i].get();
      // A lambda passed to a call runs in this step; one stored anywhere may not.
      expr(k, i > 0 ? Ctx::Other : (e->kids.size() == 1 ? Ctx::Callee0 : Ctx::CalleeArgs), guarded);
    }
  }

  void expr(const Expr* e, Ctx ctx, bool guarded) {
    if (!e) return;
    switch (e->kind) {
      case ExprKind::String:
        if (e->text.find("click") != std::string::npos) sensitive(), not_local("\"click\" is spelled in a string");
        return;
      case ExprKind::Var: name(e->name, ctx, guarded); return;
      case ExprKind::Logical: {
        // (& a b): b runs only when a held, so a clicked test in a guards b.
        expr(e->kids[0].get(), Ctx::Condition, guarded);
        expr(e->kids[1].get(), Ctx::Condition, guarded || (!e->is_or && implies_click(e->kids[0].get())));
        return;
      }
      case ExprKind::Unary:
        for (const auto& k : e->kids) expr(k.get(), Ctx::Condition, guarded);
        return;
      case ExprKind::If:
        for (size_t i = 0; i < e->kids.size(); ++i) expr(e->kids[i].get(), i == 0 ? Ctx::Condition : Ctx::Other, guarded);
        return;
      case ExprKind::Call: call(e, guarded); return;
      case ExprKind::Lambda:
        for (Sym s : e->params)
          if (is_click_name(s)) sensitive(), not_local("a parameter is named click");
        break;
      case ExprKind::Assign:
        if (is_click_name(e->name)) sensitive(), not_local("the program assigns click");
        // A value stored in a variable (a lambda above all) may run in a later step.
        for (const auto& k : e->kids) expr(k.get(), Ctx::Other, guarded && k->kind != ExprKind::Lambda);
        for (Sym s : e->cell_names) name(s, Ctx::Other, false);
        return;
      default: break;
    }
    for (const auto& k : e->kids) expr(k.get(), Ctx::Other, guarded);
    for (Sym s : e->cell_names) name(s, Ctx::Other, false);
  }

  const Program& p_;
  Sym click_ = -1, clicked_ = -1, prev_ = -1, remove_ = -1;
  Sym arrow_[4] = {-1, -1, -1, -1};
  std::unordered_set<Sym> order_names_;
  std::unordered_map<Sym, std::vector<const Expr*>> stdlib_defs_;
  std::unordered_set<Sym> seen_;
  std::vector<Sym> pending_;
  InputUse use_;
};

// Byte offset of a 1-based line and column in `text`.
size_t offset_of(const std::string& text, const SourceLoc& loc) {
  size_t off = 0;
  for (int line = 1; line < loc.line && off < text.size(); ++off)
    if (text[off] == '\n') ++line;
  return std::min(text.size(), off + static_cast<size_t>(std::max(0, loc.col - 1)));
}

}  // namespace

const char* click_use_name(ClickUse u) {
  switch (u) {
    case ClickUse::None: return "none";
    case ClickUse::PositionFree: return "position-free";
    case ClickUse::Position: return "position";
  }
  return "?";
}

ClickUse analyse_click_use(const Program& program) { return InputAnalysis(program).run().clicks; }

InputUse analyse_inputs(const Program& program) { return InputAnalysis(program).run(); }

std::vector<Action> search_actions(ClickUse use, int grid_size) {
  InputUse all;
  all.clicks = use;
  for (bool& a : all.arrows) a = true;
  return search_actions(all, grid_size);
}

std::vector<Action> search_actions(const InputUse& use, int grid_size) {
  std::vector<Action> out = {Action::noop()};
  const Action::Kind arrows[4] = {Action::Kind::Left, Action::Kind::Right, Action::Kind::Up, Action::Kind::Down};
  for (int i = 0; i < 4; ++i)
    if (use.arrows[i]) out.push_back(Action{arrows[i]});
  if (use.clicks == ClickUse::PositionFree) out.push_back(Action::click(0, 0));
  if (use.clicks == ClickUse::Position)
    for (int y = 0; y < grid_size; ++y)
      for (int x = 0; x < grid_size; ++x) out.push_back(Action::click(x, y));
  return out;
}

std::optional<std::string> click_reset_program(const std::string& text) {
  Sexp top;
  try {
    top = read_sexprs(SourceFile{"<search model>", text, SourceId::Program});
  } catch (const CompileError&) {
    return std::nullopt;
  }
  for (const Sexp& form : top.items)
    if (form.is_list && !form.items.empty() && !form.items[0].is_list && form.items[0].text == "program") {
      const size_t close = offset_of(text, form.end);
      if (close >= text.size() || text[close] != ')') return std::nullopt;
      return text.substr(0, close) + "\n  (on true (= click (Position 0 0)))\n" + text.substr(close);
    }
  return std::nullopt;
}

std::optional<std::string> click_reset_model_text(const Program& program, const InputUse& inputs, std::string* why) {
  why->clear();
  if (inputs.clicks == ClickUse::None) return std::nullopt;
  if (!inputs.click_step_local) {
    *why = "click is not step-local: " + inputs.click_note;
    return std::nullopt;
  }
  return click_reset_program(program.file.text);
}

}  // namespace autumn::agent
