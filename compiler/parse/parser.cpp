#include "compiler/parse/parser.hpp"

#include <algorithm>
#include <climits>

#include "compiler/parse/token.hpp"

namespace autumn {
namespace {

bool is_binary(Tok t) {
  switch (t) {
    case Tok::Plus: case Tok::Minus: case Tok::Star: case Tok::Slash: case Tok::EqualEqual:
    case Tok::BangEqual: case Tok::Greater: case Tok::GreaterEqual: case Tok::Less:
    case Tok::LessEqual: case Tok::Modulo:
      return true;
    default:
      return false;
  }
}

BinOp binop_of(Tok t) {
  switch (t) {
    case Tok::Plus: return BinOp::Add;
    case Tok::Minus: return BinOp::Sub;
    case Tok::Star: return BinOp::Mul;
    case Tok::Slash: return BinOp::Div;
    case Tok::Modulo: return BinOp::Mod;
    case Tok::EqualEqual: return BinOp::Eq;
    case Tok::BangEqual: return BinOp::Ne;
    case Tok::Less: return BinOp::Lt;
    case Tok::LessEqual: return BinOp::Le;
    case Tok::Greater: return BinOp::Gt;
    case Tok::GreaterEqual: return BinOp::Ge;
    default: return BinOp::Unknown;
  }
}

}  // namespace

void Parser::fail(const Sexp& at, const std::string& msg) const {
  throw CompileError(file_.name, at.loc, msg);
}

const Sexp& Parser::child(const Sexp& s, size_t i, const char* what) const {
  if (!s.is_list || i >= s.items.size()) {
    std::string form = sexp_snippet(s);
    throw CompileError(file_.name, s.loc, std::string("missing ") + what + " in '" + form + "'");
  }
  return s.items[i];
}

int32_t Parser::parse_int(const Sexp& at, const std::string& lexeme) const {
  // std::stoi semantics: leading digits only ("4.9" is 4); out of int range fails.
  long long v = 0;
  for (char c : lexeme) {
    if (c < '0' || c > '9') break;
    v = v * 10 + (c - '0');
    if (v > INT_MAX) fail(at, "integer literal '" + lexeme + "' is out of the 32-bit range");
  }
  return static_cast<int32_t>(v);
}

std::vector<ExprPtr> Parser::parse_rest(const Sexp& s, size_t from) {
  std::vector<ExprPtr> out;
  if (!s.is_list) return out;
  for (size_t i = from; i < s.items.size(); ++i) out.push_back(parse_expr(s.items[i]));
  return out;
}

// The reference captures, for a Cell construction, every name its arguments
// mention: variables, and the *raw* field names of `..` forms. Assignment targets,
// field-set targets and lambda parameters are not collected.
void Parser::collect_names(const Expr& e, std::vector<Sym>& out) {
  switch (e.kind) {
    case ExprKind::Var: out.push_back(e.name); return;
    case ExprKind::Get:
      out.push_back(symbols_.intern(e.text));
      collect_names(*e.kids[0], out);
      return;
    case ExprKind::Assign: collect_names(*e.kids[0], out); return;
    case ExprKind::Set: collect_names(*e.kids[1], out); return;
    case ExprKind::Lambda: collect_names(*e.kids[0], out); return;
    case ExprKind::TypeDecl: return;
    default:
      for (const auto& k : e.kids) collect_names(*k, out);
  }
}

ExprPtr Parser::make_call(Expr call) {
  const Expr& callee = *call.kids[0];
  if (callee.kind == ExprKind::Var && symbols_.name(callee.name) == "Cell") {
    for (size_t i = 1; i < call.kids.size(); ++i) collect_names(*call.kids[i], call.cell_names);
    std::sort(call.cell_names.begin(), call.cell_names.end());
    call.cell_names.erase(std::unique(call.cell_names.begin(), call.cell_names.end()), call.cell_names.end());
  }
  return make_expr(std::move(call));
}

ParsedProgram Parser::parse_program(const Sexp& root) {
  ParsedProgram out;
  if (root.items.empty()) fail(root, "empty program: expected (program ...)");
  const Sexp& prog = root.items[0];
  if (!prog.is_list) fail(prog, "a program must be a list of statements, got '" + prog.text + "'");
  if (root.items.size() > 1)
    out.warnings.push_back(format_diagnostic(
        file_.name, root.items[1].loc, "warning",
        "text after the first top-level form is ignored (the reference reads only the first form)"));
  for (size_t i = 1; i < prog.items.size(); ++i) out.stmts.push_back(parse_stmt(prog.items[i]));
  return out;
}

ExprPtr Parser::parse_standalone(const Sexp& root) {
  if (root.items.empty()) fail(root, "empty expression");
  return parse_expr(root);
}

Stmt Parser::parse_stmt(const Sexp& s) {
  if (!s.is_list) fail(s, "a statement must be a list, got the atom '" + s.text + "'");
  if (s.items.empty()) fail(s, "empty statement '()'");
  const Sexp& head = s.items[0];
  if (head.is_list) fail(head, "a statement must start with a name, not a list");
  Tok t = lex_atom(head.text)[0].type;
  if (t == Tok::Object) return parse_object(s);
  Stmt st;
  st.loc = s.loc;
  if (t == Tok::On) {
    st.kind = StmtKind::On;
    st.cond = parse_expr(child(s, 1, "condition of 'on'"));
    st.body = parse_expr(child(s, 2, "body of 'on'"));
    return st;
  }
  st.kind = StmtKind::Expr;
  st.expr = parse_expr(s);
  return st;
}

Stmt Parser::parse_object(const Sexp& s) {
  Stmt st;
  st.kind = StmtKind::Object;
  st.loc = s.loc;
  const Sexp& name = child(s, 1, "object name");
  if (name.is_list) fail(name, "an object name must be an atom");
  st.object_name = name.text;
  st.object_sym = symbols_.intern(name.text);
  for (size_t i = 2; i < s.items.size(); ++i) {
    ExprPtr e = parse_expr(s.items[i]);
    if (e->kind == ExprKind::TypeDecl) {
      st.fields.push_back({e->name, symbols_.name(e->name), e->type, e->loc});
    } else {
      st.cell_expr = e;  // the last non-declaration item wins
    }
  }
  if (!st.cell_expr) fail(s, "object '" + name.text + "' has no cell expression");
  return st;
}

TypeExprPtr Parser::parse_type(const Sexp& s) {
  const Sexp* head = &s;
  if (s.is_list) {
    if (s.items.empty()) fail(s, "empty type '()'");
    head = &s.items[0];
  }
  if (head->is_list) fail(*head, "invalid type expression");
  Token tok = lex_atom(head->text)[0];
  if (tok.type != Tok::Identifier)
    fail(*head, "a type must be an identifier, got " + std::string(tok_name(tok.type)));
  if (tok.lexeme == "updateObj") fail(*head, "updateObj is not a type");
  if (tok.lexeme == "Union") fail(*head, "union types are not supported");
  auto t = std::make_shared<TypeExpr>();
  if (tok.lexeme == "List") {
    t->is_list = true;
    t->elem = parse_type(child(s, 1, "element type of List"));
    return t;
  }
  t->name = head->text;  // raw: the reference resolves the untruncated atom text
  t->sym = symbols_.intern(head->text);
  return t;
}

ExprPtr Parser::parse_type_decl(const Sexp& s) {
  const Sexp& name = child(s, 1, "name in type declaration");
  Token tok = lex_atom(name.is_list ? "" : name.text)[0];
  if (tok.type != Tok::Identifier)
    fail(name, "a declared name must be an identifier, got " + std::string(tok_name(tok.type)));
  Expr e{ExprKind::TypeDecl, s.loc};
  e.name = symbols_.intern(tok.lexeme);
  e.type = parse_type(child(s, 2, "type in type declaration"));
  return make_expr(std::move(e));
}

ExprPtr Parser::parse_function(const Sexp& s) {
  Expr e{ExprKind::Lambda, s.loc};
  const Sexp& params = child(s, 1, "parameters of function");
  if (!params.is_list || params.items.empty()) {
    Token p = lex_atom(params.is_list ? "" : params.text)[0];
    const Sexp& body = child(s, 2, "body of function");
    if (p.type != Tok::Eof) {
      if (p.type != Tok::Identifier)
        fail(params, "a function parameter must be an identifier, got " + std::string(tok_name(p.type)));
      e.params.push_back(symbols_.intern(p.lexeme));
    }
    e.kids.push_back(parse_expr(body));
    return make_expr(std::move(e));
  }
  for (const Sexp& p : params.items) {
    Token t = lex_atom(p.is_list ? "" : p.text)[0];
    if (t.type != Tok::Identifier)
      fail(p, "a function parameter must be an identifier, got " + std::string(tok_name(t.type)));
    e.params.push_back(symbols_.intern(t.lexeme));
  }
  e.kids.push_back(parse_expr(child(s, 2, "body of function")));
  return make_expr(std::move(e));
}

ExprPtr Parser::parse_unary(const Sexp& s, const Sexp& head) {
  Expr e{ExprKind::Unary, s.loc};
  if (s.child_count() == 1) {
    // "-3" / "+3" / "!x" as a single atom: the operator applies to the integer
    // parsed from the *second* token. A one-element list such as (-3) has no
    // atom text at all in the reference and fails the same way.
    std::vector<Token> toks = lex_atom(s.is_list ? "" : s.text);
    if (toks.size() < 2 || toks[1].type != Tok::Number)
      fail(s, "'" + sexp_snippet(s) + "' is not a number: an operator atom needs an integer after it");
    e.unary = toks[0].type == Tok::Minus ? UnOp::Neg : toks[0].type == Tok::Plus ? UnOp::Plus : UnOp::Not;
    e.text = toks[0].lexeme;
    Expr lit{ExprKind::Number, s.loc};
    lit.number = parse_int(s, toks[1].lexeme);
    e.kids.push_back(make_expr(std::move(lit)));
    return make_expr(std::move(e));
  }
  Token t = lex_atom(head.text)[0];
  e.unary = t.type == Tok::Minus ? UnOp::Neg : t.type == Tok::Plus ? UnOp::Plus : UnOp::Not;
  e.text = t.lexeme;
  e.kids.push_back(parse_expr(s.items[1]));
  return make_expr(std::move(e));
}

// A call whose callee is itself a form: ((.. obj f) x) or ((f) x).
ExprPtr Parser::parse_computed_call(const Sexp& s, const Sexp& head) {
  ExprPtr callee = parse_expr(head);
  if (callee->kind != ExprKind::Var && callee->kind != ExprKind::Get)
    fail(head, "only a name or a field access can be called, not '" + sexp_snippet(head) + "'");
  Expr e{ExprKind::Call, s.loc};
  e.kids.push_back(callee);
  for (auto& a : parse_rest(s, 1)) e.kids.push_back(a);
  return make_call(std::move(e));
}

// (OP a b): arithmetic and comparison, or the logical & and |.
ExprPtr Parser::parse_operator(const Sexp& s, const Sexp& head, const Token& tok) {
  if (is_binary(tok.type)) {
    Expr e{ExprKind::Binary, s.loc};
    e.text = head.text;
    e.op = binop_of(whole_token_type(head.text));
    e.kids = {parse_expr(s.items[1]), parse_expr(s.items[2])};
    return make_expr(std::move(e));
  }
  Expr e{ExprKind::Logical, s.loc};
  e.text = head.text;
  e.is_or = whole_token_type(head.text) == Tok::Or;  // so `||` behaves as AND
  e.kids = {parse_expr(s.items[1]), parse_expr(s.items[2])};
  return make_expr(std::move(e));
}

// (= x v) assigns a variable, (= (.. o f) v) a field.
ExprPtr Parser::parse_assignment(const Sexp& s) {
  ExprPtr lhs = parse_expr(child(s, 1, "target of '='"));
  ExprPtr rhs = parse_expr(child(s, 2, "value of '='"));
  if (lhs->kind == ExprKind::Var) {
    Expr e{ExprKind::Assign, s.loc};
    e.name = lhs->name;
    e.kids = {rhs};
    return make_expr(std::move(e));
  }
  if (lhs->kind == ExprKind::Get) {
    Expr e{ExprKind::Set, s.loc};
    e.name = lhs->name;
    e.text = lhs->text;
    e.kids = {lhs->kids[0], rhs};
    return make_expr(std::move(e));
  }
  fail(s.items[1], "the target of '=' must be a variable or a field (.. obj f)");
}

// (.. obj field)
ExprPtr Parser::parse_get(const Sexp& s) {
  Expr e{ExprKind::Get, s.loc};
  e.kids = {parse_expr(child(s, 1, "object of '..'"))};
  const Sexp& f = child(s, 2, "field name of '..'");
  e.text = f.is_list ? "" : f.text;
  // Field names are normalised at lookup: a leading quote and the last
  // character are dropped, so (.. o "x") is (.. o x).
  std::string norm = e.text;
  if (!norm.empty() && (norm[0] == '"' || norm[0] == '\'')) norm = norm.substr(1, norm.size() - 2);
  e.name = symbols_.intern(norm);
  return make_expr(std::move(e));
}

// A name alone is a variable; (list ...) a list; (name args...) a call.
ExprPtr Parser::parse_named(const Sexp& s, const Sexp& head, const Token& tok, size_t n) {
  if (tok.lexeme == "list") {
    Expr e{ExprKind::List, s.loc};
    e.kids = parse_rest(s, 1);
    return make_expr(std::move(e));
  }
  Expr var{ExprKind::Var, head.loc};
  var.name = symbols_.intern(tok.lexeme);
  var.text = tok.lexeme;
  if (n == 1) return make_expr(std::move(var));
  Expr call{ExprKind::Call, s.loc};
  call.kids.push_back(make_expr(std::move(var)));
  for (auto& a : parse_rest(s, 1)) call.kids.push_back(a);
  return make_call(std::move(call));
}

ExprPtr Parser::parse_expr(const Sexp& s) {
  if (s.is_list && s.items.empty()) fail(s, "empty list '()' is not an expression");
  const Sexp& head = s.is_list ? s.items[0] : s;
  if (head.is_list) return parse_computed_call(s, head);
  Token tok = lex_atom(head.text)[0];
  const size_t n = s.child_count();
  switch (tok.type) {
    case Tok::Colon:
      return parse_type_decl(s);
    case Tok::Let: {
      Expr e{ExprKind::Let, s.loc};
      e.kids = parse_rest(s, 1);
      return make_expr(std::move(e));
    }
    case Tok::If: {
      Expr e{ExprKind::If, s.loc};
      if (!s.is_list || s.items.size() < 6)
        fail(s, "'if' needs the form (if COND then A else B)");
      e.kids = {parse_expr(s.items[1]), parse_expr(s.items[3]), parse_expr(s.items[5])};
      return make_expr(std::move(e));
    }
    default:
      break;
  }
  if ((is_binary(tok.type) || tok.type == Tok::And || tok.type == Tok::Or) && n == 3)
    return parse_operator(s, head, tok);
  if ((tok.type == Tok::Minus || tok.type == Tok::Plus || tok.type == Tok::Bang) && n <= 2)
    return parse_unary(s, head);
  switch (tok.type) {
    case Tok::InitNext: {
      Expr e{ExprKind::InitNext, s.loc};
      e.kids = {parse_expr(child(s, 1, "initial value of initnext")),
                parse_expr(child(s, 2, "next value of initnext"))};
      return make_expr(std::move(e));
    }
    case Tok::Equal:
      return parse_assignment(s);
    case Tok::DotDot:
      return parse_get(s);
    case Tok::Number: {
      Expr e{ExprKind::Number, s.loc};
      e.number = parse_int(head, tok.lexeme);
      return make_expr(std::move(e));
    }
    case Tok::String: {
      Expr e{ExprKind::String, s.loc};
      e.text = tok.lexeme;
      return make_expr(std::move(e));
    }
    case Tok::Fn:
    case Tok::MapTo:
      return parse_function(s);
    case Tok::True:
    case Tok::False: {
      Expr e{ExprKind::Bool, s.loc};
      e.boolean = tok.type == Tok::True;
      return make_expr(std::move(e));
    }
    case Tok::Identifier:
      return parse_named(s, head, tok, n);
    default:
      break;
  }
  if (tok.type == Tok::Eof)
    fail(head, "'" + head.text + "' is not an expression (no identifier, number or operator in it)");
  if (is_binary(tok.type) || tok.type == Tok::And || tok.type == Tok::Or)
    fail(head, "unexpected '" + head.text + "' with " + std::to_string(n - 1) +
                   " operand(s): operators take exactly two operands (or one, for - + !)");
  fail(head, std::string("unexpected ") + tok_name(tok.type) + " in expression '" + sexp_snippet(s) + "'");
}

}  // namespace autumn
