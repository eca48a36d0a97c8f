// spec_cells — cells: construction with capture, and rendering.
//
// (Cell x y colour), as compiler/interpret/eval.cpp's construct_cell does it:
// the names the arguments mention are copied, from every scope but the
// outermost instance scope (the object's own fields), into a fresh scope S with
// no parent; each argument is tried once in S alone. A number becomes a
// constant; anything else, or an error, keeps the expression ("deferred"), to be
// evaluated at every render in S over the render's own scopes (the rendered
// object's fields, the render lambda's `e`, then whoever called render).
//
// At run time a cell is a CellV (runtime/compiled_support.hpp): three int32
// values and, per argument, -1 (a constant) or the index of its DeferredArg in
// the module. Deferred arguments whose value cannot change between renders
// ("fixed": no effects, nothing but captured names, no builtin that reads
// changing state such as `defined`, `prev` or `isFreePos`) keep their value in the
// cell; the others are evaluated by render code, a case per deferred argument.
//
// A class whose objects all get the same cells (the usual case: constant
// offsets, colours that are literals or depend on fields) is rendered by code
// specialised for those cells (CellMode::Static). Otherwise each object carries
// its cells (CellMode::Stored). Example:
//
//   (object Water (: liquid Bool) (Cell 0 0 (if liquid then "blue" else "lightblue")))
//   -> Static, one cell (0, 0), colour computed from the field `liquid` at each render.
#include <algorithm>

#include "compiler/lower/specialise.hpp"
#include "compiler/parse/ast_print.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {
namespace {

void mentioned(const Expr& e, std::set<Sym>& out) {
  if (e.kind == ExprKind::Var || e.kind == ExprKind::Get) out.insert(e.name);
  for (const auto& k : e.kids) mentioned(*k, out);
}

ir::Node* clone_tree(const ir::Node* n, ir::Arena& arena) {
  ir::Node* c = &arena.nodes.emplace_back(*n);
  for (auto& k : c->a) k = clone_tree(k, arena);
  return c;
}

bool same_tree(const ir::Node* a, const ir::Node* b) {
  if (a->op != b->op || a->imm != b->imm || a->type != b->type || a->a.size() != b->a.size()) return false;
  for (size_t i = 0; i < a->a.size(); ++i)
    if (!same_tree(a->a[i], b->a[i])) return false;
  return true;
}

}  // namespace

// The names a deferred argument may look up when it is evaluated: those it
// mentions, and those the bodies of the functions it calls mention (functions
// capture nothing: a global function's free name resolves in the caller's
// scopes, which at render time are the render's callers').
void Specialiser::dynamic_names(const DeferredArg& da, std::set<Sym>& out) {
  std::set<const Expr*> seen;
  std::vector<const Expr*> todo{da.expr};
  auto add_lambda = [&](TypeP t) {
    if (t && t->k == TK::Func && t->fn.kind == FuncRef::Lambda && seen.insert(t->fn.lambda).second) todo.push_back(t->fn.lambda);
  };
  for (const auto& [n, t] : da.captured_types) add_lambda(t);
  while (!todo.empty()) {
    const Expr* e = todo.back();
    todo.pop_back();
    std::set<Sym> names;
    mentioned(*e, names);
    for (Sym n : names) {
      out.insert(n);
      const Global* g = global(n);
      if (!g || !g->type) continue;
      add_lambda(g->type);
      if (g->type->k == TK::Sum)
        for (TypeP a : g->type->alts) add_lambda(a);
    }
  }
}

// ---------------------------------------------------------------------------
// Construction

SVal Specialiser::construct_cell(const Expr& e) {
  // 1. The capture scope: globals first, then every scope but the outermost
  //    instance scope, inner copies replacing outer ones.
  SScope capture;
  auto put = [&](Sym n, SVal v) {
    Binding* b = capture.find(n);
    if (!b) {
      capture.vars.push_back(Binding{});
      b = &capture.vars.back();
      b->sym = n;
    }
    b->type = v.type;
    b->place = v.code;
    b->konst = v.konst;
    captured_konst_[n] = v.konst;
  };
  captured_konst_.clear();
  for (Sym n : e.cell_names)
    if (Global* g = global(n); g && g->state != Global::Undefined) {
      if (g->state == Global::Runtime) sites_.unsupported("a cell capturing a global that may not exist");
      put(n, read_global(*g));
    }
  bool skipped = false;
  for (SScope* sc : scopes_.visible()) {
    if (sc->kind == ScopeKind::Instance && !skipped) {
      skipped = true;
      continue;
    }
    for (Sym n : e.cell_names)
      if (Binding* b = sc->find(n)) {
        if (b->flag) sites_.unsupported("a cell capturing a name that may not be bound");
        SVal v{b->type, b->place};
        if (b->place && !b->mut) v.konst = is_const(b->place) ? b->place : nullptr;
        v = let(v);
        put(n, v);
      }
  }
  // 2. Each argument tried in the capture scope alone.
  std::vector<SVal> fields;   // x, y, colour: the value (constant or fixed)
  std::vector<int> deferred;  // -1, or the DeferredArg index
  for (size_t i = 1; i < e.kids.size(); ++i) {
    int d = -1;
    SVal v = trial(*e.kids[i], capture, static_cast<int>(i - 1), &d);
    fields.push_back(v);
    deferred.push_back(d);
  }
  if (e.kids.size() != 4) {
    fail("'Cell' takes 3 field value(s), got " + std::to_string(e.kids.size() - 1));
    return never();
  }
  std::vector<ir::Node*> ops, konsts;
  bool known = true;
  for (size_t i = 0; i < 3; ++i) {
    ir::Node* value = fields[i].code ? fields[i].code : ir_.lit(T().int_(), 0);
    ops.push_back(value);
    ir::Node* k = fields[i].code ? fields[i].konst : ir_.lit(T().int_(), 0);
    if (!k) known = false;
    konsts.push_back(k);
  }
  for (int d : deferred) {
    ops.push_back(ir_.lit(T().int_(), d));
    konsts.push_back(ir_.lit(T().int_(), d));
  }
  SVal out{T().cell(), ir_.node(ir::Op::MakeCell, T().cell(), ops)};
  if (known) out.konst = ir_.node(ir::Op::MakeCell, T().cell(), konsts);
  if (deferred[2] < 0) {
    m_.number_colours.push_back(Module::NumberColour{e.kids[3].get(), constructing_});
    out.code->index = static_cast<int>(m_.number_colours.size());
    if (out.konst) out.konst->index = out.code->index;
  }
  if (h_.tracked(T().cell())) {
    out.code->a.push_back(ir_.call(ir::Helper::NewUid, T().int_(), {}));
    out.konst = nullptr;
  }
  if (known && !h_.tracked(T().cell())) out.code = out.konst;
  else out = let(out, "cell");
  out.fresh = true;
  return out;
}

// One argument of a Cell, evaluated in the capture scope alone. Returns the
// cell's stored value for it; *deferred_index is -1 for a number constant.
SVal Specialiser::trial(const Expr& arg, SScope& capture, int which, int* deferred_index) {
  const ScopeChain::Chain saved = scopes_.replace({&capture});
  ++capture_mode_;
  capture_block_ = ir_.block();
  trial_failed_ = false;
  const bool outer_varies = trial_varies_;  // a trial inside another's argument
  trial_varies_ = false;
  const size_t effects_before = ir_.effects();
  const bool was_dead = ir_.dead();
  SVal v = lower_value(arg);
  const bool failed = trial_failed_ || (ir_.dead() && !was_dead);
  // The interpreter does not restore its scope when a trial fails: a let or a
  // call the failure left is where the cell's next arguments are tried (found
  // by a stress program: (Cell (let (= q 3) (+ n 0)) q "red") drew at y = 3).
  if (trial_failed_ && trial_fail_depth_ > 1 && which < 2)
    sites_.unsupported("a cell argument that fails inside a let or a call (the interpreter tries the next arguments there)");
  ir_.set_dead(was_dead);
  --capture_mode_;
  scopes_.replace(saved);
  const bool varies = trial_varies_;
  trial_varies_ = outer_varies || varies;  // the outer trial's, restored with this one's added
  const bool pure = ir_.effects() == effects_before;
  if (!failed && v.type->k == TK::Int) {
    *deferred_index = -1;
    return v;
  }
  // Deferred.
  DeferredArg d;
  d.expr = &arg;
  d.arg = which;
  d.classes = constructing_;
  std::set<Sym> names;
  mentioned(arg, names);
  bool runtime_capture = false;
  for (Sym n : names)
    if (Binding* b = capture.find(n)) {
      if (b->type->k == TK::Func || b->type->k == TK::Class) d.captured_types.emplace_back(n, b->type);
      else if (captured_konst_[n])
        d.captured.emplace_back(n, clone_tree(captured_konst_[n], m_.lasting)), d.captured_types.emplace_back(n, b->type);
      else runtime_capture = true;
    }
  const TypeP want = which == 2 ? T().str() : T().int_();
  d.fixed = !failed && pure && !varies && v.type == want;
  if (!d.fixed && runtime_capture)
    sites_.unsupported("a cell argument evaluated at render time that captures a value computed at run time");
  const std::string text = "(" + ast_to_string(p_.symbols, arg) + ": Expr)";
  auto it = std::find(m_.deferred_prints.begin(), m_.deferred_prints.end(), text);
  d.print = static_cast<int>(it - m_.deferred_prints.begin());
  if (it == m_.deferred_prints.end()) m_.deferred_prints.push_back(text);
  *deferred_index = -1;
  for (size_t i = 0; i < m_.deferred.size() && *deferred_index < 0; ++i) {
    const DeferredArg& o = m_.deferred[i];
    bool same = o.expr == d.expr && o.arg == d.arg && o.fixed == d.fixed && o.classes == d.classes &&
                o.captured.size() == d.captured.size() && o.captured_types == d.captured_types;
    for (size_t k = 0; same && k < d.captured.size(); ++k)
      same = o.captured[k].first == d.captured[k].first && same_tree(o.captured[k].second, d.captured[k].second);
    if (same) *deferred_index = static_cast<int>(i);
  }
  if (*deferred_index < 0) {
    m_.deferred.push_back(d);
    *deferred_index = static_cast<int>(m_.deferred.size() - 1);
  }
  if (d.fixed) return v;
  return SVal{T().int_(), ir_.lit(T().int_(), 0), ir_.lit(T().int_(), 0)};
}

// ---------------------------------------------------------------------------
// Which objects carry their cells

bool Specialiser::object_cells(int cls, const SVal& cells, std::vector<ir::Node*>& ops) {
  ClassInfo& ci = m_.classes[cls];
  TypeP want = T().list(T().cell());
  if (cells.type->k != TK::List || (cells.type->elem && cells.type->elem != T().cell())) {
    fail("field 'elems' of '" + ci.name + "' must be " + shown_type("List<" + type_string(T().cell()) + ">") + ", got " +
         shown(cells.type));
    return false;
  }
  if (!h_.stored_cells(cls) && h_.tracked(T().cell())) {  // cells with identities live in the objects
    h_.add_stored_cells(cls);
    h_.learn("cells of '" + ci.name + "' carry identities");
    return false;
  }
  if (!h_.stored_cells(cls)) {
    ir::Node* k = cells.konst;
    if (k && ci.static_shape && same_tree(k, ci.static_shape)) return true;
    if (k && !ci.static_shape) {
      ci.static_shape = k;
      h_.set_shape(cls, clone_tree(k, m_.lasting));
      return true;
    }
    h_.add_stored_cells(cls);
    h_.learn("the cells of '" + ci.name + "' depend on how objects are made");
    return false;
  }
  ci.mode = CellMode::Stored;
  ops.push_back(coerce(cells, want).code);
  return true;
}

// (.. o elems): the object's cell list.
SVal Specialiser::object_cell_list(const SVal& o) {
  ClassInfo& ci = m_.classes[o.type->cls];
  if (h_.rotated(o.type->cls)) sites_.unsupported("the cells of an object rotate turns, as a value");
  TypeP lt = T().list(T().cell());
  if (h_.stored_cells(o.type->cls) || h_.tracked(T().cell())) {
    if (!h_.stored_cells(o.type->cls)) {
      h_.add_stored_cells(o.type->cls);
      h_.learn("cells of '" + ci.name + "' carry identities");
      return never();
    }
    return let(SVal{lt, ir_.member(o.code, ir::Member::Cells, lt)});
  }
  if (!ci.static_shape) {
    h_.learn("cells of '" + ci.name + "'");
    return never();
  }
  return SVal{ci.static_shape->a.empty() ? T().empty_list() : lt, ci.static_shape, ci.static_shape};
}

// ---------------------------------------------------------------------------
// Evaluating a deferred argument

// The scopes a deferred argument is evaluated in: over the caller's chain, the
// rendered object's fields (an Instance scope), the render lambda's scope, the
// scope binding `e` to the cell, and the capture scope.
SVal Specialiser::eval_deferred(int d, const SVal* obj, const SVal& cell) {
  const DeferredArg& da = m_.deferred[d];
  size_t pushed = 0;
  if (obj) {
    SScope* inst = scopes_.push(ScopeKind::Instance, ir_.block());
    ++pushed;
    const ClassInfo& ci = m_.classes[obj->type->cls];
    for (size_t i = 0; i < ci.fields.size(); ++i) bind(*inst, ci.fields[i], instance_field(*obj, ci.fields[i]), {&ci, ci.fields[i]});
    bind(*inst, p_.names.origin, instance_field(*obj, p_.names.origin), {&ci, p_.names.origin});
    std::set<Sym> names;
    mentioned(*da.expr, names);
    if (names.count(p_.names.elems))  // (only then: a rotated object's cells have no value here)
      bind(*inst, p_.names.elems, instance_field(*obj, p_.names.elems), {&ci, p_.names.elems});
  }
  scopes_.push(ScopeKind::Local, ir_.block());
  SScope* es = scopes_.push(ScopeKind::Local, ir_.block());
  bind(*es, p_.names.e, cell, {&da, p_.names.e});
  SScope* cap = scopes_.push(ScopeKind::Local, ir_.block());
  pushed += 3;
  for (const auto& [n, t] : da.captured_types) {
    ir::Node* k = nullptr;
    for (const auto& [m, kn] : da.captured)
      if (m == n) k = kn;
    bind(*cap, n, SVal{t, k, k}, {&da, n});
  }
  SVal v = lower_value(*da.expr);
  for (size_t i = 0; i < pushed; ++i) scopes_.pop();
  return v;
}

// ((.. c x)) outside a render: the argument's value, evaluated now.
SVal Specialiser::call_deferred(const SVal& f) {
  const int which = f.type->cls;
  const ir::Node* k = f.konst;
  if (k && k->op == ir::Op::MakeCell) {
    const int d = static_cast<int>(k->a[3 + which]->imm);
    if (d < 0 || m_.deferred[d].fixed) {
      ir::Node* v = k->a[which];
      return SVal{d < 0 || which < 2 ? T().int_() : T().str(), v, v};
    }
    return eval_deferred(d, nullptr, SVal{T().cell(), f.code, f.konst});
  }
  // A cell known only at run time: constants and fixed values are in the cell.
  ir::Member m = which == 0 ? ir::Member::CellX : which == 1 ? ir::Member::CellY : ir::Member::CellColour;
  for (const DeferredArg& da : m_.deferred)
    if (da.arg == which && !da.fixed) sites_.unsupported("evaluating a cell argument of a cell made elsewhere");
  TypeP t = which == 2 ? T().str() : T().int_();
  if (which == 2) sites_.unsupported("the colour of a cell made elsewhere, as a value");
  return let(SVal{t, ir_.member(f.code, m, t)});
}

// ---------------------------------------------------------------------------
// Rendering

// Hands the rendered elements of `v` (an object, a list of them, nested) to
// `sink` in render order; anything else renders as nothing (native
// render_value). The sink appends them to a list, or (the host render) marks
// occupancy and paints them at once.
void Specialiser::render_into(const SVal& v, const ElemSink& sink) {
  if (!v.type) return;
  switch (v.type->k) {
    case TK::Obj: render_object(v, sink); return;
    case TK::List: {
      if (!v.type->elem || !renders(v.type->elem)) return;
      ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
      loop->var = ir_.var(v.type->elem, "x");
      loop->a = v.code;
      ir_.in_block(loop->body, [&] { render_into(SVal{v.type->elem, ir_.local(loop->var)}, sink); });
      return;
    }
    case TK::Sum:
      if (!renders(v.type)) return;
      split(v, [&](const SVal& a) {
        render_into(a, sink);
        return SVal{T().int_(), ir_.lit(T().int_(), 0)};
      });
      return;
    default:
      return;
  }
}

void Specialiser::render_into(const SVal& v, ir::Node* out) {
  render_into(v, [&](ir::Node* elem) { ir_.emit_push(out, elem); });
}

bool Specialiser::renders(TypeP t) const {
  if (t->k == TK::Obj) return true;
  if (t->k == TK::List) return t->elem && renders(t->elem);
  if (t->k == TK::Sum)
    for (TypeP a : t->alts)
      if (renders(a)) return true;
  return false;
}

SVal Specialiser::render_value(const SVal& v, const Expr& at) {
  (void)at;
  ir::Var* out = ir_.var(T().list(T().elem()), "rendered");
  out->scratch = true;
  out->mut = true;
  ir::Stmt* d = ir_.emit(ir::SK::Decl);
  d->var = out;
  if (renders(v.type)) render_into(v, ir_.local(out));
  return built(out);
}

// The interpreter renders an object by calling its render method, an Autumn
// lambda that looks `map` up through the caller's scopes: the specialised render
// is the builtin's. Inside renderValue (taken as a shortcut, inline_lambda), the
// render's callers include renderValue's own scope, whose parameter is the
// object rendered: a deferred argument's free name may read it.
void Specialiser::render_object(const SVal& o, const ElemSink& sink) {
  if (!means_builtin(p_.builtin_syms[static_cast<int>(Builtin::Map)], Builtin::Map))
    sites_.unsupported("rendering an object where 'map' is not the builtin the render method calls");
  const Sym param = std::exchange(render_value_param_, -1);
  if (param < 0) return render_cells(o, sink);
  SScope* sc = scopes_.push(ScopeKind::Local, ir_.block());
  bind(*sc, param, o, {f_.stdlib_render_value, param});
  render_cells(o, sink);
  scopes_.pop();
  render_value_param_ = param;
}

void Specialiser::render_cells(const SVal& o, const ElemSink& sink) {
  const int cls = o.type->cls;
  ClassInfo& ci = m_.classes[cls];
  if (h_.stored_cells(cls)) {  // the class's render function, into a buffer
    std::set<Sym>& binds = stored_render_binds_[cls];
    for (SScope* sc : scopes_.visible())
      for (const Binding& b : sc->vars) binds.insert(b.sym);
    ir::Var* out = ir_.var(T().list(T().elem()), "cells");
    out->scratch = true;
    out->mut = true;
    ir_.emit(ir::SK::Decl)->var = out;
    ir::Node* n = ir_.node(ir::Op::FnCall, nullptr, {o.code, ir_.local(out)});
    n->index = -1 - cls;  // settled to the class's render function in finish_classes
    ir_.emit_eval(n);
    ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
    loop->var = ir_.var(T().elem(), "e");
    loop->a = ir_.local(out);
    ir_.in_block(loop->body, [&] { sink(ir_.local(loop->var)); });
    return;
  }
  if (!ci.static_shape) {
    h_.learn("cells of '" + ci.name + "'");
    return;
  }
  SVal ov = let(o, "obj");
  ir::Node* origin = ir_.member(ov.code, ir::Member::Origin, T().pos());
  SVal turns;
  if (h_.rotated(cls))
    turns = let(SVal{T().int_(), ir_.call(ir::Helper::RotOf, T().int_(), {ir_.member(ov.code, ir::Member::Group, T().int_())})});
  if (tabulable(*ci.static_shape)) {
    ci.shape_table = true;
    render_shape_table(cls, origin, turns, sink);
    return;
  }
  for (const ir::Node* c : ci.static_shape->a) {
    const int dx = static_cast<int>(c->a[3]->imm), dy = static_cast<int>(c->a[4]->imm), dc = static_cast<int>(c->a[5]->imm);
    SVal cell{T().cell(), const_cast<ir::Node*>(c), const_cast<ir::Node*>(c)};
    auto offset = [&](int which, int d) -> SVal {
      if (d < 0 || m_.deferred[d].fixed) return SVal{T().int_(), c->a[which]};
      SVal v = narrow(eval_deferred(d, &ov, cell), TK::Int, [&](const SVal& a) {
        fail_at_cell_arg(m_.deferred[d].expr, cell_value_error(which, a.type));
      });
      if (ir_.dead()) return never();
      return v;
    };
    SVal cx = offset(0, dx), cy = offset(1, dy);
    if (ir_.dead()) return;
    ir::Node* ox = cx.code;
    ir::Node* oy = cy.code;
    if (turns.code) {  // rotate turned this object's cells
      SVal r = let(SVal{T().pos(), ir_.call(ir::Helper::Rotated, T().pos(), {turns.code, cx.code, cy.code})});
      ox = ir_.member(r.code, ir::Member::X, T().int_());
      oy = ir_.member(r.code, ir::Member::Y, T().int_());
    }
    SVal x{T().int_(), ir_.node(ir::Op::Add, T().int_(), {ir_.member(origin, ir::Member::X, T().int_()), ox})};
    SVal y{T().int_(), ir_.node(ir::Op::Add, T().int_(), {ir_.member(origin, ir::Member::Y, T().int_()), oy})};
    SVal colour;
    if (dc < 0) {
      const Expr* arg = c->index > 0 ? m_.number_colours[c->index - 1].expr : nullptr;
      fail_at_cell_arg(arg, cell_value_error(2, T().int_()));
      return;
    }
    if (m_.deferred[dc].fixed) colour = SVal{T().str(), c->a[2]};
    else colour = deferred_colour(dc, ov, cell);
    if (ir_.dead()) return;
    sink(ir_.node(ir::Op::MakeElem, T().elem(), {ir_.node(ir::Op::MakePos, T().pos(), {x.code, y.code}), colour.code}));
  }
}

// Whether the cells of a Static shape go in a table the render loops over: many
// of them (below kTableCells the cells are unrolled, each a few instructions),
// and every x, y and colour a literal the same at every render (no deferred
// argument evaluated then, no number where a colour is due). A 22-by-22 block
// unrolled is ~500 statements per render site, which the C++ compiler spends
// seconds optimising (docs/design.md "Tests").
bool Specialiser::tabulable(const ir::Node& shape) const {
  constexpr size_t kTableCells = 32;
  if (shape.a.size() < kTableCells || !literal_cells(shape)) return false;
  for (const ir::Node* c : shape.a)
    for (int which = 0; which < 3; ++which) {
      const int d = static_cast<int>(c->a[3 + which]->imm);
      if (which == 2 && d < 0) return false;  // a number colour: the render fails at this cell
      if (d >= 0 && !m_.deferred[d].fixed) return false;
    }
  return true;
}

// The render of a tabulable shape: one loop over the class's table (Op::Shape)
// doing what the unrolled cells do, in the same order. Like them it charges
// nothing to the loop budget (its length is a constant of the program).
void Specialiser::render_shape_table(int cls, ir::Node* origin, const SVal& turns, const ElemSink& sink) {
  ir::Node* cells = ir_.node(ir::Op::Shape, T().list(T().cell()));
  cells->index = cls;
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(T().cell(), "cell");
  loop->a = cells;
  loop->charged = false;
  ir_.in_block(loop->body, [&] {
    ir::Node* c = ir_.local(loop->var);
    ir::Node* ox = ir_.member(c, ir::Member::CellX, T().int_());
    ir::Node* oy = ir_.member(c, ir::Member::CellY, T().int_());
    if (turns.code) {  // rotate turned this object's cells
      SVal r = let(SVal{T().pos(), ir_.call(ir::Helper::Rotated, T().pos(), {turns.code, ox, oy})});
      ox = ir_.member(r.code, ir::Member::X, T().int_());
      oy = ir_.member(r.code, ir::Member::Y, T().int_());
    }
    ir::Node* x = ir_.node(ir::Op::Add, T().int_(), {ir_.member(origin, ir::Member::X, T().int_()), ox});
    ir::Node* y = ir_.node(ir::Op::Add, T().int_(), {ir_.member(origin, ir::Member::Y, T().int_()), oy});
    ir::Node* colour = ir_.member(c, ir::Member::CellColour, T().str());
    sink(ir_.node(ir::Op::MakeElem, T().elem(), {ir_.node(ir::Op::MakePos, T().pos(), {x, y}), colour}));
  });
}

// A live colour: a shared function of the object when the caller's scopes
// cannot change what its names mean, else evaluated right here.
SVal Specialiser::deferred_colour(int d, const SVal& o, const SVal& cell) {
  const DeferredArg& da = m_.deferred[d];
  std::set<Sym> names;
  dynamic_names(da, names);
  bool caller_matters = false;
  const ClassInfo& ci = m_.classes[o.type->cls];
  for (Sym n : names) {
    if (n == p_.names.e || n == p_.names.origin || n == p_.names.elems) continue;
    if (std::find(ci.fields.begin(), ci.fields.end(), n) != ci.fields.end()) continue;
    bool captured = false;
    for (const auto& [m, t] : da.captured_types) captured |= m == n;
    if (captured) continue;
    caller_matters |= scopes_.binds(n);
  }
  SVal v;
  if (caller_matters || capture_mode_) {
    v = eval_deferred(d, &o, cell);
  } else {
    int fn = colour_function(d, o.type->cls, cell);
    ir::Node* n = ir_.node(ir::Op::FnCall, T().str(), {o.code});
    n->index = fn;
    v = let(SVal{T().str(), n}, "colour");
  }
  return narrow(v, TK::Str, [&](const SVal& a) { fail_at_cell_arg(da.expr, cell_value_error(2, a.type)); });
}

// The module function (State&, const C&) -> string id for deferred argument d
// rendered in objects of class cls, made once per pair.
int Specialiser::colour_function(int d, int cls, const SVal& cell) {
  auto key = std::make_pair(d, cls);
  if (auto it = colour_fns_.find(key); it != colour_fns_.end()) return it->second;
  m_.functions.push_back(std::make_unique<ir::Function>());
  ir::Function* f = m_.functions.back().get();
  const int index = static_cast<int>(m_.functions.size() - 1);
  colour_fns_[key] = index;
  f->name = "colour_" + std::to_string(d) + "_" + m_.classes[cls].cpp;
  f->kind = ir::Function::Colour;
  f->ret = T().str();
  ir::Var* o = ir_.var(T().obj(cls), "o");
  f->params.push_back(o);
  // Specialised with only the globals around it (the caller check above).
  const IrBuilder::Point saved = ir_.point();
  const ScopeChain::Chain saved_chain = scopes_.replace({});
  ir_.begin_function(f);
  SVal ov{T().obj(cls), ir_.local(o)};
  SVal v = narrow(eval_deferred(d, &ov, cell), TK::Str,
                  [&](const SVal& a) { fail_at_cell_arg(m_.deferred[d].expr, cell_value_error(2, a.type)); });
  if (!ir_.dead()) ir_.emit(ir::SK::Return)->a = v.code;
  ir_.restore(saved);
  scopes_.replace(saved_chain);
  return index;
}

SVal Specialiser::call_render_method(int cls) {
  auto it = bound_.find(cls);
  if (it == bound_.end() || it->second.block != ir_.block())
    sites_.unsupported("a render method called away from where it was fetched");
  return render_value(it->second.obj, sites_.innermost());
}

// After the walk: each Stored class gets its render function (a loop over the
// object's cells, a case per deferred argument such cells can hold).
// The shapes earlier walks learnt, for code that renders objects before any is made.
void Specialiser::load_shapes() {
  for (const auto& [cls, shape] : h_.shapes())
    if (!h_.stored_cells(cls)) m_.classes[cls].static_shape = clone_tree(shape, m_.arena);
}

void Specialiser::finish_classes() {
  // A render helper named the number colour it knew of; a cell made later must not name another.
  for (const auto& [cls, used] : number_colour_uses_)
    for (const Module::NumberColour& n : m_.number_colours)
      if ((n.classes.empty() || std::count(n.classes.begin(), n.classes.end(), cls)) && n.expr != used)
        sites_.unsupported("cells of one class with number colours in several places");
  check_containment();
  m_.pos_tracked = h_.tracked(T().pos());
  for (size_t c = 0; c < m_.classes.size(); ++c) {
    m_.classes[c].rotatable = h_.rotated(static_cast<int>(c));
    if (m_.classes[c].rotatable) {
      check_rotated_order(static_cast<int>(c));
      check_rotated_cells(static_cast<int>(c));
    }
  }
  for (size_t c = 0; c < m_.classes.size(); ++c) {
    ClassInfo& ci = m_.classes[c];
    ci.tracked = h_.tracked(T().obj(static_cast<int>(c)));
    if (!h_.stored_cells(static_cast<int>(c))) {
      ci.mode = CellMode::Static;
      continue;
    }
    ci.mode = CellMode::Stored;
    check_render_callers(static_cast<int>(c));
    ci.render_fn = stored_render_function(static_cast<int>(c));
  }
  // Settle render calls of Stored classes.
  for (ir::Node& n : m_.arena.nodes)
    if (n.op == ir::Op::FnCall && n.index < 0) n.index = m_.classes[-1 - n.index].render_fn;
}

// The interpreter's error for a rendered cell whose argument `which` (0 x,
// 1 y, 2 colour) evaluated to a value of type `got`: the render adds a
// coordinate to the origin's, and RenderedElem checks its colour.
std::string Specialiser::cell_value_error(int which, TypeP got) {
  return which == 2 ? "field 'color' of 'RenderedElem' must be String, got " + shown(got)
                    : "binary + needs two numbers, got Number and " + shown(got);
}

// A turn makes a cell's x the negated y expression and its y the x expression,
// so after an odd number of turns the interpreter evaluates y's expression
// first; the render code evaluates x's first and turns the values. With both
// evaluated at render time, their effects (random draws) and errors come in
// another order (found by a stress program): such a class is embedded.
void Specialiser::check_rotated_order(int cls) {
  const Expr* live[2] = {nullptr, nullptr};
  for (const DeferredArg& da : m_.deferred)
    if (da.arg < 2 && !da.fixed && (da.classes.empty() || std::count(da.classes.begin(), da.classes.end(), cls)))
      live[da.arg] = da.expr;
  if (live[0] && live[1]) {
    sites_.enter(live[1]);  // located at the y argument
    sites_.unsupported("a rotated object of '" + m_.classes[cls].name +
                       "' whose cells' x and y are both evaluated at render time (a turn swaps their order)");
  }
}

// rotate turns Cell objects in place, and the state counts turns per group of
// objects made by one construction (builtin_rotate): exact only while each
// construction makes its own Cells. A class whose cell expression may return
// Cells made elsewhere (a global's list, a field's, a variable's, a function's
// result) shares them with every object holding them, and a turn of one turns
// them all, later objects included (found by a stress program): such a rotated
// class is embedded.
void Specialiser::check_rotated_cells(int cls) {
  const ClassInfo& ci = m_.classes[cls];
  if (!ci.stmt || !ci.stmt->cell_expr || cells_made_fresh(*ci.stmt->cell_expr, ci, {})) return;
  sites_.enter(ci.stmt->cell_expr.get());
  sites_.unsupported("a rotated object of '" + ci.name +
                     "' whose cells may be Cells made before its construction (rotate turns them for every object "
                     "holding them)");
}

// Whether every Cell in the value of `e` (at any depth of lists) is made anew
// by evaluating it: a (Cell ...) call, a list literal or a concat of such
// values, either branch of an if, a map of a lambda literal whose body is such.
// `Cell`, `map` and `concat` count only where they are the builtins:
// not assigned by the program or its library, nor a field of the class or a
// parameter of an enclosing lambda (`bound`).
bool Specialiser::cells_made_fresh(const Expr& e, const ClassInfo& ci, const std::vector<Sym>& bound) const {
  auto builtin = [&](Sym s) {
    const bool assigned = s >= 0 && static_cast<size_t>(s) < p_.definitions.size() && p_.definitions[s].line != 0;
    return s >= 0 && !assigned && !std::count(ci.fields.begin(), ci.fields.end(), s) &&
           !std::count(bound.begin(), bound.end(), s);
  };
  switch (e.kind) {
    case ExprKind::List:
      return std::all_of(e.kids.begin(), e.kids.end(), [&](const ExprPtr& k) { return cells_made_fresh(*k, ci, bound); });
    case ExprKind::If:
      return e.kids.size() == 3 && cells_made_fresh(*e.kids[1], ci, bound) && cells_made_fresh(*e.kids[2], ci, bound);
    case ExprKind::Call: {
      if (e.kids.empty() || e.kids[0]->kind != ExprKind::Var || !builtin(e.kids[0]->name)) return false;
      const Sym callee = e.kids[0]->name;
      if (callee == p_.names.Cell) return true;
      if (callee == p_.builtin_syms[static_cast<size_t>(Builtin::Concat)])
        return std::all_of(e.kids.begin() + 1, e.kids.end(), [&](const ExprPtr& k) { return cells_made_fresh(*k, ci, bound); });
      if (callee != p_.builtin_syms[static_cast<size_t>(Builtin::Map)] || e.kids.size() != 3) return false;
      const Expr& f = *e.kids[1];
      if (f.kind != ExprKind::Lambda || f.kids.empty()) return false;
      std::vector<Sym> inner = bound;
      inner.insert(inner.end(), f.params.begin(), f.params.end());
      return cells_made_fresh(*f.kids[0], ci, inner);
    }
    default: return false;
  }
}

// A C++ struct cannot contain itself: a class whose fields may hold (by value,
// through fields and sums, not lists) an object of that same class is the
// embedded interpreter's (the reference shares the object; found by a stress
// program: (updateObj lamp "dx" lamp) emitted a module that did not compile).
void Specialiser::check_containment() {
  std::vector<int> state(m_.classes.size(), 0);  // 0 not seen, 1 on the path, 2 done
  std::function<void(int)> visit = [&](int c) {
    state[c] = 1;
    for (TypeP t : m_.classes[c].field_types) {
      std::vector<int> held;
      classes_held(t, true, held);
      for (int d : held) {
        if (state[d] == 1) {
          if (m_.classes[c].stmt) sites_.enter(m_.classes[c].stmt->cell_expr.get());
          sites_.unsupported("a field of '" + m_.classes[c].name + "' that may hold an object of class '" +
                             m_.classes[d].name + "', which holds it in turn");
        }
        if (state[d] == 0) visit(d);
      }
    }
    state[c] = 2;
  };
  for (size_t c = 0; c < m_.classes.size(); ++c)
    if (state[c] == 0) visit(static_cast<int>(c));
}

// A deferred argument's name that neither its capture, the object's fields nor
// the cell `e` bind is looked up in the render's caller (the interpreter's
// dynamic scope). The shared render function of a Stored class sees only the
// globals, so a caller that binds such a name locally is not specialised.
void Specialiser::check_render_callers(int cls) {
  const auto sites = stored_render_binds_.find(cls);
  if (sites == stored_render_binds_.end() || sites->second.empty()) return;
  const ClassInfo& ci = m_.classes[cls];
  for (const DeferredArg& da : m_.deferred) {
    if (da.fixed || !(da.classes.empty() || std::count(da.classes.begin(), da.classes.end(), cls))) continue;
    std::set<Sym> names;
    dynamic_names(da, names);
    for (Sym n : names) {
      const bool own = n == p_.names.origin || n == p_.names.elems || n == p_.names.e ||
                       std::count(ci.fields.begin(), ci.fields.end(), n) ||
                       std::any_of(da.captured_types.begin(), da.captured_types.end(), [n](const auto& c) { return c.first == n; });
      if (!own && sites->second.count(n)) {
        sites_.enter(da.expr);  // located at the argument
        sites_.unsupported("a cell argument evaluated at render time whose name '" + nm(n) +
                           "' a caller of the render binds");
      }
    }
  }
}

int Specialiser::stored_render_function(int cls) {
  m_.functions.push_back(std::make_unique<ir::Function>());
  ir::Function* f = m_.functions.back().get();
  const int index = static_cast<int>(m_.functions.size() - 1);
  f->name = "render_" + m_.classes[cls].cpp;
  f->kind = ir::Function::Helper;
  ir::Var* o = ir_.var(T().obj(cls), "o");
  ir::Var* out = ir_.var(T().list(T().elem()), "out");
  out->mut = true;
  f->params = {o, out};
  ir_.begin_function(f);
  scopes_.replace({});
  SVal ov{T().obj(cls), ir_.local(o)};
  ir::Node* origin = ir_.member(ir_.local(o), ir::Member::Origin, T().pos());
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(T().cell(), "c");
  loop->a = ir_.member(ir_.local(o), ir::Member::Cells, T().list(T().cell()));
  ir_.in_block(loop->body, [&] {
    SVal cell{T().cell(), ir_.local(loop->var)};
    auto arg = [&](int which, ir::Member m, TypeP t) -> SVal {
      // The value in the cell, unless its argument is live: then evaluated here.
      ir::Var* r = ir_.decl(t, ir_.member(ir_.local(loop->var), m, t), which == 0 ? "x" : which == 1 ? "y" : "colour");
      ir::Member dm = which == 0 ? ir::Member::CellDx : which == 1 ? ir::Member::CellDy : ir::Member::CellDc;
      std::vector<int> live;
      for (size_t d = 0; d < m_.deferred.size(); ++d) {
        const DeferredArg& da = m_.deferred[d];
        const bool here = da.classes.empty() || std::count(da.classes.begin(), da.classes.end(), cls);
        if (da.arg == which && !da.fixed && here) live.push_back(static_cast<int>(d));
      }
      if (!live.empty()) {
        ir::Stmt* sw = ir_.emit(ir::SK::Switch);
        sw->a = ir_.member(ir_.local(loop->var), dm, T().int_());
        for (int d : live) {
          sw->cases.emplace_back(d, ir::Block{});
          ir_.in_block(sw->cases.back().second, [&] {
            SVal v = narrow(eval_deferred(d, &ov, cell), t->k,
                            [&](const SVal& a) { fail_at_cell_arg(m_.deferred[d].expr, cell_value_error(which, a.type)); });
            if (!ir_.dead()) ir_.emit_set(ir_.local(r), v.code);
          });
        }
      }
      return SVal{t, ir_.local(r)};
    };
    SVal x = arg(0, ir::Member::CellX, T().int_());
    SVal y = arg(1, ir::Member::CellY, T().int_());
    ir::Node* ox = x.code;
    ir::Node* oy = y.code;
    if (h_.rotated(cls)) {
      ir::Node* turns = ir_.call(ir::Helper::RotOf, T().int_(), {ir_.member(ir_.local(o), ir::Member::Group, T().int_())});
      SVal r = let(SVal{T().pos(), ir_.call(ir::Helper::Rotated, T().pos(), {turns, x.code, y.code})});
      ox = ir_.member(r.code, ir::Member::X, T().int_());
      oy = ir_.member(r.code, ir::Member::Y, T().int_());
    }
    ir::Node* px = ir_.node(ir::Op::Add, T().int_(), {ir_.member(origin, ir::Member::X, T().int_()), ox});
    ir::Node* py = ir_.node(ir::Op::Add, T().int_(), {ir_.member(origin, ir::Member::Y, T().int_()), oy});
    ir::Stmt* bad = ir_.emit(ir::SK::If);
    bad->a = ir_.node(ir::Op::Eq, T().bool_(), {ir_.member(ir_.local(loop->var), ir::Member::CellDc, T().int_()), ir_.lit(T().int_(), -1)});
    ir_.in_block(bad->body, [&] {
      fail_at_cell_arg(number_colour_of(cls), cell_value_error(2, T().int_()));
    });
    SVal colour = arg(2, ir::Member::CellColour, T().str());
    ir_.emit_push(ir_.local(out), ir_.node(ir::Op::MakeElem, T().elem(), {ir_.node(ir::Op::MakePos, T().pos(), {px, py}), colour.code}));
  });
  return index;
}

// ---------------------------------------------------------------------------
// Errors of the render itself

void Specialiser::fail_at_cell_arg(const Expr* arg, const std::string& msg) {
  if (sites_.in_program() || !arg) return fail(msg);
  sites_.enter(arg);
  fail(msg);
  sites_.leave();
}

const Expr* Specialiser::number_colour_of(int cls) {
  const Expr* found = nullptr;
  for (const Module::NumberColour& n : m_.number_colours) {
    if (!n.classes.empty() && !std::count(n.classes.begin(), n.classes.end(), cls)) continue;
    if (found && found != n.expr) sites_.unsupported("cells of one class with number colours in several places");
    found = n.expr;
  }
  number_colour_uses_.emplace_back(cls, found);
  return found;
}

}  // namespace autumn::lower
