// facts — see facts.hpp.
#include "compiler/lower/facts.hpp"

#include "runtime/hash_order.hpp"

namespace autumn::lower {
namespace {

void collect_assigned(const Expr& e, std::set<Sym>& out) {
  if (e.kind == ExprKind::Assign) out.insert(e.name);
  for (const auto& k : e.kids) collect_assigned(*k, out);
}

std::string cpp_ident(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

bool is_initnext(const Stmt& st) {
  return st.kind == StmtKind::Expr && st.expr->kind == ExprKind::Assign && st.expr->kids[0]->kind == ExprKind::InitNext;
}

}  // namespace

Facts program_facts(const Program& p) {
  Facts f;
  f.class_of_sym.assign(p.symbols.size(), -1);
  for (const Stmt& st : p.stmts) {
    if (st.kind == StmtKind::On) f.on_clauses.push_back(&st);
    if (st.kind != StmtKind::Object) continue;
    ClassInfo c;
    c.name = st.object_name;
    c.cpp = "C" + std::to_string(f.classes.size()) + "_" + cpp_ident(st.object_name);
    c.sym = st.object_sym;
    c.stmt = &st;
    for (const auto& field : st.fields) {
      c.fields.push_back(field.name);
      c.field_names.push_back(field.name_text);
    }
    c.field_types.assign(c.fields.size(), nullptr);
    f.class_of_sym[st.object_sym] = static_cast<int>(f.classes.size());  // a later definition wins
    f.classes.push_back(std::move(c));
  }
  for (const std::vector<Stmt>* stmts : {&p.stdlib_stmts, &p.stmts})
    for (const Stmt& st : *stmts)
      for (const ExprPtr& e : {st.cell_expr, st.cond, st.body, st.expr})
        if (e) collect_assigned(*e, f.assigned);
  if (p.trigger) collect_assigned(*p.trigger, f.assigned);
  HashOrder order;  // a second registration of a name keeps its place
  for (const Stmt& st : p.stmts)
    if (is_initnext(st)) order.insert(st.expr->name, p.symbols.hash(st.expr->name));
  for (int s : order.order()) f.initnext_order.push_back(s);
  for (const Stmt& st : p.stdlib_stmts)
    if (st.kind == StmtKind::Expr && st.expr->kind == ExprKind::Assign && p.name(st.expr->name) == "renderValue")
      f.stdlib_render_value = st.expr->kids[0].get();
  return f;
}

}  // namespace autumn::lower
