// spec_builtins_state — the builtins that touch more than their arguments: the
// random generator, the occupancy of the last render, the inputs, the globals
// (defined, allObjs, prev, one-argument removeObj) and object copies (addObj,
// updateObj, removeObj). Same checks, texts and order as
// compiler/interpret/builtins.cpp.
#include <algorithm>

#include "compiler/lower/specialise.hpp"
#include "runtime/limits.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {

// ---------------------------------------------------------------------------
// uniformChoice, randomPositions, allPositions, adjPositions, isFreePos, isWithinBounds

SVal Specialiser::builtin_is_free_pos(Builtin, std::vector<SVal>& a, const Expr&) {
  if (a[0].type->k != TK::Pos) {
    fail("isFreePos: the argument must be a Position");
    return never();
  }
  return let(SVal{T().bool_(), ir_.call(ir::Helper::OccupancyFree, T().bool_(), {a[0].code})});
}

SVal Specialiser::builtin_random_positions(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::Int, "a number")) return never();
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.node(ir::Op::Lt, T().bool_(), {a[0].code, ir_.lit(T().int_(), 0)});
  ir_.in_block(s->body, [&] { fail("randomPositions: the grid size must not be negative"); });
  if (!check_kind(b, a, 1, TK::Int, "a number")) return never();
  check_length(ir::kLengthIs, {a[1].code}, const_int(a[1]));
  charge_built(ir::kLengthIs, {a[1].code});
  ir::Var* out = ir_.decl(T().list(T().pos()), nullptr, "rpos");
  ir::Stmt* loop = builtin_loop(ir::SK::ForRange);
  loop->var = ir_.var(T().int_(), "i");
  loop->a = ir_.lit(T().int_(), 0);
  loop->b = a[1].code;
  ir_.in_block(loop->body, [&] {
    SVal x = let(SVal{T().int_(), ir_.call(ir::Helper::RngNext, T().int_(), {a[0].code})});
    SVal y = let(SVal{T().int_(), ir_.call(ir::Helper::RngNext, T().int_(), {a[0].code})});
    ir_.emit_push(ir_.local(out), make_position(x, y).code);
  });
  return built(out);
}

SVal Specialiser::builtin_all_positions(Builtin b, std::vector<SVal>& a, const Expr&) {
  const size_t n = a.size();
  if (n < 1 || n > 2) {
    fail("allPositions takes 1 or 2 arguments");
    return never();
  }
  auto size = [&](size_t i) {
    if (!check_kind(b, a, i, TK::Int, "a number")) return false;
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = ir_.node(ir::Op::Lt, T().bool_(), {a[i].code, ir_.lit(T().int_(), 0)});
    ir_.in_block(s->body, [&] { fail("allPositions: negative size"); });
    return !ir_.dead();
  };
  if (!size(0) || (n == 2 && !size(1))) return never();
  std::optional<int64_t> known;
  if (auto w = const_int(a[0]), h = const_int(a[n - 1]); w && h) known = *w * *h;
  check_length(ir::kLengthArea, {a[0].code, a[n - 1].code}, known);
  charge_built(ir::kLengthArea, {a[0].code, a[n - 1].code});
  ir::Var* out = ir_.decl(T().list(T().pos()), nullptr, "apos");
  out->scratch = true;
  ir::Stmt* outer = builtin_loop(ir::SK::ForRange);
  outer->var = ir_.var(T().int_(), "i");
  outer->a = ir_.lit(T().int_(), 0);
  outer->b = a[0].code;
  ir_.in_block(outer->body, [&] {
    ir::Stmt* inner = builtin_loop(ir::SK::ForRange);
    inner->var = ir_.var(T().int_(), "j");
    inner->a = ir_.lit(T().int_(), 0);
    inner->b = a[n - 1].code;
    ir_.in_block(inner->body, [&] {
      ir_.emit_push(ir_.local(out), make_position(SVal{T().int_(), ir_.local(outer->var)}, SVal{T().int_(), ir_.local(inner->var)}).code);
    });
  });
  return built(out);
}

SVal Specialiser::builtin_adj_positions(Builtin, std::vector<SVal>& a, const Expr& at) {
  if (a[0].type->k != TK::Pos) {
    fail("adjPositions: the argument must be a Position");
    return never();
  }
  SVal g = grid_size(at);
  if (ir_.dead()) return never();
  SVal p = let(a[0]);
  ir::Var* out = ir_.decl(T().list(T().pos()), nullptr, "adj");
  out->scratch = true;
  ir::Node* x = ir_.member(p.code, ir::Member::X, T().int_());
  ir::Node* y = ir_.member(p.code, ir::Member::Y, T().int_());
  ir::Node* one = ir_.lit(T().int_(), 1);
  const std::pair<ir::Node*, ir::Node*> cand[4] = {
      {ir_.node(ir::Op::Sub, T().int_(), {x, one}), y}, {ir_.node(ir::Op::Add, T().int_(), {x, one}), y},
      {x, ir_.node(ir::Op::Sub, T().int_(), {y, one})}, {x, ir_.node(ir::Op::Add, T().int_(), {y, one})}};
  for (const auto& [cx, cy] : cand) {
    SVal vx = let(SVal{T().int_(), cx}), vy = let(SVal{T().int_(), cy});
    ir::Node* zero = ir_.lit(T().int_(), 0);
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = ir_.node(ir::Op::And, T().bool_(),
                {ir_.node(ir::Op::And, T().bool_(), {ir_.node(ir::Op::Ge, T().bool_(), {vx.code, zero}),
                                                 ir_.node(ir::Op::Lt, T().bool_(), {vx.code, g.code})}),
                 ir_.node(ir::Op::And, T().bool_(), {ir_.node(ir::Op::Ge, T().bool_(), {vy.code, zero}),
                                                 ir_.node(ir::Op::Lt, T().bool_(), {vy.code, g.code})})});
    ir_.in_block(s->body, [&] {
      charge_one_built();
      ir_.emit_push(ir_.local(out), make_position(vx, vy).code);
    });
  }
  return built(out);
}

SVal Specialiser::builtin_within_bounds(Builtin, std::vector<SVal>& a, const Expr& at) {
  SVal elems = render_value(a[0], at);
  SVal g = grid_size(at);
  if (ir_.dead()) return never();
  ir::Var* r = ir_.decl(T().bool_(), ir_.lit(T().bool_(), 1), "within");
  if (!renders(a[0].type)) return built(r);
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(T().elem(), "e");
  loop->a = elems.code;
  ir_.in_block(loop->body, [&] {
    ir::Node* p = ir_.member(ir_.local(loop->var), ir::Member::Position, T().pos());
    ir::Node* x = ir_.member(p, ir::Member::X, T().int_());
    ir::Node* y = ir_.member(p, ir::Member::Y, T().int_());
    ir::Node* zero = ir_.lit(T().int_(), 0);
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = ir_.node(ir::Op::Or, T().bool_(),
                {ir_.node(ir::Op::Or, T().bool_(), {ir_.node(ir::Op::Lt, T().bool_(), {x, zero}), ir_.node(ir::Op::Ge, T().bool_(), {x, g.code})}),
                 ir_.node(ir::Op::Or, T().bool_(), {ir_.node(ir::Op::Lt, T().bool_(), {y, zero}), ir_.node(ir::Op::Ge, T().bool_(), {y, g.code})})});
    ir_.in_block(s->body, [&] {
      ir_.emit_set(ir_.local(r), ir_.lit(T().bool_(), 0));
      ir_.emit(ir::SK::Break);
    });
  });
  return built(r);
}

SVal Specialiser::builtin_uniform_choice(Builtin b, std::vector<SVal>& a, const Expr&) {
  const size_t n = a.size();
  if (n == 0) {
    fail("uniformChoice needs a list");
    return never();
  }
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  const SVal l = a[0];
  if (!l.type->elem) {
    fail("uniformChoice of an empty list");
    return never();
  }
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.node(ir::Op::Empty, T().bool_(), {l.code});
  ir_.in_block(s->body, [&] { fail("uniformChoice of an empty list"); });
  auto draw = [&]() {
    SVal i = let(SVal{T().int_(), ir_.call(ir::Helper::RngNext, T().int_(), {ir_.node(ir::Op::Size, T().int_(), {l.code})})});
    return ir_.node(ir::Op::Index, l.type->elem, {l.code, i.code});
  };
  if (n == 1) return let(SVal{l.type->elem, draw()});
  if (!check_kind(b, a, 1, TK::Int, "a number")) return never();
  check_appends(l.type->elem, "uniformChoice with a count");
  ir::Stmt* c = ir_.emit(ir::SK::If);
  c->a = ir_.node(ir::Op::Lt, T().bool_(), {a[1].code, ir_.lit(T().int_(), 1)});
  ir_.in_block(c->body, [&] { fail("uniformChoice: the count must be at least 1"); });
  check_length(ir::kLengthIs, {a[1].code}, const_int(a[1]));
  charge_built(ir::kLengthIs, {a[1].code});
  ir::Var* out = ir_.decl(l.type, nullptr, "choices");
  ir::Stmt* loop = builtin_loop(ir::SK::ForRange);
  loop->var = ir_.var(T().int_(), "i");
  loop->a = ir_.lit(T().int_(), 0);
  loop->b = a[1].code;
  ir_.in_block(loop->body, [&] {
    ir_.emit_push(ir_.local(out), draw());
  });
  return built(out);
}

// ---------------------------------------------------------------------------
// clicked, left, right, up, down

SVal Specialiser::builtin_arrow(Builtin b, std::vector<SVal>&, const Expr&) {
  const int kind = b == Builtin::Left ? 1 : b == Builtin::Right ? 2 : b == Builtin::Up ? 3 : 4;
  return let(SVal{T().bool_(), ir_.call(ir::Helper::InputFlag, T().bool_(), {ir_.lit(T().int_(), kind)})});
}

SVal Specialiser::builtin_clicked(Builtin, std::vector<SVal>& a, const Expr&) {
  ir::Var* r = ir_.decl(T().bool_(), ir_.lit(T().bool_(), 0), "clicked");
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.call(ir::Helper::InputFlag, T().bool_(), {ir_.lit(T().int_(), 0)});
  ir_.in_block(s->body, [&] {
    define_click();
    if (a.empty()) {
      ir_.emit_set(ir_.local(r), ir_.lit(T().bool_(), 1));
      return;
    }
    if (a.size() > 1) {
      fail("clicked takes 0 or 1 arguments, got " + std::to_string(a.size()));
      return;
    }
    // Each rendered element is compared as it is drawn, into no list: an
    // object of fixed cells costs a compare per cell. No early exit (a break
    // would leave the caller's loop when the object draws without one); the
    // comparisons have no effects, so drawing on changes nothing but time.
    render_into(a[0], [&](ir::Node* elem) {
      SVal e = let(SVal{T().elem(), elem}, "e");
      ir::Node* pos = ir_.call(ir::Helper::ClickPos, T().pos(), {});  // a plain Pos, compared by value
      ir::Stmt* hit = ir_.emit(ir::SK::If);
      hit->a = ir_.node(ir::Op::Eq, T().bool_(), {ir_.member(e.code, ir::Member::Position, T().pos()), pos});
      ir_.in_block(hit->body, [&] { ir_.emit_set(ir_.local(r), ir_.lit(T().bool_(), 1)); });
    });
  });
  return built(r);
}

// The global `click` := the pending click (a fresh Position each time).
void Specialiser::define_click() {
  Global& g = global_slot(p_.names.click, T().pos());
  g.state = Global::Runtime;
  if (h_.add_runtime_defined(p_.names.click)) {
    // Its type too, as define_global records a global a step defines: the
    // next walk gives it its slot from the step's start (specialise_step), so
    // a read before this definition has a place to read.
    if (!h_.global(p_.names.click) && g.type) h_.set_global(p_.names.click, g.type);
    h_.learn("click");
  }
  ir_.emit_set(ir_.slot(g.defined), ir_.lit(T().bool_(), 1));
  order_insert(g.sym);
  // The pending click as a new Position (a plain Pos: no identity of its own yet).
  ir::Node* click = ir_.call(ir::Helper::ClickPos, T().pos(), {});
  SVal p = h_.tracked(T().pos()) ? make_position(SVal{T().int_(), ir_.member(click, ir::Member::X, T().int_())},
                                              SVal{T().int_(), ir_.member(click, ir::Member::Y, T().int_())})
                              : let(SVal{T().pos(), click});
  save_for_prev(g);  // a store like any other: (prev click) still reads the step's start
  ir_.emit_set(ir_.slot(g.value), p.code);
}

// ---------------------------------------------------------------------------
// addObj, updateObj, removeObj

SVal Specialiser::builtin_add_obj(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  const TK k = a[1].type->k;
  if (k != TK::Obj && k != TK::Pos && k != TK::Elem && k != TK::Cell && k != TK::List) {
    fail("addObj: the second argument must be an object or a list, got " + shown(a[1].type));
    return never();
  }
  return add_obj(a[0], a[1]);
}

SVal Specialiser::builtin_remove_obj(Builtin b, std::vector<SVal>& a, const Expr& at) {
  const size_t n = a.size();
  if (n == 0) {
    fail("removeObj needs an argument (the reference interpreter crashes here)");
    return never();
  }
  if (n == 1) return remove_global(a[0]);
  if (n > 2) {
    fail("removeObj takes 1 or 2 arguments, got " + std::to_string(n));
    return never();
  }
  const TK wk = a[1].type->k;
  if (!is_function(a[1].type) && wk != TK::Obj && wk != TK::Pos && wk != TK::Elem && wk != TK::Cell && wk != TK::List) {
    fail("removeObj: the second argument must be a function, an object or a list");
    return never();
  }
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  return remove_from(a[0], a[1], at);
}

// addObj: a copy of the list with every element copied (fresh identities), then
// the object appended (or the other list's elements).
SVal Specialiser::add_obj(const SVal& l, const SVal& x) {
  TypeP et = l.type->elem;
  TypeP xt = x.type->k == TK::List ? x.type->elem : x.type;
  TypeP rt = et && xt ? T().join(et, xt) : et ? et : xt;
  if (!rt) return SVal{T().empty_list(), ir_.node(ir::Op::MakeList, T().empty_list())};
  if (is_sum(rt) && !is_typed_variant(rt)) sites_.dynamic_site("addObj mixes values of different types");
  if (et && is_sum(et) && x.type->k != TK::List)
    sites_.unsupported("addObj to a list that may hold objects of several classes");
  TypeP lt = T().list(rt);
  ir::Node* added = x.type->k != TK::List ? ir_.lit(T().int_(), 1)
                    : x.type->elem        ? ir_.node(ir::Op::Size, T().int_(), {x.code})
                                          : ir_.lit(T().int_(), 0);
  if (et) {  // an empty list gets at most the elements of x, a list already within the budget
    check_length(ir::kLengthSizePlus, {l.code, added});
    charge_built(ir::kLengthSizePlus, {l.code, added});
  } else {
    charge_built(ir::kLengthIs, {added});
  }
  ir::Var* out = ir_.decl(lt, nullptr, "added");
  if (et) {
    ir::Node* extra = x.type->k == TK::List ? (x.type->elem ? ir_.node(ir::Op::Size, T().int_(), {x.code}) : ir_.lit(T().int_(), 0))
                                            : ir_.lit(T().int_(), 1);
    ir_.emit_eval(ir_.call(ir::Helper::Reserve, nullptr, {ir_.local(out), ir_.node(ir::Op::Add, T().int_(), {ir_.node(ir::Op::Size, T().int_(), {l.code}), extra})}));
    // A loop of pushes even where the elements are copied as they are: a bulk
    // insert instead (vector::insert) made g++ stop inlining push_back at the
    // module's other pushes of that type (gravity_2's updateObj loops, 3x
    // slower steps; docs/design.md).
    ir::Stmt* loop = builtin_loop(ir::SK::ForEach);
    loop->var = ir_.var(et, "x");
    loop->a = l.code;
    ir_.in_block(loop->body, [&] {
      SVal e{et, ir_.local(loop->var)};
      if (!check_copy(e)) return;  // every element is copied
      if (h_.tracked(et)) e = renew_identity(e);
      ir_.emit_push(ir_.local(out), coerce(e, rt).code);
    });
  }
  if (x.type->k == TK::List) {
    if (x.type->elem) {
      ir::Stmt* loop = builtin_loop(ir::SK::ForEach);
      loop->var = ir_.var(x.type->elem, "x");
      loop->a = x.code;
      ir_.in_block(loop->body, [&] {
        ir_.emit_push(ir_.local(out), coerce(SVal{x.type->elem, ir_.local(loop->var)}, rt).code);
      });
    }
  } else {
    ir_.emit_push(ir_.local(out), coerce(x, rt).code);
  }
  return built(out);
}

// A copy of a tracked object with a fresh uid (copy_value).
SVal Specialiser::renew_identity(const SVal& v) {
  if (is_sum(v.type)) return split(v, [&](const SVal& a) { return renew_identity(a); });
  ir::Var* c = ir_.decl(v.type, v.code, "copy");
  ir_.emit_set(ir_.member(ir_.local(c), ir::Member::Uid, T().int_()), ir_.call(ir::Helper::NewUid, T().int_(), {}));
  return built(c);
}

SVal Specialiser::builtin_update_obj(Builtin, std::vector<SVal>& a, const Expr& at) {
  const size_t n = a.size();
  if (n < 2 || n > 3) {
    fail("updateObj takes 2 or 3 arguments, got " + std::to_string(n));
    return never();
  }
  if (a[0].type->k == TK::List) {
    if (n == 2) {
      std::vector<SVal> m{a[1], a[0]};
      return call_builtin(Builtin::Map, m, at);
    }
    if (!is_function(a[1].type) || !is_function(a[2].type)) {
      fail("updateObj: the second and third arguments must be functions");
      return never();
    }
    SVal r = update_filtered(a[0], a[1], a[2], at);
    if (!ir_.dead() && r.type->k == TK::List) check_appends(r.type->elem, "updateObj with a predicate");
    return r;
  }
  const TK k = a[0].type->k;
  if (k != TK::Obj && k != TK::Pos && k != TK::Elem && k != TK::Cell) {
    fail("updateObj: the first argument must be an object or a list");
    return never();
  }
  if (n == 2) {
    if (!is_function(a[1].type)) {
      fail("updateObj: argument 2 must be a function, got " + shown(a[1].type));
      return never();
    }
    return call1(a[1], a[0], at);
  }
  if (!check_copy(a[0])) return never();  // the copy comes first, as in the interpreter
  if (a[1].type->k != TK::Str) {
    fail("updateObj: the field name must be a string");
    return never();
  }
  if (!a[1].konst) sites_.unsupported("updateObj with a field name computed at run time");
  std::string field = m_.strings[a[1].konst->imm];
  if (!field.empty() && (field[0] == '"' || field[0] == '\'')) field = field.substr(1, field.size() - 2);
  return set_field(a[0], field, a[2]);
}

// updateObj o "f" v: a copy (fresh identity) with the field replaced, unchecked.
SVal Specialiser::set_field(const SVal& o, const std::string& field, const SVal& v) {
  Sym s = p_.symbols.find(field);
  if (o.type->k != TK::Obj) {
    const std::string cn = class_name(o.type->k == TK::Pos ? kPositionClass : o.type->k == TK::Elem ? kElemClass : kCellClass);
    sites_.unsupported("updateObj of a " + cn);
  }
  ClassInfo& ci = m_.classes[o.type->cls];
  int index = -1;
  for (size_t i = 0; i < ci.fields.size(); ++i)
    if (ci.fields[i] == s) index = static_cast<int>(i);
  const bool origin = s == p_.names.origin;
  if (s == p_.names.elems) sites_.unsupported("updateObj of the elems field");
  if (index < 0 && !origin) {
    fail("updateObj: object of class '" + ci.name + "' has no field '" + field + "'");
    return never();
  }
  if (origin && v.type->k != TK::Pos) sites_.unsupported("updateObj giving origin a value that is not a Position");
  // The new value's slot: the origin, or the field widened to hold it.
  SVal value = v;
  if (!origin) {
    widen_field(o.type->cls, index, v.type);
    TypeP ft = ci.field_types[index];
    if (!T().fits(v.type, ft)) return never();
    value = coerce(v, ft);
  }
  const bool typed = std::all_of(ci.field_types.begin(), ci.field_types.end(), [](TypeP t) { return t != nullptr; });
  if (!h_.stored_cells(o.type->cls) && !h_.rotated(o.type->cls) && typed) return rebuilt_with(o, index, value);
  ir::Var* c = ir_.decl(o.type, o.code, "upd");
  ir::Node* place = origin ? ir_.member(ir_.local(c), ir::Member::Origin, T().pos())
                           : ir_.member(ir_.local(c), ir::Member::Field, value.type, index);
  ir_.emit_set(place, value.code);
  if (h_.tracked(o.type)) ir_.emit_set(ir_.member(ir_.local(c), ir::Member::Uid, T().int_()), ir_.call(ir::Helper::NewUid, T().int_(), {}));
  return built(c);
}

// set_field's object built in place, its other fields read from o (a class
// whose objects are their fields, origin and perhaps an identity): a copy
// patched afterwards went through the stack under Clang (docs/design.md,
// "The module's compiler"). `field` -1 is the origin; `v` is already of its
// slot's type.
SVal Specialiser::rebuilt_with(const SVal& o, int field, const SVal& v) {
  const ClassInfo& ci = m_.classes[o.type->cls];
  const SVal from = let(o, "from");
  std::vector<ir::Node*> ops;
  for (size_t i = 0; i < ci.fields.size(); ++i)
    ops.push_back(static_cast<int>(i) == field
                      ? v.code
                      : ir_.member(from.code, ir::Member::Field, ci.field_types[i], static_cast<int>(i)));
  ops.push_back(field < 0 ? v.code : ir_.member(from.code, ir::Member::Origin, T().pos()));
  if (h_.tracked(o.type)) ops.push_back(ir_.call(ir::Helper::NewUid, T().int_(), {}));
  ir::Node* n = ir_.node(ir::Op::MakeObj, o.type, ops);
  n->index = o.type->cls;
  return let(SVal{o.type, n}, "upd");
}

// updateObj list f pred: f(x) where pred(x) holds, else x.
SVal Specialiser::update_filtered(const SVal& l, const SVal& f, const SVal& pred, const Expr& at) {
  if (!l.type->elem) return l;
  TypeP et = l.type->elem;
  charge_built(ir::kLengthSizes, {l.code});
  ir::Var* out = ir_.decl(l.type, nullptr, "updated");
  ir_.emit_eval(ir_.call(ir::Helper::Reserve, nullptr, {ir_.local(out), ir_.node(ir::Op::Size, T().int_(), {l.code})}));
  SVal src = let(l, "src");
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(et, "x");
  loop->a = src.code;
  ir_.in_block(loop->body, [&] {
    SVal x{et, ir_.local(loop->var)};
    SVal p = call1(pred, x, at);
    if (ir_.dead()) return;
    ir::Node* cond = truthy(p);
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = cond;
    ir_.in_block(s->body, [&] {
      SVal y = call1(f, x, at);
      if (ir_.dead()) return;
      if (!T().fits(y.type, et)) {
        // list_add re-tags the list per element: mixed types need the tags.
        sites_.unsupported("updateObj with a filter whose function changes the element type");
      }
      ir_.emit_push(ir_.local(out), coerce(y, et).code);
    });
    ir_.in_block(s->other, [&] {
      ir_.emit_push(ir_.local(out), x.code);
    });
  });
  return built(out);
}

// removeObj list f / list obj / list list.
SVal Specialiser::remove_from(const SVal& l, const SVal& what, const Expr& at) {
  if (!l.type->elem) return SVal{T().empty_list(), ir_.node(ir::Op::MakeList, T().empty_list())};
  TypeP et = l.type->elem;
  if (!is_function(what.type)) {
    note_identity(et);
    note_identity(what.type->k == TK::List ? what.type->elem : what.type);
  }
  SVal src = let(l, "src");
  ir::Var* out = ir_.decl(l.type, nullptr, "kept");
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(et, "x");
  loop->a = src.code;
  ir_.in_block(loop->body, [&] {
    SVal x{et, ir_.local(loop->var)};
    ir::Node* keep = nullptr;
    if (is_function(what.type)) {
      SVal p = call1(what, x, at);
      if (ir_.dead()) return;
      keep = ir_.node(ir::Op::Not, T().bool_(), {truthy(p)});
    } else if (what.type->k != TK::List) {
      keep = same_identity_any(x, {what}) ;
      keep = ir_.node(ir::Op::Not, T().bool_(), {keep});
    } else {
      if (!what.type->elem) {
        keep = ir_.lit(T().bool_(), 1);
      } else {
        ir::Var* found = ir_.decl(T().bool_(), ir_.lit(T().bool_(), 0), "found");
        ir::Stmt* inner = ir_.emit(ir::SK::ForEach);
        inner->var = ir_.var(what.type->elem, "y");
        inner->a = what.code;
        ir_.in_block(inner->body, [&] {
          ir::Node* cond = same_identity_any(x, {SVal{what.type->elem, ir_.local(inner->var)}});
          ir::Stmt* s = ir_.emit(ir::SK::If);
          s->a = cond;
          ir_.in_block(s->body, [&] {
            ir_.emit_set(ir_.local(found), ir_.lit(T().bool_(), 1));
            ir_.emit(ir::SK::Break);
          });
        });
        keep = ir_.node(ir::Op::Not, T().bool_(), {ir_.local(found)});
      }
    }
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = keep;
    ir_.in_block(s->body, [&] {
      charge_one_built();
      ir_.emit_push(ir_.local(out), x.code);
    });
  });
  return built(out);
}

// Whether x is a heap value with the identity number of one of `others`.
ir::Node* Specialiser::same_identity_any(const SVal& x, const std::vector<SVal>& others) {
  ir::Node* any = ir_.lit(T().bool_(), 0);
  for (const SVal& o : others) {
    SVal r = split(x, [&](const SVal& a) {
      return split(o, [&](const SVal& b) -> SVal {
        if (!is_heap(a.type) || !is_heap(b.type)) return SVal{T().bool_(), ir_.lit(T().bool_(), 0)};
        if (!h_.tracked(a.type) || !h_.tracked(b.type)) return SVal{T().bool_(), ir_.lit(T().bool_(), 0)};
        return let(SVal{T().bool_(), ir_.node(ir::Op::Eq, T().bool_(), {id_of(a), id_of(b)})});
      });
    });
    any = ir_.node(ir::Op::Or, T().bool_(), {any, r.code});
  }
  return any;
}

// rotate o: a copy of o (a fresh identity), and the cells o shares with every
// object of its construction turn (x, y) -> (-y, x), in place: all those
// objects, prev's included, turn with it. Objects of a class rotate is applied
// to carry the group of cells they share; the state counts each group's turns.
SVal Specialiser::builtin_rotate(Builtin, std::vector<SVal>& a, const Expr&) {
  const TK k = a[0].type->k;
  if (k != TK::Obj && k != TK::Pos && k != TK::Elem && k != TK::Cell) {
    fail("rotate: the argument must be an object");
    return never();
  }
  if (k != TK::Obj) {
    fail("rotate: the object has no cells");
    return never();
  }
  if (!check_copy(a[0])) return never();  // rotate turns a copy
  const int cls = a[0].type->cls;
  if (h_.add_rotated(cls)) {
    h_.learn("rotate turns '" + m_.classes[cls].name + "'");
    return never();
  }
  // Each turn wraps one of the cells' offsets once more: their number is a fixed
  // limit (limits::kMaxRotations, which the interpreter checks too).
  ir::Stmt* deep = ir_.emit(ir::SK::If);
  deep->a = ir_.node(ir::Op::Ge, T().bool_(), {ir_.call(ir::Helper::RotOf, T().int_(), {ir_.member(a[0].code, ir::Member::Group, T().int_())}),
                                           ir_.lit(T().int_(), limits::kMaxRotations)});
  ir_.in_block(deep->body, [&] { fail(limits::rotation_nesting_error()); });
  ir_.emit_eval(ir_.call(ir::Helper::RotTurn, nullptr, {ir_.member(a[0].code, ir::Member::Group, T().int_())}));
  if (!h_.tracked(a[0].type)) return a[0];
  return renew_identity(a[0]);
}

// ---------------------------------------------------------------------------
// defined, allObjs, prev (as a value), removeObj of one object

SVal Specialiser::builtin_prev(Builtin, std::vector<SVal>& a, const Expr& at) { return prev_of_value(a[0], at); }

SVal Specialiser::builtin_all_objs(Builtin, std::vector<SVal>&, const Expr&) { return all_objs(); }

SVal Specialiser::builtin_defined(Builtin, std::vector<SVal>& a, const Expr&) {
  if (a[0].type->k != TK::Str) {
    fail("defined: the argument must be a string");
    return never();
  }
  if (!a[0].konst) sites_.unsupported("defined of a name computed at run time");
  std::string name = m_.strings[a[0].konst->imm];
  if (!name.empty() && name[0] == '"') name = name.substr(1, name.size() - 2);
  Sym s = p_.symbols.find(name);
  Global* g = s >= 0 ? global(s) : nullptr;
  if (!g || g->state == Global::Undefined) return SVal{T().bool_(), ir_.lit(T().bool_(), 0), ir_.lit(T().bool_(), 0)};
  if (g->state == Global::Defined) return SVal{T().bool_(), ir_.lit(T().bool_(), 1), ir_.lit(T().bool_(), 1)};
  return let(SVal{T().bool_(), ir_.slot(g->defined)});
}

}  // namespace autumn::lower
