// spec_core — the specialiser's own services: values into temporaries, error
// locations and failures, the reference's type strings, and the driver that
// repeats the walk until the type hints settle (see specialise.hpp).
//
// Dead code is the builder's flag (ir_builder.hpp): a failure `kill()`s it, and
// values lowered after it have type Never, which fits every slot.
#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"
#include "runtime/limits.hpp"

namespace autumn::lower {

Specialiser::Specialiser(const Program& p, const Facts& f, Module& m, Hints& h)
    : sites_(m), ir_(m, [this] { return sites_.here(); }), p_(p), m_(m), h_(h), f_(f) {}

// ---------------------------------------------------------------------------
// Values into temporaries

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
  if (!v.code || v.type->k == TK::Never || is_stable(v.code) || (is_const(v.code) && v.code->op != ir::Op::MakeList))
    return v;
  ir::Var* t = ir_.var(v.type, hint);
  // Reads of places (a global, a variable) are Binds: a reference unless a store
  // can intervene (pass_refs); computed values are immutable temporaries.
  const bool place = v.code->op == ir::Op::Global || v.code->op == ir::Op::Slot || v.code->op == ir::Op::Local ||
                     v.code->op == ir::Op::Select;
  ir::Stmt* s = ir_.emit(place ? ir::SK::Bind : ir::SK::Let);
  s->var = t;
  s->a = v.code;
  v.code = ir_.local(t);
  return v;
}

SVal Specialiser::never() { return SVal{T().never(), nullptr}; }
SVal Specialiser::empty_list() {
  return SVal{T().empty_list(), ir_.node(ir::Op::MakeList, T().empty_list()), ir_.node(ir::Op::MakeList, T().empty_list())};
}

// ---------------------------------------------------------------------------
// Errors

void Specialiser::fail(const std::string& msg) { fail(std::vector<ir::Node*>{ir_.text(msg)}); }

void Specialiser::fail(std::vector<ir::Node*> parts) {
  if (capture_mode_) {
    // A cell argument's trial: the reference catches the error and defers the
    // argument. Only an error every run raises can be decided here.
    if (ir_.block() != capture_block_) sites_.unsupported("a cell argument whose evaluation fails on some runs only");
    if (!trial_failed_) trial_fail_depth_ = scopes_.visible().size();
    trial_failed_ = true;
    ir_.kill();
    return;
  }
  ir::Stmt* s = ir_.emit(ir::SK::Fail);
  s->a = ir_.node(ir::Op::Concat, nullptr, std::move(parts));
  s->loc = sites_.here();
  ir_.kill();
}

void Specialiser::check_length(ir::LengthOf how, std::vector<ir::Node*> args, std::optional<int64_t> known) {
  if (known && *known <= limits::kMinListLength) return;
  if (capture_mode_) sites_.unsupported("a cell argument that builds a list the list-length budget may refuse");
  ir::Node* c = ir_.call(ir::Helper::CheckLength, nullptr, std::move(args));
  c->index = how;
  c->imm = sites_.here();
  ir_.emit_eval(c);
}

// Only the elements the interpreter counts too (limits.hpp, cells): a program
// construct's new list, never the rendering machinery's lists or a conversion
// to a wider element type; and not in a cell argument's trial, where the
// reference would defer the argument on a budget error.
void Specialiser::charge_built(ir::LengthOf how, std::vector<ir::Node*> args) {
  if (capture_mode_ || ir_.dead()) return;
  ir::Node* c = ir_.call(ir::Helper::ChargeBuilt, nullptr, std::move(args));
  c->index = how;
  c->imm = sites_.here();
  ir_.emit_eval(c);
}

void Specialiser::charge_one_built() { charge_built(ir::kLengthIs, {ir_.lit(T().int_(), 1)}); }

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

// A value's type as an error message names it. For a list the interpreter
// prints the list's run-time tag, which depends on how the list was built
// (`List` after map or concat, `Unknown` for mixed elements, the type of the
// element appended last after addObj or filter), not on its element type: an
// error that would name one is left to the embedded interpreter (found by a
// stress program: `(+ 1 (map f l))` printed `(List Number)` for `List`).
std::string Specialiser::shown(TypeP t) {
  bool list = t->k == TK::List;
  if (is_sum(t))
    for (TypeP a : t->alts) list |= a->k == TK::List;
  if (list) sites_.unsupported("an error that names a list's type (the interpreter prints its run-time tag)");
  return shown_type(type_string(t));
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
    hints.start_walk();
    Specialiser s(p, facts, m, hints);
    s.run();
    if (std::getenv("AUTUMN_LOWER_TRACE"))  // which hint each walk learnt (debugging the lowering)
      std::fprintf(stderr, "walk %d: %s\n", walk, hints.changed() ? hints.last_change().c_str() : "settled");
    if (!hints.changed()) return;
  }
  throw Unsupported{"the types of some variables do not settle (" + hints.last_change() + ")", SourceLoc{}};
}

}  // namespace autumn::lower
