// spec_builtins — the native builtins, dispatched on the Builtin enum of
// compiler/analyse/builtins.hpp, each as compiler/interpret/builtins.cpp does it:
// the same argument checks and texts, the same order of calls and draws.
//
// Builtins that call a function argument (map, filter, foldl, any, updateObj,
// removeObj with a predicate) become loops whose body is the inlined function.
// Over a list known at compile time inside a constructor (cell shapes), the loop
// is unrolled so the cells fold to constants:
//
//   (map (--> i (Cell i 0 "red")) (range 0 3))   in an object's cell expression
//   -> three constant cells, no code at run time.
#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {
// ---------------------------------------------------------------------------
// Argument checks (the interpreter's need/list_arg/func_arg/num_arg)

bool Specialiser::need(Builtin b, size_t n) {
  const std::string why = builtin_arity_error(b, n);
  if (why.empty()) return true;
  fail(why);
  return false;
}

bool Specialiser::check_kind(Builtin b, const std::vector<SVal>& a, size_t i, TK k, const char* what) {
  if (a[i].type->k == k || a[i].type->k == TK::Never) return !ir_.dead();
  fail(std::string(builtin_name(b)) + ": argument " + std::to_string(i + 1) + " must be " + what + ", got " +
       shown(a[i].type));
  return false;
}

ir::Node* Specialiser::int_text(ir::Node* n) { return ir_.call(ir::Helper::StrOfInt, nullptr, {n}); }

SVal Specialiser::call1(const SVal& f, const SVal& x, const Expr& at) {
  std::vector<SVal> args{x};
  return call_value(f, args, at);
}

// GRID_SIZE as builtins look it up: dynamically, by name.
SVal Specialiser::grid_size(const Expr& at) {
  SVal g = read_name(p_.names.GRID_SIZE, at);
  if (g.type->k != TK::Int && g.type->k != TK::Never) {
    fail("GRID_SIZE must be a number");
    return never();
  }
  return g;
}

// ---------------------------------------------------------------------------

// A cell argument's trial that calls a builtin reading changing state is not
// fixed: it is evaluated at every render (spec_cells.cpp).
void Specialiser::note_reads(Builtin b) {
  if (capture_mode_ && (builtin_info(b).effects & kReadsChangingState)) trial_varies_ = true;
}

SVal Specialiser::call_builtin(Builtin b, std::vector<SVal>& a, const Expr& at) {
  // A builtin of one argument count: checked first, from the table, as the interpreter does.
  if (!need(b, a.size())) return never();
  note_reads(b);
  // A value of several types: one case per type (a dynamic site).
  for (size_t i = 0; i < a.size(); ++i)
    if (is_sum(a[i].type) && a[i].type->alts[0]->k != TK::Func) {
      sites_.dynamic_site(std::string("the argument of ") + builtin_name(b) + " has several possible types");
      return split(a[i], [&, i](const SVal& x) {
        std::vector<SVal> narrowed = a;
        narrowed[i] = x;
        return call_builtin(b, narrowed, at);
      });
    }
  return (this->*lowerings()[static_cast<int>(b)])(b, a, at);
}

// The lowering of each builtin, indexed by the Builtin enum. Several builtins
// may share one (map, filter, any and foldl are one loop); each is told which
// builtin it lowers.
const std::array<Specialiser::Lowering, kBuiltinCount>& Specialiser::lowerings() {
  static const std::array<Lowering, kBuiltinCount> table = [] {
    std::array<Lowering, kBuiltinCount> t{};
    auto set = [&t](Builtin b, Lowering l) { t[static_cast<int>(b)] = l; };
    for (Builtin b : {Builtin::Map, Builtin::Filter, Builtin::Any, Builtin::Foldl}) set(b, &Specialiser::builtin_iterate);
    set(Builtin::Concat, &Specialiser::builtin_concat);
    set(Builtin::Length, &Specialiser::builtin_length);
    set(Builtin::Head, &Specialiser::builtin_head_tail);
    set(Builtin::Tail, &Specialiser::builtin_head_tail);
    set(Builtin::At, &Specialiser::builtin_at);
    set(Builtin::Range, &Specialiser::builtin_range);
    set(Builtin::ArrayEqual, &Specialiser::builtin_array_equal);
    set(Builtin::IsList, &Specialiser::builtin_is_list);
    set(Builtin::Print, &Specialiser::builtin_print);
    set(Builtin::Sqrt, &Specialiser::builtin_sqrt);
    set(Builtin::UniformChoice, &Specialiser::builtin_uniform_choice);
    set(Builtin::RandomPositions, &Specialiser::builtin_random_positions);
    set(Builtin::AllPositions, &Specialiser::builtin_all_positions);
    set(Builtin::AdjPositions, &Specialiser::builtin_adj_positions);
    set(Builtin::IsFreePos, &Specialiser::builtin_is_free_pos);
    set(Builtin::IsWithinBounds, &Specialiser::builtin_within_bounds);
    set(Builtin::AddObj, &Specialiser::builtin_add_obj);
    set(Builtin::UpdateObj, &Specialiser::builtin_update_obj);
    set(Builtin::RemoveObj, &Specialiser::builtin_remove_obj);
    set(Builtin::Clicked, &Specialiser::builtin_clicked);
    for (Builtin b : {Builtin::Left, Builtin::Right, Builtin::Up, Builtin::Down}) set(b, &Specialiser::builtin_arrow);
    set(Builtin::Defined, &Specialiser::builtin_defined);
    set(Builtin::AllObjs, &Specialiser::builtin_all_objs);
    set(Builtin::Prev, &Specialiser::builtin_prev);
    set(Builtin::RenderAll, &Specialiser::builtin_render_all);
    set(Builtin::Rotate, &Specialiser::builtin_rotate);
    for (int i = 0; i < kBuiltinCount; ++i)
      if (!t[i]) {
        std::fprintf(stderr, "autumnc: internal error: builtin %s has no lowering\n", builtin_name(static_cast<Builtin>(i)));
        std::abort();
      }
    return t;
  }();
  return table;
}

SVal Specialiser::builtin_render_all(Builtin, std::vector<SVal>&, const Expr&) {
  sites_.unsupported("renderAll called by the program");
}

// ---------------------------------------------------------------------------
// map, filter, any, foldl

SVal Specialiser::builtin_iterate(Builtin b, std::vector<SVal>& a, const Expr& at) {
  const size_t n = a.size();
  if (b == Builtin::Any) {
    if (n != 1 && n != 2) {
      fail("any takes 1 or 2 arguments, got " + std::to_string(n));
      return never();
    }
  }
  const size_t fi = 0, li = b == Builtin::Foldl ? 2 : n - 1;
  const bool with_fn = !(b == Builtin::Any && n == 1);
  if (with_fn && a[fi].type->k != TK::Func && !is_sum(a[fi].type)) {
    fail(std::string(builtin_name(b)) + ": argument 1 must be a function, got " + shown(a[fi].type));
    return never();
  }
  if (!check_kind(b, a, li, TK::List, "a list")) return never();
  const SVal l = a[li];
  if (b == Builtin::Foldl) return fold(a[0], a[1], l, at);
  // filter checks values of several non-list types as it runs (check_kept_type).
  if (b == Builtin::Filter && l.type->elem)
    for (TypeP t : is_sum(l.type->elem) ? l.type->elem->alts : std::vector<TypeP>{l.type->elem}) check_appends(t, "filter");
  auto apply = [&](const SVal& x) { return with_fn ? call1(a[fi], x, at) : x; };
  if (!l.type->elem) {  // statically empty: the function is never called
    if (b == Builtin::Any) return SVal{T().bool_(), ir_.lit(T().bool_(), 0), ir_.lit(T().bool_(), 0)};
    return empty_list();
  }
  if (unroll(l)) {  // fold inside constructors: keeps cell shapes constant
    std::vector<SVal> out;
    for (ir::Node* item : l.konst->a) {
      SVal x{l.type->elem, item, item};
      SVal y = apply(x);
      if (ir_.dead()) return never();
      if (b == Builtin::Map) out.push_back(y);
      else {
        ir::Node* t = truthy(y);
        if (t->op != ir::Op::Lit) return iterate_loop(b, a, l, at, apply);  // not constant after all
        if (t->imm && b == Builtin::Any) return SVal{T().bool_(), ir_.lit(T().bool_(), 1), ir_.lit(T().bool_(), 1)};
        if (t->imm) out.push_back(x);
      }
    }
    if (b == Builtin::Any) return SVal{T().bool_(), ir_.lit(T().bool_(), 0), ir_.lit(T().bool_(), 0)};
    return make_list(out);
  }
  return iterate_loop(b, a, l, at, apply);
}

// The interpreter builds filter's, updateObj's (with a predicate) and
// uniformChoice's (with a count) lists by appending, and each append compares
// the element's run-time type with the one appended before (objects exempt):
// "list element type mismatch". A list's type is its run-time tag, and values
// of several types differ at run time; either is left to the embedded
// interpreter (found by a stress program: filter over (list 1 "a") ran on).
void Specialiser::check_appends(TypeP elem, const char* what) {
  if (!elem) return;
  bool varies = elem->k == TK::List;
  if (is_sum(elem))
    for (TypeP a : elem->alts) varies |= a->k != TK::Obj;
  if (varies)
    sites_.unsupported(std::string(what) + " appending values whose run-time types the interpreter compares (lists, or values of several types)");
}

bool Specialiser::unroll(const SVal& l) const {
  return !constructing_.empty() && l.konst && l.konst->op == ir::Op::MakeList && l.konst->a.size() <= 4096 &&
         !h_.tracked(l.type->elem);
}

SVal Specialiser::iterate_loop(Builtin b, std::vector<SVal>& a, const SVal& l, const Expr& at,
                               const std::function<SVal(const SVal&)>& apply) {
  (void)a;
  (void)at;
  SVal src = let(l, "src");
  ir::Stmt* loop = ir_.emit_detached(ir::SK::ForEach);
  loop->var = ir_.var(l.type->elem, "x");
  loop->a = src.code;
  SVal x{l.type->elem, ir_.local(loop->var)};
  SVal y;
  bool body_alive = true;
  ir_.in_block(loop->body, [&] {
    y = apply(x);
    body_alive = !ir_.dead();
  });
  TypeP rt = b == Builtin::Map ? (body_alive && y.type ? y.type : T().never()) : l.type->elem;
  if (b == Builtin::Map && (rt->k == TK::Func || rt->k == TK::Class))
    sites_.unsupported("map producing functions");
  if (b == Builtin::Map && !y.type) sites_.unsupported("map whose function has no value");
  TypeP out_t = b == Builtin::Any ? T().bool_() : (rt->k == TK::Never ? T().empty_list() : T().list(rt));
  ir::Var* out = ir_.decl(out_t, b == Builtin::Any ? ir_.lit(T().bool_(), 0) : nullptr, b == Builtin::Any ? "any" : "out");
  if (b == Builtin::Map && rt->k != TK::Never) {
    charge_built(ir::kLengthSizes, {src.code});
    ir_.emit_eval(ir_.call(ir::Helper::Reserve, nullptr, {ir_.local(out), ir_.node(ir::Op::Size, T().int_(), {src.code})}));
  }
  // filter over values of several types: the alternative appended last, for
  // the interpreter's check of each appended element (check_kept_type).
  ir::Var* last_kept = nullptr;
  if (b == Builtin::Filter && is_sum(l.type->elem) && !is_object_like(l.type->elem))
    last_kept = ir_.decl(T().int_(), ir_.lit(T().int_(), -1), "last_kept");
  if (!ir_.dead()) ir_.block()->push_back(loop);
  if (body_alive)
    ir_.in_block(loop->body, [&] {
      if (b == Builtin::Map) {
        if (rt->k == TK::Never) return;
        ir_.emit_push(ir_.local(out), y.code);
        return;
      }
      ir::Node* cond = truthy(y);
      ir::Stmt* s = ir_.emit(ir::SK::If);
      s->a = cond;
      ir_.in_block(s->body, [&] {
        if (b == Builtin::Any) {
          ir_.emit_set(ir_.local(out), ir_.lit(T().bool_(), 1));
          ir_.emit(ir::SK::Break);
        } else {
          charge_one_built();
          if (last_kept) check_kept_type(x, last_kept);
          ir_.emit_push(ir_.local(out), x.code);
        }
      });
    });
  return built(out);
}

// The interpreter's list_add as filter appends x: an element that is not an
// instance (an object of a user class, a Position, a Cell, a RenderedElem) must
// have the run-time type of the element appended before it ("list element type
// mismatch"), where every function has one type; `last` holds that one's
// alternative, the first function alternative for any function (-1: none).
// Found by a stress program (round z2): a Position after an object, and two
// different functions, failed on the compiled engine only.
void Specialiser::check_kept_type(const SVal& x, ir::Var* last) {
  const std::vector<TypeP>& alts = x.type->alts;
  auto run_time_type = [&](size_t j) {
    if (alts[j]->k != TK::Func) return static_cast<int>(j);
    return static_cast<int>(std::find_if(alts.begin(), alts.end(), [](TypeP t) { return t->k == TK::Func; }) - alts.begin());
  };
  split(x, [&](const SVal& a) -> SVal {
    const int i = run_time_type(std::find(alts.begin(), alts.end(), a.type) - alts.begin());
    if (!is_instance(a.type)) {
      ir::Stmt* differs = ir_.emit(ir::SK::If);
      differs->a = ir_.node(ir::Op::And, T().bool_(),
                            {ir_.node(ir::Op::Ge, T().bool_(), {ir_.local(last), ir_.lit(T().int_(), 0)}),
                             ir_.node(ir::Op::Ne, T().bool_(), {ir_.local(last), ir_.lit(T().int_(), i)})});
      ir_.in_block(differs->body, [&] {
        ir::Stmt* sw = ir_.emit(ir::SK::Switch);
        sw->a = ir_.local(last);
        for (size_t j = 0; j < alts.size(); ++j) {
          if (run_time_type(j) != static_cast<int>(j) || static_cast<int>(j) == i) continue;
          sw->cases.emplace_back(static_cast<int>(j), ir::Block{});
          ir_.in_block(sw->cases.back().second, [&] {
            fail("list element type mismatch: got " + shown(a.type) + ", expected " + shown(alts[j]));
          });
        }
      });
    }
    ir_.emit_set(ir_.local(last), ir_.lit(T().int_(), i));
    return SVal{T().int_(), ir_.lit(T().int_(), 0)};
  });
}

// foldl: the accumulator's type is the join of the initial value's and the
// function's results; a result that does not fit widens it for the next walk.
SVal Specialiser::fold(const SVal& f, const SVal& init, const SVal& l, const Expr& at) {
  std::pair<const void*, Sym> key{&at, -1};
  TypeP acc_t = init.type;
  if (TypeP hinted = h_.local(key)) acc_t = T().join(acc_t, hinted);
  if (!l.type->elem) return init;
  if (unroll(l)) {
    SVal acc = init;
    for (ir::Node* item : l.konst->a) {
      std::vector<SVal> args{acc, SVal{l.type->elem, item, item}};
      acc = let(call_value(f, args, at));
      if (ir_.dead()) return never();
    }
    return acc;
  }
  ir::Var* acc = ir_.decl(acc_t, coerce(init, acc_t).code, "acc");
  SVal src = let(l, "src");
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(l.type->elem, "x");
  loop->a = src.code;
  ir_.in_block(loop->body, [&] {
    SVal accv = let(SVal{acc_t, ir_.local(acc)}, "a");
    std::vector<SVal> args{accv, SVal{l.type->elem, ir_.local(loop->var)}};
    SVal y = call_value(f, args, at);
    if (ir_.dead() || !y.type) return;
    if (!T().fits(y.type, acc_t)) {
      h_.set_local(key, T().join(acc_t, y.type));
      h_.learn("foldl accumulator");
      return;
    }
    ir_.emit_set(ir_.local(acc), coerce(y, acc_t).code);
  });
  return let(SVal{acc_t, ir_.local(acc)}, "folded");
}

// ---------------------------------------------------------------------------
// concat, length, head, tail, at, range, arrayEqual, isList, print, sqrt

SVal Specialiser::builtin_is_list(Builtin, std::vector<SVal>& a, const Expr&) {
  const bool v = a[0].type->k == TK::List;
  return SVal{T().bool_(), ir_.lit(T().bool_(), v), ir_.lit(T().bool_(), v)};
}

SVal Specialiser::builtin_print(Builtin, std::vector<SVal>& a, const Expr&) { return a[0]; }

SVal Specialiser::builtin_sqrt(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::Int, "a number")) return never();
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.node(ir::Op::Lt, T().bool_(), {a[0].code, ir_.lit(T().int_(), 0)});
  ir_.in_block(s->body, [&] { fail("sqrt of a negative number"); });
  return let(SVal{T().int_(), ir_.call(ir::Helper::Sqrt, T().int_(), {a[0].code})});
}

SVal Specialiser::builtin_length(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  if (!a[0].type->elem) return SVal{T().int_(), ir_.lit(T().int_(), 0), ir_.lit(T().int_(), 0)};
  if (a[0].konst && a[0].konst->op == ir::Op::MakeList) {
    auto c = static_cast<int64_t>(a[0].konst->a.size());
    return SVal{T().int_(), ir_.lit(T().int_(), c), ir_.lit(T().int_(), c)};
  }
  return let(SVal{T().int_(), ir_.node(ir::Op::Size, T().int_(), {a[0].code})});
}

// head and tail: the first or the last element (the reference's tail is its last element).
SVal Specialiser::builtin_head_tail(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  const char* what = b == Builtin::Head ? "head of an empty list" : "tail of an empty list";
  if (!a[0].type->elem) {
    fail(what);
    return never();
  }
  if (a[0].konst && a[0].konst->op == ir::Op::MakeList && !a[0].konst->a.empty() && !h_.tracked(a[0].type->elem)) {
    ir::Node* k = b == Builtin::Head ? a[0].konst->a.front() : a[0].konst->a.back();
    return SVal{a[0].type->elem, k, is_const(k) ? k : nullptr};
  }
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.node(ir::Op::Empty, T().bool_(), {a[0].code});
  ir_.in_block(s->body, [&] { fail(what); });
  return let(SVal{a[0].type->elem, ir_.node(b == Builtin::Head ? ir::Op::Front : ir::Op::Back, a[0].type->elem, {a[0].code})});
}

SVal Specialiser::builtin_range(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::Int, "a number") || !check_kind(b, a, 1, TK::Int, "a number"))
    return never();
  auto lo = const_int(a[0]), hi = const_int(a[1]);
  std::optional<int64_t> known;
  if (lo && hi) known = *hi - *lo;
  check_length(ir::kLengthSpan, {a[0].code, a[1].code}, known);
  if (lo && hi && *hi - *lo <= 4096) {
    std::vector<SVal> items;
    for (int64_t i = *lo; i < *hi; ++i) items.push_back(SVal{T().int_(), ir_.lit(T().int_(), i), ir_.lit(T().int_(), i)});
    if (!items.empty() && (!constructing_.empty() || items.size() <= 16)) return make_list(items);
  }
  charge_built(ir::kLengthSpan, {a[0].code, a[1].code});
  ir::Var* out = ir_.decl(T().list(T().int_()), nullptr, "range");
  out->scratch = true;
  ir::Stmt* loop = builtin_loop(ir::SK::ForRange);
  loop->var = ir_.var(T().int_(), "i");
  loop->a = a[0].code;
  loop->b = a[1].code;
  ir_.in_block(loop->body, [&] { ir_.emit_push(ir_.local(out), ir_.local(loop->var)); });
  return built(out);
}

SVal Specialiser::builtin_at(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  if (!a[0].type->elem) {
    fail("at: empty list");
    return never();
  }
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.node(ir::Op::Empty, T().bool_(), {a[0].code});
  ir_.in_block(s->body, [&] { fail("at: empty list"); });
  if (!check_kind(b, a, 1, TK::Int, "a number")) return never();
  ir::Node* i = a[1].code;
  ir::Stmt* r = ir_.emit(ir::SK::If);
  r->a = ir_.node(ir::Op::Or, T().bool_(), {ir_.node(ir::Op::Lt, T().bool_(), {i, ir_.lit(T().int_(), 0)}),
                                        ir_.node(ir::Op::Ge, T().bool_(), {i, ir_.node(ir::Op::Size, T().int_(), {a[0].code})})});
  ir_.in_block(r->body, [&] { fail({ir_.text("at: index "), int_text(i), ir_.text(" out of bounds")}); });
  return let(SVal{a[0].type->elem, ir_.node(ir::Op::Index, a[0].type->elem, {a[0].code, i})});
}

SVal Specialiser::builtin_concat(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::List, "a list")) return never();
  const SVal l = a[0];
  if (!l.type->elem) return empty_list();
  TypeP inner = l.type->elem;
  if (inner->k != TK::List) {
    if (is_sum(inner)) sites_.unsupported("concat of a list holding lists and other values");
    fail("concat: every element must be a list");
    return never();
  }
  bool checked = false;  // the list-length budget
  if (l.konst && l.konst->op == ir::Op::MakeList && !(inner->elem && h_.tracked(inner->elem))) {  // fold
    std::vector<SVal> items;
    bool ok = true;
    for (ir::Node* part : l.konst->a) {
      if (part->op != ir::Op::MakeList) ok = false;
      else
        for (ir::Node* x : part->a) items.push_back(SVal{inner->elem ? inner->elem : T().never(), x, x});
    }
    if (ok) {
      check_length(ir::kLengthIs, {ir_.lit(T().int_(), static_cast<int64_t>(items.size()))},
                   static_cast<int64_t>(items.size()));
      checked = true;
    }
    if (ok && (!constructing_.empty() || items.size() <= 16)) return items.empty() ? empty_list() : make_list(items);
  }
  if (!inner->elem) return empty_list();
  if (!l.parts.empty()) {  // (concat (list a b ...)): the parts are known, no list of lists is needed
    if (!checked) check_length(ir::kLengthSizes, l.parts);
    charge_built(ir::kLengthSizes, l.parts);
    ir::Var* out = ir_.decl(inner, nullptr, "cat");
    for (ir::Node* part : l.parts) ir_.emit_eval(ir_.call(ir::Helper::Append, nullptr, {ir_.local(out), part}));
    return built(out);
  }
  SVal src = let(l, "src");
  if (!checked) check_length(ir::kLengthTotal, {src.code});
  charge_built(ir::kLengthTotal, {src.code});
  ir::Var* out = ir_.decl(inner, nullptr, "cat");
  ir::Stmt* loop = builtin_loop(ir::SK::ForEach);
  loop->var = ir_.var(inner, "part");
  loop->a = src.code;
  ir_.in_block(loop->body, [&] { ir_.emit_eval(ir_.call(ir::Helper::Append, nullptr, {ir_.local(out), ir_.local(loop->var)})); });
  return built(out);
}

SVal Specialiser::builtin_array_equal(Builtin b, std::vector<SVal>& a, const Expr&) {
  if (!check_kind(b, a, 0, TK::List, "a list") || !check_kind(b, a, 1, TK::List, "a list"))
    return never();
  TypeP out_t = T().list(T().bool_());
  if (!a[0].type->elem || !a[1].type->elem) {
    if (a[0].type->elem || a[1].type->elem) {
      ir::Stmt* s = ir_.emit(ir::SK::If);
      s->a = ir_.node(ir::Op::Not, T().bool_(), {ir_.node(ir::Op::Empty, T().bool_(), {a[a[0].type->elem ? 0 : 1].code})});
      ir_.in_block(s->body, [&] { fail("arrayEqual: lists of different lengths"); });
    }
    return empty_list();
  }
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.node(ir::Op::Ne, T().bool_(), {ir_.node(ir::Op::Size, T().int_(), {a[0].code}), ir_.node(ir::Op::Size, T().int_(), {a[1].code})});
  ir_.in_block(s->body, [&] { fail("arrayEqual: lists of different lengths"); });
  charge_built(ir::kLengthSizes, {a[0].code});
  ir::Var* out = ir_.decl(out_t, nullptr, "eqs");
  ir::Stmt* loop = builtin_loop(ir::SK::ForRange);
  loop->var = ir_.var(T().int_(), "i");
  loop->a = ir_.lit(T().int_(), 0);
  loop->b = ir_.node(ir::Op::Size, T().int_(), {a[0].code});
  ir_.in_block(loop->body, [&] {
    SVal x = let(SVal{a[0].type->elem, ir_.node(ir::Op::Index, a[0].type->elem, {a[0].code, ir_.local(loop->var)})});
    SVal y = let(SVal{a[1].type->elem, ir_.node(ir::Op::Index, a[1].type->elem, {a[1].code, ir_.local(loop->var)})});
    SVal e = equals(x, y);
    ir_.emit_push(ir_.local(out), e.code);
  });
  return built(out);
}

}  // namespace autumn::lower
