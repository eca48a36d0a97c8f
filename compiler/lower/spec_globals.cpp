// spec_globals — what observes the global hash map: its iteration order
// (allObjs, removeObj of one object, prev by identity), and prev.
//
// The reference keeps its globals in a std::unordered_map; runtime/hash_order
// models libstdc++'s iteration order from the history of insertions. Start-up's
// history is known here (every definition it makes, in order), so the order is
// computed at compile time. When the only key a step may add is `click` (its
// first evaluation of `clicked` defines it), whether that insertion reordered
// the map is also computed here, and the emitted code picks one of the two
// orders by whether `click` exists. Erasing a key (removeObj) keeps the order of
// the others.
//
// A program whose steps define other globals, or define keys after erasing
// some, changes the order in ways only the run decides. When a step observes
// the order in such a program, the module keeps the map's history at run time
// (State::order, a HashOrder fed the same inserts and erasures as the
// interpreter's map) and the observers loop over its keys:
//
//   before: (allObjs) in a step  ->  if (d_late) push(g_late); push(g_base);
//   after:                       ->  s.order.keys_into(keys); for (k : keys)
//                                      switch (k) { case 12: push(g_base); break; case 31: push(g_late); break; }
#include <algorithm>

#include "compiler/lower/specialise.hpp"
#include "runtime/hash_order.hpp"

namespace autumn::lower {

namespace {

// Whether a place is state (a global's value, a flag, a prev copy), or part of one.
bool in_state(const ir::Node* n) {
  switch (n->op) {
    case ir::Op::Global:
    case ir::Op::Slot: return true;
    case ir::Op::Member:
    case ir::Op::Index:
    case ir::Op::Front:
    case ir::Op::Back:
    case ir::Op::SumGet: return in_state(n->a[0]);
    case ir::Op::Select: return in_state(n->a[1]) || in_state(n->a[2]);
    default: return false;
  }
}

// Whether statements b[from..] write the state: store into, push onto, swap or
// clear a global or a flag, or define or erase a global (the map's order).
bool writes_state(const ir::Block& b, size_t from = 0) {
  for (size_t i = from; i < b.size(); ++i) {
    const ir::Stmt& s = *b[i];
    if ((s.k == ir::SK::Set || s.k == ir::SK::Push) && in_state(s.a)) return true;
    if (s.k == ir::SK::Swap && (in_state(s.a) || in_state(s.b))) return true;
    if (s.k == ir::SK::Eval && s.a->op == ir::Op::Call) {
      const ir::Helper h = s.a->helper;
      if (h == ir::Helper::DefineGlobal || h == ir::Helper::EraseGlobal) return true;
      if ((h == ir::Helper::Clear || h == ir::Helper::Append || h == ir::Helper::Reserve) && in_state(s.a->a[0])) return true;
    }
    if (s.k == ir::SK::Eval && s.a->op == ir::Op::FnCall && !s.a->a.empty() && in_state(s.a->a.back())) return true;
    if (writes_state(s.body) || writes_state(s.other)) return true;
    for (const auto& [alt, block] : s.cases)
      if (writes_state(block)) return true;
  }
  return false;
}

}  // namespace

// The global map's iteration order after start-up, without and with `click`.
std::vector<Sym> Specialiser::global_order(bool with_click) {
  HashOrder order;
  auto insert = [&](Sym s) { order.insert(s, p_.symbols.hash(s)); };
  insert(p_.names.GRID_SIZE);
  for (Sym s : p_.builtin_syms) insert(s);
  for (Sym s : start_defines_) insert(s);
  insert(p_.names.cacheRendered);
  if (with_click) insert(p_.names.click);
  std::vector<Sym> out;
  for (int s : order.order()) out.push_back(s);
  return out;
}

// Whether a step may change the map's order other than by defining `click` on
// an intact map (see the top of this file).
bool Specialiser::order_changes_in_steps() const {
  for (Sym s : h_.all_runtime_defined())
    if (s != p_.names.click) return true;
  if (h_.all_erasable().empty()) return false;
  if (h_.runtime_defined(p_.names.click)) return true;
  for (Sym s : h_.all_erasable())
    if (h_.stored_in_step(s)) return true;
  return false;
}

// The run-time order learns s (a first definition, or one after an erasure).
void Specialiser::order_insert(Sym s) {
  if (!m_.runtime_order) return;
  m_.order_hashes[s] = p_.symbols.hash(s);
  ir_.emit_eval(ir_.call(ir::Helper::DefineGlobal, nullptr, {ir_.lit(T().int_(), s)}));
}

// g's first definition: start-up's history gains it.
void Specialiser::note_definition(Global& g) {
  if (g.state != Global::Undefined) return;
  g.state = Global::Defined;
  if (!in_start_) return;
  start_defines_.push_back(g.sym);
  order_insert(g.sym);
}

// `visit` for each global in the run-time order: a loop over the keys (copied
// into a list the step keeps, pass_scratch), with a case per global that has a
// value slot (a switch: egg's state check compared each key with up to 60
// symbols in turn).
void Specialiser::walk_runtime_order(const std::function<void(Global&)>& visit, bool slotless) {
  std::vector<Global*> held;
  for (auto& [s, g] : globals_)
    if (g.state != Global::Undefined && (g.value >= 0 || slotless)) held.push_back(&g);
  switch_over_keys(ir::Helper::OrderKeys, "keys", held, visit);
}

// A loop over the symbols `keys` lists at run time (OrderKeys, DrawnKeys), with
// a case per global of `globals` that runs `visit` on it.
void Specialiser::switch_over_keys(ir::Helper keys, const char* hint, const std::vector<Global*>& globals,
                                   const std::function<void(Global&)>& visit) {
  if (globals.empty()) return;
  ir::Var* list = ir_.decl(T().list(T().int_()), nullptr, hint);
  ir_.emit_eval(ir_.call(keys, nullptr, {ir_.local(list)}));
  ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
  loop->var = ir_.var(T().int_(), "key");
  loop->a = ir_.local(list);
  ir_.in_block(loop->body, [&] {
    ir::Stmt* sw = ir_.emit(ir::SK::Switch);
    sw->a = ir_.local(loop->var);
    for (Global* g : globals) {
      sw->cases.emplace_back(g->sym, ir::Block{});
      ir_.in_block(sw->cases.back().second, [&] { visit(*g); });
    }
  });
}

// Runs `visit` over the globals in map order: once if the order cannot change,
// else in each of the two orders under a test of whether `click` exists, or
// over the order kept at run time.
void Specialiser::for_each_global_in_order(const std::function<void(Global&)>& visit, bool slotless) {
  if (in_step_ && order_changes_in_steps()) {
    if (h_.set_runtime_order()) {
      h_.learn("the global map's order is kept at run time");
      return;
    }
    walk_runtime_order(visit, slotless);
    return;
  }
  auto walk = [&](bool with_click) {
    for (Sym s : global_order(with_click)) {
      Global* g = global(s);
      if (!g || g->state == Global::Undefined || (g->value < 0 && !slotless)) continue;
      if (g->state == Global::Runtime && g->defined >= 0) {
        ir::Stmt* s_if = ir_.emit(ir::SK::If);
        s_if->a = ir_.slot(g->defined);
        ir_.in_block(s_if->body, [&] { visit(*g); });
      } else {
        visit(*g);
      }
    }
  };
  Global* click = global(p_.names.click);
  if (!click || click->value < 0 || global_order(false) == global_order(true)) {
    walk(false);
    return;
  }
  ir::Stmt* s = ir_.emit(ir::SK::If);
  s->a = ir_.slot(click->defined);
  ir_.in_block(s->body, [&] { walk(true); });
  ir_.in_block(s->other, [&] { walk(false); });
}

// The state check: every global holding a list or an instance, in map order,
// counted by the runtime's tally_global (runtime/compiled_support.hpp,
// StateTally); an excess is reported at the definition of the largest global.
void Specialiser::check_state() {
  if (ir_.dead()) return;
  ir_.emit_eval(ir_.call(ir::Helper::TallyBegin, nullptr, {}));
  auto site = [&](Sym s) {
    ErrorLoc l;
    const SourceLoc at = static_cast<size_t>(s) < p_.definitions.size() ? p_.definitions[s] : SourceLoc{};
    l.at = at;
    l.in_program = at.line > 0 && at.source == SourceId::Program;
    l.program_at = at;
    return static_cast<int64_t>(sites_.intern(l));
  };
  // A list or an instance (the interpreter counts nothing else), or a sum that may hold one.
  auto container = [](TypeP t) {
    return t->k == TK::List || t->k == TK::Pos || t->k == TK::Cell || t->k == TK::Elem || t->k == TK::Obj;
  };
  auto counted = [&](TypeP t) {
    return t && (container(t) || (t->k == TK::Sum && std::any_of(t->alts.begin(), t->alts.end(), container)));
  };
  for_each_global_in_order(
      [&](Global& g) {
        if (g.sym == p_.names.cacheRendered) {
          ir::Node* c = ir_.call(ir::Helper::TallyRendered, nullptr, {});
          c->imm = site(g.sym);
          c->text = p_.name(g.sym);
          ir_.emit_eval(c);
          return;
        }
        if (g.value < 0 || !counted(g.type)) return;
        SVal v = read_global(g);
        ir::Node* c = ir_.call(ir::Helper::TallyGlobal, nullptr, {v.code});
        c->imm = site(g.sym);
        c->text = p_.name(g.sym);
        ir_.emit_eval(c);
      },
      true);
}

// The classes of the objects allObjs may list, joined into one type; null
// when it lists none.
TypeP Specialiser::all_objs_type() {
  std::vector<TypeP> classes;
  std::function<void(TypeP)> objects_in = [&](TypeP t) {
    if (!t) return;
    if (t->k == TK::Obj && std::find(classes.begin(), classes.end(), t) == classes.end()) classes.push_back(t);
    if (t->k == TK::List) objects_in(t->elem);
    if (t->k == TK::Sum)
      for (TypeP a : t->alts) objects_in(a);
  };
  for (auto& [s, g] : globals_)
    if (g.state != Global::Undefined) objects_in(g.type);
  return classes.empty() ? nullptr : T().sum(classes);
}

// Each object allObjs lists, in its order: every object (with a render method)
// in the globals, lists searched recursively, in map order. `each` is given the
// object with its own class, where it is met (inside the loops over lists); a
// list of objects of one class goes to `whole` instead, when given.
void Specialiser::for_each_listed_object(const std::function<void(const SVal&)>& each,
                                         const std::function<void(const SVal&)>& whole) {
  std::function<void(const SVal&)> collect = [&](const SVal& v) {
    if (v.type->k == TK::Obj) {
      each(v);
    } else if (whole && v.type->k == TK::List && v.type->elem && v.type->elem->k == TK::Obj &&
               renders(v.type->elem)) {
      whole(v);
    } else if (v.type->k == TK::List && v.type->elem && renders(v.type->elem)) {
      ir::Stmt* loop = ir_.emit(ir::SK::ForEach);
      loop->var = ir_.var(v.type->elem, "x");
      loop->a = v.code;
      ir_.in_block(loop->body, [&] { collect(SVal{v.type->elem, ir_.local(loop->var)}); });
    } else if (is_sum(v.type) && renders(v.type)) {
      split(v, [&](const SVal& a) {
        collect(a);
        return SVal{T().int_(), ir_.lit(T().int_(), 0)};
      });
    }
  };
  for_each_global_in_order([&](Global& g) {
    if (renders(g.type)) collect(read_global(g));
  });
}

// allObjs: the listed objects in one list of their joined type.
SVal Specialiser::all_objs() {
  TypeP u = all_objs_type();
  if (!u) return SVal{T().empty_list(), ir_.node(ir::Op::MakeList, T().empty_list())};
  ir::Var* out = ir_.decl(T().list(u), nullptr, "all");
  for_each_listed_object([&](const SVal& v) {
    charge_one_built();
    ir_.emit_push(ir_.local(out), coerce(v, u).code);
  });
  check_length(ir::kLengthAppended, {ir_.local(out)});
  return built(out);
}

// (filter f ((allObjs))) (the stdlib's adjacentObjs): each listed object is
// tested where it is met, with its own class, and only those kept are put in a
// list; the list of every object is never built. What building it cost is
// charged as before, and before f is first called: a cell per object (at the
// allObjs call) and the list-length check on their count.
//
//   before: for (x : g_earth) { charge_built(1); all.push_back(S{x}); } ...; check_appended_length(all.size());
//           for (x : all) switch (x.index()) { case 0: if (f(get<0>(x))) out.push_back(x); ... }
//   after:  charge_built(g_earth.size()); n = n + g_earth.size(); ...; check_appended_length(n);
//           for (x : g_earth) if (f(x)) out.push_back(S{x}); ...
// A list's elements are charged at once (nothing runs between the charges one
// by one, so the step fails, or not, with the same error).
// Not where the function writes the state (below; the next walk builds the list).
// Test: tests/lowering/filter_all_objs.au.
SVal Specialiser::filter_all_objs(const SVal& f, const Expr& list, const Expr& at) {
  TypeP u = all_objs_type();
  if (!u) return empty_list();
  sites_.enter(&list);
  ir::Var* n = ir_.decl(T().int_(), ir_.lit(T().int_(), 0), "objects");
  auto count = [&](ir::Node* k) {
    charge_built(ir::kLengthIs, {k});
    ir_.emit_set(ir_.local(n), ir_.node(ir::Op::Add, T().int_(), {ir_.local(n), k}));
  };
  for_each_listed_object([&](const SVal&) { count(ir_.lit(T().int_(), 1)); },
                         [&](const SVal& l) { count(ir_.node(ir::Op::Size, T().int_(), {l.code})); });
  check_length(ir::kLengthCounted, {ir_.local(n)});
  sites_.leave();
  ir::Var* out = ir_.decl(T().list(u), nullptr, "out");
  ir::Block* block = ir_.block();
  const size_t from = block->size();
  for_each_listed_object([&](const SVal& v) {
    if (ir_.dead()) return;
    SVal y = call1(f, v, at);
    if (ir_.dead()) return;
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = truthy(y);
    ir_.in_block(s->body, [&] {
      charge_one_built();
      ir_.emit_push(ir_.local(out), coerce(v, u).code);
    });
  });
  // A function that writes the state could change what is being walked (a
  // global's list reassigned under its loop, a global defined or erased); the
  // list built first holds what allObjs listed before any call.
  if (writes_state(*block, from) && h_.add_unfused(&at))
    h_.learn("a filter over allObjs whose function writes the state (allObjs' list is built first)");
  return built(out);
}

// removeObj obj: erases the first global (map order) whose value has obj's
// identity, and returns obj.
SVal Specialiser::remove_global(const SVal& v) {
  // A function has an identity too, and erases the global holding it; the
  // compiled state keeps none for functions (found by a stress program).
  auto function = [](TypeP t) { return t->k == TK::Func; };
  if (function(v.type) || (is_sum(v.type) && std::any_of(v.type->alts.begin(), v.type->alts.end(), function)))
    sites_.unsupported("removeObj of a function (it erases the global that holds it)");
  if (!is_heap(v.type) && !is_sum(v.type)) return v;
  note_identity(v.type);
  // A global holding a sum (one class or another) is a candidate when some
  // alternative is tracked (found by a stress program: it was never erased).
  auto tracked = [&](TypeP t) {
    if (!is_sum(t)) return is_heap(t) && h_.tracked(t);
    return std::any_of(t->alts.begin(), t->alts.end(), [&](TypeP a) { return is_heap(a) && h_.tracked(a); });
  };
  std::vector<Global*> candidates;
  for (auto& [s, g] : globals_)
    if (g.state != Global::Undefined && g.type && g.value >= 0 &&
        (T().fits(v.type, g.type) || T().fits(g.type, v.type)) && tracked(g.type))
      candidates.push_back(&g);
  if (candidates.empty()) return v;
  ir::Var* done = ir_.decl(T().bool_(), ir_.lit(T().bool_(), 0), "erased");
  auto try_erase = [&](Global& g) {
    if (std::find(candidates.begin(), candidates.end(), &g) == candidates.end()) return;
    if (!h_.erasable(g.sym)) {
      h_.add_erasable(g.sym);
      h_.learn("global '" + nm(g.sym) + "' may be erased");
      return;
    }
    // A global whose slots were made before it was known to be erasable can
    // have no definedness flag (found by fuzz_emit: an initnext whose next
    // fails); such a program is the embedded engine's.
    if (g.defined < 0) sites_.unsupported("removeObj erasing '" + nm(g.sym) + "', which has no definedness flag");
    ir::Node* same = same_identity_any(SVal{g.type, ir_.slot(g.value)}, {v});
    ir::Stmt* s = ir_.emit(ir::SK::If);
    s->a = ir_.node(ir::Op::And, T().bool_(), {ir_.node(ir::Op::Not, T().bool_(), {ir_.local(done)}), same});
    ir_.in_block(s->body, [&] {
      ir_.emit_set(ir_.slot(g.defined), ir_.lit(T().bool_(), 0));
      ir_.emit_set(ir_.local(done), ir_.lit(T().bool_(), 1));
      if (m_.runtime_order) ir_.emit_eval(ir_.call(ir::Helper::EraseGlobal, nullptr, {ir_.lit(T().int_(), g.sym)}));
    });
  };
  if (candidates.size() == 1) try_erase(*candidates[0]);
  else for_each_global_in_order(try_erase);
  return v;
}

// ---------------------------------------------------------------------------
// prev

SVal Specialiser::lower_prev(const Expr& call) {
  note_reads(Builtin::Prev);
  const size_t nargs = call.kids.size() - 1;
  if (nargs != 1) {
    fail("prev takes 1 argument, got " + std::to_string(nargs));
    return never();
  }
  const Expr& arg = *call.kids[1];
  if (arg.kind == ExprKind::Var) return prev_of_name(arg.name);
  SVal v = lower_value(arg);
  if (ir_.dead()) return never();
  return prev_of_value(v, call);
}

SVal Specialiser::prev_of_name(Sym s) {
  if (!in_step_) {
    fail("prev used before the first step");
    return never();
  }
  Global* g = global(s);
  if (!g || g->state == Global::Undefined) {
    fail("prev: '" + nm(s) + "' had no value at the start of the step");
    return never();
  }
  if (!g->type || (g->value < 0 && (g->type->k == TK::Func || g->type->k == TK::Class)))
    return SVal{g->type ? g->type : T().never(), nullptr};  // a function: nothing to snapshot
  if (!h_.prev_read(s) || g->prev < 0) {  // the next walk keeps a copy
    if (h_.add_prev_read(s)) {
      h_.learn("prev of '" + nm(s) + "'");
    }
    return never();
  }
  if (g->prev_defined >= 0) {
    ir::Stmt* st = ir_.emit(ir::SK::If);
    st->a = ir_.node(ir::Op::Not, T().bool_(), {ir_.slot(g->prev_defined)});
    ir_.in_block(st->body, [&] { fail("prev: '" + nm(s) + "' had no value at the start of the step"); });
  }
  ir::Node* value = ir_.node(ir::Op::Select, g->type, {ir_.slot(g->saved), ir_.slot(g->prev), ir_.slot(g->value)});
  return let(SVal{g->type, value}, "prev");
}

// Before the step's first store to a global prev reads: its value moves into
// the snapshot (nothing else holds it; prev reads the global until now). A swap:
// the store that follows at once overwrites what the global receives, and the
// snapshot's old storage is reused instead of freed.
void Specialiser::save_for_prev(Global& g) {
  if (!in_step_ || g.prev < 0 || g.saved < 0) return;
  ir::Stmt* s_if = ir_.emit(ir::SK::If);
  s_if->a = ir_.node(ir::Op::Not, T().bool_(), {ir_.slot(g.saved)});
  ir_.in_block(s_if->body, [&] {
    ir::Stmt* sw = ir_.emit(ir::SK::Swap);
    sw->a = ir_.slot(g.prev);
    sw->b = ir_.slot(g.value);
    ir_.emit_set(ir_.slot(g.saved), ir_.lit(T().bool_(), 1));
  });
}

SVal Specialiser::prev_of_value(const SVal& v, const Expr& at) {
  (void)at;
  if (!in_step_) {
    fail("prev used before the first step");
    return never();
  }
  if (v.type->k == TK::Str) {
    if (!v.konst) sites_.unsupported("prev of a name computed at run time");
    std::string name = m_.strings[v.konst->imm];
    if (!name.empty() && name[0] == '"') name = name.substr(1, name.size() - 2);
    Sym s = p_.symbols.find(name);
    if (s < 0) {
      fail("prev: '" + name + "' had no value at the start of the step");
      return never();
    }
    return prev_of_name(s);
  }
  // A value that may be an object of one of several classes (or any other heap
  // value) is found by identity as one of one class is (found by a stress
  // program, round z2: the compiled engine failed with "no variable held this value").
  const bool heap = is_heap(v.type) || (is_sum(v.type) && std::any_of(v.type->alts.begin(), v.type->alts.end(), is_heap));
  if (!heap) {
    fail("prev: no variable held this value at the start of the step");
    return never();
  }
  sites_.unsupported("prev of a value (identity scan of the snapshot)");
}

}  // namespace autumn::lower
