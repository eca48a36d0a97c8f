// ir_builder — see ir_builder.hpp. Every node, variable and statement lives in
// the module's arena (deques: pointers stay valid while the walk adds more).
#include "compiler/lower/ir_builder.hpp"

#include <algorithm>
#include <utility>

namespace autumn::lower {

bool is_const(const ir::Node* n) {
  if (!n) return false;
  switch (n->op) {
    case ir::Op::Lit: return true;
    case ir::Op::MakePos:
    case ir::Op::MakeElem:
    case ir::Op::MakeList:
      return std::all_of(n->a.begin(), n->a.end(), [](const ir::Node* k) { return is_const(k); });
    default: return false;
  }
}

bool is_stable(const ir::Node* n) {
  if (!n) return true;
  if (n->op == ir::Op::Lit) return true;
  if (n->op == ir::Op::Local) return !n->var->mut;
  if (n->op == ir::Op::Member) return is_stable(n->a[0]);
  return false;
}

IrBuilder::IrBuilder(Module& m, std::function<int()> location) : m_(m), location_(std::move(location)) {}

ir::Node* IrBuilder::node(ir::Op op, TypeP t, std::vector<ir::Node*> a) {
  m_.arena.nodes.emplace_back();
  ir::Node* n = &m_.arena.nodes.back();
  n->op = op;
  n->type = t;
  n->a = std::move(a);
  return n;
}

ir::Node* IrBuilder::lit(TypeP t, int64_t v) {
  ir::Node* n = node(ir::Op::Lit, t);
  n->imm = v;
  return n;
}

ir::Node* IrBuilder::text(const std::string& s) {
  ir::Node* n = node(ir::Op::Text, nullptr);
  n->text = s;
  return n;
}

ir::Node* IrBuilder::local(ir::Var* v) {
  ir::Node* n = node(ir::Op::Local, v->type);
  n->var = v;
  return n;
}

ir::Node* IrBuilder::slot(int s) {
  const ir::Slot& sl = m_.slots[s];
  ir::Node* n = node(sl.kind == ir::Slot::Value || sl.kind == ir::Slot::Prev ? ir::Op::Global : ir::Op::Slot,
                     sl.type ? sl.type : m_.types.bool_());
  n->slot = s;
  return n;
}

ir::Node* IrBuilder::member(ir::Node* base, ir::Member m, TypeP t, int index) {
  ir::Node* n = node(ir::Op::Member, t, {base});
  n->member = m;
  n->index = index;
  return n;
}

ir::Node* IrBuilder::call(ir::Helper h, TypeP t, std::vector<ir::Node*> a) {
  ir::Node* n = node(ir::Op::Call, t, std::move(a));
  n->helper = h;
  switch (h) {
    case ir::Helper::RngNext:
    case ir::Helper::IdTransfer:
    case ir::Helper::DefineGlobal:
    case ir::Helper::EraseGlobal:
    case ir::Helper::OrderKeys:
    case ir::Helper::NoteDrawn:
    case ir::Helper::DrawnKeys:
    case ir::Helper::ClickDefine:
    case ir::Helper::Covered:
    case ir::Helper::SetTriggered:
      ++effects_;
      break;
    default:
      break;
  }
  return n;
}

ir::Var* IrBuilder::var(TypeP t, const std::string& hint) {
  m_.arena.vars.emplace_back();
  ir::Var* v = &m_.arena.vars.back();
  v->id = static_cast<int>(m_.arena.vars.size());
  v->type = t;
  v->hint = hint;
  return v;
}

ir::Stmt* IrBuilder::emit(ir::SK k) {
  m_.arena.stmts.emplace_back();
  ir::Stmt* s = &m_.arena.stmts.back();
  s->k = k;
  // A loop charges the elements it visits where it is (limits.hpp, calls).
  if (k == ir::SK::ForEach || k == ir::SK::ForRange) s->loc = location_();
  attach(s);
  return s;
}

ir::Stmt* IrBuilder::emit_detached(ir::SK k) {
  const bool was = dead_;
  dead_ = true;  // emit() builds it without attaching
  ir::Stmt* s = emit(k);
  dead_ = was;
  return s;
}

void IrBuilder::attach(ir::Stmt* s) {
  if (!dead_) block_->push_back(s);
}

void IrBuilder::emit_set(ir::Node* place, ir::Node* value) {
  if (place->op != ir::Op::Local) ++effects_;
  ir::Stmt* s = emit(ir::SK::Set);
  s->a = place;
  s->b = value;
}

void IrBuilder::emit_eval(ir::Node* n) { emit(ir::SK::Eval)->a = n; }

void IrBuilder::emit_push(ir::Node* list, ir::Node* value) {
  ir::Stmt* s = emit(ir::SK::Push);
  s->a = list;
  s->b = value;
}

ir::Var* IrBuilder::decl(TypeP t, ir::Node* init, const std::string& hint) {
  ir::Var* v = var(t, hint);
  v->mut = true;
  ir::Stmt* s = emit(ir::SK::Decl);
  s->var = v;
  s->a = init;
  return v;
}

void IrBuilder::comment(const std::string& t) { emit(ir::SK::Comment)->text = t; }

void IrBuilder::begin_function(ir::Function* f) {
  fn_ = f;
  block_ = &f->body;
  dead_ = false;
}

void IrBuilder::in_block(ir::Block& b, const std::function<void()>& f) {
  ir::Block* saved = block_;
  const bool was_dead = dead_;
  block_ = &b;
  f();
  block_ = saved;
  dead_ = was_dead;
}

void IrBuilder::restore(const Point& p) {
  fn_ = p.fn;
  block_ = p.block;
  dead_ = p.dead;
}

}  // namespace autumn::lower
