// lower — see lower.hpp. Each lower_* function mirrors the interpreter case of the
// same construct (compiler/interpret/eval.cpp, builtins.cpp) and emits C++ that
// performs the same observable operations in the same order.
#include "compiler/lower/lower.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "runtime/compiled_support.hpp"
#include "runtime/frame.hpp"
#include "runtime/hash_order.hpp"

namespace autumn {
namespace {

struct Unsupported {
  std::string why;
  SourceLoc loc;
};

// ---------------------------------------------------------------------------
// Static types

// Void: the value of an `if` whose branches differ in type; usable only where the
// value is discarded (statement position).
enum class TK { Int, Bool, Str, Pos, Elem, Obj, List, Func, Type, Void };

struct T;
using TP = std::shared_ptr<const T>;
struct T {
  TK k = TK::Int;
  int cls = -1;                 // Obj, Type (class index; -2 = Position)
  TP elem;                      // List (null: element type not known, the list is empty)
  const Expr* lambda = nullptr; // Func: a lambda
  std::string builtin;          // Func: a native builtin
  int method_cls = -1;          // Func: the render method of a class
};

TP mk(TK k) { auto t = std::make_shared<T>(); t->k = k; return t; }
TP mk_obj(int cls) { auto t = std::make_shared<T>(); t->k = TK::Obj; t->cls = cls; return t; }
TP mk_list(TP e) { auto t = std::make_shared<T>(); t->k = TK::List; t->elem = std::move(e); return t; }
const TP kInt = mk(TK::Int), kBool = mk(TK::Bool), kStr = mk(TK::Str), kPos = mk(TK::Pos), kElem = mk(TK::Elem);

bool same(const TP& a, const TP& b) {
  if (a->k != b->k) return false;
  switch (a->k) {
    case TK::Obj: return a->cls == b->cls;
    case TK::List: return !a->elem || !b->elem || same(a->elem, b->elem);
    case TK::Func: return a->lambda == b->lambda && a->builtin == b->builtin && a->method_cls == b->method_cls;
    case TK::Type: return a->cls == b->cls;
    default: return true;
  }
}
// The more precise of two compatible types (an empty list takes the other's element type).
TP unify(const TP& a, const TP& b) {
  if (a->k == TK::List && b->k == TK::List) {
    if (!a->elem) return b;
    if (!b->elem) return a;
    return mk_list(unify(a->elem, b->elem));
  }
  return a;
}

struct Val {
  std::string code;
  TP type;
};

struct ClassInfo {
  std::string name;
  Sym sym;
  std::vector<Sym> fields;
  std::vector<TP> field_types;
  const Stmt* stmt;
  struct CellSpec {
    int x, y;
    int colour = -1;         // string id of a constant colour, or -1
    ExprPtr colour_expr;     // deferred colour, evaluated at each render
    // Names the colour captured at construction (lambda locals of the cell
    // expression), with their constant values: Int or string id.
    std::vector<std::pair<Sym, std::pair<bool, int32_t>>> captured;  // (is_string, value)
  };
  std::vector<CellSpec> cells;
};

struct LVar {
  Sym sym;
  std::string cpp;
  TP type;
  int depth;  // C++ block depth of the declaration
};

struct LScope {
  std::vector<LVar> vars;
  int depth = 0;
  bool top = false;  // a top-level statement scope (assignments to new names define globals)
};

struct Global {
  TP type;
  std::string cpp;       // "s.g_x"
  bool initnext = false;
  bool is_const_func = false;
  bool prev_used = false;
  bool plain = false;    // defined by a plain top-level assignment (a State member)
};

std::string cpp_ident(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

// ---------------------------------------------------------------------------

class Lowerer {
 public:
  Lowerer(const Program& p, std::string name) : P(p), name_(std::move(name)) {}
  Lowered run();

 private:
  [[noreturn]] void bail(const Expr* e, const std::string& why) {
    throw Unsupported{why, e ? e->loc : SourceLoc{}};
  }
  const std::string& nm(Sym s) const { return P.name(s); }
  // "PROGRAM:LINE" for the comments that tie emitted code to its source.
  std::string where(SourceLoc loc) const { return P.file_name(loc.source) + ":" + std::to_string(loc.line); }

  // code output
  std::string* out_ = nullptr;
  int depth_ = 0;
  int temp_ = 0;
  void line(const std::string& s) { *out_ += std::string(2 * (depth_ + 2), ' ') + s + "\n"; }
  // A list that is rebuilt each time this code runs and never outlives the run:
  // it lives in a per-site buffer, so its storage is reused instead of allocated.
  // (The same site cannot run again while its previous result is in use: every
  // inlined call is its own site, and results are copied whenever they are kept.)
  std::string scratch_list(const std::string& type) {
    std::string t = temp();
    scratch_fields_ += "    " + type + " " + t + ";\n";
    line("s.scratch.v." + t + ".clear();");
    line(type + "& " + t + " = s.scratch.v." + t + ";");
    return t;
  }
  std::string scratch_fields_;  // members of the per-state buffer struct
  std::string temp() {
    std::string t = "t" + std::to_string(++temp_);
    immutable_names_.insert(t);
    return t;
  }
  std::set<std::string> immutable_names_;  // C++ names whose value never changes in scope
  std::set<Sym> assigned_names_;           // every name some assignment targets

  // types
  std::string cpp_type(const TP& t) {
    switch (t->k) {
      case TK::Int: return "int32_t";
      case TK::Bool: return "bool";
      case TK::Str: return "int32_t";
      case TK::Pos: return "Pos";
      case TK::Elem: return "Elem";
      case TK::Obj: return "C_" + cpp_ident(classes_[t->cls].name);
      case TK::List: return "std::vector<" + (t->elem ? cpp_type(t->elem) : std::string("int32_t")) + ">";
      case TK::Func:
      case TK::Type:
      case TK::Void: return "Unit";
    }
    return "Unit";
  }
  int string_id(const std::string& quoted) {
    auto it = strings_.find(quoted);
    if (it != strings_.end()) return it->second;
    int id = static_cast<int>(string_list_.size());
    strings_[quoted] = id;
    string_list_.push_back(quoted);
    return id;
  }
  TP type_of_decl(const TypeExpr& te, const Expr* at) {
    if (te.is_list) return mk_list(type_of_decl(*te.elem, at));
    const std::string& n = te.name;
    if (n == "Number" || n == "Int") return kInt;
    if (n == "Bool") return kBool;
    if (n == "String") return kStr;
    if (n == "Position") return kPos;
    for (size_t i = 0; i < classes_.size(); ++i)
      if (classes_[i].name == n) return mk_obj(static_cast<int>(i));
    bail(at, "declared type '" + n + "' is not supported");
  }

  // values
  // Gives a value a name that later evaluation cannot change. Temporaries and
  // never-assigned variables already are such names; anything else is copied.
  Val declare(const Val& v) {
    if (v.code == "{}" || v.type->k == TK::Func || v.type->k == TK::Type || v.type->k == TK::Void) return v;
    if (immutable_names_.count(v.code)) return v;
    std::string t = temp();
    line("const " + cpp_type(v.type) + " " + t + " = " + v.code + ";");
    return {t, v.type};
  }
  // A read of a global list or object: marked, and made a reference or a copy by
  // bind_global_reads once the whole module is emitted (a reference when no store
  // to that global can run while it is still to be read). Saves a list copy per
  // read, which was most of a step's allocations.
  Val declare_global_read(const Val& v) {
    if (v.type->k != TK::List && v.type->k != TK::Obj) return declare(v);
    if (immutable_names_.count(v.code)) return v;
    std::string t = temp();
    line("const " + cpp_type(v.type) + kRefMark + " " + t + " = " + v.code + ";");
    return {t, v.type};
  }
  static constexpr const char* kRefMark = "/*ref?*/";
  std::string truthy(const Val& v) {
    if (v.type->k == TK::Void) throw Unsupported{"the value of an if whose branches differ in type", {}};
    if (v.type->k == TK::Bool) return v.code;
    if (v.type->k == TK::List) return "!" + v.code + ".empty()";
    return "true";
  }

  // scopes
  std::vector<LScope*> chain_;
  std::map<Sym, Global> globals_;
  std::set<Sym> defined_initnext_;  // during start: initnext variables initialised so far
  bool in_start_ = false;
  std::vector<const Expr*> inline_stack_;

  LVar* find_local(Sym s) {
    for (auto it = chain_.rbegin(); it != chain_.rend(); ++it)
      for (auto& v : (*it)->vars)
        if (v.sym == s) return &v;
    return nullptr;
  }
  Global* find_global(Sym s) {
    auto it = globals_.find(s);
    if (it == globals_.end()) return nullptr;
    if (it->second.initnext && in_start_ && !defined_initnext_.count(s)) return nullptr;
    return &it->second;
  }

  Val lower(const Expr& e);
  Val lower_var(const Expr& e);
  Val lower_binary(const Expr& e);
  Val lower_logical(const Expr& e);
  Val lower_if(const Expr& e);
  Val lower_let(const Expr& e, bool unused);
  // Lowers an expression whose value nobody reads (a statement): an assignment
  // there may move a freshly built list into place instead of copying it.
  Val lower_discarded(const Expr& e) {
    value_unused_ = true;
    return lower(e);
  }
  bool value_unused_ = false;
  std::set<std::string> movable_;  // non-const temporaries holding freshly built values
  Val lower_list(const Expr& e);
  Val lower_call(const Expr& e);
  Val lower_get(const Expr& e);
  Val lower_assign(const Expr& e, bool unused);
  Val call_func(const TP& f, std::vector<Val>& args, const Expr& at);
  Val inline_lambda(const Expr& lambda, std::vector<Val>& args, const Expr& at);
  Val call_builtin(const std::string& b, std::vector<Val>& args, const Expr& at);
  Val construct(int cls, std::vector<Val>& args, const Expr& at);
  Val render_of(const Val& v, const Expr& at);
  Val equals(const Val& a, const Val& b, const Expr& at);
  Val prev_of(Sym s, const Expr& at);
  Val zero_arg_call(const Val& v, const Expr& at);
  void assign_to(Sym s, const Val& v, const Expr& at, bool move = false);
  // loops: runs `body` for each element (bound to a fresh const reference), inside a for.
  void for_each(const Val& list, const std::function<void(const Val&)>& body);
  std::string capture(const std::function<void()>& f, int extra_depth = 1);

  void analyse_classes();
  void fold_cells(const Stmt& st, ClassInfo& c);
  bool program_defines(Sym s) const {
    for (const Stmt& st : P.stmts)
      if (st.kind == StmtKind::Expr && st.expr->kind == ExprKind::Assign && st.expr->name == s) return true;
    return false;
  }
  void analyse_globals();
  void check_program_features();
  std::string emit();
  std::string bind_global_reads(std::string text);

  const Program& P;
  std::string name_;
  std::vector<ClassInfo> classes_;
  std::map<std::string, int> strings_;
  std::vector<std::string> string_list_;
  int grid_ = 16;
  std::vector<Sym> render_order_;
  std::vector<Sym> init_order_;
  std::vector<Sym> plain_order_;
  std::set<Sym> builtin_names_;
  std::set<Sym> all_global_names_;
  const Expr* stdlib_render_value_ = nullptr;  // null when the program redefines what it uses
  std::string stdlib_init_;
  std::string start_code_, step_code_, colour_fns_;
  std::vector<const Stmt*> on_;
};

std::string Lowerer::capture(const std::function<void()>& f, int extra_depth) {
  std::string* saved = out_;
  std::string buf;
  out_ = &buf;
  depth_ += extra_depth;
  f();
  depth_ -= extra_depth;
  out_ = saved;
  return buf;
}

void Lowerer::for_each(const Val& list, const std::function<void(const Val&)>& body) {
  if (!list.type->elem) return;  // statically empty: the loop never runs
  std::string e = temp();
  line("for (const " + cpp_type(list.type->elem) + "& " + e + " : " + list.code + ") {");
  ++depth_;
  body(Val{e, list.type->elem});
  --depth_;
  line("}");
}

// ---------------------------------------------------------------------------
// Expressions

Val Lowerer::lower(const Expr& e) {
  const bool unused = value_unused_;
  value_unused_ = false;
  switch (e.kind) {
    case ExprKind::Number: return {"int32_t(" + std::to_string(e.number) + ")", kInt};
    case ExprKind::Bool: return {e.boolean ? "true" : "false", kBool};
    case ExprKind::String: return {"int32_t(" + std::to_string(string_id(e.text)) + ")", kStr};
    case ExprKind::Var: return lower_var(e);
    case ExprKind::Binary: return lower_binary(e);
    case ExprKind::Logical: return lower_logical(e);
    case ExprKind::Unary: {
      Val v = lower(*e.kids[0]);
      if (e.unary == UnOp::Not) {
        if (v.type->k != TK::Bool) bail(&e, "'!' of a non-Bool");
        return declare({"!" + v.code, kBool});
      }
      if (v.type->k != TK::Int) bail(&e, "unary minus of a non-number");
      return e.unary == UnOp::Neg ? declare({"neg(" + v.code + ")", kInt}) : v;
    }
    case ExprKind::If: return lower_if(e);
    case ExprKind::Let: return lower_let(e, unused);
    case ExprKind::List: return lower_list(e);
    case ExprKind::Lambda: {
      auto t = std::make_shared<T>();
      t->k = TK::Func;
      t->lambda = &e;
      return {"Unit{}", t};
    }
    case ExprKind::Call: return lower_call(e);
    case ExprKind::Get: return lower_get(e);
    case ExprKind::Assign: return lower_assign(e, unused);
    case ExprKind::Set: bail(&e, "field assignment (= (.. o f) v) mutates shared objects");
    case ExprKind::InitNext: bail(&e, "initnext inside an expression");
    case ExprKind::TypeDecl: bail(&e, "type declaration inside an expression");
  }
  bail(&e, "unknown expression");
}

Val Lowerer::lower_var(const Expr& e) {
  const std::string& n = nm(e.name);
  if (n == "Position") {
    auto t = std::make_shared<T>();
    t->k = TK::Type;
    t->cls = -2;
    return {"Unit{}", t};
  }
  for (size_t i = 0; i < classes_.size(); ++i)
    if (classes_[i].sym == e.name) {
      auto t = std::make_shared<T>();
      t->k = TK::Type;
      t->cls = static_cast<int>(i);
      return {"Unit{}", t};
    }
  if (n == "Cell" || n == "RenderedElem" || n == "Bool" || n == "String" || n == "Number" || n == "Int")
    bail(&e, "type '" + n + "' used directly");
  if (LVar* v = find_local(e.name)) return declare({v->cpp, v->type});
  if (n == "click") {
    std::string t = temp();
    line("if (!s.core.click_defined) fail(\"undefined variable 'click'\");");
    line("const Pos " + t + " = s.core.click_pos;");
    return {t, kPos};
  }
  if (Global* g = find_global(e.name)) {
    if (g->type->k == TK::Func) return {"Unit{}", g->type};
    return declare_global_read({g->cpp, g->type});
  }
  if (builtin_names_.count(e.name)) {
    auto t = std::make_shared<T>();
    t->k = TK::Func;
    t->builtin = n;
    return {"Unit{}", t};
  }
  bail(&e, "'" + n + "' is not statically bound here");
}

Val Lowerer::lower_binary(const Expr& e) {
  Val l = lower(*e.kids[0]);
  Val r = lower(*e.kids[1]);
  if (e.op == BinOp::Eq) return equals(l, r, e);
  if (e.op == BinOp::Ne) {
    Val v = equals(l, r, e);
    return declare({"!" + v.code, kBool});
  }
  if (l.type->k != TK::Int || r.type->k != TK::Int) bail(&e, "arithmetic or comparison on non-numbers");
  const std::string a = l.code, b = r.code;
  switch (e.op) {
    case BinOp::Add: return declare({"add(" + a + ", " + b + ")", kInt});
    case BinOp::Sub: return declare({"sub(" + a + ", " + b + ")", kInt});
    case BinOp::Mul: return declare({"mul(" + a + ", " + b + ")", kInt});
    case BinOp::Div: return declare({"idiv(" + a + ", " + b + ")", kInt});
    case BinOp::Mod: return declare({"imod(" + a + ", " + b + ")", kInt});
    case BinOp::Lt: return declare({a + " < " + b, kBool});
    case BinOp::Le: return declare({a + " <= " + b, kBool});
    case BinOp::Gt: return declare({a + " > " + b, kBool});
    case BinOp::Ge: return declare({a + " >= " + b, kBool});
    default: bail(&e, "unknown binary operator");
  }
}

Val Lowerer::equals(const Val& l, const Val& r, const Expr& at) {
  const TK a = l.type->k, b = r.type->k;
  if (a == TK::Void || b == TK::Void) bail(&at, "the value of an if whose branches differ in type");
  if (a == TK::Int && b == TK::Bool) return declare({l.code + " == (" + r.code + " ? 1 : 0)", kBool});
  if (a == TK::List || a == TK::Func || a == TK::Type) bail(&at, "equality of lists or functions compares printed forms");
  if (a != b) return {"false", kBool};
  if (a == TK::Obj) {
    if (l.type->cls != r.type->cls) bail(&at, "equality of objects of different classes");
    return declare({"eq(" + l.code + ", " + r.code + ")", kBool});
  }
  return declare({l.code + " == " + r.code, kBool});
}

Val Lowerer::zero_arg_call(const Val& v, const Expr& at) {
  std::vector<Val> none;
  return call_func(v.type, none, at);
}

Val Lowerer::lower_logical(const Expr& e) {
  Val l = lower(*e.kids[0]);
  if (l.type->k == TK::Func) l = zero_arg_call(l, e);
  std::string res = temp();
  line("bool " + res + " = " + (e.is_or ? "true" : "false") + ";");
  line("if (" + std::string(e.is_or ? "!(" : "(") + truthy(l) + ")) {");
  ++depth_;
  Val r = lower(*e.kids[1]);
  if (r.type->k == TK::Func) r = zero_arg_call(r, e);
  line(res + " = " + truthy(r) + ";");
  --depth_;
  line("}");
  return {res, kBool};
}

Val Lowerer::lower_if(const Expr& e) {
  Val c = lower(*e.kids[0]);
  if (c.type->k == TK::Func) {  // a function value is truthy and is *not* called
    return lower(*e.kids[1]);
  }
  // A condition known at compile time (isList of a static type): only the branch
  // the interpreter would take is lowered.
  if (c.code == "true") return lower(*e.kids[1]);
  if (c.code == "false") return lower(*e.kids[2]);
  Val tv, ev;
  std::string then_code = capture([&] { tv = lower(*e.kids[1]); });
  std::string else_code = capture([&] { ev = lower(*e.kids[2]); });
  TP t = unify(tv.type, ev.type);
  auto effects_only = [&] {
    line("if (" + truthy(c) + ") {");
    *out_ += then_code;
    line("} else {");
    *out_ += else_code;
    line("}");
  };
  if (!same(tv.type, ev.type) || tv.type->k == TK::Func || ev.type->k == TK::Func) {
    effects_only();  // only the side effects can matter: the value must never be used
    return {"Unit{}", mk(TK::Void)};
  }
  if (t->k == TK::Type) bail(&e, "an if choosing between types");
  if (t->k == TK::List && !t->elem) {  // both branches are empty lists: the value is {}
    effects_only();
    return {"{}", t};
  }
  std::string res = temp();
  line(cpp_type(t) + " " + res + ";");
  line("if (" + truthy(c) + ") {");
  *out_ += then_code;
  line("  " + res + " = " + tv.code + ";");
  line("} else {");
  *out_ += else_code;
  line("  " + res + " = " + ev.code + ";");
  line("}");
  return {res, t};
}

Val Lowerer::lower_let(const Expr& e, bool unused) {
  if (e.kids.empty()) bail(&e, "empty let");
  LScope scope;
  scope.depth = depth_;
  chain_.push_back(&scope);
  Val last;
  for (size_t i = 0; i < e.kids.size(); ++i) {
    if (i + 1 < e.kids.size() || unused) last = lower_discarded(*e.kids[i]);
    else last = lower(*e.kids[i]);
  }
  chain_.pop_back();
  if (last.type->k == TK::Func || last.type->k == TK::Type) bail(&e, "a let producing a function");
  return last;
}

Val Lowerer::lower_list(const Expr& e) {
  if (e.kids.empty()) return {"{}", mk_list(nullptr)};
  std::vector<Val> items;
  for (const auto& k : e.kids) items.push_back(lower(*k));
  TP t = items[0].type;
  for (const auto& v : items)
    if (!same(v.type, t)) bail(&e, "a list literal with elements of different types");
  if (t->k == TK::Func || t->k == TK::Type || t->k == TK::List) bail(&e, "a list of functions or lists");
  std::string code = cpp_type(mk_list(t)) + "{";
  for (size_t i = 0; i < items.size(); ++i) code += (i ? ", " : "") + items[i].code;
  return declare({code + "}", mk_list(t)});
}

Val Lowerer::lower_get(const Expr& e) {
  Val o = lower(*e.kids[0]);
  const std::string& f = nm(e.name);
  switch (o.type->k) {
    case TK::Pos:
      if (f == "x") return {o.code + ".x", kInt};
      if (f == "y") return {o.code + ".y", kInt};
      break;
    case TK::Elem:
      if (f == "position") return {o.code + ".position", kPos};
      if (f == "color") return {o.code + ".color", kStr};
      break;
    case TK::Obj: {
      const ClassInfo& c = classes_[o.type->cls];
      if (f == "origin") return {o.code + ".origin", kPos};
      for (size_t i = 0; i < c.fields.size(); ++i)
        if (c.fields[i] == e.name) return {o.code + ".f_" + cpp_ident(f), c.field_types[i]};
      if (f == "render") {
        auto t = std::make_shared<T>();
        t->k = TK::Func;
        t->method_cls = o.type->cls;
        return {o.code, t};
      }
      break;
    }
    default:
      break;
  }
  bail(&e, "field '" + e.text + "' of a value that is not a known object");
}

void Lowerer::assign_to(Sym s, const Val& v, const Expr& at, bool move) {
  const std::string value = move && movable_.count(v.code) ? "std::move(" + v.code + ")" : v.code;
  if (v.type->k == TK::Func || v.type->k == TK::Type || v.type->k == TK::Void)
    bail(&at, "assigning a function, or the value of an if whose branches differ");
  if (LVar* l = find_local(s)) {
    if (!same(l->type, v.type)) bail(&at, "a local variable changes type");
    if (l->type->k == TK::List && !l->type->elem && v.type->elem) bail(&at, "a local empty list gains an element type");
    line(l->cpp + " = " + value + ";");
    return;
  }
  if (Global* g = find_global(s)) {
    if (g->is_const_func) bail(&at, "reassigning a function");
    if (!same(g->type, v.type)) bail(&at, "global '" + nm(s) + "' changes type");
    line(g->cpp + " = " + value + ";");
    if (g->initnext) line("s.u_" + cpp_ident(nm(s)) + " = true;");
    return;
  }
  LScope* scope = chain_.empty() ? nullptr : chain_.back();
  if (!scope || scope->top) bail(&at, "'" + nm(s) + "' is first defined at run time");
  if (scope->depth != depth_) bail(&at, "'" + nm(s) + "' is first defined inside a branch");
  if (v.type->k == TK::List && !v.type->elem) bail(&at, "a local empty list of unknown type");
  std::string c = "v_" + cpp_ident(nm(s)) + "_" + std::to_string(++temp_);
  line(cpp_type(v.type) + " " + c + " = " + v.code + ";");
  scope->vars.push_back(LVar{s, c, v.type, depth_});
}

Val Lowerer::lower_assign(const Expr& e, bool unused) {
  if (e.kids[0]->kind == ExprKind::InitNext) bail(&e, "initnext outside the top level");
  Val v = lower(*e.kids[0]);
  v = declare(v);
  assign_to(e.name, v, e, unused);
  if (unused && movable_.count(v.code)) return {"Unit{}", mk(TK::Void)};  // moved from
  return v;
}

Val Lowerer::prev_of(Sym s, const Expr& at) {
  auto it = globals_.find(s);
  if (it == globals_.end() || !it->second.initnext) bail(&at, "prev of something that is not an initnext variable");
  it->second.prev_used = true;
  line("if (!s.core.have_prev) fail(\"prev used before the first step\");");
  immutable_names_.insert("s.p_" + cpp_ident(nm(s)));
  return {"s.p_" + cpp_ident(nm(s)), it->second.type};
}

Val Lowerer::lower_call(const Expr& e) {
  Val callee = lower(*e.kids[0]);
  const size_t n = e.kids.size() - 1;
  if (callee.type->k == TK::Type) {
    std::vector<Val> args;
    for (size_t i = 1; i <= n; ++i) args.push_back(declare(lower(*e.kids[i])));
    if (callee.type->cls == -2) {
      if (n != 2 || args[0].type->k != TK::Int || args[1].type->k != TK::Int) bail(&e, "Position needs two numbers");
      return declare({"Pos{" + args[0].code + ", " + args[1].code + "}", kPos});
    }
    return construct(callee.type->cls, args, e);
  }
  if (callee.type->k != TK::Func) bail(&e, "calling something that is not a known function");
  if (callee.type->builtin == "prev") {
    if (n != 1) bail(&e, "prev with other than one argument");
    const Expr& a = *e.kids[1];
    if (a.kind == ExprKind::Var) return prev_of(a.name, e);
    if (a.kind == ExprKind::String) {
      Sym s = P.symbols.find(a.text.substr(1, a.text.size() - 2));
      if (s < 0) bail(&e, "prev of an unknown name");
      return prev_of(s, e);
    }
    bail(&e, "prev by identity");
  }
  std::vector<Val> args;
  for (size_t i = 1; i <= n; ++i) args.push_back(declare(lower(*e.kids[i])));
  if (callee.type->method_cls >= 0) return render_of(Val{callee.code, mk_obj(callee.type->method_cls)}, e);
  return call_func(callee.type, args, e);
}

Val Lowerer::call_func(const TP& f, std::vector<Val>& args, const Expr& at) {
  if (f->lambda) return inline_lambda(*f->lambda, args, at);
  if (f->method_cls >= 0) bail(&at, "a stored render method");
  return call_builtin(f->builtin, args, at);
}

Val Lowerer::inline_lambda(const Expr& lambda, std::vector<Val>& args, const Expr& at) {
  // The stdlib's renderValue on an object or a (nested) list of objects renders
  // each object in order and concatenates: one output vector does the same
  // without a vector per element.
  if (&lambda == stdlib_render_value_ && !args.empty()) {
    std::function<bool(const TP&)> renderable = [&](const TP& t) {
      return t->k == TK::Obj || (t->k == TK::List && t->elem && renderable(t->elem));
    };
    if (renderable(args[0].type)) return render_of(args[0], at);
  }
  // Recursion is inlined only while the types shrink it (renderValue on nested
  // lists); anything deeper is real recursion.
  if (std::count(inline_stack_.begin(), inline_stack_.end(), &lambda) >= 3) bail(&at, "recursion");
  if (inline_stack_.size() > 40) bail(&at, "calls nested too deeply to inline");
  if (args.size() < lambda.params.size()) bail(&at, "a call with missing arguments");
  LScope scope;
  scope.depth = depth_;
  for (size_t i = 0; i < lambda.params.size(); ++i) {
    // A later parameter of the same name replaces the earlier one.
    scope.vars.erase(std::remove_if(scope.vars.begin(), scope.vars.end(),
                                    [&](const LVar& v) { return v.sym == lambda.params[i]; }),
                     scope.vars.end());
    if (args[i].type->k == TK::Func || args[i].type->k == TK::Type || args[i].code == "{}") {
      scope.vars.push_back(LVar{lambda.params[i], args[i].code, args[i].type, depth_});
    } else {
      std::string c = "a_" + cpp_ident(nm(lambda.params[i])) + "_" + std::to_string(++temp_);
      if (assigned_names_.count(lambda.params[i])) {
        line(cpp_type(args[i].type) + " " + c + " = " + args[i].code + ";");
      } else {
        line("const " + cpp_type(args[i].type) + "& " + c + " = " + args[i].code + ";");
        immutable_names_.insert(c);
      }
      scope.vars.push_back(LVar{lambda.params[i], c, args[i].type, depth_});
    }
  }
  if (lambda.loc.source == SourceId::Program) line("// inlined: function at " + where(lambda.loc));
  inline_stack_.push_back(&lambda);
  chain_.push_back(&scope);
  Val r = lower(*lambda.kids[0]);
  chain_.pop_back();
  inline_stack_.pop_back();
  if (r.type->k == TK::Type) bail(&at, "a function returning a type");
  if (r.type->k != TK::Func && r.type->k != TK::Void) r = declare(r);
  return r;
}

Val Lowerer::construct(int cls, std::vector<Val>& args, const Expr& at) {
  const ClassInfo& c = classes_[cls];
  if (args.size() < c.fields.size() + 1) bail(&at, "object constructed with missing arguments");
  std::string code = cpp_type(mk_obj(cls)) + "{";
  for (size_t i = 0; i < c.fields.size(); ++i) {
    if (!same(args[i].type, c.field_types[i]) || args[i].code == "{}")
      bail(&at, "field '" + nm(c.fields[i]) + "' of '" + c.name + "' given a value of another type");
    code += args[i].code + ", ";
  }
  if (args[c.fields.size()].type->k != TK::Pos) bail(&at, "origin is not a Position");
  code += args[c.fields.size()].code + "}";
  return declare({code, mk_obj(cls)});
}

// Renders an object, or a list of objects, into a vector of Elems.
Val Lowerer::render_of(const Val& v, const Expr& at) {
  std::string out = scratch_list("std::vector<Elem>");
  std::function<void(const Val&)> rec = [&](const Val& x) {
    if (x.type->k == TK::Obj) {
      line("render_" + cpp_ident(classes_[x.type->cls].name) + "(s, " + x.code + ", " + out + ");");
    } else if (x.type->k == TK::List) {
      for_each(x, rec);
    }
  };
  rec(v);
  return {out, mk_list(kElem)};
}

Val Lowerer::call_builtin(const std::string& b, std::vector<Val>& a, const Expr& at) {
  const size_t n = a.size();
  auto need = [&](size_t k) {
    if (n != k) bail(&at, b + " with " + std::to_string(n) + " arguments");
  };
  auto list_arg = [&](size_t i) -> const Val& {
    if (a[i].type->k != TK::List) bail(&at, b + " of something that is not a list");
    return a[i];
  };
  auto func_arg = [&](size_t i) -> const TP& {
    if (a[i].type->k != TK::Func) bail(&at, b + " needs a function");
    return a[i].type;
  };
  auto call1 = [&](const TP& f, const Val& x) {
    std::vector<Val> args{x};
    return call_func(f, args, at);
  };
  if (b == "left" || b == "right" || b == "up" || b == "down") return {"s.core." + b, kBool};
  if (b == "clicked") {
    if (n > 1) bail(&at, "clicked with several arguments");
    std::string r = temp();
    line("bool " + r + " = false;");
    line("if (s.core.click) {");
    ++depth_;
    line("s.core.click_defined = true;");
    line("s.core.click_pos = Pos{s.core.click_x, s.core.click_y};");
    if (n == 0) {
      line(r + " = true;");
    } else {
      Val elems = render_of(a[0], at);
      line("for (const Elem& e : " + elems.code + ")");
      line("  if (e.position.x == s.core.click_x && e.position.y == s.core.click_y) { " + r + " = true; break; }");
    }
    --depth_;
    line("}");
    return {r, kBool};
  }
  if (b == "removeObj" && n == 1) {
    // (removeObj o) erases the first global whose value has o's identity and
    // returns o. A global can share an object's identity only if it holds an
    // object of the same class (assignments never change a variable's type here),
    // so when no global is of o's class nothing is erased.
    if (a[0].type->k != TK::Obj) bail(&at, "removeObj of something that is not an object");
    for (const auto& [sym, g] : globals_)
      if (g.type && g.type->k == TK::Obj && g.type->cls == a[0].type->cls)
        bail(&at, "removeObj of an object whose class a global also holds (identity)");
    return a[0];
  }
  if (b == "map" || b == "filter" || b == "any" || b == "updateObj" || b == "removeObj") {
    if (b == "updateObj" && n == 3 && a[0].type->k == TK::Obj) {
      const Expr* field = at.kids[2].get();
      if (field->kind != ExprKind::String) bail(&at, "updateObj with a computed field name");
      std::string fname = field->text.substr(1, field->text.size() - 2);
      const ClassInfo& c = classes_[a[0].type->cls];
      std::string r = temp();
      line(cpp_type(a[0].type) + " " + r + " = " + a[0].code + ";");
      if (fname == "origin") {
        if (a[2].type->k != TK::Pos) bail(&at, "updateObj origin with a non-Position");
        line(r + ".origin = " + a[2].code + ";");
        return {r, a[0].type};
      }
      for (size_t i = 0; i < c.fields.size(); ++i)
        if (nm(c.fields[i]) == fname) {
          if (!same(a[2].type, c.field_types[i]) || a[2].code == "{}")
            bail(&at, "updateObj gives field '" + fname + "' a value of another type");
          line(r + ".f_" + cpp_ident(fname) + " = " + a[2].code + ";");
          return {r, a[0].type};
        }
      bail(&at, "updateObj of an unknown field");
    }
    if (b == "updateObj" && n == 2 && a[0].type->k == TK::Obj) return call1(func_arg(1), a[0]);
    if (b == "any" && n == 1) {
      const Val& l = list_arg(0);
      std::string r = temp();
      line("bool " + r + " = false;");
      for_each(l, [&](const Val& x) { line("if (" + truthy(x) + ") { " + r + " = true; break; }"); });
      return {r, kBool};
    }
    size_t fi = (b == "updateObj" || b == "removeObj") ? 1 : 0;
    size_t li = (b == "updateObj" || b == "removeObj") ? 0 : 1;
    if (b == "updateObj" && n == 3) {
      const Val& l = list_arg(0);
      const TP& f = func_arg(1);
      const TP& pred = func_arg(2);
      if (!l.type->elem) return {"{}", l.type};
      std::string r = temp();
      TP rt;
      std::string body = capture([&] {
        std::string x = temp();
        line("const " + cpp_type(l.type->elem) + "& " + x + " = " + r + "_src[" + r + "_i];");
        Val xv{x, l.type->elem};
        Val p = call1(pred, xv);
        line("if (" + truthy(p) + ") {");
        ++depth_;
        Val y = call1(f, xv);
        rt = y.type;
        line(r + ".push_back(" + y.code + ");");
        --depth_;
        line("} else {");
        line("  " + r + ".push_back(" + x + ");");
        line("}");
      });
      if (!same(rt, l.type->elem)) bail(&at, "updateObj with a filter changes the element type");
      line("const " + cpp_type(l.type) + "& " + r + "_src = " + l.code + ";");
      line(cpp_type(l.type) + " " + r + ";");
      line(r + ".reserve(" + r + "_src.size());");  // one allocation, not log2(n)
      movable_.insert(r);
      line("for (size_t " + r + "_i = 0; " + r + "_i < " + r + "_src.size(); ++" + r + "_i) {");
      *out_ += body;
      line("}");
      return {r, l.type};
    }
    need(2);
    const Val& l = list_arg(li);
    const TP& f = func_arg(fi);
    if (!l.type->elem) {
      if (b == "any") return {"false", kBool};
      return {"{}", mk_list(nullptr)};
    }
    std::string r = temp();
    TP rt;
    std::string body = capture([&] {
      Val xv{r + "_x", l.type->elem};
      Val y = call1(f, xv);
      rt = y.type;
      if (b == "map" || b == "updateObj") line(r + ".push_back(" + y.code + ");");
      else if (b == "filter") line("if (" + truthy(y) + ") " + r + ".push_back(" + xv.code + ");");
      else if (b == "removeObj") line("if (!(" + truthy(y) + ")) " + r + ".push_back(" + xv.code + ");");
      else line("if (" + truthy(y) + ") { " + r + " = true; break; }");
    });
    TP result;
    if (b == "map" || b == "updateObj") {
      if (rt->k == TK::Func || rt->k == TK::Type || rt->k == TK::Void || (rt->k == TK::List && !rt->elem))
        bail(&at, "map producing functions or values of no single type");
      result = mk_list(rt);
    } else if (b == "any") {
      result = kBool;
    } else {
      result = l.type;
    }
    if (b == "any") line("bool " + r + " = false;");
    else {
      line(cpp_type(result) + " " + r + ";");
      if (b == "map" || b == "updateObj") line(r + ".reserve(" + l.code + ".size());");
      movable_.insert(r);
    }
    line("for (const " + cpp_type(l.type->elem) + "& " + r + "_x : " + l.code + ") {");
    *out_ += body;
    line("}");
    return {r, result};
  }
  if (b == "foldl") {
    need(3);
    const TP& f = func_arg(0);
    const Val& l = list_arg(2);
    TP acc_type = a[1].type;
    if (acc_type->k == TK::List && !acc_type->elem && l.type->elem) {
      // Learn the accumulator's element type from one (discarded) lowering of the body.
      std::string ignored = capture([&] {
        std::vector<Val> args{{"acc_probe", acc_type}, {"elem_probe", l.type->elem}};
        acc_type = unify(acc_type, call_func(f, args, at).type);
      });
    }
    if (acc_type->k == TK::List && !acc_type->elem) bail(&at, "foldl over lists of unknown type");
    std::string acc = temp();
    immutable_names_.erase(acc);
    line(cpp_type(acc_type) + " " + acc + (a[1].code == "{}" ? "" : " = " + a[1].code) + ";");
    for_each(l, [&](const Val& x) {
      std::vector<Val> args{{acc, acc_type}, x};
      Val y = call_func(f, args, at);
      if (!same(y.type, acc_type)) bail(&at, "foldl accumulator changes type");
      line(acc + " = " + y.code + ";");
    });
    return declare({acc, acc_type});
  }
  if (b == "length") {
    need(1);
    return declare({"int32_t(" + list_arg(0).code + ".size())", kInt});
  }
  if (b == "head" || b == "tail") {
    need(1);
    const Val& l = list_arg(0);
    if (!l.type->elem) bail(&at, b + " of a statically empty list");
    line("if (" + l.code + ".empty()) fail(\"" + b + " of an empty list\");");
    return declare({l.code + (b == "head" ? ".front()" : ".back()"), l.type->elem});
  }
  if (b == "at") {
    need(2);
    const Val& l = list_arg(0);
    if (!l.type->elem || a[1].type->k != TK::Int) bail(&at, "at of an empty list or a non-number");
    line("if (" + l.code + ".empty() || " + a[1].code + " < 0 || size_t(" + a[1].code + ") >= " + l.code +
         ".size()) fail(\"at: index out of bounds\");");
    return declare({l.code + "[" + a[1].code + "]", l.type->elem});
  }
  if (b == "isList") {
    need(1);
    return {a[0].type->k == TK::List ? "true" : "false", kBool};
  }
  if (b == "print") {
    need(1);
    return a[0];
  }
  if (b == "range") {
    need(2);
    if (a[0].type->k != TK::Int || a[1].type->k != TK::Int) bail(&at, "range of non-numbers");
    std::string r = scratch_list("std::vector<int32_t>");
    line("for (int32_t i = " + a[0].code + "; i < " + a[1].code + "; ++i) " + r + ".push_back(i);");
    return {r, mk_list(kInt)};
  }
  if (b == "concat") {
    need(1);
    const Val& l = list_arg(0);
    if (!l.type->elem || l.type->elem->k != TK::List || !l.type->elem->elem) bail(&at, "concat of unknown lists");
    std::string r = temp();
    line(cpp_type(l.type->elem) + " " + r + ";");
    line("for (const auto& part : " + l.code + ") " + r + ".insert(" + r + ".end(), part.begin(), part.end());");
    return {r, l.type->elem};
  }
  if (b == "uniformChoice") {
    const Val& l = list_arg(0);
    if (!l.type->elem) bail(&at, "uniformChoice of an empty list");
    line("if (" + l.code + ".empty()) fail(\"uniformChoice of an empty list\");");
    if (n == 1) return declare({l.code + "[s.core.rng.next(" + l.code + ".size())]", l.type->elem});
    need(2);
    if (a[1].type->k != TK::Int) bail(&at, "uniformChoice count is not a number");
    std::string r = temp();
    line("if (" + a[1].code + " < 1) fail(\"uniformChoice: the count must be at least 1\");");
    line(cpp_type(l.type) + " " + r + ";");
    line("for (int32_t i = 0; i < " + a[1].code + "; ++i) " + r + ".push_back(" + l.code + "[s.core.rng.next(" +
         l.code + ".size())]);");
    return {r, l.type};
  }
  if (b == "randomPositions") {
    need(2);
    if (a[0].type->k != TK::Int || a[1].type->k != TK::Int) bail(&at, "randomPositions of non-numbers");
    std::string r = temp();
    line("if (" + a[0].code + " < 0) fail(\"randomPositions: negative size\");");
    line("std::vector<Pos> " + r + ";");
    line("for (int32_t i = 0; i < " + a[1].code + "; ++i) { int32_t x = int32_t(s.core.rng.next(uint64_t(" + a[0].code +
         "))); int32_t y = int32_t(s.core.rng.next(uint64_t(" + a[0].code + "))); " + r + ".push_back(Pos{x, y}); }");
    return {r, mk_list(kPos)};
  }
  if (b == "allPositions") {
    if (n < 1 || n > 2 || a[0].type->k != TK::Int || (n == 2 && a[1].type->k != TK::Int)) bail(&at, "allPositions");
    std::string w = a[0].code, h = n == 2 ? a[1].code : a[0].code;
    line("if (" + w + " < 0 || " + h + " < 0) fail(\"allPositions: negative size\");");
    std::string r = scratch_list("std::vector<Pos>");
    line("for (int32_t i = 0; i < " + w + "; ++i) for (int32_t j = 0; j < " + h + "; ++j) " + r +
         ".push_back(Pos{i, j});");
    return {r, mk_list(kPos)};
  }
  if (b == "adjPositions") {
    need(1);
    if (a[0].type->k != TK::Pos) bail(&at, "adjPositions of a non-Position");
    std::string p = a[0].code, g = std::to_string(grid_);
    std::string r = scratch_list("std::vector<Pos>");
    line("for (Pos q : {Pos{sub(" + p + ".x, 1), " + p + ".y}, Pos{add(" + p + ".x, 1), " + p + ".y}, Pos{" + p +
         ".x, sub(" + p + ".y, 1)}, Pos{" + p + ".x, add(" + p + ".y, 1)}})");
    line("  if (q.x >= 0 && q.x < " + g + " && q.y >= 0 && q.y < " + g + ") " + r + ".push_back(q);");
    return {r, mk_list(kPos)};
  }
  if (b == "addObj") {
    need(2);
    const Val& l = list_arg(0);
    std::string r = temp();
    if (a[1].type->k == TK::Obj) {
      TP t = mk_list(a[1].type);
      if (l.type->elem && !same(l.type->elem, a[1].type)) bail(&at, "addObj of an object of another class");
      line(cpp_type(t) + " " + r + ";");
      if (l.code != "{}") {  // one allocation for the copy and the new element
        line(r + ".reserve(" + l.code + ".size() + 1);");
        line(r + ".assign(" + l.code + ".begin(), " + l.code + ".end());");
      }
      movable_.insert(r);
      line(r + ".push_back(" + a[1].code + ");");
      return {r, t};
    }
    if (a[1].type->k == TK::List) {
      TP t = unify(l.type, a[1].type);
      if (!same(l.type, a[1].type) || !t->elem) bail(&at, "addObj of lists of different types");
      line(cpp_type(t) + " " + r + (l.code == "{}" ? "" : " = " + l.code) + ";");
      if (a[1].code != "{}") line(r + ".insert(" + r + ".end(), " + a[1].code + ".begin(), " + a[1].code + ".end());");
      return {r, t};
    }
    bail(&at, "addObj of something that is not an object");
  }
  if (b == "isFreePos") {
    need(1);
    if (a[0].type->k != TK::Pos) bail(&at, "isFreePos of a non-Position");
    return declare({"s.core.occupied.free(" + a[0].code + ")", kBool});
  }
  if (b == "isWithinBounds") {
    need(1);
    Val elems = render_of(a[0], at);
    std::string r = temp(), g = std::to_string(grid_);
    line("bool " + r + " = true;");
    line("for (const Elem& e : " + elems.code + ")");
    line("  if (e.position.x < 0 || e.position.x >= " + g + " || e.position.y < 0 || e.position.y >= " + g + ") { " +
         r + " = false; break; }");
    return {r, kBool};
  }
  if (b == "sqrt") {
    need(1);
    if (a[0].type->k != TK::Int) bail(&at, "sqrt of a non-number");
    line("if (" + a[0].code + " < 0) fail(\"sqrt of a negative number\");");
    return declare({"int32_t(std::sqrt(double(" + a[0].code + ")))", kInt});
  }
  bail(&at, "builtin '" + b + "' has no specialised lowering");
}

// ---------------------------------------------------------------------------
// Whole-program analysis

void Lowerer::check_program_features() {
  // Constructs whose meaning depends on identity numbers, the global map order,
  // shared mutable cells or printed forms.
  std::function<void(const Expr&)> scan = [&](const Expr& e) {
    if (e.kind == ExprKind::Var) {
      const std::string& n = nm(e.name);
      if (n == "allObjs" || n == "rotate" || n == "renderAll" || n == "defined" || n == "arrayEqual" ||
          n == "cacheRendered" || n == "SpecialConditionTriggered" || n == "allCells" || n == "adjacentObjs" ||
          n == "adjacentObjsDiag")
        bail(&e, "'" + n + "' depends on global map order, identity or shared cells");
    }
    if (e.kind == ExprKind::Call && e.kids[0]->kind == ExprKind::Var && nm(e.kids[0]->name) == "removeObj" &&
        e.kids.size() != 3 && e.kids.size() != 2)
      bail(&e, "removeObj with other than one or two arguments");
    if (e.kind == ExprKind::Call && e.kids[0]->kind == ExprKind::Var && nm(e.kids[0]->name) == "removeObj" &&
        e.kids.size() == 3 && e.kids[2]->kind != ExprKind::Lambda)
      bail(&e, "removeObj with a value that may be an object (identity)");
    for (const auto& k : e.kids) scan(*k);
  };
  for (const Stmt& st : P.stmts) {
    for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr})
      if (e) scan(*e);
  }
  if (P.trigger) scan(*P.trigger);
}

void Lowerer::analyse_classes() {
  for (const Stmt& st : P.stmts) {
    if (st.kind != StmtKind::Object) continue;
    ClassInfo c;
    c.name = st.object_name;
    c.sym = st.object_sym;
    c.stmt = &st;
    if (c.name != cpp_ident(c.name)) bail(st.cell_expr.get(), "object name with special characters");
    for (const auto& f : st.fields) {
      if (nm(f.name) == "origin" || nm(f.name) == "elems" || nm(f.name) == "render")
        bail(st.cell_expr.get(), "field named like a built-in field");
      c.fields.push_back(f.name);
    }
    classes_.push_back(c);
    // Field types can name classes defined earlier only (as in the reference).
    for (const auto& f : st.fields) {
      TP t = type_of_decl(*f.type, st.cell_expr.get());
      if (t->k == TK::Obj && t->cls >= static_cast<int>(classes_.size()) - 1)
        bail(st.cell_expr.get(), "a field whose class is not defined before it");
      classes_.back().field_types.push_back(t);
    }
    fold_cells(st, classes_.back());
  }
}

// Evaluates a class's cell expression at compile time, as the interpreter would
// at every construction, when it does not depend on the constructor's arguments:
// literals, GRID_SIZE, list/map/range/rect/Position/(.. p x|y), arithmetic and
// Cell. A cell coordinate must come out a number; a colour either a string or a
// deferred expression over the object's fields and the lambda locals it captured.
struct FV {
  enum Kind { Int, Str, List, Pos, Cell, Lambda } k = Int;
  int32_t i = 0, x = 0, y = 0;
  std::vector<FV> items;
  const Expr* lambda = nullptr;
  ClassInfo::CellSpec cell;
};

void Lowerer::fold_cells(const Stmt& st, ClassInfo& c) {
  std::set<Sym> field_set(c.fields.begin(), c.fields.end());
  std::vector<std::pair<Sym, FV>> env;  // lambda locals, innermost last
  std::function<FV(const Expr&)> ev = [&](const Expr& e) -> FV {
    FV v;
    switch (e.kind) {
      case ExprKind::Number: v.i = e.number; return v;
      case ExprKind::String: v.k = FV::Str; v.i = string_id(e.text); return v;
      case ExprKind::Var: {
        for (auto it = env.rbegin(); it != env.rend(); ++it)
          if (it->first == e.name) return it->second;
        if (nm(e.name) == "GRID_SIZE") { v.i = grid_; return v; }
        bail(&e, "a cell shape that depends on '" + nm(e.name) + "'");
      }
      case ExprKind::Unary:
        if (e.unary == UnOp::Neg) { v = ev(*e.kids[0]); if (v.k != FV::Int) break; v.i = rt::neg(v.i); return v; }
        break;
      case ExprKind::Binary: {
        FV a = ev(*e.kids[0]), b = ev(*e.kids[1]);
        if (a.k != FV::Int || b.k != FV::Int) break;
        // 32-bit wrapping, as in the emitted code and the interpreter.
        if (e.op == BinOp::Add) { v.i = rt::add(a.i, b.i); return v; }
        if (e.op == BinOp::Sub) { v.i = rt::sub(a.i, b.i); return v; }
        if (e.op == BinOp::Mul) { v.i = rt::mul(a.i, b.i); return v; }
        break;
      }
      case ExprKind::List:
        v.k = FV::List;
        for (const auto& k : e.kids) v.items.push_back(ev(*k));
        return v;
      case ExprKind::Lambda: v.k = FV::Lambda; v.lambda = &e; return v;
      case ExprKind::Get: {
        FV o = ev(*e.kids[0]);
        if (o.k == FV::Pos && nm(e.name) == "x") { v.i = o.x; return v; }
        if (o.k == FV::Pos && nm(e.name) == "y") { v.i = o.y; return v; }
        break;
      }
      case ExprKind::Call: {
        if (e.kids[0]->kind != ExprKind::Var) break;
        const std::string f = nm(e.kids[0]->name);
        if (program_defines(e.kids[0]->name)) bail(&e, "'" + f + "' is redefined by the program");
        if (f == "Cell" && e.kids.size() == 4) {
          FV x = ev(*e.kids[1]), y = ev(*e.kids[2]);
          if (x.k != FV::Int || y.k != FV::Int) bail(&e, "a cell coordinate that is not a constant");
          v.k = FV::Cell;
          v.cell.x = x.i;
          v.cell.y = y.i;
          const Expr& col = *e.kids[3];
          // Names a global could capture make the colour depend on timing.
          for (Sym n : e.cell_names)
            if (all_global_names_.count(n) || builtin_names_.count(n) || nm(n) == "click")
              if (std::none_of(env.begin(), env.end(), [&](const auto& b) { return b.first == n; }))
                bail(&e, "a cell mentions '" + nm(n) + "', which a global would capture");
          if (col.kind == ExprKind::String) {
            v.cell.colour = string_id(col.text);
            return v;
          }
          // Deferred: no calls (so the trial evaluation has no side effects), and
          // every name a field or a captured local.
          std::function<void(const Expr&)> check = [&](const Expr& x) {
            if (x.kind == ExprKind::Call || x.kind == ExprKind::Assign || x.kind == ExprKind::Let ||
                x.kind == ExprKind::Lambda || x.kind == ExprKind::List)
              bail(&x, "a deferred colour with calls or bindings");
            for (const auto& k : x.kids) check(*k);
          };
          check(col);
          for (Sym n : e.cell_names) {
            auto it = std::find_if(env.rbegin(), env.rend(), [&](const auto& b) { return b.first == n; });
            if (it != env.rend()) {
              if (it->second.k != FV::Int && it->second.k != FV::Str) bail(&col, "a colour capturing a non-scalar");
              v.cell.captured.push_back({n, {it->second.k == FV::Str, it->second.i}});
            } else if (!field_set.count(n)) {
              bail(&col, "a deferred colour mentions '" + nm(n) + "', not a field");
            }
          }
          bool uses_field = false;
          for (Sym n : e.cell_names) uses_field |= field_set.count(n) > 0;
          if (!uses_field) bail(&col, "a computed colour that does not depend on a field");
          v.cell.colour_expr = e.kids[3];
          return v;
        }
        if (f == "Position" && e.kids.size() == 3) {
          FV x = ev(*e.kids[1]), y = ev(*e.kids[2]);
          if (x.k != FV::Int || y.k != FV::Int) break;
          v.k = FV::Pos;
          v.x = x.i;
          v.y = y.i;
          return v;
        }
        if (f == "range" && e.kids.size() == 3) {
          FV a = ev(*e.kids[1]), b = ev(*e.kids[2]);
          if (a.k != FV::Int || b.k != FV::Int) break;
          v.k = FV::List;
          for (int32_t i = a.i; i < b.i; ++i) { FV n; n.i = i; v.items.push_back(n); }
          return v;
        }
        if (f == "rect" && e.kids.size() == 3) {
          for (const char* t : {"xmin", "xmax", "ymin", "ymax", "rectPos"})
            if (Sym ts = P.symbols.find(t); ts >= 0 && all_global_names_.count(ts)) bail(&e, "rect would clobber a global");
          FV a = ev(*e.kids[1]), b = ev(*e.kids[2]);
          if (a.k != FV::Pos || b.k != FV::Pos) break;
          v.k = FV::List;
          for (int32_t y = a.y; y < b.y; ++y)
            for (int32_t x = a.x; x < b.x; ++x) { FV p; p.k = FV::Pos; p.x = x; p.y = y; v.items.push_back(p); }
          return v;
        }
        if (f == "map" && e.kids.size() == 3) {
          FV fn = ev(*e.kids[1]), l = ev(*e.kids[2]);
          if (fn.k != FV::Lambda || l.k != FV::List || fn.lambda->params.size() != 1) break;
          v.k = FV::List;
          for (const FV& item : l.items) {
            env.push_back({fn.lambda->params[0], item});
            v.items.push_back(ev(*fn.lambda->kids[0]));
            env.pop_back();
          }
          return v;
        }
        break;
      }
      default:
        break;
    }
    bail(&e, "a cell expression the lowering cannot evaluate at compile time");
  };
  FV cells = ev(*st.cell_expr);
  std::vector<FV> flat;
  if (cells.k == FV::List) flat = cells.items;
  else flat.push_back(cells);
  if (flat.empty()) bail(st.cell_expr.get(), "an object without cells");
  for (const FV& f : flat) {
    if (f.k != FV::Cell) bail(st.cell_expr.get(), "a cell list holding something other than cells");
    c.cells.push_back(f.cell);
  }
}

void Lowerer::analyse_globals() {
  for (const char* b : {"map", "concat", "filter", "foldl", "length", "head", "at", "tail", "renderAll", "defined",
                        "arrayEqual", "sqrt", "prev", "any", "isList", "uniformChoice", "adjPositions", "addObj",
                        "isFreePos", "range", "print", "removeObj", "updateObj", "randomPositions", "allPositions",
                        "clicked", "left", "right", "up", "down", "isWithinBounds", "allObjs", "rotate"})
    builtin_names_.insert(P.symbols.find(b));
}

// ---------------------------------------------------------------------------

Lowered Lowerer::run() {
  Lowered result;
  try {
    check_program_features();
    analyse_globals();
    std::function<void(const Expr&)> assigned = [&](const Expr& e) {
      if (e.kind == ExprKind::Assign) assigned_names_.insert(e.name);
      for (const auto& k : e.kids) assigned(*k);
    };
    for (const std::vector<Stmt>* stmts : {&P.stdlib_stmts, &P.stmts})
      for (const Stmt& st : *stmts)
        for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr})
          if (e) assigned(*e);
    if (P.trigger) assigned(*P.trigger);
    // The interpreter keeps one slot for `click`, which the input latch overwrites;
    // specialised code reads the latch alone, so a program's own `click` cannot be
    // told apart from it here.
    for (Sym s : assigned_names_)
      if (nm(s) == "click") bail(nullptr, "the program assigns 'click'");
    // Stdlib: plain definitions of functions and three constants.
    for (const Stmt& st : P.stdlib_stmts) {
      const Expr& e = *st.expr;
      if (e.kind != ExprKind::Assign) continue;
      const Expr& v = *e.kids[0];
      Global g;
      if (v.kind == ExprKind::Lambda) {
        auto t = std::make_shared<T>();
        t->k = TK::Func;
        t->lambda = &v;
        g.type = t;
        g.is_const_func = true;
      } else if (v.kind == ExprKind::Var && globals_.count(v.name)) {
        g = globals_[v.name];  // (= nextSolid moveDownNoCollision)
      } else if (v.kind == ExprKind::Var && builtin_names_.count(v.name)) {
        auto t = std::make_shared<T>();
        t->k = TK::Func;
        t->builtin = nm(v.name);
        g.type = t;
        g.is_const_func = true;
      } else {
        g.type = v.kind == ExprKind::String ? kStr : kInt;
        g.plain = true;
        g.cpp = "s.g_" + cpp_ident(nm(e.name));
        if (nm(e.name) == "GRID_SIZE") grid_ = v.number;
        stdlib_init_ += "    " + g.cpp + " = int32_t(" +
                        std::to_string(v.kind == ExprKind::String ? string_id(v.text) : v.number) + ");\n";
      }
      globals_[e.name] = g;
      plain_order_.push_back(e.name);
    }
    // Every name the program defines globally: a cell mentioning one would capture it.
    for (const Stmt& st : P.stmts)
      if (st.kind == StmtKind::Expr && st.expr->kind == ExprKind::Assign) all_global_names_.insert(st.expr->name);
    for (const auto& [sym, g] : globals_) all_global_names_.insert(sym);
    analyse_classes();
    {
      Sym rv = P.symbols.find("renderValue");
      bool redefined = false;
      for (const char* n : {"renderValue", "map", "concat", "isList"})
        if (Sym sym = P.symbols.find(n); sym >= 0 && program_defines(sym)) redefined = true;
      if (!redefined && globals_.count(rv) && globals_[rv].type && globals_[rv].type->lambda)
        stdlib_render_value_ = globals_[rv].type->lambda;
    }

    // Program statements: declarations, plain definitions (evaluated at start),
    // initnext registrations, on-clauses.
    std::map<Sym, TP> declared;
    std::vector<Sym> initnext;
    std::map<Sym, std::pair<const Expr*, const Expr*>> init_next;
    std::vector<const Stmt*> plain_stmts;
    for (const Stmt& st : P.stmts) {
      if (st.kind == StmtKind::On) {
        on_.push_back(&st);
        continue;
      }
      if (st.kind != StmtKind::Expr) continue;
      const Expr& e = *st.expr;
      if (e.kind == ExprKind::TypeDecl) {
        declared[e.name] = type_of_decl(*e.type, &e);
        continue;
      }
      if (e.kind == ExprKind::Assign && e.kids[0]->kind == ExprKind::InitNext) {
        if (!init_next.count(e.name)) initnext.push_back(e.name);
        else bail(&e, "an initnext variable declared twice");
        init_next[e.name] = {e.kids[0]->kids[0].get(), e.kids[0]->kids[1].get()};
        continue;
      }
      plain_stmts.push_back(&st);
    }
    // GRID_SIZE must be a constant: the last plain (= GRID_SIZE n) wins.
    for (const Stmt* st : plain_stmts) {
      const Expr& e = *st->expr;
      if (e.kind == ExprKind::Assign && nm(e.name) == "GRID_SIZE") {
        if (e.kids[0]->kind != ExprKind::Number) bail(&e, "GRID_SIZE is not a literal");
        grid_ = e.kids[0]->number;
      }
    }
    if (grid_ <= 0 || grid_ > 4096) bail(nullptr, "GRID_SIZE out of range");

    // Types of initnext variables: declared, else the initialiser's.
    for (Sym s : initnext) {
      Global g;
      g.initnext = true;
      g.cpp = "s.g_" + cpp_ident(nm(s));
      if (declared.count(s)) g.type = declared[s];
      globals_[s] = g;  // provisional (type may be null)
    }
    {
      // Infer undeclared types by lowering initialisers into a scratch buffer.
      for (Sym s : initnext) {
        if (globals_[s].type) continue;
        std::string scratch;
        std::string* saved = out_;
        out_ = &scratch;
        in_start_ = false;
        LScope top;
        top.top = true;
        chain_ = {&top};
        Val v = lower(*init_next[s].first);
        out_ = saved;
        if (v.type->k == TK::List && !v.type->elem) bail(init_next[s].first, "'" + nm(s) + "': list of unknown type (declare it)");
        if (v.type->k == TK::Func || v.type->k == TK::Type) bail(init_next[s].first, "a function-valued variable");
        globals_[s].type = v.type;
      }
    }
    // INIT/NEXT order: the libstdc++ hash order of the initnext names.
    HashOrder order;
    for (Sym s : initnext) order.insert(s, P.symbols.hash(s));
    for (int s : order.order()) init_order_.push_back(s);

    // ---- start()
    std::string start;
    out_ = &start;
    depth_ = 0;
    in_start_ = true;
    for (const Stmt* st : plain_stmts) {
      LScope top;
      top.top = true;
      chain_ = {&top};
      const Expr& e = *st->expr;
      if (e.kind == ExprKind::Assign) {
        const Expr& v = *e.kids[0];
        if (v.kind == ExprKind::Lambda || (v.kind == ExprKind::Var && globals_.count(v.name) &&
                                            globals_[v.name].type && globals_[v.name].type->k == TK::Func)) {
          Val fv = lower(v);
          Global g;
          g.type = fv.type;
          g.is_const_func = true;
          if (globals_.count(e.name) && !globals_[e.name].is_const_func) bail(&e, "a variable redefined as a function");
          globals_[e.name] = g;
          continue;
        }
        Val val = declare(lower(v));
        if (declared.count(e.name) && !same(declared[e.name], val.type)) bail(&e, "value does not match declared type");
        if (globals_.count(e.name)) {
          Global& g = globals_[e.name];
          if (g.is_const_func) bail(&e, "a function redefined as a variable");
          if (!same(g.type, val.type)) bail(&e, "'" + nm(e.name) + "' redefined with another type");
          line(g.cpp + " = " + val.code + ";");
        } else {
          if (val.type->k == TK::List && !val.type->elem) bail(&e, "a global empty list of unknown type");
          Global g;
          g.type = val.type;
          g.plain = true;
          g.cpp = "s.g_" + cpp_ident(nm(e.name));
          globals_[e.name] = g;
          plain_order_.push_back(e.name);
          line(g.cpp + " = " + val.code + ";");
        }
      } else {
        lower(e);
      }
    }
    for (Sym s : init_order_) {
      LScope top;
      top.top = true;
      chain_ = {&top};
      line("// init " + nm(s) + ", " + where(init_next[s].first->loc));
      Val v = lower(*init_next[s].first);
      if (!same(v.type, globals_[s].type)) bail(init_next[s].first, "initialiser of '" + nm(s) + "' has another type");
      if (v.code != "{}") line(globals_[s].cpp + " = " + v.code + ";");
      else line(globals_[s].cpp + " = {};");
      defined_initnext_.insert(s);
    }
    in_start_ = false;
    start_code_ = start;

    // ---- step()
    std::string step;
    out_ = &step;
    if (P.trigger) {
      LScope top;
      top.top = true;
      chain_ = {&top};
      line("{");
      ++depth_;
      Val c = lower(*P.trigger);
      line("s.core.triggered = " + truthy(c) + ";");
      --depth_;
      line("}");
    }
    for (size_t i = 0; i < on_.size(); ++i) {
      LScope top;
      top.top = true;
      chain_ = {&top};
      line("{  // on-clause " + std::to_string(i + 1) + ", " + where(on_[i]->loc));
      ++depth_;
      Val c = lower(*on_[i]->cond);
      if (c.type->k == TK::Func) c = zero_arg_call(c, *on_[i]->cond);
      if (c.type->k != TK::Bool) bail(on_[i]->cond.get(), "an on-clause condition that is not a Bool");
      line("if (" + c.code + ") {");
      ++depth_;
      line("s.core.covered[" + std::to_string(i) + "] = 1;");
      top.depth = depth_;
      Val v = lower_discarded(*on_[i]->body);
      if (v.type->k == TK::Type) bail(on_[i]->body.get(), "an on-clause body that is a type");
      --depth_;
      line("}");
      --depth_;
      line("}");
    }
    for (Sym s : init_order_) {
      LScope top;
      top.top = true;
      chain_ = {&top};
      line("if (!s.u_" + cpp_ident(nm(s)) + ") {  // NEXT of " + nm(s) + ", " + where(init_next[s].second->loc));
      ++depth_;
      Val v = lower(*init_next[s].second);
      if (!same(v.type, globals_[s].type)) bail(init_next[s].second, "NEXT of '" + nm(s) + "' has another type");
      line(globals_[s].cpp + " = " + (v.code == "{}" ? std::string("{}") : movable_.count(v.code) ? "std::move(" + v.code + ")" : v.code) + ";");
      --depth_;
      line("}");
    }
    step_code_ = step;

    // Render order: initnext declaration order, then plain definitions.
    for (Sym s : initnext) render_order_.push_back(s);
    for (Sym s : plain_order_)
      if (std::find(render_order_.begin(), render_order_.end(), s) == render_order_.end()) render_order_.push_back(s);

    // Deferred colours, lowered per class with the fields in scope.
    for (size_t ci = 0; ci < classes_.size(); ++ci) {
      ClassInfo& c = classes_[ci];
      for (size_t k = 0; k < c.cells.size(); ++k) {
        if (!c.cells[k].colour_expr) continue;
        std::string fn;
        out_ = &fn;
        depth_ = -1;
        LScope inst, captured;
        for (size_t i = 0; i < c.fields.size(); ++i)
          inst.vars.push_back(LVar{c.fields[i], "o.f_" + cpp_ident(nm(c.fields[i])), c.field_types[i], 0});
        for (const auto& [sym, val] : c.cells[k].captured) {
          std::string lit = "int32_t(" + std::to_string(val.second) + ")";
          immutable_names_.insert(lit);
          captured.vars.push_back(LVar{sym, lit, val.first ? kStr : kInt, 0});
        }
        chain_ = {&inst, &captured};
        Val v = lower(*c.cells[k].colour_expr);
        if (v.type->k != TK::Str) bail(c.cells[k].colour_expr.get(), "a deferred colour that is not a string");
        colour_fns_ += "  static int32_t colour_" + cpp_ident(c.name) + "_" + std::to_string(k) + "(State& s, const C_" +
                       cpp_ident(c.name) + "& o) {\n    (void)s;\n" + fn + "    return " + v.code + ";\n  }\n";
        depth_ = 0;
      }
    }
    result.code = emit();
    result.ok = true;
  } catch (const Unsupported& u) {
    result.ok = false;
    result.reason = (u.loc.line ? P.file_name(u.loc.source) + ":" + std::to_string(u.loc.line) + ":" +
                                      std::to_string(u.loc.col) + ": "
                                : std::string()) +
                    u.why;
  }
  return result;
}

std::string Lowerer::emit() {
  std::ostringstream o;
  o << "struct Prog {\n";
  o << "  static constexpr const char* kProgramName = \"" << name_ << "\";\n";
  o << "  static constexpr int kOnClauses = " << on_.size() << ";\n";
  o << "  static constexpr bool kUsesRandom = " << (P.uses_random ? "true" : "false") << ";\n";
  o << "  static constexpr int kGrid = " << grid_ << ";\n";
  o << "  static const char* const kColours[];\n\n";
  for (const ClassInfo& c : classes_) {
    std::string cn = "C_" + cpp_ident(c.name);
    o << "  struct " << cn << " {\n";
    for (size_t i = 0; i < c.fields.size(); ++i)
      o << "    " << cpp_type(c.field_types[i]) << " f_" << cpp_ident(nm(c.fields[i])) << ";\n";
    o << "    Pos origin;\n";
    o << "  };\n";
    o << "  static bool eq(const " << cn << "& a, const " << cn << "& b) {\n    return true";
    for (Sym f : c.fields) o << " && a.f_" << cpp_ident(nm(f)) << " == b.f_" << cpp_ident(nm(f));
    o << " && a.origin == b.origin;\n  }\n";
    o << "  friend void hash_value(Hash& h, const " << cn << "& v) {\n";
    for (Sym f : c.fields) o << "    hash_value(h, v.f_" << cpp_ident(nm(f)) << ");\n";
    o << "    hash_value(h, v.origin);\n  }\n";
    o << "  friend void save_value(SnapshotWriter& w, const " << cn << "& v) {\n";
    for (Sym f : c.fields) o << "    save_value(w, v.f_" << cpp_ident(nm(f)) << ");\n";
    o << "    save_value(w, v.origin);\n  }\n";
    o << "  friend void load_value(SnapshotReader& r, " << cn << "& v) {\n";
    for (Sym f : c.fields) o << "    load_value(r, v.f_" << cpp_ident(nm(f)) << ");\n";
    o << "    load_value(r, v.origin);\n  }\n";
  }
  o << "\n  // Working buffers, one per place that builds a short-lived list.\n";
  o << "  struct Scratch {\n    std::vector<Elem> render_elems;\n" << scratch_fields_ << "  };\n";
  o << "\n  struct State {\n    Core core;\n    NoCopy<Scratch> scratch;\n";
  for (const auto& [s, g] : globals_) {
    if (g.is_const_func || !g.type || g.type->k == TK::Func) continue;
    o << "    " << cpp_type(g.type) << " g_" << cpp_ident(nm(s)) << "{};\n";
    if (g.initnext) o << "    bool u_" << cpp_ident(nm(s)) << " = false;\n";
    if (g.prev_used) o << "    " << cpp_type(g.type) << " p_" << cpp_ident(nm(s)) << "{};\n";
  }
  o << "  };\n\n";
  o << colour_fns_;
  for (const ClassInfo& c : classes_) {
    std::string cn = "C_" + cpp_ident(c.name);
    o << "  static void render_" << cpp_ident(c.name) << "(State& s, const " << cn
      << "& o, std::vector<Elem>& out) {\n    (void)s;\n";
    for (size_t k = 0; k < c.cells.size(); ++k) {
      const auto& cell = c.cells[k];
      std::string colour = cell.colour >= 0 ? std::to_string(cell.colour)
                                            : "colour_" + cpp_ident(c.name) + "_" + std::to_string(k) + "(s, o)";
      o << "    out.push_back(Elem{Pos{add(o.origin.x, " << cell.x << "), add(o.origin.y, " << cell.y << ")}, " << colour
        << "});\n";
    }
    o << "  }\n";
  }
  o << "\n  static void start(State& s, uint64_t seed) {\n";
  o << "    s.core.rng.reseed(seed);\n    s.core.covered.assign(" << on_.size() << ", 0);\n";
  o << stdlib_init_;
  o << start_code_;
  o << "    render(s, nullptr, {});\n  }\n\n";
  o << "  static void step(State& s) {\n";
  for (const auto& [sym, g] : globals_)
    if (g.prev_used) o << "    s.p_" << cpp_ident(nm(sym)) << " = s.g_" << cpp_ident(nm(sym)) << ";\n";
  o << "    s.core.have_prev = true;\n";
  for (const auto& [sym, g] : globals_)
    if (g.initnext) o << "    s.u_" << cpp_ident(nm(sym)) << " = false;\n";
  o << step_code_;
  o << "    s.core.click = s.core.left = s.core.right = s.core.up = s.core.down = false;\n  }\n\n";
  o << "  static void render(State& s, Painter* paint, const std::vector<uint16_t>& pal) {\n";
  o << "    s.core.occupied.clear(kGrid);\n";
  o << "    std::vector<Elem>& elems = s.scratch.v.render_elems;\n";
  o << "    if (paint) paint->begin(kGrid, pal[s.g_background]);\n";
  for (Sym s : render_order_) {
    const Global& g = globals_[s];
    if (!g.type) continue;
    std::function<bool(const TP&)> renders = [&](const TP& t) {
      return t->k == TK::Obj || (t->k == TK::List && t->elem && renders(t->elem));
    };
    if (!renders(g.type)) continue;
    o << "    elems.clear();\n";
    std::string buf;
    out_ = &buf;
    depth_ = 0;
    std::function<void(const Val&)> rec = [&](const Val& x) {
      if (x.type->k == TK::Obj) line("render_" + cpp_ident(classes_[x.type->cls].name) + "(s, " + x.code + ", elems);");
      else for_each(x, rec);
    };
    rec(Val{g.cpp, g.type});
    o << buf;
    o << "    for (const Elem& e : elems) {\n      s.core.occupied.add(e.position);\n";
    o << "      if (paint) paint->paint(e.position, pal[e.color]);\n    }\n";
  }
  o << "  }\n\n";
  // One statement per state global (the State members that carry a value): the
  // hash and the snapshot walk the same list.
  auto each_state_global = [&](const std::string& call) {
    for (const auto& [sym, g] : globals_)
      if (!g.is_const_func && g.type && g.type->k != TK::Func) o << "    " << call << "s.g_" << cpp_ident(nm(sym)) << ");\n";
  };
  o << "  static uint64_t hash(const State& s) {\n    Hash h;\n    hash_core(h, s.core, kUsesRandom);\n";
  each_state_global("hash_value(h, ");
  o << "    return h.h;\n  }\n";
  // Snapshots hold the globals only: prev_/u_ copies are rewritten at the start
  // of every step (compiled_support.hpp, SnapshotWriter).
  o << "  static void save(const State& s, SnapshotWriter& w) {\n    (void)s;\n    (void)w;\n";
  each_state_global("save_value(w, ");
  o << "  }\n";
  o << "  static void load(State& s, SnapshotReader& r) {\n    (void)s;\n    (void)r;\n";
  each_state_global("load_value(r, ");
  o << "  }\n";
  o << "};\n\n";
  o << "const char* const Prog::kColours[] = {\n";
  for (const std::string& q : string_list_) {
    std::string inner = q.size() >= 2 ? q.substr(1, q.size() - 2) : q;
    std::string lowered = lower_ascii(inner);
    std::string escaped;
    for (char c : lowered) {
      if (c == '"' || c == '\\') escaped += '\\';
      escaped += c;
    }
    o << "    \"" << escaped << "\",\n";
  }
  o << "    nullptr};\n";
  return bind_global_reads(o.str());
}

// Settles each global read that declare_global_read marked: "&" (a reference)
// when no assignment to that global can run while the reference is still to be
// read, nothing (a copy) otherwise. Every store to a global is emitted as
// "s.g_name = ..." inside the function that runs it (render and the helpers
// only read), and a reference lives until the end of its enclosing C++ block.
// A store in that span is harmless unless the reference, or a reference bound
// to it (an inlined function's parameter), is named after it, or the store sits
// inside a loop that began after the declaration (the next iteration would read
// the reference again).
std::string Lowerer::bind_global_reads(std::string text) {
  const std::string mark = kRefMark;
  const size_t npos = std::string::npos;
  // Index of the first unmatched '}' at or after `from`, skipping string and
  // character literals and comments.
  auto block_end = [&](size_t from) -> size_t {
    int depth = 0;
    for (size_t i = from; i < text.size(); ++i) {
      char c = text[i];
      if (c == '"' || c == '\'') {
        for (++i; i < text.size() && text[i] != c; ++i)
          if (text[i] == '\\') ++i;
      } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
        i = text.find('\n', i);
        if (i == npos) return npos;
      } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
        i = text.find("*/", i + 2);
        if (i == npos) return npos;
        ++i;
      } else if (c == '{') {
        ++depth;
      } else if (c == '}' && depth-- == 0) {
        return i;
      }
    }
    return npos;
  };
  auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  // Whether identifier `name` occurs in [from, to).
  auto named = [&](const std::string& name, size_t from, size_t to) {
    for (size_t i = text.find(name, from); i != npos && i < to; i = text.find(name, i + 1))
      if ((i == 0 || !ident(text[i - 1])) && (i + name.size() >= text.size() || !ident(text[i + name.size()])))
        return true;
    return false;
  };
  // Whether a loop starting in [from, store) has `store` in its body.
  auto loop_holds = [&](size_t from, size_t store) {
    for (const char* kw : {"for (", "while ("})
      for (size_t l = text.find(kw, from); l != npos && l < store; l = text.find(kw, l + 1)) {
        size_t i = text.find('(', l), depth = 0;
        for (; i < text.size(); ++i) {
          if (text[i] == '(') ++depth;
          else if (text[i] == ')' && --depth == 0) break;
        }
        size_t j = text.find_first_not_of(" \n", i + 1);
        if (j == npos) return true;
        size_t body_end = text[j] == '{' ? block_end(j + 1) : text.find(';', j);
        if (body_end == npos || body_end > store) return true;
      }
    return false;
  };
  // Render methods and cell colour functions (render_<Class>, colour_<Class>_k)
  // run in the middle of a step (renderValue, intersects...). None stores a
  // global today; should one ever, every read of that global stays a copy
  // rather than trusting the textual span.
  std::set<std::string> stored_in_render;
  for (const char* head : {"static void render_", "static int32_t colour_"}) {
    for (size_t r = text.find(head); r != npos; r = text.find(head, r + 1)) {
      const size_t body = text.find('{', r);
      const size_t body_end = body == npos ? npos : block_end(body + 1);
      for (size_t g = text.find("s.g_", body); g != npos && g < body_end; g = text.find("s.g_", g + 1)) {
        size_t e = g + 4;
        while (e < text.size() && ident(text[e])) ++e;
        if (text.compare(e, 3, " = ") == 0) stored_in_render.insert(text.substr(g, e - g));
      }
    }
  }
  std::string out;
  size_t done = 0;
  for (size_t at = text.find(mark); at != npos; at = text.find(mark, at + mark.size())) {
    // "const T/*ref?*/ tN = s.g_name;"
    const size_t name_at = at + mark.size() + 1;
    const size_t eq = text.find(" = ", at);
    const std::string temp = text.substr(name_at, eq - name_at);
    const size_t semi = text.find(';', eq);
    const std::string store = text.substr(eq + 3, semi - eq - 3) + " = ";
    const size_t end = block_end(semi + 1);
    // The reference and its aliases: "const U& a_x = tN;" (an inlined function's
    // parameter) names the same object, and so on transitively.
    std::vector<std::string> names = {temp};
    for (size_t n = 0; n < names.size() && end != npos; ++n) {
      const std::string bound = " = " + names[n] + ";";
      for (size_t i = text.find(bound, semi); i != npos && i < end; i = text.find(bound, i + 1)) {
        size_t b = i;
        while (b > 0 && ident(text[b - 1])) --b;
        if (b >= 2 && text.compare(b - 2, 2, "& ") == 0 && b < i) names.push_back(text.substr(b, i - b));
      }
    }
    bool copy = end == npos || stored_in_render.count(store.substr(0, store.size() - 3)) > 0;
    for (size_t st = text.find(store, semi); !copy && st != npos && st < end; st = text.find(store, st + 1)) {
      copy = loop_holds(semi, st);
      for (const std::string& name : names) copy = copy || named(name, st, end);
    }
    out.append(text, done, at - done);
    out += copy ? "" : "&";
    done = at + mark.size();
  }
  out.append(text, done, npos);
  return out;
}

}  // namespace

Lowered lower_program(const Program& program, const std::string& program_name) {
  return Lowerer(program, program_name).run();
}

}  // namespace autumn
