// session_code — the Session calls that run code against the state:
// evaluate_to_string, tmp_execute_stmt and get_environment_string.
//
// The text is parsed with a copy of the program's symbol table, the way the
// reference parses it (the whole reader result: no outer parentheses). The
// interpreter's state is laid out by the program's symbols, so a name the
// program never mentions cannot be bound or looked up: such text is refused
// with a clear error (the reference would report it undefined when evaluated,
// or define it when assigned). Evaluation goes to the interpreter track; an
// evaluation that changed the state (an assignment, a click read, a random
// draw) ends the compiled track, which cannot replay it.
#include <functional>

#include "compiler/parse/parser.hpp"
#include "compiler/read/sexpr.hpp"
#include "python/src/session.hpp"

namespace autumn::py {
namespace {

void check_known_names(const Program& program, const Expr& e) {
  const Sym limit = static_cast<Sym>(program.symbols.size());
  std::function<void(const Expr&)> walk = [&](const Expr& x) {
    auto check = [&](Sym s) {
      if (s >= limit)
        throw std::runtime_error("'" + x.text + "' is not a name of this program: autumnc can only evaluate "
                                 "names the program (or the standard library) mentions");
    };
    check(x.name);
    for (Sym p : x.params) check(p);
    for (const auto& k : x.kids) walk(*k);
  };
  walk(e);
}

}  // namespace

// Throws CompileError for text that does not parse, std::runtime_error for
// names or statements the interpreter cannot take.
void Session::parse_snippet(Snippet& s, bool statement) const {
  SymbolTable symbols = program_->symbols;
  if (!statement) {
    SourceFile file{"<expression>", s.text, SourceId::Trigger};
    Parser parser(file, symbols);
    s.expr = parser.parse_standalone(read_sexprs(file));
    check_known_names(*program_, *s.expr);
    return;
  }
  // The reference parses the reader result itself as one statement; wrapping it
  // as the only statement of a program gives our parser the same list.
  SourceFile file{"<statement>", "(program (\n" + s.text + "\n))", SourceId::Trigger};
  Parser parser(file, symbols);
  ParsedProgram parsed = parser.parse_program(read_sexprs(file));
  if (parsed.stmts.size() != 1) throw std::runtime_error("tmp_execute_stmt: expected one statement");
  s.stmt = std::make_shared<Stmt>(std::move(parsed.stmts[0]));
  const Stmt& st = *s.stmt;
  if (st.kind == StmtKind::Object) throw std::runtime_error("tmp_execute_stmt: autumnc cannot add object classes");
  for (const ExprPtr& e : {st.cond, st.body, st.expr})
    if (e) check_known_names(*program_, *e);
}

std::string Session::evaluate(const std::string& text) {
  check_alive();
  auto snippet = std::make_shared<Snippet>();
  snippet->text = text;
  parse_snippet(*snippet, false);
  InterpTrack& t = interp();
  bool changed = false;
  std::string out;
  try {
    out = t.evaluate(*snippet, &changed);
  } catch (const interp::RuntimeError& e) {
    throw std::runtime_error(t.interpreter().describe(e));
  }
  HostOp op;
  op.kind = HostOp::Eval;
  op.effect = changed;
  op.arg = snippets_->add(snippet);
  log_.push_back(op);
  t.skip();
  sync_compiled();
  return out;
}

std::string Session::execute(const std::string& text) {
  check_alive();
  auto snippet = std::make_shared<Snippet>();
  snippet->text = text;
  parse_snippet(*snippet, true);
  InterpTrack& t = interp();
  try {
    t.execute(*snippet);
  } catch (const interp::RuntimeError& e) {
    throw std::runtime_error("Error in tmpExecuteStmt: " + t.interpreter().describe(e));
  }
  HostOp op;
  op.kind = HostOp::Exec;
  op.arg = snippets_->add(snippet);
  log_.push_back(op);
  t.skip();
  sync_compiled();
  return t.interpreter().environment_string();
}

std::string Session::environment_string() {
  check_alive();
  return interp().interpreter().environment_string();
}

}  // namespace autumn::py
