// spec_values — the value rules of compiler/interpret/values.cpp on static types:
// truthiness, equality, conversion between types (into Sums, lists of wider
// element types), case splits over Sums, and identity numbers.
//
// Identity (docs/design.md, "Identity"): objects of a type whose identity some
// removeObj or prev observes carry a uid, unique per object the reference would
// have made. The identity number an object shows is looked up by uid in a small
// table that assignment's transfer rule writes (IdTransfer); copies share the
// uid, so every holder of an object sees the transferred number, as every holder
// of the reference's shared object does.
#include <algorithm>

#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {

std::optional<int64_t> Specialiser::const_int(const SVal& v) const {
  const ir::Node* k = v.konst ? v.konst : v.code;
  if (k && k->op == ir::Op::Lit && (v.type->k == TK::Int || v.type->k == TK::Bool)) return k->imm;
  return std::nullopt;
}

// ---------------------------------------------------------------------------
// Building an If or Switch whose branches produce a value

// Appends `s` to the current block (a statement built detached).
// Runs each producer in its own block, then declares the result (the join of
// the values' types) before the statement and assigns it at the end of each block.
SVal Specialiser::join_blocks(ir::Stmt* stmt, std::vector<ir::Block*> blocks,
                              std::vector<std::function<SVal()>> producers, bool value_used, bool report) {
  std::vector<SVal> results(blocks.size());
  std::vector<bool> alive(blocks.size());
  for (size_t i = 0; i < blocks.size(); ++i)
    ir_.in_block(*blocks[i], [&] {
      results[i] = producers[i]();
      alive[i] = !ir_.dead();
    });
  TypeP t = T().never();
  bool any_alive = false, no_value = false;
  for (size_t i = 0; i < blocks.size(); ++i) {
    if (!alive[i]) continue;
    any_alive = true;
    if (!results[i].type || results[i].type->k == TK::Class) no_value = true;
    else t = T().join(t, results[i].type);
  }
  if (!value_used || no_value || t->k == TK::Never || t->k == TK::Func || t->k == TK::Class) {
    ir_.attach(stmt);
    if (!any_alive) ir_.kill();
    if (no_value) return SVal{};
    if (t->k == TK::Func) return SVal{t, nullptr};  // one function on every path
    return SVal{any_alive ? t : T().never(), nullptr};
  }
  if (report && t->k == TK::Sum && !is_typed_variant(t)) sites_.dynamic_site("the branches give values of different types");
  ir::Var* r = ir_.decl(t, nullptr, "r");
  ir_.attach(stmt);
  for (size_t i = 0; i < blocks.size(); ++i)
    if (alive[i]) ir_.in_block(*blocks[i], [&] { ir_.emit_set(ir_.local(r), coerce(results[i], t).code); });
  if (!any_alive) ir_.kill();
  r->mut = false;
  return SVal{t, ir_.local(r)};
}

SVal Specialiser::join_branches(ir::Node* cond, const std::function<SVal()>& then_f,
                                const std::function<SVal()>& else_f, bool value_used) {
  ir::Stmt* s = ir_.emit_detached(ir::SK::If);
  s->a = cond;
  return join_blocks(s, {&s->body, &s->other}, {then_f, else_f}, value_used, true);
}

SVal Specialiser::split(const SVal& v, const std::function<SVal(const SVal&)>& f) {
  if (!v.type || !is_sum(v.type)) return f(v);
  // Found by fuzz_emit (tests/lowering/deep_sum_splits.au): autumnc overflowed its stack.
  if (split_depth_ >= kMaxSplitDepth) sites_.unsupported("values of union types nested too deeply to specialise");
  struct Depth {
    int& d;
    explicit Depth(int& x) : d(++x) {}
    ~Depth() { --d; }
  } depth(split_depth_);
  SVal x = let(v, "u");
  ir::Stmt* s = ir_.emit_detached(ir::SK::Switch);
  s->a = x.code;
  std::vector<ir::Block*> blocks;
  std::vector<std::function<SVal()>> producers;
  s->cases.resize(x.type->alts.size());
  for (size_t i = 0; i < x.type->alts.size(); ++i) {
    s->cases[i].first = static_cast<int>(i);
    blocks.push_back(&s->cases[i].second);
    TypeP alt = x.type->alts[i];
    producers.push_back([&, i, alt]() -> SVal {
      ir::Node* get = ir_.node(ir::Op::SumGet, alt, {x.code});
      get->index = static_cast<int>(i);
      SVal part{alt, alt->k == TK::Func ? nullptr : get};
      return f(let(part, "a"));
    });
  }
  return join_blocks(s, blocks, producers, true, false);
}

// A value that must be of kind `want` (a condition, a cell's coordinate or
// colour): a sum is split, and each alternative of another kind calls `bad`,
// which emits the error the interpreter raises for that run-time type.
SVal Specialiser::narrow(const SVal& v, TK want, const std::function<void(const SVal&)>& bad) {
  return split(v, [&](const SVal& a) -> SVal {
    if (a.type->k == want) return a;
    if (a.type->k != TK::Never) bad(a);
    return never();
  });
}

// ---------------------------------------------------------------------------
// Conversion

SVal Specialiser::coerce(SVal v, TypeP to) {
  if (!v.type || v.type == to || v.type->k == TK::Never) return v;
  if (is_list(v.type) && is_list(to)) {
    if (!v.type->elem || v.code == nullptr) return SVal{to, ir_.node(ir::Op::MakeList, to), v.konst};
    // Element by element into a list of the wider element type.
    SVal src = let(v);
    ir::Var* out = ir_.decl(to, nullptr, "conv");
    ir_.emit_eval(ir_.call(ir::Helper::Reserve, nullptr, {ir_.local(out), ir_.node(ir::Op::Size, T().int_(), {src.code})}));
    ir::Stmt* loop = builtin_loop(ir::SK::ForEach);
    loop->var = ir_.var(v.type->elem, "x");
    loop->a = src.code;
    ir_.in_block(loop->body, [&] {
      SVal e = coerce(SVal{v.type->elem, ir_.local(loop->var)}, to->elem);
      ir_.emit_push(ir_.local(out), e.code);
    });
    return built(out);
  }
  if (is_sum(to)) {
    if (is_sum(v.type))
      return split(v, [&](const SVal& a) { return coerce(a, to); });
    for (size_t i = 0; i < to->alts.size(); ++i)
      if (T().fits(v.type, to->alts[i])) {
        SVal inner = coerce(v, to->alts[i]);
        ir::Node* n = ir_.node(ir::Op::MakeSum, to, {inner.code ? inner.code : ir_.lit(to->alts[i], 0)});
        n->index = static_cast<int>(i);
        return SVal{to, n, nullptr, v.fresh};
      }
  }
  sites_.unsupported("internal: no conversion from " + shown_type(type_string(v.type)) + " to " + shown_type(type_string(to)));
}

// ---------------------------------------------------------------------------
// Truthiness and equality

ir::Node* Specialiser::truthy(const SVal& v) {
  switch (v.type->k) {
    case TK::Bool: return v.code;
    case TK::List: return v.type->elem ? ir_.node(ir::Op::Not, T().bool_(), {ir_.node(ir::Op::Empty, T().bool_(), {v.code})})
                                       : ir_.lit(T().bool_(), 0);
    case TK::Never: return ir_.lit(T().bool_(), 0);
    case TK::Sum: return split(v, [&](const SVal& a) { return let(SVal{T().bool_(), truthy(a)}); }).code;
    default: return ir_.lit(T().bool_(), 1);
  }
}

// Field names of an instance type, as the interpreter's field_syms (user fields,
// origin, elems for user classes).
std::vector<Sym> Specialiser::instance_fields(TypeP t) {
  const WellKnownNames& n = p_.names;
  switch (t->k) {
    case TK::Pos: return {n.x, n.y};
    case TK::Elem: return {n.position, n.color};
    case TK::Cell: return {n.x, n.y, n.color};
    case TK::Obj: {
      std::vector<Sym> f = m_.classes[t->cls].fields;
      f.push_back(n.origin);
      f.push_back(n.elems);
      return f;
    }
    default: return {};
  }
}

SVal Specialiser::equals(const SVal& a, const SVal& b) {
  auto known = [&](bool v) { return SVal{T().bool_(), ir_.lit(T().bool_(), v), ir_.lit(T().bool_(), v)}; };
  return split(a, [&](const SVal& x) {
    return split(b, [&](const SVal& y) -> SVal {
      const TK l = x.type->k, r = y.type->k;
      if (l == TK::Never || r == TK::Never) return never();
      auto cx = const_int(x), cy = const_int(y);
      switch (l) {
        case TK::Int:
          if (r == TK::Int) return cx && cy ? known(*cx == *cy) : let(SVal{T().bool_(), ir_.node(ir::Op::Eq, T().bool_(), {x.code, y.code})});
          if (r == TK::Bool) {  // asymmetric, as in the reference
            if (cx && cy) return known(*cx == (*cy ? 1 : 0));
            ir::Node* as_int = ir_.node(ir::Op::Ne, T().int_(), {y.code, ir_.lit(T().bool_(), 0)});  // bool -> 0/1
            return let(SVal{T().bool_(), ir_.node(ir::Op::Eq, T().bool_(), {x.code, as_int})});
          }
          return known(false);
        case TK::Bool:
        case TK::Str:
          if (r != l) return known(false);
          if (cx && cy) return known(*cx == *cy);
          return let(SVal{T().bool_(), ir_.node(ir::Op::Eq, T().bool_(), {x.code, y.code})});
        case TK::Func:
          if (r != TK::Func) return known(false);
          if (x.type->fn.kind == FuncRef::Native && y.type == x.type) return known(true);
          if (x.type != y.type) return known(false);
          sites_.unsupported("equality of two function values made by the same lambda");
        case TK::List:
          if (r != TK::List) return known(false);
          return list_equals(x, y);
        default:
          if (!is_instance(x.type)) return known(false);
          if (!is_instance(y.type)) return known(false);
          return instance_equals(x, y);
      }
    });
  });
}

// Instances are equal when they have the same field names and every field of the
// left one equals the right one's field of that name.
SVal Specialiser::instance_equals(const SVal& x, const SVal& y) {
  std::vector<Sym> fx = instance_fields(x.type), fy = instance_fields(y.type);
  std::vector<Sym> sx = fx, sy = fy;
  std::sort(sx.begin(), sx.end());
  std::sort(sy.begin(), sy.end());
  if (sx != sy) return SVal{T().bool_(), ir_.lit(T().bool_(), 0), ir_.lit(T().bool_(), 0)};
  if (x.type == y.type && x.type->k != TK::Obj && x.type->k != TK::Cell)
    return let(SVal{T().bool_(), ir_.node(ir::Op::Eq, T().bool_(), {x.code, y.code})});
  // Field by field, stopping at the first difference (as the interpreter does:
  // the comparison itself cannot raise errors or draw, so order is not observable).
  ir::Var* r = ir_.decl(T().bool_(), ir_.lit(T().bool_(), 1), "same");
  ir::Block* outer = ir_.block();
  ir::Block* cur = ir_.block();
  for (Sym f : fx) {
    ir_.continue_in(*cur);
    SVal eq;
    if (f == p_.names.elems) {
      eq = cells_equal(x, y);
    } else {
      SVal a = instance_field(x, f), b = instance_field(y, f);
      eq = equals(a, b);
    }
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = ir_.node(ir::Op::Not, T().bool_(), {eq.code});
    s->body.push_back(&m_.arena.stmts.emplace_back());
    s->body.back()->k = ir::SK::Set;
    s->body.back()->a = ir_.local(r);
    s->body.back()->b = ir_.lit(T().bool_(), 0);
    cur = &s->other;
  }
  ir_.continue_in(*outer);
  return built(r);
}

// The `elems` of two objects compared (by printed form, as lists): objects of a
// class whose cells are the same for every object print the same cells.
SVal Specialiser::cells_equal(const SVal& x, const SVal& y) {
  const bool xs = !h_.stored_cells(x.type->cls), ys = !h_.stored_cells(y.type->cls);
  if (xs && ys && x.type->cls == y.type->cls) {
    if (!h_.rotated(x.type->cls)) return SVal{T().bool_(), ir_.lit(T().bool_(), 1), ir_.lit(T().bool_(), 1)};
    // Each rotate wraps the coordinates' expressions once more: equal prints, equal turns.
    auto turns = [&](const SVal& v) { return ir_.call(ir::Helper::RotOf, T().int_(), {ir_.member(v.code, ir::Member::Group, T().int_())}); };
    return let(SVal{T().bool_(), ir_.node(ir::Op::Eq, T().bool_(), {turns(x), turns(y)})});
  }
  sites_.unsupported("equality of objects whose cells may differ (it compares the cells' printed forms)");
}

// Lists compare by printed form, type tag included (values.cpp). Empty lists all
// print alike; beyond that the tags would have to be kept at run time.
SVal Specialiser::list_equals(const SVal& x, const SVal& y) {
  if (!x.type->elem && !y.type->elem) return SVal{T().bool_(), ir_.lit(T().bool_(), 1), ir_.lit(T().bool_(), 1)};
  if (!x.type->elem || !y.type->elem) {
    const SVal& other = x.type->elem ? x : y;
    return let(SVal{T().bool_(), ir_.node(ir::Op::Empty, T().bool_(), {other.code})});
  }
  sites_.unsupported("equality of lists (it compares printed forms, list type tags included)");
}

bool Specialiser::list_tag_may_pass(TypeP value, TypeP declared) {
  if (!value->elem) return true;
  return declared->k == TK::List && type_string(value) == type_string(declared);
}

// ---------------------------------------------------------------------------
// Identity

void Specialiser::note_identity(TypeP t) {
  if (!t) return;
  if (is_sum(t)) {
    for (TypeP a : t->alts) note_identity(a);
    return;
  }
  if (!is_instance(t)) {
    if (t->k == TK::List) sites_.unsupported("identity of a list (removeObj or prev by a list value)");
    return;
  }
  if (t->k == TK::Elem) sites_.unsupported("identity of rendered elements (removeObj or prev by one)");
  m_.uses_ids = true;
  if (h_.add_tracked(t)) {
    h_.learn("identity of " + type_string(t));
  }
}

ir::Node* Specialiser::id_of(const SVal& v) {
  if (!h_.tracked(v.type)) return ir_.lit(T().int_(), -1);  // not yet known to matter: the next walk tracks it
  return ir_.call(ir::Helper::IdOf, T().int_(), {ir_.member(v.code, ir::Member::Uid, T().int_())});
}

SVal Specialiser::fresh_identity(SVal v) {
  v.fresh = true;
  return v;
}

// Assignment to an existing variable gives the new value the old value's
// identity number (a fresh one when the old value was not an object).
void Specialiser::transfer_identity(const SVal& v, const SVal& old) {
  if (!h_.tracked(v.type)) return;
  ir::Node* uid = ir_.member(v.code, ir::Member::Uid, T().int_());
  ir::Node* id = nullptr;
  if (h_.tracked(old.type)) {
    id = id_of(old);
  } else if (is_sum(old.type)) {
    id = split(old, [&](const SVal& a) {
           return SVal{T().int_(), h_.tracked(a.type) ? id_of(a) : ir_.call(ir::Helper::NewUid, T().int_(), {})};
         }).code;
  } else {
    id = ir_.call(ir::Helper::NewUid, T().int_(), {});
  }
  ir_.emit_eval(ir_.call(ir::Helper::IdTransfer, nullptr, {uid, id}));
}

}  // namespace autumn::lower
