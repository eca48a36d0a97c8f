// spec_host — the host algorithm, specialised: start-up, the step, the host render.
//
// Mirrors compiler/interpret/host.cpp statement for statement:
//   start: GRID_SIZE and the builtins, the stdlib, SpecialConditionTriggered, the
//          program's statements in source order (classes defined, on-clauses and
//          initnext registered, everything else evaluated), the initialisers in
//          INIT hash order, then a render;
//   step:  the prev snapshot, updated flags cleared, the trigger, the on-clauses in
//          source order, NEXT in hash order for variables no clause assigned and
//          still defined;
//   render: globals in the render order analyse computed, occupancy and frame.
// Start-up runs once, so it is specialised with everything it knows: which
// globals exist, their constant values. The step is specialised once for all
// steps: what varies between steps (a global a step may erase or create) is
// checked at run time.
#include <algorithm>
#include <set>

#include "compiler/analyse/render_order.hpp"
#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {
namespace {

void walk_vars(const Expr& e, std::set<Sym>& out) {
  if (e.kind == ExprKind::Var) out.insert(e.name);
  for (const auto& k : e.kids) walk_vars(*k, out);
}

}  // namespace

void Specialiser::run() {
  m_.classes = f_.classes;
  class_defined_.assign(m_.classes.size(), 0);
  load_shapes();
  m_.uses_random = p_.uses_random;
  m_.runtime_order = h_.runtime_order();
  m_.draw_order = h_.draw_order();
  specialise_start();
  specialise_step();
  specialise_render();
  finish_classes();
}

// ---------------------------------------------------------------------------
// start

void Specialiser::specialise_start() {
  m_.functions.push_back(std::make_unique<ir::Function>());
  ir::Function* fn = m_.functions.back().get();
  fn->name = "start";
  fn->kind = ir::Function::Start;
  m_.start_fn = static_cast<int>(m_.functions.size() - 1);
  ir_.begin_function(fn);
  in_start_ = true;

  Global& grid = global_slot(p_.names.GRID_SIZE, T().int_());
  define_global(grid, SVal{T().int_(), ir_.lit(T().int_(), 16), ir_.lit(T().int_(), 16)});
  for (int i = 0; i < kBuiltinCount; ++i) {
    Global& g = globals_[p_.builtin_syms[i]];
    g.sym = p_.builtin_syms[i];
    g.type = T().func(FuncRef{FuncRef::Native, nullptr, static_cast<Builtin>(i), -1});
    g.state = Global::Defined;
    order_insert(g.sym);
  }
  auto run_statement = [&](const Stmt& st) {
    sites_.enter(st.expr.get());
    lower_discarded(*st.expr);
    sites_.leave();
  };
  for (const Stmt& st : p_.stdlib_stmts)
    if (st.kind == StmtKind::Expr) run_statement(st);
  {
    Expr at{ExprKind::Bool, SourceLoc{0, 0, SourceId::Internal}};
    assign(p_.names.SpecialConditionTriggered, SVal{T().bool_(), ir_.lit(T().bool_(), 0), ir_.lit(T().bool_(), 0)}, at);
  }
  for (const Stmt& st : p_.stmts) {
    if (st.kind == StmtKind::Object) {
      define_class(st);
    } else if (st.kind == StmtKind::On) {
      continue;  // registered in the facts
    } else if (st.expr->kind == ExprKind::Assign && st.expr->kids[0]->kind == ExprKind::InitNext) {
      Global& g = globals_[st.expr->name];
      g.sym = st.expr->name;
      g.initnext = true;
      g.init = st.expr->kids[0]->kids[0].get();
      g.next = st.expr->kids[0]->kids[1].get();
    } else {
      run_statement(st);
    }
  }
  m_.on_clauses = static_cast<int>(f_.on_clauses.size());
  for (Sym s : f_.initnext_order) {
    Global& g = globals_[s];
    sites_.set_prefix("initialising '" + nm(s) + "': ");
    ir_.comment("init " + nm(s) + ", " + p_.file_name(g.init->loc.source) + ":" + std::to_string(g.init->loc.line));
    sites_.enter(g.init);
    SVal v = lower_value(*g.init);
    sites_.leave();
    sites_.set_prefix("");
    if (v.type->k != TK::Never) define_global(g, v);
  }
  publish_trigger();
  check_state();
  // The render that ends start-up defines cacheRendered (the printer calls it).
  Global& cache = globals_[p_.names.cacheRendered];
  cache.sym = p_.names.cacheRendered;
  note_definition(cache);
  in_start_ = false;
}

// A class definition: its field types (declared, joined with what the hints saw)
// and the type text errors print.
void Specialiser::define_class(const Stmt& st) {
  int c = f_.class_of_sym[st.object_sym];
  ClassInfo& ci = m_.classes[c];
  // A name defined twice: each definition has a class, the later one is
  // the name's; the lowering knows only one class per name (found by
  // fuzz_emit: fields of the earlier written into the later's).
  if (ci.stmt != &st) sites_.unsupported("object '" + ci.name + "' defined twice");
  check_render_lookups(st);
  for (size_t i = 0; i < st.fields.size(); ++i) {
    TypeP declared = declared_type(*st.fields[i].type);
    if (!declared && ci.unknown_field.empty()) ci.unknown_field = ci.field_names[i];
    TypeP hinted = h_.field(c, static_cast<int>(i));
    ci.field_types[i] = declared && hinted ? T().join(declared, hinted) : declared ? declared : hinted;
  }
  ci.type_string = "class " + ci.name + " {";
  for (size_t i = 0; i < st.fields.size(); ++i) {
    TypeP declared = declared_type(*st.fields[i].type);
    ci.type_string += ci.field_names[i] + ": " + (declared ? type_string(declared) : std::string("?")) + ", ";
  }
  ci.type_string += "origin: " + type_string(T().pos()) + ", elems: List<" + type_string(T().cell()) + ">, }";
  class_defined_[c] = 1;
}

// The interpreter's render method is an Autumn lambda run in a scope that binds
// the object's fields, so a field named like a name the lambda looks up
// (`map`, `RenderedElem`, `Position`) is what it calls; and the native render
// (the host's, isWithinBounds, clicked) calls a field named `render` instead of
// the method. The specialised render does neither, so such a class is left to
// the embedded interpreter.
void Specialiser::check_render_lookups(const Stmt& st) {
  std::set<Sym> looked_up;
  walk_vars(*p_.render_lambda, looked_up);
  for (Sym own : {p_.names.origin, p_.names.elems, p_.names.e}) looked_up.erase(own);
  looked_up.insert(p_.names.render);
  for (const ObjectField& f : st.fields)
    if (looked_up.count(f.name)) {
      sites_.enter(st.cell_expr.get());
      sites_.unsupported("field '" + f.name_text + "' of '" + st.object_name +
                         "' shadows a name the render calls");
    }
}

// ---------------------------------------------------------------------------
// step

void Specialiser::specialise_step() {
  m_.functions.push_back(std::make_unique<ir::Function>());
  ir::Function* fn = m_.functions.back().get();
  fn->name = "step";
  fn->kind = ir::Function::Step;
  m_.step_fn = static_cast<int>(m_.functions.size() - 1);
  ir_.begin_function(fn);
  in_step_ = true;
  scopes_.replace({});

  // What a step may change about a global's existence is checked at run time.
  for (const std::set<Sym>* set : {&h_.all_erasable(), &h_.all_runtime_defined()})
    for (Sym s : *set) {
      Global& g = globals_[s];
      g.sym = s;
      g.state = Global::Runtime;
      // First defined by a step: its slot now, so that a read before this
      // walk meets the definition finds it (define_global and define_click
      // record the type).
      if (TypeP hinted = h_.global(s); g.value < 0 && hinted) global_slot(s, hinted);
    }
  for (auto& [sym, g] : globals_)
    if (g.state != Global::Undefined && h_.stored_in_step(sym) && g.constant && g.constant->type->k != TK::Func)
      g.constant.reset();
  // 1. The prev snapshot: the globals prev reads, as they are now. Not copied:
  //    a global's value moves into its snapshot at the step's first store to it
  //    (save_for_prev), and prev reads the global until then.
  for (Sym s : h_.all_prev_read()) {
    Global& g = globals_[s];
    if (g.value < 0 || g.prev < 0) continue;
    ir_.emit_set(ir_.slot(g.saved), ir_.lit(T().bool_(), 0));
    if (g.prev_defined >= 0) ir_.emit_set(ir_.slot(g.prev_defined), g.defined >= 0 ? ir_.slot(g.defined) : ir_.lit(T().bool_(), 1));
  }
  // 2. Updated flags.
  for (Sym s : f_.initnext_order) {
    Global& g = globals_[s];
    if (g.updated >= 0) ir_.emit_set(ir_.slot(g.updated), ir_.lit(T().bool_(), 0));
  }
  // 3. The trigger, on the state before this step's updates.
  if (p_.trigger) {
    sites_.enter(p_.trigger.get());
    SVal c = lower_value(*p_.trigger);
    if (!ir_.dead()) {
      ir::Node* t = truthy(c);
      SVal b = let(SVal{T().bool_(), t});
      assign(p_.names.SpecialConditionTriggered, b, *p_.trigger);
      ir_.emit_eval(ir_.call(ir::Helper::SetTriggered, nullptr, {b.code}));
    }
    sites_.leave();
  }
  // 4. On-clauses in source order.
  for (size_t i = 0; i < f_.on_clauses.size() && !ir_.dead(); ++i) on_clause(i, *f_.on_clauses[i]);
  // 5. NEXT for every initnext variable no clause assigned, in hash order.
  for (Sym s : f_.initnext_order) {
    if (ir_.dead()) break;
    next_update(s);
  }
  publish_trigger();
  // 6. The state budget.
  check_state();
  in_step_ = false;
}

// The host's trigger state (Environment::triggered) is the global
// SpecialConditionTriggered, which a program may assign as any other (the
// interpreter's triggered() reads it): where start-up or a step may have
// changed it, the runtime learns its value. Start-up's false and a step that
// never stores it need nothing (the trigger's own SetTriggered covers it).
// With a --trigger both stores are kept: the trigger's publishes before the
// clauses run, so a step that fails in them still reports the trigger's value,
// as the interpreter's triggered() does after a failed step.
void Specialiser::publish_trigger() {
  Global* g = global(p_.names.SpecialConditionTriggered);
  if (!g || g->value < 0 || ir_.dead()) return;
  const bool start_false = g->constant && g->constant->konst && g->constant->konst->op == ir::Op::Lit &&
                           g->constant->type == T().bool_() && g->constant->konst->imm == 0;
  if (in_step_ ? !h_.stored_in_step(g->sym) : start_false) return;
  if (g->type != T().bool_()) sites_.unsupported("SpecialConditionTriggered holding a value that is not a Bool");
  ir::Node* v = ir_.slot(g->value);
  if (g->defined >= 0) v = ir_.node(ir::Op::And, T().bool_(), {ir_.slot(g->defined), v});
  ir_.emit_eval(ir_.call(ir::Helper::SetTriggered, nullptr, {v}));
}

// One on-clause: its condition (a Bool, or a function called with no arguments
// that must return one), then, when it holds, its body.
void Specialiser::on_clause(size_t i, const Stmt& st) {
  ir_.comment("on-clause " + std::to_string(i + 1) + ", " + p_.file_name(st.loc.source) + ":" +
          std::to_string(st.loc.line));
  ir::Stmt* blk = ir_.emit(ir::SK::Block);
  ir_.in_block(blk->body, [&] {
    sites_.enter(st.cond.get());
    SVal c = lower_value(*st.cond);
    ir::Node* fire = nullptr;
    auto bad = [&](const SVal& v, bool from_fn) {
      sites_.enter(st.cond.get());
      fail(std::string(from_fn ? "an on-clause condition function must return a Bool, got "
                               : "an on-clause condition must be a Bool, got ") + shown(v.type));
      sites_.leave();
    };
    if (is_function(c.type)) {
      std::vector<SVal> none;
      SVal r = call_value(c, none, *st.cond);
      if (!ir_.dead()) fire = narrow(r, TK::Bool, [&](const SVal& a) { bad(a, true); }).code;
    } else if (may_be_function(c.type)) {
      // A function or another value (a mixed list's head, an if's branches):
      // each alternative as the interpreter's condition_holds takes it (found
      // by a stress program, round z2: such a function was refused).
      SVal f = split(c, [&](const SVal& a) -> SVal {
        if (a.type->k != TK::Func) return narrow(a, TK::Bool, [&](const SVal& b) { bad(b, false); });
        std::vector<SVal> none;
        SVal r = call_value(a, none, *st.cond);
        if (ir_.dead()) return never();
        return narrow(r, TK::Bool, [&](const SVal& b) { bad(b, true); });
      });
      if (!ir_.dead()) fire = f.code;
    } else {
      fire = narrow(c, TK::Bool, [&](const SVal& a) { bad(a, false); }).code;
    }
    sites_.leave();
    if (ir_.dead() || !fire) return;
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = fire;
    ir_.in_block(s->body, [&] {
      ir_.emit_eval(ir_.call(ir::Helper::Covered, nullptr, {ir_.lit(T().int_(), static_cast<int64_t>(i))}));
      sites_.enter(st.body.get());
      value_unused_ = true;  // its value is only checked to exist
      lower_value(*st.body);
      sites_.leave();
      scopes_.replace({});
    });
  });
}

// NEXT of one initnext variable: when no clause assigned it and it is defined.
void Specialiser::next_update(Sym s) {
  Global& g = globals_[s];
  if (g.value < 0) {  // its initialiser's type is not known yet (the next walk), or a function
    if (g.type && (g.type->k == TK::Func || g.type->k == TK::Class)) sites_.unsupported("an initnext variable holding a function");
    return;
  }
  // A global whose value slot was made before it was known to be an initnext
  // (GRID_SIZE, set up first) has no update flag (found by fuzz_emit).
  if (g.updated < 0) sites_.unsupported("'" + nm(s) + "' defined by initnext");
  ir_.comment("NEXT of " + nm(s) + ", " + p_.file_name(g.next->loc.source) + ":" + std::to_string(g.next->loc.line));
  ir::Node* run = ir_.node(ir::Op::Not, T().bool_(), {ir_.slot(g.updated)});
  if (g.state == Global::Runtime) run = ir_.node(ir::Op::And, T().bool_(), {run, ir_.slot(g.defined)});
  // (prev x) as x's own NEXT, the usual idiom: while nothing stored x in this
  // step, x holds that very value (assigning it to itself changes nothing).
  // (Unless the assignment's type check itself fails: a class that cannot be printed.)
  auto printable = [&](TypeP t) { return t->k != TK::Obj || m_.classes[t->cls].unknown_field.empty(); };
  bool checkable = printable(g.type);
  if (is_sum(g.type))
    for (TypeP a : g.type->alts) checkable = checkable && printable(a);
  if (is_own_prev(*g.next, s) && g.saved >= 0 && checkable)
    run = ir_.node(ir::Op::And, T().bool_(), {run, ir_.slot(g.saved)});
  ir::Stmt* s_if = ir_.emit(ir::SK::If);
  s_if->a = run;
  ir_.in_block(s_if->body, [&] {
    sites_.enter(g.next);
    SVal v = lower_value(*g.next);
    if (!ir_.dead()) assign(s, v, *g.next);
    sites_.leave();
  });
}

// Whether `e` is (prev x) with the builtin prev, for the global x.
bool Specialiser::is_own_prev(const Expr& e, Sym x) {
  if (e.kind != ExprKind::Call || e.kids.size() != 2 || e.kids[0]->kind != ExprKind::Var) return false;
  if (e.kids[1]->kind != ExprKind::Var || e.kids[1]->name != x) return false;
  Global* prev = global(e.kids[0]->name);
  return prev && prev->type && prev->type->k == TK::Func && prev->type->fn.kind == FuncRef::Native &&
         prev->type->fn.builtin == Builtin::Prev && !prev->constant;
}

// ---------------------------------------------------------------------------
// render

void Specialiser::specialise_render() {
  m_.functions.push_back(std::make_unique<ir::Function>());
  ir::Function* fn = m_.functions.back().get();
  fn->name = "render";
  fn->kind = ir::Function::Render;
  m_.render_fn = static_cast<int>(m_.functions.size() - 1);
  ir_.begin_function(fn);
  scopes_.replace({});
  Expr at{ExprKind::Var, SourceLoc{0, 0, SourceId::Internal}};
  sites_.reset(&at);

  Global* grid = global(p_.names.GRID_SIZE);
  if (!grid || !grid->constant || grid->type->k != TK::Int) sites_.unsupported("GRID_SIZE changes while the program runs");
  m_.grid = static_cast<int>(grid->constant->konst->imm);
  if (m_.grid <= 0 || m_.grid > 4096) sites_.unsupported("GRID_SIZE " + std::to_string(m_.grid) + " cannot be painted");

  ir_.emit_eval(ir_.call(ir::Helper::OccupancyClear, nullptr, {}));
  Global* bg = global(p_.names.background);
  ir::Node* background = bg && bg->state != Global::Undefined && bg->type == T().str() && bg->value >= 0
                             ? ir_.slot(bg->value)
                             : ir_.lit(T().str(), string_id("\"black\""));
  if (bg && bg->state == Global::Runtime && bg->type == T().str())
    background = nullptr;  // checked below
  if (!background) sites_.unsupported("background may be erased");
  ir_.emit_eval(ir_.call(ir::Helper::PaintBegin, nullptr, {background}));

  // Every rendered element marks the occupancy and is painted, in render order.
  // The host's render_all() JSON names each element's global: the painter
  // learns it before the global's elements (runtime/render_json.hpp).
  auto draw = [&](Global& g) {
    m_.render_names.push_back(nm(g.sym));
    ir_.emit_eval(ir_.call(ir::Helper::PaintGlobal, nullptr,
                   {ir_.lit(T().int_(), static_cast<int64_t>(m_.render_names.size() - 1))}));
    render_into(read_global(g), [&](ir::Node* elem) {
      SVal e = let(SVal{T().elem(), elem}, "e");
      ir_.emit_eval(ir_.call(ir::Helper::OccupancyAdd, nullptr, {ir_.member(e.code, ir::Member::Position, T().pos())}));
      ir_.emit_eval(ir_.call(ir::Helper::Paint, nullptr, {e.code}));
    });
  };
  auto draw_if_defined = [&](Global& g) {
    if (g.state != Global::Runtime) return draw(g);
    ir::Stmt* s_if = ir_.emit(ir::SK::If);
    s_if->a = ir_.slot(g.defined);
    ir_.in_block(s_if->body, [&] { draw(g); });
  };
  auto drawable = [&](Sym s) {
    Global* g = global(s);
    return g && g->state != Global::Undefined && g->type && g->value >= 0 && renders(g->type) ? g : nullptr;
  };
  for (Sym s : p_.render_order)
    if (Global* g = drawable(s)) draw_if_defined(*g);
  // Globals steps first define draw after start-up's, in the order the run
  // first defines them (render_order.hpp): kept at run time (State::drawn)
  // when two or more of them draw.
  std::vector<Global*> later;
  for (Sym s : h_.all_runtime_defined())
    if (Global* g = drawable(s); g && drawn_late(*g)) later.push_back(g);
  if (later.size() > 1 && h_.set_draw_order()) h_.learn("globals steps define are drawn in the order the run defines them");
  if (!m_.draw_order)
    for (Global* g : later) draw_if_defined(*g);
  else
    switch_over_keys(ir::Helper::DrawnKeys, "drawn", later, draw_if_defined);
  ir_.emit_eval(ir_.call(ir::Helper::PaintEnd, nullptr, {}));
  sites_.reset(nullptr);
}

// A global that steps first define and that draws: drawn after start-up's
// globals, in the order the run first defines such globals (State::drawn).
bool Specialiser::drawn_late(const Global& g) const {
  return h_.runtime_defined(g.sym) && g.type && g.value >= 0 && renders(g.type) &&
         !std::count(p_.render_order.begin(), p_.render_order.end(), g.sym);
}

}  // namespace autumn::lower
