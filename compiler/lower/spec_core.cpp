// spec_core — the IR builder the specialiser emits with, error locations, the
// reference's type strings, and the driver that repeats the walk until the type
// hints settle (see specialise.hpp).
//
// Dead code: after a statement that certainly raises an error (an undefined
// name, a type error the types already prove), the rest of the block never
// runs. `dead_` is set, statements are still built but not attached, and values
// have type Never, which fits every slot. Blocks restore the flag of their parent.
#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "compiler/lower/specialise.hpp"
#include "runtime/limits.hpp"

namespace autumn::lower {

Specialiser::Specialiser(const Program& p, const Facts& f, Module& m, Hints& h) : p_(p), m_(m), h_(h), f_(f) {}

// ---------------------------------------------------------------------------
// Builder

ir::Node* Specialiser::node(ir::Op op, TypeP t, std::vector<ir::Node*> a) {
  m_.arena.nodes.emplace_back();
  ir::Node* n = &m_.arena.nodes.back();
  n->op = op;
  n->type = t;
  n->a = std::move(a);
  return n;
}

ir::Node* Specialiser::lit(TypeP t, int64_t v) {
  ir::Node* n = node(ir::Op::Lit, t);
  n->imm = v;
  return n;
}

ir::Node* Specialiser::text(const std::string& s) {
  ir::Node* n = node(ir::Op::Text, nullptr);
  n->text = s;
  return n;
}

ir::Node* Specialiser::local(ir::Var* v) {
  ir::Node* n = node(ir::Op::Local, v->type);
  n->var = v;
  return n;
}

ir::Node* Specialiser::slot(int s) {
  const ir::Slot& sl = m_.slots[s];
  ir::Node* n = node(sl.kind == ir::Slot::Value || sl.kind == ir::Slot::Prev ? ir::Op::Global : ir::Op::Slot,
                     sl.type ? sl.type : T().bool_());
  n->slot = s;
  return n;
}

ir::Node* Specialiser::member(ir::Node* base, ir::Member m, TypeP t, int index) {
  ir::Node* n = node(ir::Op::Member, t, {base});
  n->member = m;
  n->index = index;
  return n;
}

ir::Node* Specialiser::call(ir::Helper h, TypeP t, std::vector<ir::Node*> a) {
  ir::Node* n = node(ir::Op::Call, t, std::move(a));
  n->helper = h;
  switch (h) {
    case ir::Helper::RngNext:
    case ir::Helper::IdTransfer:
    case ir::Helper::DefineGlobal:
    case ir::Helper::EraseGlobal:
    case ir::Helper::OrderKeys:
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

ir::Var* Specialiser::var(TypeP t, const std::string& hint) {
  m_.arena.vars.emplace_back();
  ir::Var* v = &m_.arena.vars.back();
  v->id = static_cast<int>(m_.arena.vars.size());
  v->type = t;
  v->hint = hint;
  return v;
}

ir::Stmt* Specialiser::emit(ir::SK k) {
  m_.arena.stmts.emplace_back();
  ir::Stmt* s = &m_.arena.stmts.back();
  s->k = k;
  // A loop charges the elements it visits where it is (limits.hpp, calls).
  if (k == ir::SK::ForEach || k == ir::SK::ForRange) s->loc = location();
  if (!dead_) block_->push_back(s);
  return s;
}

ir::Stmt* Specialiser::emit_detached(ir::SK k) {
  const bool was = dead_;
  dead_ = true;  // emit() builds it without attaching
  ir::Stmt* s = emit(k);
  dead_ = was;
  return s;
}

void Specialiser::emit_set(ir::Node* place, ir::Node* value) {
  if (place->op != ir::Op::Local) ++effects_;
  ir::Stmt* s = emit(ir::SK::Set);
  s->a = place;
  s->b = value;
}

void Specialiser::emit_eval(ir::Node* n) { emit(ir::SK::Eval)->a = n; }

void Specialiser::emit_push(ir::Node* list, ir::Node* value) {
  ir::Stmt* s = emit(ir::SK::Push);
  s->a = list;
  s->b = value;
}

bool Specialiser::is_const(const ir::Node* n) const {
  if (!n) return false;
  switch (n->op) {
    case ir::Op::Lit: return true;
    case ir::Op::MakePos:
    case ir::Op::MakeElem:
    case ir::Op::MakeList:
      return std::all_of(n->a.begin(), n->a.end(), [&](const ir::Node* k) { return is_const(k); });
    default: return false;
  }
}

// Values that cannot change while in use need no temporary: constants,
// temporaries and the immutable names of a block.
static bool stable(const ir::Node* n) {
  if (!n) return true;
  if (n->op == ir::Op::Lit) return true;
  if (n->op == ir::Op::Local) return !n->var->mut;
  if (n->op == ir::Op::Member) return stable(n->a[0]);
  return false;
}

// Whether a block raises an error on some path.
bool has_fail(const ir::Block& b) {
  for (const ir::Stmt* s : b) {
    if (s->k == ir::SK::Fail || has_fail(s->body) || has_fail(s->other)) return true;
    for (const auto& [k, c] : s->cases)
      if (has_fail(c)) return true;
  }
  return false;
}

SVal Specialiser::let(SVal v, const std::string& hint) {
  // Constants are printed where used, except lists (a vector built at every use).
  if (!v.code || v.type->k == TK::Never || stable(v.code) || (is_const(v.code) && v.code->op != ir::Op::MakeList))
    return v;
  ir::Var* t = var(v.type, hint);
  // Reads of places (a global, a variable) are Binds: a reference unless a store
  // can intervene (pass_refs); computed values are immutable temporaries.
  const bool place = v.code->op == ir::Op::Global || v.code->op == ir::Op::Slot || v.code->op == ir::Op::Local ||
                     v.code->op == ir::Op::Select;
  ir::Stmt* s = emit(place ? ir::SK::Bind : ir::SK::Let);
  s->var = t;
  s->a = v.code;
  v.code = local(t);
  return v;
}

ir::Var* Specialiser::decl(TypeP t, ir::Node* init, const std::string& hint) {
  ir::Var* v = var(t, hint);
  v->mut = true;
  ir::Stmt* s = emit(ir::SK::Decl);
  s->var = v;
  s->a = init;
  return v;
}

void Specialiser::comment(const std::string& t) { emit(ir::SK::Comment)->text = t; }

void Specialiser::in_block(ir::Block& b, const std::function<void()>& f) {
  ir::Block* saved = block_;
  const bool was_dead = dead_;
  block_ = &b;
  f();
  block_ = saved;
  dead_ = was_dead;
}

SVal Specialiser::never() { return SVal{T().never(), nullptr}; }

// A hint changed: the walk will be repeated (AUTUMN_LOWER_TRACE=1 prints why).
void Specialiser::learn(const std::string& what) {
  h_.changed = true;
  h_.last_change = what;
  if (std::getenv("AUTUMN_LOWER_TRACE")) std::fprintf(stderr, "  learnt: %s\n", what.c_str());
}

// ---------------------------------------------------------------------------
// Errors

int Specialiser::location() {
  ErrorLoc l;
  if (!loc_stack_.empty()) l.at = loc_stack_.back()->loc;
  for (auto it = loc_stack_.rbegin(); it != loc_stack_.rend(); ++it)
    if ((*it)->loc.source == SourceId::Program) {
      l.in_program = true;
      l.program_at = (*it)->loc;
      break;
    }
  l.prefix = error_prefix_;
  return intern_location(l);
}

// The index of `l` among the module's error sites, added if new.
int Specialiser::intern_location(const ErrorLoc& l) {
  for (size_t i = 0; i < m_.locations.size(); ++i) {
    const ErrorLoc& o = m_.locations[i];
    if (o.at.line == l.at.line && o.at.col == l.at.col && o.at.source == l.at.source &&
        o.in_program == l.in_program && o.program_at.line == l.program_at.line &&
        o.program_at.col == l.program_at.col && o.prefix == l.prefix)
      return static_cast<int>(i);
  }
  m_.locations.push_back(l);
  return static_cast<int>(m_.locations.size() - 1);
}

void Specialiser::fail(const std::string& msg) { fail(std::vector<ir::Node*>{text(msg)}); }

void Specialiser::fail(std::vector<ir::Node*> parts) {
  if (capture_mode_) {
    // A cell argument's trial: the reference catches the error and defers the
    // argument. Only an error every run raises can be decided here.
    if (block_ != capture_block_) unsupported("a cell argument whose evaluation fails on some runs only");
    trial_failed_ = true;
    dead_ = true;
    return;
  }
  ir::Stmt* s = emit(ir::SK::Fail);
  s->a = node(ir::Op::Concat, nullptr, std::move(parts));
  s->loc = location();
  dead_ = true;
}

void Specialiser::check_length(ir::LengthOf how, std::vector<ir::Node*> args, std::optional<int64_t> known) {
  if (known && *known <= limits::kMinListLength) return;
  if (capture_mode_) unsupported("a cell argument that builds a list the list-length budget may refuse");
  ir::Node* c = call(ir::Helper::CheckLength, nullptr, std::move(args));
  c->index = how;
  c->imm = location();
  emit_eval(c);
}

// Only the elements the interpreter counts too (limits.hpp, cells): a program
// construct's new list, never the rendering machinery's lists or a conversion
// to a wider element type; and not in a cell argument's trial, where the
// reference would defer the argument on a budget error.
void Specialiser::charge_built(ir::LengthOf how, std::vector<ir::Node*> args) {
  if (capture_mode_ || dead_) return;
  ir::Node* c = call(ir::Helper::ChargeBuilt, nullptr, std::move(args));
  c->index = how;
  c->imm = location();
  emit_eval(c);
}

void Specialiser::charge_one_built() { charge_built(ir::kLengthIs, {lit(T().int_(), 1)}); }

void Specialiser::unsupported(const std::string& why) {
  SourceLoc at;
  if (!loc_stack_.empty()) at = loc_stack_.back()->loc;
  for (auto it = loc_stack_.rbegin(); it != loc_stack_.rend(); ++it)
    if ((*it)->loc.source == SourceId::Program) {
      at = (*it)->loc;
      break;
    }
  throw Unsupported{why, at};
}

void Specialiser::dynamic_site(const std::string& why) {
  SourceLoc at;
  for (auto it = loc_stack_.rbegin(); it != loc_stack_.rend(); ++it)
    if ((*it)->loc.source == SourceId::Program) {
      at = (*it)->loc;
      break;
    }
  for (const DynamicSite& d : m_.dynamic_sites)
    if (d.loc.line == at.line && d.loc.col == at.col && d.why == why) return;
  m_.dynamic_sites.push_back(DynamicSite{at, why});
}

// ---------------------------------------------------------------------------
// Strings and type strings

int Specialiser::string_id(const std::string& quoted) {
  auto it = std::find(m_.strings.begin(), m_.strings.end(), quoted);
  if (it != m_.strings.end()) return static_cast<int>(it - m_.strings.begin());
  m_.strings.push_back(quoted);
  return static_cast<int>(m_.strings.size() - 1);
}

std::string Specialiser::type_string(TypeP t) {
  // Not a static std::string: a module may be lowered on a background thread
  // while the process exits (harness/module_cache.hpp).
  const std::string pos = "class Position {x: Number, y: Number, }";
  switch (t->k) {
    case TK::Int: return "Number";
    case TK::Bool: return "Bool";
    case TK::Str: return "String";
    case TK::Pos: return pos;
    case TK::Elem: return "class RenderedElem {position: " + pos + ", color: String, }";
    case TK::Cell: return "class Cell {x: Expr, y: Expr, color: Expr, }";
    case TK::Obj: return m_.classes[t->cls].type_string;
    case TK::List: return t->elem ? "List<" + type_string(t->elem) + ">" : "List<Unknown>";
    case TK::Func: return "AutumnFunc";
    case TK::Class:
    case TK::Sum:
    case TK::Deferred:
    case TK::Never: return "Unknown";
  }
  return "Unknown";
}

// The interpreter builds a type string where it compares types (assignment,
// declared types, construction, list tags); for a class with a field of unknown
// type that is an error (the reference crashes). Emits it when `t` is such a class.
bool Specialiser::check_printable(TypeP t) {
  if (t->k == TK::List && t->elem) return check_printable(t->elem);
  if (t->k != TK::Obj) return true;
  const ClassInfo& c = m_.classes[t->cls];
  if (c.unknown_field.empty()) return true;
  fail("class '" + c.name + "' has field '" + c.unknown_field + "' of an unknown type (the reference interpreter crashes here)");
  return false;
}

TypeP Specialiser::declared_type(const TypeExpr& te) {
  if (te.is_list) {
    TypeP e = declared_type(*te.elem);
    return e ? T().list(e) : nullptr;
  }
  const std::string& n = te.name;
  if (n == "Number" || n == "Int") return T().int_();
  if (n == "Bool") return T().bool_();
  if (n == "String") return T().str();
  if (n == "Position") return T().pos();
  if (n == "Cell") return T().cell();
  if (n == "RenderedElem") return T().elem();
  if (te.sym >= 0 && te.sym < static_cast<Sym>(f_.class_of_sym.size()) && f_.class_of_sym[te.sym] >= 0 &&
      class_defined_[f_.class_of_sym[te.sym]])
    return T().obj(f_.class_of_sym[te.sym]);
  return nullptr;
}

// ---------------------------------------------------------------------------
// The driver

void specialise_program(const Program& p, Module& m) {
  const Facts facts = program_facts(p);
  Hints hints;
  constexpr int kMaxWalks = 12;
  for (int walk = 0; walk < kMaxWalks; ++walk) {
    m.clear_for_walk();
    hints.changed = false;
    Specialiser s(p, facts, m, hints);
    s.run();
    if (std::getenv("AUTUMN_LOWER_TRACE"))  // which hint each walk learnt (debugging the lowering)
      std::fprintf(stderr, "walk %d: %s\n", walk, hints.changed ? hints.last_change.c_str() : "settled");
    if (!hints.changed) return;
  }
  throw Unsupported{"the types of some variables do not settle (" + hints.last_change + ")", SourceLoc{}};
}

}  // namespace autumn::lower
