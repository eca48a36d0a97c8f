// spec_scope — names: lookup, assignment and definition over the static scope chain.
//
// The interpreter's scope chain is dynamic, but every call is inlined here, so at
// each point the chain is a list of static scopes (scope_chain.hpp, outermost first) over
// the globals. A name resolves to the innermost binding that has it. Whether a
// binding exists can depend on the run (a `let` variable first assigned in one
// branch of an `if`, a global that removeObj erased or an on-clause creates);
// such bindings carry a run-time flag, and a lookup becomes a chain of guarded
// candidates ending in an "undefined variable" error if none holds.
//
// Assignment follows eval.cpp's Interpreter::assign: the innermost scope holding
// the name gets the value (type-checked by type string unless the value is a
// list, and given the old value's identity), else the name is defined in the
// current scope. New local names are declared at the start of their scope's
// block (hoisted), so every branch and the code after it can see them.
#include <algorithm>

#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {

Global* Specialiser::global(Sym s) {
  auto it = globals_.find(s);
  return it == globals_.end() ? nullptr : &it->second;
}

static std::string slot_name(const std::string& prefix, const std::string& name) {
  std::string out = prefix;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

// The global's state members, made when it first needs a value slot. The slot
// type is the hint if one was learnt, else the first value's type.
Global& Specialiser::global_slot(Sym s, TypeP t) {
  Global& g = globals_[s];
  g.sym = s;
  if (g.value >= 0) return g;
  if (TypeP hinted = h_.global(s)) t = T().join(hinted, t);
  g.type = t;
  if (t->k == TK::Func || t->k == TK::Class || t->k == TK::Never) return g;  // nothing at run time
  const std::string& n = nm(s);
  auto add = [&](const std::string& prefix, TypeP type, ir::Slot::Kind kind, bool snapshot) {
    m_.slots.push_back(ir::Slot{slot_name(prefix, n) + "_" + std::to_string(m_.slots.size()), type, kind, s, snapshot});
    return static_cast<int>(m_.slots.size() - 1);
  };
  g.value = add("g_", t, ir::Slot::Value, true);
  if (g.initnext) g.updated = add("u_", nullptr, ir::Slot::Updated, false);
  if (h_.erasable(s) || h_.runtime_defined(s) || s == p_.names.click)
    g.defined = add("d_", nullptr, ir::Slot::Defined, true);
  if (h_.prev_read(s)) {
    g.prev = add("p_", t, ir::Slot::Prev, false);
    g.saved = add("sv_", nullptr, ir::Slot::Saved, false);
    if (g.defined >= 0) g.prev_defined = add("pd_", nullptr, ir::Slot::PrevDefined, false);
  }
  return g;
}

// ---------------------------------------------------------------------------
// Lookup

struct Specialiser::Candidate {
  Binding* b = nullptr;
  Global* g = nullptr;
  ir::Node* guard = nullptr;  // null: certainly bound
};

std::vector<Specialiser::Candidate> Specialiser::resolve(Sym sym) {
  std::vector<Candidate> out;
  for (auto it = scopes_.visible().rbegin(); it != scopes_.visible().rend(); ++it)
    if (Binding* b = (*it)->find(sym)) {
      out.push_back(Candidate{b, nullptr, b->flag ? ir_.local(b->flag) : nullptr});
      if (!b->flag) return out;
    }
  if (capture_mode_) return out;  // a cell's capture scope has no parent
  if (Global* g = global(sym); g && g->state != Global::Undefined) {
    ir::Node* guard = g->state == Global::Runtime && g->defined >= 0 ? ir_.slot(g->defined) : nullptr;
    out.push_back(Candidate{nullptr, g, guard});
  }
  return out;
}

SVal Specialiser::read_global(Global& g) {
  if (g.constant && (g.constant->type->k == TK::Int || g.constant->type->k == TK::Bool ||
                     g.constant->type->k == TK::Str || g.constant->type->k == TK::Func))
    return *g.constant;
  if (!g.type || g.value < 0) {
    // Nothing at run time (a function, a class) reads as nothing. A global with
    // a value but no slot yet would lower to nothing too, and the code after it
    // would be dropped: a step's read of click before its definition did so
    // (fixed in define_click). No program of the corpus reaches this; one
    // that does gets the interpreter in its module, not a clause that runs on.
    if (!g.type || (g.type->k != TK::Func && g.type->k != TK::Class && g.type->k != TK::Never))
      sites_.unsupported("global '" + nm(g.sym) + "' read before the lowering gave it a place");
    return SVal{g.type ? g.type : T().never(), nullptr};  // never a value without a type
  }
  SVal v = let(SVal{g.type, ir_.slot(g.value)}, "g");
  if (g.constant) v.konst = g.constant->konst;
  return v;
}

SVal Specialiser::read_binding(Binding& b) {
  ir::Node* k = !b.mut || b.home == ir_.block() ? b.konst : nullptr;
  if (!b.place) return SVal{b.type, nullptr, k};
  SVal v = let(SVal{b.type, b.place}, "v");
  v.konst = k;
  return v;
}

SVal Specialiser::read_name(Sym s, const Expr& at) {
  (void)at;
  std::vector<Candidate> cands = resolve(s);
  auto read = [&](Candidate& c) { return c.b ? read_binding(*c.b) : read_global(*c.g); };
  if (!cands.empty() && !cands[0].guard) return read(cands[0]);
  // Guarded: the first candidate bound at run time, else an error.
  std::function<SVal(size_t)> chain = [&](size_t i) -> SVal {
    if (i == cands.size()) {
      fail("undefined variable '" + nm(s) + "'");
      return never();
    }
    if (!cands[i].guard) return read(cands[i]);
    return join_branches(cands[i].guard, [&] { return read(cands[i]); }, [&] { return chain(i + 1); }, true);
  };
  return chain(0);
}

// ---------------------------------------------------------------------------
// Assignment and definition

void Specialiser::check_declared(Sym s, const SVal& v) {
  const TypeExpr* decl = nullptr;
  for (auto it = scopes_.visible().rbegin(); it != scopes_.visible().rend() && !decl; ++it)
    for (auto& [name, te] : (*it)->declared)
      if (name == s) decl = te;
  if (!decl) {
    auto it = global_decls_.find(s);
    if (it != global_decls_.end()) decl = it->second;
  }
  if (!decl || decl->is_list || !v.type || v.type->k == TK::Never) return;
  TypeP dt = declared_type(*decl);
  // An unknown declared type prints as nothing the value's type can equal.
  const std::string want = dt ? type_string(dt) : std::string("?");
  auto check = [&](const SVal& x) {
    if (x.type->k == TK::List) return x;
    if (dt && !check_printable(dt)) return x;
    if (!check_printable(x.type)) return x;
    if (want != type_string(x.type))
      fail("cannot assign a value of type '" + shown(x.type) + "' to '" + nm(s) + "', declared as '" + shown_type(want) +
           "'");
    return x;
  };
  split(v, check);
}

// Stores into an existing binding or global: the type check and identity rule of
// Interpreter::assign.
void Specialiser::store_checked(TypeP slot_type, ir::Node* place, SVal v, Sym s, const std::function<void(TypeP)>& widen,
                                const std::function<void()>& before_write) {
  // Unless the new value is a list, the old and new values' type strings must agree
  // (each alternative of either, when one holds a variant).
  auto check_new = [&](const SVal& nv) {
    if (nv.type->k == TK::List || nv.type->k == TK::Never) return nv;
    auto check_old = [&](const SVal& old) {
      if (old.type->k == TK::Never) return old;
      if (!check_printable(old.type) || !check_printable(nv.type)) return old;
      // The message names the old list's type tag, which depends on how the list
      // was made (a map's result is a List of Unknown): not known here.
      if (old.type->k == TK::List)
        sites_.unsupported("assigning a value that is not a list to a variable that holds a list (the error names the list's type tag)");
      if (type_string(old.type) != type_string(nv.type))
        fail("cannot assign a value of type '" + shown(nv.type) + "' to variable '" + nm(s) + "' of type '" +
             shown(old.type) + "'");
      return old;
    };
    split(SVal{slot_type, place}, check_old);
    return nv;
  };
  split(v, check_new);
  if (ir_.dead()) return;
  if (h_.tracked(v.type) || (is_heap(v.type) && h_.tracked(slot_type))) transfer_identity(v, SVal{slot_type, place});
  if (!T().fits(v.type, slot_type)) {
    widen(T().join(slot_type, v.type));
    return;
  }
  ir::Node* value = coerce(v, slot_type).code;
  if (before_write) before_write();
  ir_.emit_set(place, value);
}

void Specialiser::define_local(SScope& sc, Sym s, SVal v, const void* site) {
  // A cell argument's capture scope (construct_cell) owns no block to declare
  // in: an assignment inside a cell argument is the embedded engine's (found by
  // fuzz_emit: tests/lowering/assign_in_cell_argument.au).
  if (!sc.block) sites_.unsupported("an assignment inside a cell argument");
  std::pair<const void*, Sym> key{site, s};
  if (Binding* b = sc.find(s)) {  // a maybe-bound name of this scope, now bound
    if (b->flag) ir_.emit_set(ir_.local(b->flag), ir_.lit(T().bool_(), 1));
    b->konst = v.konst;
    b->home = ir_.block();
    if (!T().fits(v.type, b->type)) {
      h_.set_local(b->key, T().join(b->type, v.type));
      h_.learn("local '" + nm(s) + "'");
      return;
    }
    if (b->place) ir_.emit_set(b->place, coerce(v, b->type).code);
    return;
  }
  TypeP t = v.type;
  if (TypeP hinted = h_.local(key)) t = T().join(hinted, t);
  Binding b;
  b.sym = s;
  b.type = t;
  b.key = key;
  b.mut = true;
  // Declared where the scope begins, so that code after a branch can read it.
  auto hoisted = [&](ir::Var* x, ir::Node* init) {
    ir::Stmt* d = &(m_.arena.stmts.emplace_back());
    d->k = ir::SK::Decl;
    d->var = x;
    d->a = init;
    if (!ir_.dead() || sc.block != ir_.block()) sc.block->insert(sc.block->begin() + sc.hoist++, d);
  };
  if (t->k != TK::Func && t->k != TK::Class && t->k != TK::Never) {
    ir::Var* x = ir_.var(t, "l_" + nm(s));
    x->mut = true;
    hoisted(x, nullptr);
    b.place = ir_.local(x);
  }
  b.konst = v.konst;
  b.home = ir_.block();
  if (ir_.block() != sc.block) {  // defined on some paths only
    b.flag = ir_.var(T().bool_(), "has_" + nm(s));
    b.flag->mut = true;
    hoisted(b.flag, ir_.lit(T().bool_(), 0));
    ir_.emit_set(ir_.local(b.flag), ir_.lit(T().bool_(), 1));
  }
  if (b.place) ir_.emit_set(b.place, coerce(v, t).code);
  sc.vars.push_back(b);
}

// A function's value is all compile-time: a global holding one is a constant
// while start-up assigns it on every path and no step assigns another.
bool Specialiser::store_function(Global& g, const SVal& v) {
  if (v.type->k != TK::Func && !(g.type && g.type->k == TK::Func && g.value < 0)) return false;
  if (v.type->k != TK::Func || (g.type && g.type->k != TK::Func && g.state != Global::Undefined)) {
    const std::string old = g.type ? type_string(g.type) : "";
    if (v.type->k != TK::List && g.state != Global::Undefined && old != type_string(v.type))
      fail("cannot assign a value of type '" + shown(v.type) + "' to variable '" + nm(g.sym) + "' of type '" +
           shown_type(old) + "'");
    else if (!ir_.dead()) sites_.unsupported("a global holding a function and then another kind of value");
    return true;
  }
  if (in_step_ || !ir_.at_function_top()) {
    if (g.constant && g.constant->type == v.type) return true;  // the same function again
    sites_.unsupported("a global assigned a different function on some paths or while the program runs");
  }
  g.type = v.type;
  g.constant = v;
  note_definition(g);
  return true;
}

void Specialiser::define_global(Global& g, SVal v) {
  if (store_function(g, v)) return;
  if (g.value < 0 && v.type->k != TK::Func && v.type->k != TK::Class) global_slot(g.sym, v.type);
  if (!g.type) g.type = v.type;
  if (!T().fits(v.type, g.type)) {
    h_.set_global(g.sym, T().join(g.type, v.type));
    h_.learn("global '" + nm(g.sym) + "'");
    return;
  }
  if (in_step_) {
    if (!h_.runtime_defined(g.sym) && g.state != Global::Runtime) {
      h_.add_runtime_defined(g.sym);
      if (!h_.global(g.sym) && g.type) h_.set_global(g.sym, g.type);
      h_.learn("'" + nm(g.sym) + "' is defined while the program runs");
      return;
    }
  }
  save_for_prev(g);
  if (g.defined >= 0) ir_.emit_set(ir_.slot(g.defined), ir_.lit(T().bool_(), 1));
  if (in_step_ && (h_.runtime_defined(g.sym) || h_.erasable(g.sym))) order_insert(g.sym);
  if (in_step_ && m_.draw_order && drawn_late(g))
    ir_.emit_eval(ir_.call(ir::Helper::NoteDrawn, nullptr, {ir_.lit(T().int_(), g.sym)}));
  if (g.value >= 0) ir_.emit_set(ir_.slot(g.value), coerce(v, g.type).code);
  if (g.updated >= 0) ir_.emit_set(ir_.slot(g.updated), ir_.lit(T().bool_(), 0));
  note_definition(g);
  // Start-up knows the values it computes from constants (on every path).
  if (in_start_ && v.konst && ir_.at_function_top()) g.constant = v;
  else g.constant.reset();
}

void Specialiser::store_global(Global& g, SVal v, const Expr& at, bool mark_updated) {
  (void)at;
  if (in_step_ && !h_.stored_in_step(g.sym)) {
    h_.add_stored_in_step(g.sym);
    if (g.constant) {  // a constant global that a step changes is not a constant
      h_.learn("global '" + nm(g.sym) + "' changes while the program runs");
    }
  }
  if (store_function(g, v)) return;
  if (g.value < 0) {
    h_.set_global(g.sym, g.type ? T().join(g.type, v.type) : v.type);
    h_.learn("global '" + nm(g.sym) + "'");
    return;
  }
  store_checked(
      g.type, ir_.slot(g.value), v, g.sym,
      [&](TypeP wider) {
        h_.set_global(g.sym, wider);
        h_.learn("global '" + nm(g.sym) + "'");
      },
      [&] { save_for_prev(g); });
  if (mark_updated && g.updated >= 0) ir_.emit_set(ir_.slot(g.updated), ir_.lit(T().bool_(), 1));
  if (in_start_ && v.konst && !ir_.dead() && ir_.at_function_top()) g.constant = v;
  else g.constant.reset();
}

void Specialiser::assign(Sym s, SVal v, const Expr& at) {
  if (!v.type || v.type->k == TK::Never || ir_.dead()) return;
  std::vector<Candidate> cands = resolve(s);
  auto store = [&](Candidate& c) {
    if (c.g) {
      store_global(*c.g, v, at, true);
      return;
    }
    Binding& b = *c.b;
    if (!b.mut) {  // a name for a value: the next walk gives it a variable of its own
      if (h_.add_mutable_binding(b.key)) {
        h_.learn("'" + nm(s) + "' is assigned");
      }
      return;
    }
    b.konst = v.konst;
    b.home = ir_.block();
    if (!b.place) {  // a function-valued binding: only the same function fits
      if (v.type != b.type) {
        h_.set_local(b.key, T().join(b.type, v.type));
        h_.learn("local '" + nm(s) + "'");
      }
      return;
    }
    store_checked(b.type, b.place, v, s, [&](TypeP wider) {
      h_.set_local(b.key, wider);
      h_.learn("local '" + nm(s) + "'");
    });
  };
  auto define_here = [&] {
    if (scopes_.empty()) {
      Global& g = globals_[s];
      g.sym = s;
      define_global(g, v);
    } else {
      define_local(scopes_.innermost(), s, v, &at);
    }
  };
  std::function<void(size_t)> walk = [&](size_t i) {
    if (i == cands.size()) return define_here();
    if (!cands[i].guard) return store(cands[i]);
    ir::Stmt* s_if = ir_.emit(ir::SK::If);
    s_if->a = cands[i].guard;
    ir_.in_block(s_if->body, [&] { store(cands[i]); });
    ir_.in_block(s_if->other, [&] { walk(i + 1); });
  };
  walk(0);
}

SVal Specialiser::lower_assign(const Expr& e, bool unused) {
  (void)unused;
  const Expr& rhs = *e.kids[0];
  if (rhs.kind == ExprKind::InitNext) sites_.unsupported("initnext evaluated while the program runs");
  SVal v = lower_value(rhs);
  if (v.type->k == TK::Never) return v;
  v = let(v);
  check_declared(e.name, v);
  assign(e.name, v, e);
  return v;
}

}  // namespace autumn::lower
