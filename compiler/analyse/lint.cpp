#include "compiler/analyse/lint.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <set>

#include "compiler/analyse/colour_names.hpp"
#include "compiler/analyse/program.hpp"
#include "compiler/parse/token.hpp"
#include "compiler/read/sexpr.hpp"
#include "runtime/frame.hpp"

namespace autumn {
namespace {

std::string plural(size_t n, const char* word) { return std::to_string(n) + " " + word + (n == 1 ? "" : "s"); }

// A symbol atom as the author wrote it (the reader re-escapes ' " ? \).
std::string unescaped(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i)
    if (!(text[i] == '\\' && i + 1 < text.size())) out += text[i];
    else out += text[++i];
  return out;
}

// ---------------------------------------------------------------------------- bindings

// What the names of the program and the stdlib are bound to, everywhere.
struct Bindings {
  std::map<Sym, std::set<int>> lambda_arity;  // names assigned lambdas: their parameter counts
  std::set<Sym> other;                        // names bound to anything else somewhere
  std::map<Sym, size_t> class_fields;         // object classes (last definition)

  void collect(const Expr& e) {
    if (e.kind == ExprKind::Assign) {
      if (e.kids[0]->kind == ExprKind::Lambda) lambda_arity[e.name].insert(static_cast<int>(e.kids[0]->params.size()));
      else other.insert(e.name);
    }
    if (e.kind == ExprKind::Lambda) other.insert(e.params.begin(), e.params.end());
    for (const auto& k : e.kids) collect(*k);
  }
  void collect(const std::vector<Stmt>& stmts) {
    for (const Stmt& st : stmts) {
      if (st.kind == StmtKind::Object) {
        class_fields[st.object_sym] = st.fields.size();
        for (const auto& f : st.fields) other.insert(f.name);
      }
      for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr})
        if (e) collect(*e);
    }
  }
  // The one parameter count of a function bound only to lambdas, if it has one.
  std::optional<int> arity(Sym s) const {
    auto it = lambda_arity.find(s);
    if (it == lambda_arity.end() || other.count(s) || it->second.size() != 1) return std::nullopt;
    return *it->second.begin();
  }
  bool is_function(const Program& p, Sym s) const {
    if (other.count(s) || class_fields.count(s)) return false;
    return lambda_arity.count(s) || p.builtin_of(s).has_value();
  }
};

// Every value each name is given anywhere (the program's and the stdlib's
// globals, and let's and on-clauses' assignments alike: scope is dynamic, so a
// name's value at a use may come from any of them), and the names also bound
// some other way (a lambda's parameter, an object's field), whose values the
// syntax does not show.
struct Assignments {
  std::map<Sym, std::vector<const Expr*>> values;
  std::set<Sym> otherwise;

  void collect(const Expr& e) {
    if (e.kind == ExprKind::Assign && !e.kids.empty() && e.kids[0]) {
      const Expr& v = *e.kids[0];
      if (v.kind != ExprKind::InitNext) values[e.name].push_back(&v);
      for (const ExprPtr& k : v.kind == ExprKind::InitNext ? v.kids : std::vector<ExprPtr>{})
        if (k) values[e.name].push_back(k.get());
    }
    if (e.kind == ExprKind::Lambda) otherwise.insert(e.params.begin(), e.params.end());
    for (const ExprPtr& k : e.kids)
      if (k) collect(*k);
  }
  void collect(const std::vector<Stmt>& stmts) {
    for (const Stmt& st : stmts) {
      for (const auto& f : st.fields) otherwise.insert(f.name);
      for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr, st.constructor_body})
        if (e) collect(*e);
    }
  }
};

// ---------------------------------------------------------------------------- the linter

class Linter {
 public:
  Linter(const Program& p, std::vector<std::string>& out) : p_(p), out_(out) {
    b_.collect(p.stdlib_stmts);
    b_.collect(p.stmts);
    a_.collect(p.stdlib_stmts);
    a_.collect(p.stmts);
    for (const Stmt& st : p.stmts)
      if (st.kind == StmtKind::Object) classes_.insert(st.object_sym);
  }
  void run();

 private:
  void warn(SourceLoc loc, const std::string& msg) { found_.emplace_back(loc, msg); }
  // s-expression checks
  void atoms(const Sexp& s, bool field_position);
  void truncated_atom(const Sexp& s);
  void non_calls(const Sexp& s, bool calls_functions);
  // syntax-tree checks
  void expr(const Expr& e);
  void call_arity(const Expr& call);
  void colours(const Expr& e);
  void statements();
  void or_spelling(const Sexp& s);
  void clobbered_globals();
  void type_name(const TypeExprPtr& t, SourceLoc loc, const std::set<Sym>& classes, bool field);
  void declared_value(const Expr& assign, const std::map<Sym, std::string>& declared);
  // static types
  std::optional<std::string> static_type(const Expr& e, bool top);
  std::optional<std::string> name_type(Sym s, bool top);
  std::optional<std::string> call_type(const Expr& call, bool top);
  bool is_type_name(Sym s) const;
  void operand_types(const Expr& e);

  const Program& p_;
  std::vector<std::string>& out_;
  std::vector<std::pair<SourceLoc, std::string>> found_;
  Bindings b_;
  Assignments a_;
  std::set<Sym> classes_;
  // name_type's answers; nullopt also while a name's own values are being typed.
  std::map<std::pair<Sym, bool>, std::optional<std::string>> name_types_;
  int lambda_depth_ = 0;  // expr(): inside this many lambdas or object cell expressions
};

void Linter::run() {
  const Sexp root = read_sexprs(p_.file);
  if (!root.items.empty()) {
    atoms(root.items[0], false);
    non_calls(root.items[0], false);
    or_spelling(root.items[0]);
  }
  statements();
  clobbered_globals();
  for (const Stmt& st : p_.stmts) {
    for (const ExprPtr& e : {st.cond, st.body, st.expr})
      if (e) expr(*e);
    if (st.cell_expr) {  // evaluated where the object's fields are bound
      ++lambda_depth_;
      expr(*st.cell_expr);
      --lambda_depth_;
    }
  }
  std::stable_sort(found_.begin(), found_.end(), [](const auto& a, const auto& b) {
    return std::pair(a.first.line, a.first.col) < std::pair(b.first.line, b.first.col);
  });
  for (const auto& [loc, msg] : found_) out_.push_back(format_diagnostic(p_.file.name, loc, "warning", msg));
}

// Every symbol atom, except the raw field name of (.. o f) and object names.
void Linter::atoms(const Sexp& s, bool field_position) {
  if (!s.is_list) {
    if (!s.is_string && !field_position) truncated_atom(s);
    return;
  }
  const std::string head = !s.items.empty() && !s.items[0].is_list ? s.items[0].text : "";
  for (size_t i = 0; i < s.items.size(); ++i)
    atoms(s.items[i], (head == ".." || head == "object") && i == (head == ".." ? 2u : 1u));
}

void Linter::truncated_atom(const Sexp& s) {
  const std::vector<Token> toks = lex_atom(s.text);
  if (toks.empty()) return;
  size_t first = 0;
  if ((toks[0].type == Tok::Minus || toks[0].type == Tok::Plus) && toks.size() > 1 && toks[1].type == Tok::Number)
    first = 1;  // "-2.7": unary minus of the number after it
  const Token& t = toks[first];
  if (t.type != Tok::Number && t.type != Tok::Identifier) return;
  std::string used;
  for (size_t i = 0; i <= first; ++i) used += toks[i].lexeme;
  const std::string written = unescaped(s.text);
  if (t.type == Tok::Number && (t.lexeme.find('.') != std::string::npos || used != s.text)) {
    const std::string whole = used.substr(0, used.find('.'));
    warn(s.loc, "'" + written + "' reads as the integer " + whole + " (Autumn numbers are whole numbers)");
  } else if (t.type == Tok::Identifier && used != s.text) {
    warn(s.loc, "'" + written + "' reads as the name '" + t.lexeme +
                    "' (names end at the first character that is not a letter, digit or underscore)");
  }
}

// (f) with f a function, where function values are not called.
void Linter::non_calls(const Sexp& s, bool calls_functions) {
  if (!s.is_list || s.items.empty()) return;
  const Sexp& h = s.items[0];
  if (s.items.size() == 1 && !h.is_list && !h.is_string && !calls_functions) {
    const std::vector<Token> toks = lex_atom(h.text);
    if (!toks.empty() && toks[0].type == Tok::Identifier && toks[0].lexeme != "list") {
      const Sym sym = p_.symbols.find(toks[0].lexeme);
      if (sym >= 0 && b_.is_function(p_, sym))
        warn(s.loc, "'(" + toks[0].lexeme + ")' is the function '" + toks[0].lexeme + "' itself, not a call " +
                        "(a call with no arguments is written '((" + toks[0].lexeme + "))')");
    }
  }
  const std::string head = h.is_list ? "" : h.text;
  if (head == ":") return;  // types
  const bool logical = head == "and" || head == "or" || head == "&" || head == "|" || head == "&&" || head == "||";
  for (size_t i = 0; i < s.items.size(); ++i) {
    if ((head == "fn" || head == "-->") && i == 1) continue;  // parameters
    const bool callee = i == 0 && h.is_list;                  // ((f) ...) calls f
    const bool auto_call = (head == "on" && i == 1) || (logical && i > 0);
    non_calls(s.items[i], callee || auto_call);
  }
}

// (|| a b) is AND, as in the reference (its lexer's first token of "||").
void Linter::or_spelling(const Sexp& s) {
  if (!s.is_list) return;
  if (!s.items.empty() && !s.items[0].is_list && !s.items[0].is_string && s.items[0].text == "||")
    warn(s.loc, "'(|| ...)' is AND in Autumn, as in the reference interpreter; OR is written (or ...) or (| ...)");
  for (const Sexp& k : s.items) or_spelling(k);
}

// ---------------------------------------------------------------------------- calls and colours

void Linter::expr(const Expr& e) {
  if (e.kind == ExprKind::Call) call_arity(e);
  if (e.kind == ExprKind::Binary || e.kind == ExprKind::Unary) operand_types(e);
  if (e.kind == ExprKind::Lambda) {
    ++lambda_depth_;
    for (const auto& k : e.kids) expr(*k);
    --lambda_depth_;
    return;
  }
  if (e.kind == ExprKind::Call && e.kids[0]->kind == ExprKind::Var && e.kids.size() >= 4 &&
      p_.name(e.kids[0]->name) == "Cell")
    colours(*e.kids[3]);
  if (e.kind == ExprKind::Assign && e.name == p_.names.background) colours(*e.kids[0]);
  for (const auto& k : e.kids) expr(*k);
}

void Linter::call_arity(const Expr& call) {
  const Expr& callee = *call.kids[0];
  if (callee.kind != ExprKind::Var) return;
  const size_t given = call.kids.size() - 1;
  const std::string name = p_.name(callee.name);
  if (auto c = b_.class_fields.find(callee.name); c != b_.class_fields.end()) {
    const size_t want = c->second + 1;  // the fields, then the origin
    if (given != want)
      warn(call.loc, "object '" + name + "' is made from " + plural(c->second, "field") + " and an origin Position (" +
                         std::to_string(want) + " arguments) but is given " + std::to_string(given) +
                         (given > want ? "; the extra ones are ignored" : "; that is an error at run time"));
    return;
  }
  if (auto b = p_.builtin_of(callee.name); b && !b_.other.count(callee.name) && !b_.lambda_arity.count(callee.name)) {
    const BuiltinInfo& info = builtin_info(*b);
    if (given < info.min_args || (info.max_args != kAnyArity && given > info.max_args))
      warn(call.loc, "'" + name + "' takes " +
                         (info.min_args == info.max_args ? std::to_string(info.min_args)
                                                         : std::to_string(info.min_args) + " to " +
                                                               std::to_string(info.max_args)) +
                         " argument" + (info.max_args == 1 ? "" : "s") + " but is given " + std::to_string(given) +
                         "; that is an error at run time");
    return;
  }
  if (auto a = b_.arity(callee.name); a && static_cast<int>(given) != *a)
    warn(call.loc, "'" + name + "' takes " + plural(static_cast<size_t>(*a), "argument") + " but is given " +
                       std::to_string(given) +
                       (static_cast<int>(given) > *a ? "; the extra ones are ignored"
                                                     : "; the call is an error at run time"));
}

// String literals that end up as a colour.
void Linter::colours(const Expr& e) {
  switch (e.kind) {
    case ExprKind::String: {
      const std::string name = lower_ascii(e.text.size() >= 2 ? e.text.substr(1, e.text.size() - 2) : e.text);
      if (colour_rgb(name)) return;
      auto near = closest_colour(name);
      warn(e.loc, "\"" + name + "\" is not a colour the benchmark draws (it is drawn black)" +
                      (near ? "; did you mean \"" + std::string(*near) + "\"?" : std::string()));
      return;
    }
    case ExprKind::If:
      colours(*e.kids[1]);
      colours(*e.kids[2]);
      return;
    case ExprKind::Let:
      if (!e.kids.empty()) colours(*e.kids.back());
      return;
    case ExprKind::InitNext:
      colours(*e.kids[0]);
      colours(*e.kids[1]);
      return;
    default:
      return;
  }
}

// ---------------------------------------------------------------------------- statements

void Linter::statements() {
  std::map<std::string, SourceLoc> objects;
  std::set<Sym> classes;
  std::map<Sym, std::string> declared;
  for (const Stmt& st : p_.stmts) {
    if (st.kind == StmtKind::Object) {
      auto [it, fresh] = objects.emplace(st.object_name, st.loc);
      if (!fresh)
        warn(st.loc, "object '" + st.object_name + "' is defined again (first at line " +
                         std::to_string(it->second.line) + "); this definition replaces the earlier one");
      for (const auto& f : st.fields) type_name(f.type, f.loc, classes, true);
      classes.insert(st.object_sym);
    }
    if (st.kind != StmtKind::Expr) continue;
    const Expr& e = *st.expr;
    if (e.kind == ExprKind::TypeDecl) {
      type_name(e.type, e.loc, classes, false);
      if (e.type && !e.type->is_list) declared[e.name] = e.type->name;
    }
    if (e.kind == ExprKind::Assign) declared_value(e, declared);
  }
}

// A global whose name the standard library's functions assign (`let` does not
// make a new name: sqdist's `delta`), or every object's construction (its
// `allCells` temporary, analyse/program.cpp): overwritten whenever they run.
void Linter::clobbered_globals() {
  std::map<Sym, std::string> assigners;
  std::function<void(const Expr&, const std::string&)> walk = [&](const Expr& e, const std::string& who) {
    if (e.kind == ExprKind::Assign) assigners.emplace(e.name, who);
    for (const ExprPtr& k : e.kids)
      if (k) walk(*k, who);
  };
  for (const Stmt& st : p_.stdlib_stmts)
    if (st.kind == StmtKind::Expr && st.expr->kind == ExprKind::Assign && !st.expr->kids.empty() &&
        st.expr->kids[0] && st.expr->kids[0]->kind == ExprKind::Lambda)
      walk(*st.expr->kids[0], "the standard library's '" + p_.name(st.expr->name) + "' runs");
  for (const Stmt& st : p_.stmts)
    if (st.kind == StmtKind::Object && st.constructor_body) walk(*st.constructor_body, "an object is made");
  for (const Stmt& st : p_.stmts) {
    if (st.kind != StmtKind::Expr || st.expr->kind != ExprKind::Assign) continue;
    const auto it = assigners.find(st.expr->name);
    if (it != assigners.end())
      warn(st.expr->loc, "the global '" + p_.name(st.expr->name) + "' is overwritten whenever " + it->second +
                             " (that assigns the name: `let` does not make a new one)");
  }
}

void Linter::type_name(const TypeExprPtr& t, SourceLoc loc, const std::set<Sym>& classes, bool field) {
  if (!t) return;
  if (t->is_list) return type_name(t->elem, loc, classes, field);
  for (const char* b : kBuiltinTypeNames)
    if (t->name == b) return;
  if (t->sym >= 0 && classes.count(t->sym)) return;
  warn(loc, "'" + t->name + "' is not a type (Bool, String, Number, Int, Position, Cell, RenderedElem, or an object "
                            "defined above)" +
                (field ? "; printing an object of this class fails at run time" : std::string()));
}

// A top-level assignment to a name declared (: name Type) with a value whose type
// is proven another: the interpreter refuses the assignment (a runtime error).
// Checked for the value assigned first (initnext's initial value, or the value).
void Linter::declared_value(const Expr& assign, const std::map<Sym, std::string>& declared) {
  auto it = declared.find(assign.name);
  if (it == declared.end()) return;
  const std::string want = it->second == "Int" ? "Number" : it->second;
  const Sym declared_sym = p_.symbols.find(it->second);
  if (!(declared_sym >= 0 && is_type_name(declared_sym))) return;  // not a type: type_name says so
  const Expr& v = assign.kids[0]->kind == ExprKind::InitNext ? *assign.kids[0]->kids[0] : *assign.kids[0];
  const std::optional<std::string> got = static_type(v, true);
  if (got && *got != want && got->front() != '(')
    warn(v.loc, "'" + p_.name(assign.name) + "' is declared " + it->second + " but is given a" +
                    (std::string("AEIOU").find(got->front()) != std::string::npos ? "n " : " ") + *got +
                    "; assigning it is an error at run time");
}

// ---------------------------------------------------------------------------- static types

// The type of every value `e` can evaluate to, when the syntax proves it, in
// shown_type's notation (what the author writes): literals; arithmetic
// (Number); comparisons, equality, not, and, or (Bool); a lambda (Function); a
// construction of a class or Position; a builtin with a fixed result
// (builtins.hpp); an `if` whose branches agree; a name every one of whose
// values (Assignments) has the one type, and (prev name). Otherwise nullopt.
// `top`: e is outside every lambda and object, where a name is the global (or a
// let's); inside, scope is dynamic and any parameter or field of that name
// (the stdlib's `x`, `obj`, ...) may be the one in scope, so such names are not
// typed there.
std::optional<std::string> Linter::static_type(const Expr& e, bool top) {
  switch (e.kind) {
    case ExprKind::Number: return "Number";
    case ExprKind::String: return "String";
    case ExprKind::Bool: return "Bool";
    case ExprKind::Logical: return "Bool";
    case ExprKind::Lambda: return "Function";
    case ExprKind::Unary: return e.unary == UnOp::Not ? "Bool" : "Number";
    case ExprKind::Binary:
      if (e.op == BinOp::Unknown) return std::nullopt;
      return e.op == BinOp::Add || e.op == BinOp::Sub || e.op == BinOp::Mul || e.op == BinOp::Div ||
                     e.op == BinOp::Mod
                 ? "Number"
                 : "Bool";
    case ExprKind::If: {
      if (e.kids.size() < 3) return std::nullopt;
      std::optional<std::string> a = static_type(*e.kids[1], top), b = static_type(*e.kids[2], top);
      return a && a == b ? a : std::nullopt;
    }
    case ExprKind::Var: return name_type(e.name, top);
    case ExprKind::Call: return call_type(e, top);
    default: return std::nullopt;
  }
}

bool Linter::is_type_name(Sym s) const {
  if (classes_.count(s)) return true;
  for (const char* b : kBuiltinTypeNames)
    if (p_.name(s) == b) return true;
  return false;
}

// A name's values are typed as if inside (they may be let's or the stdlib's).
std::optional<std::string> Linter::name_type(Sym s, bool top) {
  if (is_type_name(s) || (!top && a_.otherwise.count(s))) return std::nullopt;  // a type evaluates to itself
  const std::pair<Sym, bool> key{s, top};
  if (auto it = name_types_.find(key); it != name_types_.end()) return it->second;
  name_types_[key] = std::nullopt;  // while its values are typed
  const auto values = a_.values.find(s);
  if (values == a_.values.end() || values->second.empty()) return std::nullopt;
  // A value that is the name itself or its prev adds no type of its own (by
  // induction over the steps it has one of the others'), so (= x (initnext 0
  // (prev x))) is a Number.
  auto is_itself = [&](const Expr& v) {
    if (v.kind == ExprKind::Var) return v.name == s;
    return v.kind == ExprKind::Call && v.kids.size() == 2 && v.kids[0]->kind == ExprKind::Var &&
           p_.builtin_of(v.kids[0]->name) == Builtin::Prev && !b_.other.count(v.kids[0]->name) &&
           v.kids[1]->kind == ExprKind::Var && v.kids[1]->name == s;
  };
  std::optional<std::string> t;
  for (const Expr* v : values->second) {
    if (is_itself(*v)) continue;
    std::optional<std::string> vt = static_type(*v, false);
    if (!vt || (t && vt != t)) return name_types_[key] = std::nullopt;
    t = vt;
  }
  return name_types_[key] = t;
}

std::optional<std::string> Linter::call_type(const Expr& call, bool top) {
  const Expr& callee = *call.kids[0];
  if (callee.kind != ExprKind::Var || b_.other.count(callee.name) || b_.lambda_arity.count(callee.name))
    return std::nullopt;
  if (classes_.count(callee.name) || p_.name(callee.name) == "Position") return p_.name(callee.name);
  const std::optional<Builtin> b = p_.builtin_of(callee.name);
  if (!b) return std::nullopt;
  if (*b == Builtin::Prev)
    return call.kids.size() == 2 && call.kids[1]->kind == ExprKind::Var ? name_type(call.kids[1]->name, top)
                                                                        : std::nullopt;
  if (const char* r = builtin_info(*b).result) return std::string(r);
  return std::nullopt;
}

// An operator whose operand is proven the wrong type: evaluating it is a
// runtime error, always (the interpreter's "binary + needs two numbers").
void Linter::operand_types(const Expr& e) {
  const bool logical_not = e.kind == ExprKind::Unary && e.unary == UnOp::Not;
  if (e.kind == ExprKind::Binary && (e.op == BinOp::Eq || e.op == BinOp::Ne || e.op == BinOp::Unknown)) return;
  const char* want = logical_not ? "Bool" : "Number";
  for (size_t i = 0; i < e.kids.size(); ++i) {
    const std::optional<std::string> t = static_type(*e.kids[i], lambda_depth_ == 0);
    if (!t || *t == want) continue;
    const std::string which = e.kids.size() == 1 ? "its operand" : i == 0 ? "its first operand" : "its second operand";
    warn(e.loc, "'(" + e.text + " ...)' needs " + (e.kind == ExprKind::Binary ? "two numbers" : logical_not ? "a Bool" : "a number") +
                    ", but " + which + " is always " + (std::string("AEIOU").find(t->front()) != std::string::npos ? "an " : "a ") +
                    *t + ": evaluating it is an error at run time");
  }
}

}  // namespace

std::string warnings_as_errors(const std::string& path, size_t count) {
  return path + ": error: " + plural(count, "warning") + " treated as errors (--Werror)";
}

void lint_program(const Program& p, std::vector<std::string>& warnings) {
  Linter(p, warnings).run();
}

}  // namespace autumn
