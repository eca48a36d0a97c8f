#include "compiler/analyse/program.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "compiler/analyse/builtins.hpp"
#include "compiler/analyse/did_you_mean.hpp"
#include "compiler/analyse/lint.hpp"
#include "compiler/analyse/render_order.hpp"
#include "compiler/parse/parser.hpp"
#include "compiler/read/sexpr.hpp"
#include "runtime/limits.hpp"

namespace autumn {
namespace {

// The render method every object class gets (the reference builds it from text
// too). Deferred cell fields are *called*, and `origin`/`elems` are looked up
// dynamically, so they resolve to the instance's fields bound by the method call.
constexpr const char* kRenderMethod =
    "--> () (map (--> e (RenderedElem (Position (+ (.. origin x) ((.. e x))) "
    "(+ (.. origin y) ((.. e y)))) ((.. e color)))) elems)";

ExprPtr var(SymbolTable& syms, const char* n, SourceLoc loc) {
  Expr e{ExprKind::Var, loc};
  e.name = syms.intern(n);
  e.text = n;
  return make_expr(std::move(e));
}

// (fn (f1 ... fn origin) (list f1 ... fn origin (let (= allCells CELLS)
//                                                    (if (isList allCells) then allCells else (list allCells)))))
ExprPtr build_constructor(SymbolTable& syms, const Stmt& obj) {
  SourceLoc loc = obj.cell_expr->loc;
  Expr list{ExprKind::List, loc};
  Expr lambda{ExprKind::Lambda, loc};
  for (const auto& f : obj.fields) {
    lambda.params.push_back(f.name);
    Expr v{ExprKind::Var, loc};
    v.name = f.name;
    v.text = f.name_text;
    list.kids.push_back(make_expr(std::move(v)));
  }
  lambda.params.push_back(syms.intern("origin"));
  list.kids.push_back(var(syms, "origin", loc));
  Expr assign{ExprKind::Assign, loc};
  assign.name = syms.intern("allCells");
  assign.kids.push_back(obj.cell_expr);
  Expr is_list{ExprKind::Call, loc};
  is_list.kids = {var(syms, "isList", loc), var(syms, "allCells", loc)};
  Expr wrap{ExprKind::List, loc};
  wrap.kids = {var(syms, "allCells", loc)};
  Expr cond{ExprKind::If, loc};
  cond.kids = {make_expr(std::move(is_list)), var(syms, "allCells", loc), make_expr(std::move(wrap))};
  Expr let{ExprKind::Let, loc};
  let.kids = {make_expr(std::move(assign)), make_expr(std::move(cond))};
  list.kids.push_back(make_expr(std::move(let)));
  lambda.kids.push_back(make_expr(std::move(list)));
  return make_expr(std::move(lambda));
}

// Names that some construct can bind: assignment targets, parameters, object
// fields and classes, plus everything the runtime defines itself.
void collect_binders(const Expr& e, std::set<Sym>& out) {
  if (e.kind == ExprKind::Assign || e.kind == ExprKind::TypeDecl) out.insert(e.name);
  if (e.kind == ExprKind::Lambda) out.insert(e.params.begin(), e.params.end());
  for (const auto& k : e.kids) collect_binders(*k, out);
}

void check_unbound(const Program& p, const Expr& e, const std::set<Sym>& bound,
                   std::set<Sym>& reported, std::vector<std::string>& warnings) {
  if (e.kind == ExprKind::Var && !bound.count(e.name) && !reported.count(e.name)) {
    reported.insert(e.name);
    std::vector<std::string_view> names;
    for (Sym s : bound) names.push_back(p.name(s));
    std::sort(names.begin(), names.end());  // of equally near names, the first in order
    const auto near = did_you_mean(p.name(e.name), names);
    warnings.push_back(format_diagnostic(p.file_name(e.loc.source), e.loc, "warning",
                                         "'" + p.name(e.name) +
                                             "' is not defined anywhere; evaluating it is a runtime error" +
                                             (near ? "; did you mean '" + std::string(*near) + "'?" : std::string())));
  }
  for (const auto& k : e.kids) check_unbound(p, *k, bound, reported, warnings);
}

// Feeds `order` the globals evaluating `e` at the top level defines, in
// evaluation order: assignments evaluated in the global scope. Let bodies,
// lambda bodies and cell arguments run in scopes of their own; `if` branches and
// the right operand of and/or may not run at all (*conditional is set).
void note_global_definitions(const Expr& e, const Program& p, RenderOrder& order, std::set<Sym>& defined,
                             bool conditional, bool* any_conditional) {
  auto rec = [&](const Expr& k, bool cond) { note_global_definitions(k, p, order, defined, cond, any_conditional); };
  switch (e.kind) {
    case ExprKind::Let:
    case ExprKind::Lambda:
    case ExprKind::InitNext:
    case ExprKind::TypeDecl:
      return;
    case ExprKind::If:
      rec(*e.kids[0], conditional);
      rec(*e.kids[1], true);
      rec(*e.kids[2], true);
      return;
    case ExprKind::Logical:
      rec(*e.kids[0], conditional);
      rec(*e.kids[1], true);
      return;
    case ExprKind::Call:
      if (e.kids[0]->kind == ExprKind::Var && e.kids[0]->name == p.names.Cell) return;
      for (const auto& k : e.kids) rec(*k, conditional);
      return;
    case ExprKind::Assign:
      rec(*e.kids[0], conditional);
      if (defined.count(e.name)) return;
      if (conditional) {
        *any_conditional = true;
        return;
      }
      defined.insert(e.name);
      order.note_definition(e.name);
      return;
    default:
      for (const auto& k : e.kids) rec(*k, conditional);
  }
}

// Program::render_order: what start-up defines, in the order the reference does.
void compute_render_order(Program& p) {
  RenderOrder order(p.symbols.size());
  std::set<Sym> defined;
  auto define = [&](Sym s) {
    if (defined.insert(s).second) order.note_definition(s);
  };
  define(p.names.GRID_SIZE);
  for (Sym s : p.builtin_syms) define(s);
  bool conditional = false;
  for (const Stmt& st : p.stdlib_stmts)
    if (st.kind == StmtKind::Expr) note_global_definitions(*st.expr, p, order, defined, false, &conditional);
  define(p.names.SpecialConditionTriggered);
  for (const Stmt& st : p.stmts) {
    if (st.kind != StmtKind::Expr) continue;
    const Expr& e = *st.expr;
    if (e.kind == ExprKind::Assign && e.kids[0]->kind == ExprKind::InitNext) order.note_initnext(e.name);
    else note_global_definitions(e, p, order, defined, false, &conditional);
  }
  define(p.names.cacheRendered);  // by the render that ends start-up
  p.render_order = order.order();
  p.start_defines_conditionally = conditional;
}

// Program::definitions: top-level assignments first, then any assignment, each
// pass over the program and then the stdlib, in source order.
void compute_definitions(Program& p) {
  p.definitions.assign(p.symbols.size(), SourceLoc{});
  auto note = [&](Sym s, SourceLoc at) {
    if (p.definitions[s].line == 0) p.definitions[s] = at;
  };
  std::function<void(const Expr&)> anywhere = [&](const Expr& e) {
    if (e.kind == ExprKind::Assign) note(e.name, e.loc);
    for (const auto& k : e.kids) anywhere(*k);
  };
  for (const auto* stmts : {&p.stmts, &p.stdlib_stmts})
    for (const Stmt& st : *stmts)
      if (st.kind == StmtKind::Expr && st.expr->kind == ExprKind::Assign) note(st.expr->name, st.expr->loc);
  for (const auto* stmts : {&p.stmts, &p.stdlib_stmts})
    for (const Stmt& st : *stmts)
      for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr})
        if (e) anywhere(*e);
}

// A top-level (= GRID_SIZE literal) outside the paintable range is refused when
// the program is loaded, at the definition (so autumnc refuses it too). Computed
// values are checked at every render (the interpreter and compiled modules).
void check_grid_size(const Program& p) {
  for (const Stmt& st : p.stmts) {
    if (st.kind != StmtKind::Expr || st.expr->kind != ExprKind::Assign || st.expr->name != p.names.GRID_SIZE) continue;
    const Expr& v = *st.expr->kids[0];
    std::string why;
    if (v.kind == ExprKind::Number) {
      why = limits::grid_size_error(v.number);
    } else if (v.kind == ExprKind::Unary && v.unary == UnOp::Neg && v.kids[0]->kind == ExprKind::Number) {
      why = limits::grid_size_error(-static_cast<int64_t>(v.kids[0]->number));
    } else if (v.kind == ExprKind::String || v.kind == ExprKind::Bool || v.kind == ExprKind::List ||
               v.kind == ExprKind::Lambda) {
      why = limits::grid_size_type_error(v.kind == ExprKind::String ? "String"
                                         : v.kind == ExprKind::Bool ? "Bool"
                                         : v.kind == ExprKind::List ? "list"
                                                                    : "function");
    }
    if (!why.empty()) throw CompileError(p.file.name, st.expr->loc, why);
  }
}

}  // namespace

const std::string& Program::file_name(SourceId id) const {
  static const std::string trigger_name = "<trigger>", internal = "<internal>";
  switch (id) {
    case SourceId::Program: return file.name;
    case SourceId::Stdlib: return stdlib.name;
    case SourceId::Trigger: return trigger_name;
    case SourceId::Internal: return internal;
  }
  return internal;
}

namespace {

// The names every program interns first, in this order, so that builtin and
// prelude symbol ids are the same in every Program (the stdlib parse below
// relies on it). Interning is idempotent: a second call only fills p.names.
void intern_prelude(Program& p) {
  SymbolTable& syms = p.symbols;
  // Builtins and their global order come first so that symbol ids are stable.
  syms.intern("GRID_SIZE");
  for (int i = 0; i < kBuiltinCount; ++i) p.builtin_syms[i] = syms.intern(builtin_table()[i].name);
  auto& n = p.names;
  n.GRID_SIZE = syms.intern("GRID_SIZE");
  n.FRAME_RATE = syms.intern("FRAME_RATE");
  n.background = syms.intern("background");
  n.SpecialConditionTriggered = syms.intern("SpecialConditionTriggered");
  n.cacheRendered = syms.intern("cacheRendered");
  n.click = syms.intern("click");
  n.allCells = syms.intern("allCells");
  n.isList = syms.intern("isList");
  n.origin = syms.intern("origin");
  n.elems = syms.intern("elems");
  n.x = syms.intern("x");
  n.y = syms.intern("y");
  n.color = syms.intern("color");
  n.position = syms.intern("position");
  n.render = syms.intern("render");
  n.e = syms.intern("e");
  n.Bool = syms.intern("Bool");
  n.String = syms.intern("String");
  n.Number = syms.intern("Number");
  n.Int = syms.intern("Int");
  n.Position = syms.intern("Position");
  n.Cell = syms.intern("Cell");
  n.RenderedElem = syms.intern("RenderedElem");

}

// The default stdlib parsed once per process, after the prelude: its symbol
// table and statements are the start of every program loaded without a
// stdlib override. Statements hold shared immutable expressions, so copies share
// them. Thread-safe (static initialisation).
const Program& default_stdlib_parse() {
  static const Program parsed = [] {
    Program p;
    p.stdlib = SourceFile{"<stdlib>", stdlib_text(), SourceId::Stdlib};
    intern_prelude(p);
    Parser parser(p.stdlib, p.symbols);
    p.stdlib_stmts = parser.parse_program(read_sexprs(p.stdlib)).stmts;
    return p;
  }();
  return parsed;
}

}  // namespace

namespace {

// The standard library (the default one's parse reused), the program, the
// trigger and the internal render method, parsed into `p`.
void parse_sources(Program& p, const std::optional<std::string>& trigger, const std::optional<std::string>& stdlib) {
  SymbolTable& syms = p.symbols;
  if (stdlib) {
    intern_prelude(p);
    Parser parser(p.stdlib, syms);
    p.stdlib_stmts = parser.parse_program(read_sexprs(p.stdlib)).stmts;
  } else {
    // The default stdlib parses the same way every time: start from its parse.
    const Program& cached = default_stdlib_parse();
    syms = cached.symbols;
    p.stdlib_stmts = cached.stdlib_stmts;
    // The same table, so the same ids: copied, not looked up again (a hundred
    // lookups were a fifth of a small program's load under the sanitizers).
    p.builtin_syms = cached.builtin_syms;
    p.names = cached.names;
  }
  {
    Parser parser(p.file, syms);
    ParsedProgram parsed = parser.parse_program(read_sexprs(p.file));
    p.stmts = std::move(parsed.stmts);
    p.warnings = std::move(parsed.warnings);
  }
  if (trigger && !trigger->empty()) {
    SourceFile tf{"<trigger>", *trigger, SourceId::Trigger};
    Parser parser(tf, syms);
    p.trigger = parser.parse_standalone(read_sexprs(tf));
    p.trigger_text = *trigger;
  }
  {
    SourceFile rf{"<internal>", kRenderMethod, SourceId::Internal};
    Parser parser(rf, syms);
    p.render_lambda = parser.parse_standalone(read_sexprs(rf));
  }
  for (auto& st : p.stmts)
    if (st.kind == StmtKind::Object) st.constructor_body = build_constructor(syms, st);
}

// Unbound-name warnings (user program only): a name no definition, parameter,
// field or builtin binds anywhere.
void warn_unbound(Program& p) {
  SymbolTable& syms = p.symbols;
  std::set<Sym> bound(p.builtin_syms.begin(), p.builtin_syms.end());
  for (const char* b : kBuiltinTypeNames) bound.insert(syms.intern(b));
  for (const char* b : {"GRID_SIZE", "SpecialConditionTriggered", "cacheRendered", "click", "origin", "elems",
                        "allCells"})
    bound.insert(syms.intern(b));
  auto binders_of = [&](const std::vector<Stmt>& stmts) {
    for (const auto& st : stmts) {
      if (st.kind == StmtKind::Object) {
        bound.insert(st.object_sym);
        Sym truncated = syms.find(st.object_name);
        if (truncated >= 0) bound.insert(truncated);
        for (const auto& f : st.fields) bound.insert(f.name);
        collect_binders(*st.cell_expr, bound);
      } else if (st.kind == StmtKind::On) {
        collect_binders(*st.cond, bound);
        collect_binders(*st.body, bound);
      } else {
        collect_binders(*st.expr, bound);
      }
    }
  };
  binders_of(p.stdlib_stmts);
  binders_of(p.stmts);
  if (p.trigger) collect_binders(*p.trigger, bound);
  std::set<Sym> reported;
  for (const auto& st : p.stmts) {
    if (st.kind == StmtKind::Object) check_unbound(p, *st.cell_expr, bound, reported, p.warnings);
    if (st.kind == StmtKind::On) {
      check_unbound(p, *st.cond, bound, reported, p.warnings);
      check_unbound(p, *st.body, bound, reported, p.warnings);
    }
    if (st.kind == StmtKind::Expr) check_unbound(p, *st.expr, bound, reported, p.warnings);
  }
  if (p.trigger) check_unbound(p, *p.trigger, bound, reported, p.warnings);
}

// Whether the program (or its trigger) mentions a builtin that draws random numbers.
bool mentions_random(const Program& p) {
  std::function<bool(const Expr&)> mentions_rng = [&](const Expr& e) {
    if (e.kind == ExprKind::Var)
      if (auto b = p.builtin_of(e.name); b && (builtin_info(*b).effects & kDrawsRandom)) return true;
    for (const auto& k : e.kids)
      if (mentions_rng(*k)) return true;
    return false;
  };
  bool uses = p.trigger && mentions_rng(*p.trigger);
  for (const auto& st : p.stmts) {
    for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr})
      if (e && mentions_rng(*e)) uses = true;
  }
  return uses;
}

}  // namespace

std::shared_ptr<const Program> load_program(SourceFile file, const std::optional<std::string>& trigger,
                                            const std::optional<std::string>& stdlib) {
  auto p = std::make_shared<Program>();
  p->file = std::move(file);
  p->file.id = SourceId::Program;
  p->stdlib = SourceFile{"<stdlib>", stdlib ? *stdlib : stdlib_text(), SourceId::Stdlib};
  parse_sources(*p, trigger, stdlib);
  warn_unbound(*p);
  lint_program(*p, p->warnings);
  check_grid_size(*p);
  compute_definitions(*p);
  compute_render_order(*p);
  p->uses_random = mentions_random(*p);
  return p;
}

std::string read_program_text(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw CompileError(path, SourceLoc{0, 0}, "is a folder, not a program file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CompileError(path, SourceLoc{0, 0}, "cannot open file");
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

std::shared_ptr<const Program> load_program_file(const std::string& path,
                                                 const std::optional<std::string>& trigger) {
  return load_program(SourceFile{path, read_program_text(path), SourceId::Program}, trigger);
}

}  // namespace autumn
