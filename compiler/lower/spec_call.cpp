// spec_call — calls, inlining, object construction and field access.
//
// A lambda call is inlined: a new static scope binds the parameters to the
// argument values, the body is specialised in place (so dynamic scoping resolves
// the body's free names through the caller's scopes, as in the interpreter).
// A parameter that no assignment anywhere can target is just a name for the
// argument value; otherwise it is a variable of its own.
//
// Construction inlines the class's initializer (analyse builds it): the fields
// and origin are the arguments, the cell expression runs in an Instance scope,
// and its result becomes the object's cells (spec_cells.cpp decides whether
// objects of the class need to carry them).
#include <algorithm>

#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {

std::string Specialiser::class_name(int c) const {
  switch (c) {
    case kPositionClass: return "Position";
    case kCellClass: return "Cell";
    case kElemClass: return "RenderedElem";
    default: return c >= 0 ? m_.classes[c].name : std::string();  // primitive types have no name
  }
}

std::optional<int> Specialiser::type_named(Sym s) const {
  const WellKnownNames& n = p_.names;
  if (s == n.Position) return kPositionClass;
  if (s == n.Cell) return kCellClass;
  if (s == n.RenderedElem) return kElemClass;
  if (s == n.Bool) return kBoolType;
  if (s == n.String) return kStringType;
  if (s == n.Number || s == n.Int) return kNumberType;
  if (s >= 0 && s < static_cast<Sym>(f_.class_of_sym.size()) && f_.class_of_sym[s] >= 0 && class_defined_[f_.class_of_sym[s]])
    return f_.class_of_sym[s];
  return std::nullopt;
}

// ---------------------------------------------------------------------------
// Calls

SVal Specialiser::lower_call(const Expr& e) {
  const size_t nargs = e.kids.size() - 1;
  if (e.kids[0]->kind == ExprKind::Get && e.kids[0]->name == p_.names.render) return call_render(e);
  SVal callee = lower(*e.kids[0]);
  if (ir_.dead()) return never();
  auto args_of = [&]() {
    std::vector<SVal> args;
    for (size_t i = 1; i <= nargs && !ir_.dead(); ++i) args.push_back(let(lower_value(*e.kids[i]), "arg"));
    return args;
  };
  if (callee.type && callee.type->k == TK::Class) {
    const int c = callee.type->cls;
    if (c <= kBoolType) {
      fail("'" + std::string(c == kBoolType ? "Bool" : c == kStringType ? "String" : "Number") +
           "' is not a class and cannot be called");
      return never();
    }
    if (c == kCellClass) return construct_cell(e);
    std::vector<SVal> args = args_of();
    if (ir_.dead()) return never();
    if (c == kPositionClass || c == kElemClass) return construct_builtin_class(c, args);
    return construct(c, args, e);
  }
  if (callee.type && callee.type->k == TK::Deferred) return call_deferred(callee);
  // (prev x) reads the name x in the snapshot: its argument is not evaluated.
  if (callee.type && callee.type->k == TK::Func && callee.type->fn.kind == FuncRef::Native &&
      callee.type->fn.builtin == Builtin::Prev)
    return lower_prev(e);
  if (callee.type && is_sum(callee.type) && !is_function(callee.type))  // a function or not, decided at run time
    return split(callee, [&](const SVal& f) -> SVal {
      if (f.type->k != TK::Func) {
        fail("only functions and classes can be called, got " + shown(f.type));
        return never();
      }
      std::vector<SVal> args = args_of();
      if (ir_.dead()) return never();
      return call_value(f, args, e);
    });
  if (!callee.type || !(callee.type->k == TK::Func || (is_sum(callee.type) && callee.type->alts[0]->k == TK::Func))) {
    fail("only functions and classes can be called, got " + (callee.type ? shown(callee.type) : "Unknown"));
    return never();
  }
  if (callee.type->k == TK::Func && callee.type->fn.kind == FuncRef::Native && callee.type->fn.builtin == Builtin::Filter &&
      nargs == 2 && calls_all_objs(*e.kids[2]))
    return lower_filter_call(callee, e);
  std::vector<SVal> args = args_of();
  if (ir_.dead()) return never();
  return call_value(callee, args, e);
}

// (filter f ((allObjs))): its arguments in order, as any call's; with f a
// function, the objects are filtered as allObjs meets them (filter_all_objs).
SVal Specialiser::lower_filter_call(const SVal& callee, const Expr& e) {
  std::vector<SVal> args{let(lower_value(*e.kids[1]), "arg")};
  if (ir_.dead()) return never();
  const TypeP ft = args[0].type;
  if ((ft->k == TK::Func || (is_sum(ft) && ft->alts[0]->k == TK::Func)) && !h_.unfused(&e))
    return filter_all_objs(args[0], *e.kids[2], e);
  args.push_back(let(lower_value(*e.kids[2]), "arg"));
  if (ir_.dead()) return never();
  return call_value(callee, args, e);
}

bool Specialiser::calls_all_objs(const Expr& e) {
  return e.kind == ExprKind::Call && e.kids.size() == 1 && e.kids[0]->kind == ExprKind::Var &&
         means_builtin(e.kids[0]->name, Builtin::AllObjs);
}

bool Specialiser::means_builtin(Sym s, Builtin b) {
  if (scopes_.binds(s)) return false;
  Global* g = global(s);
  SVal v = g && g->state == Global::Defined ? read_global(*g) : SVal{};
  return v.type && v.type->k == TK::Func && v.type->fn.kind == FuncRef::Native && v.type->fn.builtin == b;
}

// ((.. o render) args...): the render method of o's class, called at once (the
// stdlib's renderValue does this): o's rendered elements, a fresh list.
SVal Specialiser::call_render(const Expr& e) {
  const Expr& get = *e.kids[0];
  sites_.enter(&get);
  SVal o = lower_value(*get.kids[0]);
  sites_.leave();
  if (ir_.dead()) return never();
  return split(o, [&](const SVal& x) -> SVal {
    // An object's render is its method: a class with a field named render is
    // the embedded interpreter's (check_render_lookups).
    sites_.enter(&get);
    SVal f = x.type->k == TK::Obj ? SVal{} : get_field(x, p_.names.render, get.text);
    sites_.leave();
    if (ir_.dead()) return never();
    std::vector<SVal> args;
    for (size_t i = 1; i < e.kids.size() && !ir_.dead(); ++i) args.push_back(let(lower_value(*e.kids[i]), "arg"));
    if (ir_.dead()) return never();
    if (!f.type) return render_value(x, e);
    return call_value(f, args, e);
  });
}

SVal Specialiser::call_value(const SVal& f, std::vector<SVal>& args, const Expr& at) {
  if (is_sum(f.type)) {  // which function is decided at run time: a case per function
    return split(f, [&](const SVal& g) { return call_value(g, args, at); });
  }
  if (f.type->k == TK::Never) return never();
  if (f.type->k == TK::Deferred) return call_deferred(f);
  if (f.type->k != TK::Func) {
    fail("only functions and classes can be called, got " + shown(f.type));
    return never();
  }
  const FuncRef& fr = f.type->fn;
  switch (fr.kind) {
    case FuncRef::Lambda: return inline_lambda(*fr.lambda, args, at);
    case FuncRef::Native: return call_builtin(fr.builtin, args, at);
    case FuncRef::Method: return call_render_method(fr.cls);
  }
  return never();
}

// The stdlib's renderValue on objects (or lists of them, nested) renders each
// object in order and concatenates: rendering straight into one list does the
// same without a list per element, as long as the names its body uses (map,
// concat, isList, renderValue) still mean the stdlib's here.
bool Specialiser::render_value_shortcut(const Expr& lambda, const std::vector<SVal>& args) {
  if (args.empty() || &lambda != f_.stdlib_render_value) return false;
  std::function<bool(TypeP)> objects = [&](TypeP t) {
    if (t->k == TK::Obj) return true;
    if (t->k == TK::List) return !t->elem || objects(t->elem);
    if (t->k == TK::Sum)
      for (TypeP a : t->alts)
        if (!objects(a)) return false;
    return t->k == TK::Sum;
  };
  if (!objects(args[0].type)) return false;
  auto native = [&](const char* name, Builtin b) { return means_builtin(p_.symbols.find(name), b); };
  auto is_this_lambda = [&] {
    const Sym rv = p_.symbols.find("renderValue");
    Global* g = scopes_.binds(rv) ? nullptr : global(rv);
    SVal v = g && g->state == Global::Defined ? read_global(*g) : SVal{};
    return v.type && v.type->k == TK::Func && v.type->fn.lambda == &lambda;
  };
  return native("map", Builtin::Map) && native("concat", Builtin::Concat) && native("isList", Builtin::IsList) &&
         is_this_lambda();
}

SVal Specialiser::inline_lambda(const Expr& lambda, std::vector<SVal>& args, const Expr& at, ScopeKind kind) {
  if (kind == ScopeKind::Local && render_value_shortcut(lambda, args)) {
    const Sym saved = std::exchange(render_value_param_, lambda.params.empty() ? -1 : lambda.params[0]);
    SVal r = render_value(args[0], at);
    render_value_param_ = saved;
    return r;
  }
  if (args.size() < lambda.params.size()) {
    fail("function called with " + std::to_string(args.size()) + " argument(s) but it takes " +
         std::to_string(lambda.params.size()) + " (the reference interpreter crashes here)");
    return never();
  }
  // Recursion is inlined while the argument types keep changing (renderValue on
  // nested lists); the same lambda with the same argument types again is a loop.
  std::vector<TypeP> sig;
  for (const SVal& a : args) sig.push_back(a.type);
  int depth = 0;
  for (const auto& [l, s] : inline_sigs_)
    if (l == &lambda) ++depth;
  for (const auto& [l, s] : inline_sigs_)
    if (l == &lambda && s == sig && depth >= 2) sites_.unsupported("recursion");
  if (inline_sigs_.size() > 64) sites_.unsupported("calls nested too deeply to inline");
  SScope* sc = scopes_.push(kind, ir_.block());
  for (size_t i = 0; i < lambda.params.size(); ++i) bind(*sc, lambda.params[i], args[i], {&lambda, lambda.params[i]});
  if (lambda.loc.source == SourceId::Program) ir_.comment("inlined: function at " + where(lambda.loc));
  inline_sigs_.emplace_back(&lambda, sig);
  SVal r = lower(*lambda.kids[0]);
  inline_sigs_.pop_back();
  scopes_.pop();
  if (ir_.dead()) return never();
  if (!r.type || r.type->k == TK::Class) {
    fail("the function body has no value");
    return never();
  }
  return r;
}

// Binds a name in a scope (a later parameter of the same name replaces the
// earlier one). The binding names the value itself, unless an assignment was
// found to target it (then it is a variable of its own).
void Specialiser::bind(SScope& sc, Sym p, const SVal& v, std::pair<const void*, Sym> key) {
  sc.vars.erase(std::remove_if(sc.vars.begin(), sc.vars.end(), [&](const Binding& b) { return b.sym == p; }),
                sc.vars.end());
  Binding b;
  b.sym = p;
  b.key = key;
  b.type = v.type;
  b.konst = v.konst;
  b.home = ir_.block();
  if (h_.mutable_binding(key) && v.code && v.type->k != TK::Never) {
    if (TypeP hinted = h_.local(key)) b.type = T().join(hinted, v.type);
    ir::Var* x = ir_.decl(b.type, coerce(v, b.type).code, "a_" + nm(p));
    b.place = ir_.local(x);
    b.mut = true;
  } else {
    b.place = v.code;
  }
  sc.vars.push_back(b);
}

SVal Specialiser::built(ir::Var* v) {
  v->mut = false;
  return SVal{v->type, ir_.local(v), nullptr, true};
}

// The interpreter runs a builtin's loop inside one builtin call, and its calls
// budget counts calls of the program's functions only (call_lambda), so such a
// loop charges nothing to the compiled engine's stand-in for it (charge_loop,
// docs/design.md "Limits"): charged, `(allPositions 20000000 0)` stopped the
// compiled engine where the interpreter ran on (found by a stress program,
// round y; tests/limits/builtin_loops.au). What the loop builds is charged to
// the cells budget (charge_built) and its length checked before it runs.
ir::Stmt* Specialiser::builtin_loop(ir::SK kind) {
  ir::Stmt* loop = ir_.emit(kind);
  loop->charged = false;
  return loop;
}

// ---------------------------------------------------------------------------
// Construction

SVal Specialiser::construct_builtin_class(int c, std::vector<SVal>& args) {
  const bool pos = c == kPositionClass;
  const char* name = pos ? "Position" : "RenderedElem";
  if (args.size() != 2) {
    fail(std::string("'") + name + "' takes 2 field value(s), got " + std::to_string(args.size()));
    return never();
  }
  const std::vector<std::pair<const char*, TypeP>> want =
      pos ? std::vector<std::pair<const char*, TypeP>>{{"x", T().int_()}, {"y", T().int_()}}
          : std::vector<std::pair<const char*, TypeP>>{{"position", T().pos()}, {"color", T().str()}};
  for (size_t i = 0; i < 2; ++i) {
    SVal ok = split(args[i], [&](const SVal& a) -> SVal {
      if (a.type->k != TK::Never && type_string(a.type) != type_string(want[i].second) &&
          !(a.type->k == TK::List && !a.type->elem)) {
        fail(std::string("field '") + want[i].first + "' of '" + name + "' must be " + shown(want[i].second) +
             ", got " + shown(a.type));
        return never();
      }
      return a;
    });
    if (ir_.dead()) return never();
    args[i] = coerce(ok, want[i].second);
  }
  // A coordinate that is never computed (a value the walk only reaches where
  // evaluation has already failed) makes no Position either (found by fuzz_emit:
  // a MakePos with a null operand crashed the printer).
  if (args[0].type->k == TK::Never || args[1].type->k == TK::Never) return never();
  if (pos) return make_position(args[0], args[1]);
  return fresh_identity(let(SVal{T().elem(), ir_.node(ir::Op::MakeElem, T().elem(), {args[0].code, args[1].code})}));
}

SVal Specialiser::make_position(SVal x, SVal y) {
  SVal v{T().pos(), ir_.node(ir::Op::MakePos, T().pos(), {x.code, y.code})};
  if (x.konst && y.konst) v.konst = ir_.node(ir::Op::MakePos, T().pos(), {x.konst, y.konst});
  if (h_.tracked(T().pos())) {  // every Position the reference makes is a new object
    v.code->a.push_back(ir_.call(ir::Helper::NewUid, T().int_(), {}));
    v = let(v);
  } else if (const_int(x) && const_int(y)) {
    v.code = v.konst;
  } else {
    v = let(v);
  }
  v.fresh = true;
  return v;
}

SVal Specialiser::construct(int cls, std::vector<SVal>& args, const Expr& at) {
  ClassInfo& ci = m_.classes[cls];
  const Expr& ctor = *ci.stmt->constructor_body;
  if (args.size() < ctor.params.size()) {
    fail("function called with " + std::to_string(args.size()) + " argument(s) but it takes " +
         std::to_string(ctor.params.size()) + " (the reference interpreter crashes here)");
    return never();
  }
  // A constructor that (through its cells) constructs its own class again
  // recurses without a bound in this lowering, which inlines every constructor.
  if (std::find(constructing_.begin(), constructing_.end(), cls) != constructing_.end()) {
    sites_.unsupported("recursion: an object whose construction makes another of its class");
  }
  // The initializer: (list f1 .. fn origin (let (= allCells CELLS) ...)) in an Instance scope.
  SScope* sc = scopes_.push(ScopeKind::Instance, ir_.block());
  for (size_t i = 0; i < ctor.params.size(); ++i) bind(*sc, ctor.params[i], args[i], {&ctor, ctor.params[i]});
  constructing_.push_back(cls);
  const Expr& made = *ctor.kids[0];
  std::vector<SVal> values;
  for (size_t i = 0; i + 1 < made.kids.size() && !ir_.dead(); ++i) values.push_back(let(lower_value(*made.kids[i])));
  // The cells are computed aside: when every object of the class gets the same
  // constant cells and computing them has no effect, the objects do not carry
  // them and nothing of that computation needs to run.
  ir::Block cells_block;
  SVal cells;
  const size_t effects_before = ir_.effects();
  bool died = ir_.dead();
  if (!died)
    ir_.in_block(cells_block, [&] {
      cells = lower_value(*made.kids.back());
      died = ir_.dead();
    });
  constructing_.pop_back();
  const bool pure = ir_.effects() == effects_before && !has_fail(cells_block);
  const bool shared = !h_.stored_cells(cls) && !h_.tracked(T().cell()) && cells.konst;
  if (!(pure && shared) && !ir_.dead()) ir_.block()->insert(ir_.block()->end(), cells_block.begin(), cells_block.end());
  if (died) ir_.kill();
  scopes_.pop();
  if (ir_.dead()) return never();
  (void)at;
  return make_instance(cls, values, cells);
}

// The interpreter's make_instance check of field i's value against the type
// its class declares (an error where they differ; a case per alternative of a sum).
void Specialiser::check_field_type(int cls, size_t i, TypeP declared, const SVal& value) {
  const ClassInfo& ci = m_.classes[cls];
  const std::string want = type_string(declared);
  split(value, [&](const SVal& v) -> SVal {
    if (v.type->k == TK::Never) return v;
    if (!check_printable(v.type) || !check_printable(declared)) return v;
    if (v.type->k == TK::List) {
      if (!list_tag_may_pass(v.type, declared))
        sites_.unsupported("a list field given a list of another element type (the check reads the list's type tag)");
      return v;
    }
    if (type_string(v.type) != want)
      fail("field '" + ci.field_names[i] + "' of '" + ci.name + "' must be " + shown_type(want) + ", got " +
           shown(v.type));
    return v;
  });
}

// A copy of an object (updateObj's, addObj's, rotate's) is a new instance to the
// interpreter (copy_value), so its fields are checked as make_instance checks
// them: a field updateObj gave a value of another type fails at the next copy.
// Only fields whose slot may hold another type than the declared one are read.
bool Specialiser::check_copy(const SVal& o) {
  if (o.type->k != TK::Obj) return true;
  const int cls = o.type->cls;
  const ClassInfo& ci = m_.classes[cls];
  for (size_t i = 0; i < ci.fields.size(); ++i) {
    TypeP declared = declared_type(*ci.stmt->fields[i].type);
    TypeP slot = ci.field_types[i];
    if (!declared || !slot || type_string(slot) == type_string(declared)) continue;
    check_field_type(cls, i, declared, let(SVal{slot, ir_.member(o.code, ir::Member::Field, slot, static_cast<int>(i))}, "field"));
    if (ir_.dead()) return false;
  }
  return true;
}

// Field type checks of make_instance, then the struct.
SVal Specialiser::make_instance(int cls, std::vector<SVal>& values, const SVal& cells) {
  ClassInfo& ci = m_.classes[cls];
  for (size_t i = 0; i < ci.fields.size(); ++i) {
    TypeP declared = declared_type(*ci.stmt->fields[i].type);
    if (declared) {
      check_field_type(cls, i, declared, values[i]);
      if (ir_.dead()) return never();
    }
    widen_field(cls, static_cast<int>(i), values[i].type);
  }
  if (values.back().type->k == TK::Never) return never();
  // The interpreter (as the reference) keeps such an object and fails only
  // when it is rendered, at the object's definition; a typed struct cannot hold it.
  if (values.back().type->k != TK::Pos)
    sites_.unsupported("an object made with an origin that is not a Position (" + shown_type(type_string(values.back().type)) + ")");
  std::vector<ir::Node*> ops;
  for (size_t i = 0; i < ci.fields.size(); ++i) {
    TypeP ft = ci.field_types[i] ? ci.field_types[i] : values[i].type;
    if (!T().fits(values[i].type, ft)) return never();  // widened: the next walk
    ops.push_back(values[i].code ? coerce(values[i], ft).code : ir_.lit(T().int_(), 0));
  }
  ops.push_back(values.back().code);
  if (!object_cells(cls, cells, ops)) return never();
  if (h_.tracked(T().obj(cls))) ops.push_back(ir_.call(ir::Helper::NewUid, T().int_(), {}));
  if (h_.rotated(cls)) ops.push_back(ir_.call(ir::Helper::NewUid, T().int_(), {}));  // a new group of cells
  ir::Node* n = ir_.node(ir::Op::MakeObj, T().obj(cls), ops);
  n->index = cls;
  return fresh_identity(let(SVal{T().obj(cls), n}, "o"));
}

void Specialiser::widen_field(int cls, int field, TypeP t) {
  ClassInfo& ci = m_.classes[cls];
  TypeP& ft = ci.field_types[field];
  if (!ft) {
    ft = t;
    h_.set_field(cls, field, t);
    return;
  }
  if (T().fits(t, ft)) return;
  ft = T().join(ft, t);
  h_.set_field(cls, field, ft);
  h_.learn("field '" + ci.field_names[field] + "' of '" + ci.name + "'");
}

// ---------------------------------------------------------------------------
// Fields

SVal Specialiser::get_field(const SVal& obj, Sym field, const std::string& raw) {
  return split(obj, [&](const SVal& o) -> SVal {
    if (o.type->k == TK::Never) return o;
    if (o.type->k == TK::Obj) {
      ClassInfo& ci = m_.classes[o.type->cls];
      for (size_t i = 0; i < ci.fields.size(); ++i)
        if (ci.fields[i] == field) {
          TypeP ft = ci.field_types[i];
          if (!ft) {
            h_.learn("field '" + raw + "'");
            return never();
          }
          return let(SVal{ft, ir_.member(o.code, ir::Member::Field, ft, static_cast<int>(i))});
        }
      if (field == p_.names.origin) return let(SVal{T().pos(), ir_.member(o.code, ir::Member::Origin, T().pos())});
      if (field == p_.names.elems) return object_cell_list(o);
      if (field == p_.names.render) {
        bound_[o.type->cls] = BoundMethod{o, ir_.block()};
        return SVal{T().func(FuncRef{FuncRef::Method, nullptr, Builtin::Map, o.type->cls}), nullptr};
      }
      fail("object of class '" + ci.name + "' has no field '" + raw + "'");
      return never();
    }
    const WellKnownNames& n = p_.names;
    if (o.type->k == TK::Pos && (field == n.x || field == n.y)) {
      if (o.konst) {
        ir::Node* k = o.konst->a[field == n.x ? 0 : 1];
        return SVal{T().int_(), k, k};
      }
      return let(SVal{T().int_(), ir_.member(o.code, field == n.x ? ir::Member::X : ir::Member::Y, T().int_())});
    }
    if (o.type->k == TK::Elem && field == n.position) {
      ir::Node* at = ir_.member(o.code, ir::Member::Position, T().pos());
      if (!h_.tracked(T().pos())) return let(SVal{T().pos(), at});
      SVal p{T().pos(), at};
      // The rendered element's Position, with an identity of its own (the
      // reference's same object on every read: not modelled).
      return make_position(SVal{T().int_(), ir_.member(p.code, ir::Member::X, T().int_())},
                           SVal{T().int_(), ir_.member(p.code, ir::Member::Y, T().int_())});
    }
    if (o.type->k == TK::Elem && field == n.color) return let(SVal{T().str(), ir_.member(o.code, ir::Member::Color, T().str())});
    if (o.type->k == TK::Cell && (field == n.x || field == n.y || field == n.color))
      return SVal{T().deferred(field == n.x ? 0 : field == n.y ? 1 : 2), o.code, o.konst};
    if (o.type->k == TK::Pos || o.type->k == TK::Elem || o.type->k == TK::Cell) {
      fail("object of class '" + class_name(o.type->k == TK::Pos ? kPositionClass : o.type->k == TK::Elem ? kElemClass : kCellClass) +
           "' has no field '" + raw + "'");
      return never();
    }
    fail("(.. _ " + raw + "): only objects have fields, got " + shown(o.type));
    return never();
  });
}

// The value of field `f` of an instance, by name (for equality).
SVal Specialiser::instance_field(const SVal& v, Sym f) { return get_field(v, f, nm(f)); }

// ---------------------------------------------------------------------------
// Lists

SVal Specialiser::make_list(const std::vector<SVal>& items) {
  if (items.empty()) return empty_list();
  TypeP et = T().never();
  for (const SVal& v : items) et = T().join(et, v.type);
  if (et->k == TK::Never) return never();
  if (et->k == TK::Func || et->k == TK::Class) sites_.unsupported("a list of functions or types");
  if (is_sum(et) && !is_typed_variant(et)) sites_.dynamic_site("a list holds values of different types");
  TypeP lt = T().list(et);
  std::vector<ir::Node*> codes, konsts;
  bool all_const = true;
  for (const SVal& v : items) {
    codes.push_back(coerce(v, et).code);
    if (v.konst && v.type == et) konsts.push_back(v.konst);
    else all_const = false;
  }
  SVal out{lt, ir_.node(ir::Op::MakeList, lt, codes)};
  if (all_const) out.konst = ir_.node(ir::Op::MakeList, lt, konsts);
  out.fresh = true;
  out.parts = codes;
  return let(out, "list");
}

// ---------------------------------------------------------------------------

std::string Specialiser::where(SourceLoc loc) const {
  return p_.file_name(loc.source) + ":" + std::to_string(loc.line);
}

}  // namespace autumn::lower
