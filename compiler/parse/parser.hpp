// parser — s-expressions to AST (pass 2: parse).
//
// Follows the reference parser's dispatch exactly (see token.hpp for how atoms
// are classified by their first token): `(: n T)`, `let`, positional `if`
// (children 1, 3, 5; `then`/`else` are never checked), binary operators with
// exactly three children, `and`/`or`/`&`/`|`/`&&`/`||` (only `or` and `|` mean OR),
// unary `- + !`, `initnext`, `=` (variable or field target), `..`, literals,
// `fn`/`-->` lambdas, `list`, variables, calls. `(f)` is the variable f, not a call.
// Where the reference would crash or throw an opaque std exception, we throw a
// CompileError at the offending form instead.
#pragma once
#include <string>
#include <vector>

#include "compiler/parse/ast.hpp"
#include "compiler/parse/token.hpp"
#include "compiler/read/sexpr.hpp"

namespace autumn {

struct ParsedProgram {
  std::vector<Stmt> stmts;
  std::vector<std::string> warnings;  // formatted diagnostics
};

class Parser {
 public:
  Parser(const SourceFile& file, SymbolTable& symbols) : file_(file), symbols_(symbols) {}

  // The first top-level form is the program; its children from index 1 are
  // statements. Later forms are ignored (with a warning), as in the reference.
  ParsedProgram parse_program(const Sexp& root);
  // A trigger condition or other standalone expression: the *whole* reader result
  // is parsed as one expression, so its text omits the outer parentheses.
  ExprPtr parse_standalone(const Sexp& root);
  ExprPtr parse_expr(const Sexp& s);

 private:
  [[noreturn]] void fail(const Sexp& at, const std::string& msg) const;
  const Sexp& child(const Sexp& s, size_t i, const char* what) const;
  Stmt parse_stmt(const Sexp& s);
  Stmt parse_object(const Sexp& s);
  ExprPtr parse_type_decl(const Sexp& s);
  TypeExprPtr parse_type(const Sexp& s);
  ExprPtr parse_function(const Sexp& s);
  ExprPtr parse_unary(const Sexp& s, const Sexp& head);
  ExprPtr parse_computed_call(const Sexp& s, const Sexp& head);
  ExprPtr parse_operator(const Sexp& s, const Sexp& head, const Token& tok);
  ExprPtr parse_assignment(const Sexp& s);
  ExprPtr parse_get(const Sexp& s);
  ExprPtr parse_named(const Sexp& s, const Sexp& head, const Token& tok, size_t n);
  int32_t parse_int(const Sexp& at, const std::string& digits) const;
  std::vector<ExprPtr> parse_rest(const Sexp& s, size_t from);
  ExprPtr make_call(Expr call);
  void collect_names(const Expr& e, std::vector<Sym>& out);

  const SourceFile& file_;
  SymbolTable& symbols_;
};

}  // namespace autumn
