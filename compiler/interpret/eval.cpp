// eval — expression evaluation, scopes, calls and object construction.
//
// Each case mirrors what the reference's visitor does, in the same order, because
// order is observable (RNG draws, renders inside collision tests, which variables
// are defined when). Scope switches are *not* undone when an error unwinds, as in
// the reference: the only place an error is caught and evaluation continues is
// the trial evaluation of Cell arguments, which then runs in whatever scope the
// failed expression left behind.
//
// Depth: eval() counts its own nesting (kMaxEvalNesting, with the deep stack's
// floor as a last resort) and call_lambda the call depth and the step's calls
// (runtime/limits.hpp), polling the host for an interrupt as it counts them
// (runtime/interrupt.hpp); running out of memory inside an expression becomes a
// located error at that expression.
#include <algorithm>
#include <exception>
#include <new>
#include <optional>
#include <stdexcept>
#include <utility>

#include "compiler/interpret/interpreter.hpp"
#include "compiler/parse/ast_print.hpp"
#include "runtime/arith.hpp"
#include "runtime/interrupt.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::interp {

// Nested eval() calls allowed: far above call-depth x ordinary nesting, and
// what the deep stack holds in any build (about 1 KiB a level under ASan).
constexpr int64_t kMaxEvalNesting = 400'000;

void Interpreter::fail(const std::string& msg) { throw RuntimeError(msg); }

// The host's poll (runtime/interrupt.hpp), every kInterruptPollCalls calls.
void Interpreter::poll_interrupt() {
  if (InterruptPoll poll = interrupt_poll(); poll && poll()) fail(interrupted_error());
}

void locate(RuntimeError& err, const Expr& e) {
  if (!err.located) {
    err.loc = e.loc;
    err.located = true;
  }
  if (!err.in_program && e.loc.source == SourceId::Program) {
    err.program_loc = e.loc;
    err.in_program = true;
  }
}

// ---------------------------------------------------------------------------
// Scopes

Ref<Scope> Interpreter::new_scope(ScopeKind kind, Ref<Scope> parent) {
  Ref<Scope> s(new Scope);
  // Most scopes bind a handful of names (parameters, let variables): one
  // allocation up front instead of growing 1, 2, 4.
  s->vars.reserve(4);
  s->kind = kind;
  s->parent = std::move(parent);
  return s;
}

Value* Interpreter::lookup(Sym s) {
  for (Scope* sc = env_.get(); sc; sc = sc->parent.get()) {
    if (sc == global_.get()) return gdefined_[s] ? &gvalues_[s] : nullptr;
    if (Binding* b = sc->find(s)) return &b->value;
  }
  return nullptr;
}

TypeObj* Interpreter::lookup_type(Sym s) { return gtypes_[s].get(); }

TypeObj* Interpreter::find_declared(Sym s, bool* found) {
  for (Scope* sc = env_.get(); sc; sc = sc->parent.get())
    for (auto& [name, type] : sc->declared)
      if (name == s) {
        *found = true;
        return type.get();
      }
  *found = false;
  return nullptr;
}

bool Interpreter::is_updated(Sym s) {
  for (Scope* sc = env_.get(); sc; sc = sc->parent.get()) {
    if (sc == global_.get()) return gupdated_[s];
    if (Binding* b = sc->find(s)) return b->updated;
  }
  return false;
}

void Interpreter::define_global(Sym s, Value v) {
  if (!gdefined_[s]) {
    gorder_.insert(s, program_->symbols.hash(s));
    gdefined_[s] = 1;
  }
  gvalues_[s] = std::move(v);
  gupdated_[s] = 0;
  definition_order_.push_back(s);
  render_order_.note_definition(s);
}

void Interpreter::erase_global(Sym s) {
  gorder_.erase(s);
  gdefined_[s] = 0;
  gvalues_[s] = Value();
}

void Interpreter::define(Scope* scope, Sym s, Value v) {
  if (scope == global_.get()) return define_global(s, std::move(v));
  if (Binding* b = scope->find(s)) {
    b->value = std::move(v);
    b->updated = false;
    return;
  }
  scope->vars.push_back(Binding{s, std::move(v), false});
}

// The reference's Environment::assign: the innermost scope holding the name gets
// the value (type-checked against the old value unless the new one is a list, and
// given the old value's identity); otherwise the name is defined in the current
// scope.
void Interpreter::assign(Sym s, Value v) {
  for (Scope* sc = env_.get(); sc; sc = sc->parent.get()) {
    Value* slot = nullptr;
    Binding* local = nullptr;
    if (sc == global_.get()) {
      if (!gdefined_[s]) break;
      slot = &gvalues_[s];
    } else if ((local = sc->find(s))) {
      slot = &local->value;
    } else {
      continue;
    }
    if (!v.is(VKind::List) && type_string(type_of(*slot)) != type_string(type_of(v)))
      fail("cannot assign a value of type '" + shown_type(type_string(type_of(v))) + "' to variable '" +
           program_->name(s) + "' of type '" + shown_type(type_string(type_of(*slot))) + "'");
    if (v.is_heap()) v.obj->id = slot->is_heap() ? slot->obj->id : next_id();
    *slot = std::move(v);
    if (local) local->updated = true;
    else gupdated_[s] = 1;
    return;
  }
  define(env_.get(), s, std::move(v));
}

// ---------------------------------------------------------------------------
// Expressions

Value Interpreter::eval_value(const Expr& e) {
  Value v = eval(e);
  if (v.is(VKind::None)) {
    RuntimeError err("this expression has no value (an initnext or type declaration cannot be used here)");
    locate(err, e);
    throw err;
  }
  if (v.is(VKind::Type)) {
    RuntimeError err("the type '" + v.as<TypeObj>()->name + "' can only be called, not used as a value");
    locate(err, e);
    throw err;
  }
  return v;
}

// A frame is on eval_stack_ while it runs; a throw leaves it there for the
// catch site to locate the error at (unwound()).
Value Interpreter::eval(const Expr& e) {
  Nest nest(eval_depth_);
  eval_stack_.push_back({&e, nullptr});
  note_stack_depth();
  if (eval_depth_ > kMaxEvalNesting || stack_exhausted(stack_floor_))
    fail("evaluation nested too deeply: more than " + std::to_string(kMaxEvalNesting) +
         " levels of expressions and calls");
  Value v = eval_node(e);
  eval_stack_.pop_back();
  return v;
}

// (OP a b): == and != on any values, the rest on two numbers (runtime/arith).
Value Interpreter::eval_binary(const Expr& e) {
  Value l = eval_value(*e.kids[0]);
  Value r = eval_value(*e.kids[1]);
  if (e.op == BinOp::Eq) return Value::boolean(equals(l, r));
  if (e.op == BinOp::Ne) return Value::boolean(!equals(l, r));
  if (e.op == BinOp::Unknown) fail("unknown binary operator '" + e.text + "'");
  if (!l.is(VKind::Number) || !r.is(VKind::Number))
    fail("binary " + e.text + " needs two numbers, got " + shown_type(type_string(type_of(l))) + " and " +
         shown_type(type_string(type_of(r))));
  const int32_t a = l.num, b = r.num;
  switch (e.op) {
    case BinOp::Add: return Value::number(arith::add(a, b));
    case BinOp::Sub: return Value::number(arith::sub(a, b));
    case BinOp::Mul: return Value::number(arith::mul(a, b));
    case BinOp::Div:
    case BinOp::Mod:
      if (std::string why = arith::division_error(a, b, e.text); !why.empty()) fail(why);
      return Value::number(e.op == BinOp::Div ? arith::div_unchecked(a, b) : arith::mod_unchecked(a, b));
    case BinOp::Lt: return Value::boolean(l.num < r.num);
    case BinOp::Le: return Value::boolean(l.num <= r.num);
    case BinOp::Gt: return Value::boolean(l.num > r.num);
    case BinOp::Ge: return Value::boolean(l.num >= r.num);
    default: fail("unknown binary operator '" + e.text + "'");
  }
}

// (! b), (- n), (+ n).
Value Interpreter::eval_unary(const Expr& e) {
  Value v = eval_value(*e.kids[0]);
  if (e.unary == UnOp::Not) {
    if (!v.is(VKind::Bool)) fail("'!' needs a Bool, got " + shown_type(type_string(type_of(v))));
    return Value::boolean(!v.num);
  }
  if (!v.is(VKind::Number)) fail("unary " + e.text + " needs a number, got " + shown_type(type_string(type_of(v))));
  if (e.unary == UnOp::Neg) return Value::number(arith::neg(v.num));
  return v;
}

// (let e1 ... en): a scope of its own; the last expression's value.
Value Interpreter::eval_let(const Expr& e) {
  Ref<Scope> sub = new_scope(ScopeKind::Local, env_);
  env_ = sub;
  Value ret;
  for (const auto& k : e.kids) ret = eval(*k);
  if (ret.is(VKind::None) || ret.is(VKind::Type))
    fail(e.kids.empty() ? "empty let" : "the last expression of a let has no value");
  env_ = sub->parent;
  return ret;
}

// (= (.. obj f) v): the object's field, shared by every holder.
Value Interpreter::eval_set(const Expr& e) {
  Value obj = eval_value(*e.kids[0]);
  if (!obj.is(VKind::Instance)) fail("only objects have fields, got " + shown_type(type_string(type_of(obj))));
  Value v = eval_value(*e.kids[1]);
  InstanceObj* in = obj.as<InstanceObj>();
  int i = in->cls->field_index(e.name);
  if (i < 0) fail("object of class '" + in->cls->name + "' has no field '" + program_->name(e.name) + "'");
  in->fields[i] = v;
  return v;
}

// (: x T) declares x's type in the current scope.
Value Interpreter::eval_type_decl(const Expr& e) {
  TypeRef t = resolve_type(*e.type);
  for (auto& d : env_->declared)
    if (d.first == e.name) {
      d.second = t;
      return Value();
    }
  env_->declared.emplace_back(e.name, t);
  return Value();
}

Value Interpreter::eval_node(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Number: return Value::number(e.number);
    case ExprKind::String: return Value::string(&e.text);
    case ExprKind::Bool: return Value::boolean(e.boolean);
    case ExprKind::Var: {
      if (TypeObj* t = lookup_type(e.name)) return Value::heap(VKind::Type, t);
      if (Value* v = lookup(e.name)) return *v;
      fail("undefined variable '" + program_->name(e.name) + "'");
    }
    case ExprKind::Binary: return eval_binary(e);
    case ExprKind::Logical: {
      std::vector<Value> none;
      Value l = eval_value(*e.kids[0]);
      if (l.is(VKind::Function)) l = call_function(l, none);
      if (e.is_or ? truthy(l) : !truthy(l)) return Value::boolean(e.is_or);
      Value r = eval_value(*e.kids[1]);
      if (r.is(VKind::Function)) r = call_function(r, none);
      return Value::boolean(truthy(r));
    }
    case ExprKind::Unary: return eval_unary(e);
    case ExprKind::If: {
      Value c = eval_value(*e.kids[0]);
      return truthy(c) ? eval(*e.kids[1]) : eval(*e.kids[2]);
    }
    case ExprKind::Let: return eval_let(e);
    case ExprKind::List: {
      std::vector<Value> items;
      items.reserve(e.kids.size());
      for (const auto& k : e.kids) items.push_back(eval_value(*k));
      check_length(static_cast<int64_t>(items.size()));
      count_cells(static_cast<int64_t>(items.size()));
      return make_list(std::move(items));
    }
    case ExprKind::Lambda: return make_function(FuncObj::Kind::Lambda, Builtin::Map, &e, nullptr);
    case ExprKind::Call: return eval_call(e);
    case ExprKind::Get: return get_field(eval_value(*e.kids[0]), e.name, e.text);
    case ExprKind::Assign: return eval_assign(e);
    case ExprKind::Set: return eval_set(e);
    case ExprKind::InitNext: return Value();
    case ExprKind::TypeDecl: return eval_type_decl(e);
  }
  fail("unknown expression");
}

// The frames are visited innermost first, as if each had caught the error,
// located it and thrown it on: an eval() frame locates it (a memory error
// becomes "out of memory" at the innermost eval() frame it left), a render
// method's frame applies its rule (locate_in_render). Any other exception goes
// on unchanged.
RuntimeError Interpreter::unwound(size_t height) {
  std::optional<RuntimeError> err;
  bool memory = false;
  std::exception_ptr other;
  try {
    throw;
  } catch (const RuntimeError& e) {
    err = e;
  } catch (const std::bad_alloc&) {
    memory = true;
    other = std::current_exception();
  } catch (const std::length_error&) {
    memory = true;
    other = std::current_exception();
  } catch (...) {
    other = std::current_exception();
  }
  for (size_t i = eval_stack_.size(); i > height; --i) {
    const Frame& f = eval_stack_[i - 1];
    if (f.expr && !err && memory) err = RuntimeError("out of memory");
    if (!err) continue;
    if (f.expr) locate(*err, *f.expr);
    else locate_in_render(*err, f.render);
  }
  drop_unwound(height);
  if (!err) std::rethrow_exception(other);
  return std::move(*err);
}

TypeRef Interpreter::resolve_type(const TypeExpr& t) {
  if (t.is_list) {
    TypeRef elem = resolve_type(*t.elem);
    if (!elem) fail("unknown element type in a List type (types must be defined before use)");
    return make_type(TypeKind::List, elem);
  }
  return TypeRef(lookup_type(t.sym));
}

Value Interpreter::eval_assign(const Expr& e) {
  const Expr& rhs = *e.kids[0];
  if (rhs.kind == ExprKind::InitNext) {
    render_order_.note_initnext(e.name);
    init_expr_[e.name] = rhs.kids[0];
    next_expr_[e.name] = rhs.kids[1];
    init_map_order_.insert(e.name, program_->symbols.hash(e.name));
    return Value();
  }
  Value v = eval_value(rhs);
  bool declared = false;
  TypeObj* decl = find_declared(e.name, &declared);
  if (decl && decl->kind != TypeKind::List && type_string(decl) != type_string(type_of(v)))
    fail("cannot assign a value of type '" + shown_type(type_string(type_of(v))) + "' to '" + program_->name(e.name) +
         "', declared as '" + shown_type(type_string(decl)) + "'");
  assign(e.name, v);
  return v;
}

Value Interpreter::get_field(const Value& obj, Sym field, const std::string& raw) {
  if (!obj.is(VKind::Instance))
    fail("(.. _ " + raw + "): only objects have fields, got " + shown_type(type_string(type_of(obj))));
  InstanceObj* in = obj.as<InstanceObj>();
  TypeObj* cls = in->cls.get();
  int i = cls->field_index(field);
  if (i >= 0) return in->fields[i];
  if (field == names_.render && cls->has_render) {
    cls->bound = Ref<InstanceObj>(in);  // the method is shared by the class: last fetch wins
    return Value::heap(VKind::Function, cls->render_method.get());
  }
  fail("object of class '" + cls->name + "' has no field '" + raw + "'");
}

// ---------------------------------------------------------------------------
// Calls

Value Interpreter::eval_call(const Expr& e) {
  const Expr& callee_expr = *e.kids[0];
  const size_t nargs = e.kids.size() - 1;
  Value callee = eval(callee_expr);
  if (callee.is(VKind::Type)) {
    TypeObj* cls = callee.as<TypeObj>();
    if (cls->kind != TypeKind::Class) fail("'" + shown_type(type_string(cls)) + "' is not a class and cannot be called");
    if (cls->name == "Cell") return construct_cell(e, cls);
    std::vector<Value> args;
    args.reserve(nargs);
    for (size_t i = 1; i <= nargs; ++i) args.push_back(eval_value(*e.kids[i]));
    if (cls->object) {
      Value made = call_lambda(*cls->object->constructor_body, args, ScopeKind::Instance, &e);
      if (made.is(VKind::List)) args = made.as<ListObj>()->items;
    }
    return make_instance(cls, std::move(args));
  }
  if (callee.is(VKind::Deferred)) return call_deferred(callee.as<DeferredObj>());
  if (!callee.is(VKind::Function))
    fail("only functions and classes can be called, got " + shown_type(type_string(type_of(callee))));
  FuncObj* f = callee.as<FuncObj>();
  if (f->kind == FuncObj::Kind::Native && f->builtin == Builtin::Prev) {
    if (nargs != 1) fail("prev takes 1 argument, got " + std::to_string(nargs));
    const Expr& arg = *e.kids[1];
    if (arg.kind == ExprKind::Var) {
      // (prev x) looks the *name* up in the snapshot, ignoring local bindings.
      if (!have_prev_) fail("prev used before the first step");
      if (!prev_defined_[arg.name]) fail("prev: '" + program_->name(arg.name) + "' had no value at the start of the step");
      return prev_values_[arg.name];
    }
    return builtin_prev(eval_value(arg));
  }
  std::vector<Value> args;
  args.reserve(nargs);
  for (size_t i = 1; i <= nargs; ++i) args.push_back(eval_value(*e.kids[i]));
  if (f->kind == FuncObj::Kind::Native) return call_builtin(f->builtin, args);
  return call_function(callee, args, &e);
}

Value Interpreter::call_function(const Value& fv, std::vector<Value>& args, const Expr* site) {
  FuncObj* f = fv.as<FuncObj>();
  switch (f->kind) {
    case FuncObj::Kind::Native: return call_builtin(f->builtin, args);
    case FuncObj::Kind::Lambda: return call_lambda(*f->lambda, args, ScopeKind::Local, site);
    case FuncObj::Kind::Method: return call_render_method(f->cls);
  }
  fail("bad function");
}

Value Interpreter::call_lambda(const Expr& lambda, std::vector<Value>& args, ScopeKind kind, const Expr* site) {
  Nest depth(call_depth_);
  if (call_depth_ > limits_.call_depth) fail_call_depth(lambda, site);
  if (!internal_) {
    if (++step_calls_ > limits_.calls) fail(limits::calls_error(limits_.calls));
    if (step_calls_ % kInterruptPollCalls == 0) poll_interrupt();
  }
  Ref<Scope> sc = new_scope(kind, env_);
  env_ = sc;
  if (args.size() < lambda.params.size())
    fail("function called with " + std::to_string(args.size()) + " argument(s) but it takes " +
         std::to_string(lambda.params.size()) + " (the reference interpreter crashes here)");
  for (size_t i = 0; i < lambda.params.size(); ++i) define(sc.get(), lambda.params[i], args[i]);
  Value r = eval(*lambda.kids[0]);
  if (r.is(VKind::None) || r.is(VKind::Type)) fail("the function body has no value");
  env_ = sc->parent;
  return r;
}

// An error in the method's own machinery (a colour that is not a String, a
// coordinate that is not a Number) is the program's: it is reported at the cell
// argument evaluated last, the one whose value did not fit; before any (an
// origin that is not a Position), at the object's definition.
Value Interpreter::call_render_method(TypeObj* cls) {
  Nest machinery(internal_);  // nothing the method itself builds is counted
  Ref<InstanceObj> self = cls->bound;
  if (!self) fail("render method called without an object");
  Ref<Scope> sc = new_scope(ScopeKind::Instance, env_);
  env_ = sc;
  for (size_t i = 0; i < cls->field_syms.size(); ++i) define(sc.get(), cls->field_syms[i], self->fields[i]);
  std::vector<Value> none;
  last_cell_arg_ = SourceLoc{};
  eval_stack_.push_back({nullptr, cls});  // an error leaves it for unwound(): locate_in_render
  Value r = call_lambda(*program_->render_lambda, none);
  eval_stack_.pop_back();
  env_ = sc->parent;
  return r;
}

void Interpreter::locate_in_render(RuntimeError& e, TypeObj* cls) const {
  if (e.in_program) return;
  if (last_cell_arg_.line > 0 && last_cell_arg_.source == SourceId::Program) {
    e.program_loc = last_cell_arg_;
    e.in_program = true;
  } else if (cls->object) {
    e.program_loc = cls->object->loc;
    e.in_program = true;
  }
}

Value Interpreter::call_deferred(DeferredObj* d) {
  // A cell's expression is the program's own, even when a render evaluates it.
  struct Counted {
    int64_t& flag;
    int64_t saved;
    ~Counted() { flag = saved; }
  } counted{internal_, std::exchange(internal_, 0)};
  last_cell_arg_ = d->expr->loc;
  Ref<Scope> cenv = d->env;
  cenv->parent = env_;  // captured names win; the rest resolves through the caller
  // Undone on the way out, an error included: the caller's scope may hold this
  // cell, and a parent link left behind would make a cycle that is never freed.
  struct Restore {
    Interpreter& in;
    Ref<Scope> cenv, saved;
    ~Restore() {
      cenv->parent.reset();
      in.env_ = saved;
    }
  } restore{*this, cenv, env_};
  env_ = cenv;
  return eval(*d->expr);
}

// (Cell X Y COLOUR): each argument is tried once in a parentless scope holding
// copies of the names it mentions (taken from every scope but the outermost
// instance scope). A Number becomes a constant; anything else, or an error,
// keeps the expression to be evaluated at every render.
Value Interpreter::construct_cell(const Expr& e, TypeObj* cls) {
  Ref<Scope> capture = new_scope(ScopeKind::Local, Ref<Scope>());
  std::vector<Scope*> chain;
  for (Scope* sc = env_.get(); sc; sc = sc->parent.get()) chain.push_back(sc);
  bool skipped_instance = false;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    Scope* sc = *it;
    if (sc->kind == ScopeKind::Instance && !skipped_instance) {
      skipped_instance = true;
      continue;
    }
    for (Sym n : e.cell_names) {
      if (sc == global_.get()) {
        if (gdefined_[n]) define(capture.get(), n, gvalues_[n]);
      } else if (Binding* b = sc->find(n)) {
        define(capture.get(), n, b->value);
      }
      for (auto& d : sc->declared)
        if (d.first == n) capture->declared.push_back(d);
    }
  }
  Ref<Scope> saved = env_;
  env_ = capture;
  std::vector<Value> fields;
  for (size_t i = 1; i < e.kids.size(); ++i) {
    const ExprPtr& arg = e.kids[i];
    Ref<DeferredObj> d(new DeferredObj);
    d->id = next_id();
    d->env = capture;
    d->expr = arg;
    const size_t height = eval_stack_.size();
    try {
      Value v = eval(*arg);
      if (v.is(VKind::None) || v.is(VKind::Type)) fail("a cell coordinate or colour must be a value");
      if (v.is(VKind::Number)) {
        Expr lit{ExprKind::Number, arg->loc};
        lit.number = v.num;
        d->expr = make_expr(std::move(lit));
      }
    } catch (const RuntimeError&) {  // deferred; the scope the failure left behind stays current, as in the reference
      forget_unwound_frames();
      drop_unwound(height);
    } catch (...) {
      forget_unwound_frames();
      (void)unwound(height);  // out of memory is deferred too; anything else goes on
    }
    fields.push_back(Value::heap(VKind::Deferred, d.get()));
  }
  env_ = saved;
  return make_instance(cls, std::move(fields));
}

// ---------------------------------------------------------------------------
// Statements

void Interpreter::run_statement(const Stmt& st) {
  switch (st.kind) {
    case StmtKind::Object: {
      std::vector<Sym> syms;
      std::vector<std::string> fnames;
      std::vector<TypeRef> types;
      for (const auto& f : st.fields) {
        syms.push_back(f.name);
        fnames.push_back(f.name_text);
        types.push_back(resolve_type(*f.type));
      }
      syms.push_back(names_.origin);
      fnames.push_back("origin");
      types.push_back(c_position_);
      syms.push_back(names_.elems);
      fnames.push_back("elems");
      types.push_back(make_type(TypeKind::List, c_cell_));
      TypeRef cls = make_class(st.object_name, std::move(syms), std::move(fnames), std::move(types));
      cls->object = &st;
      cls->has_render = true;
      cls->render_method = Ref<FuncObj>(make_function(FuncObj::Kind::Method, Builtin::Map, nullptr, cls.get())
                                            .as<FuncObj>());
      gtypes_[st.object_sym] = cls;
      return;
    }
    case StmtKind::On:
      on_clauses_.push_back(&st);
      covered_.push_back(0);
      return;
    case StmtKind::Expr:
      eval(*st.expr);
      return;
  }
}

}  // namespace autumn::interp
