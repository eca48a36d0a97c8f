// spec_expr — expressions, case by case as compiler/interpret/eval.cpp evaluates them.
//
// Each lower_* keeps the interpreter's order of evaluation (operands left to
// right, both operands of arithmetic before the type check) and its error texts,
// and folds what is known at compile time: literals, constant globals of the
// start-up, `isList` of a static type, arithmetic on constants (with the same
// runtime/arith.hpp functions the interpreter uses). Example:
//
//   (+ (.. o x) 1)      const int32_t t3 = add(t2.x, int32_t(1));
//   (if (isList a) ..)  only the branch the static type of `a` selects
#include <climits>

#include "compiler/lower/specialise.hpp"
#include "runtime/arith.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::lower {

SVal Specialiser::lower(const Expr& e) {
  const bool unused = value_unused_;
  value_unused_ = false;
  if (ir_.dead()) return never();
  sites_.enter(&e);
  SVal v;
  switch (e.kind) {
    case ExprKind::Number: v = SVal{T().int_(), ir_.lit(T().int_(), e.number)}; v.konst = v.code; break;
    case ExprKind::Bool: v = SVal{T().bool_(), ir_.lit(T().bool_(), e.boolean)}; v.konst = v.code; break;
    case ExprKind::String: v = SVal{T().str(), ir_.lit(T().str(), string_id(e.text))}; v.konst = v.code; break;
    case ExprKind::Var: v = lower_var(e); break;
    case ExprKind::Binary: v = lower_binary(e); break;
    case ExprKind::Logical: v = lower_logical(e); break;
    case ExprKind::Unary: v = lower_unary(e); break;
    case ExprKind::If: v = lower_if(e, unused); break;
    case ExprKind::Let: v = lower_let(e, unused); break;
    case ExprKind::List: v = lower_list(e); break;
    case ExprKind::Lambda: v = SVal{T().func(FuncRef{FuncRef::Lambda, &e, Builtin::Map, -1}), nullptr}; break;
    case ExprKind::Call: v = lower_call(e); break;
    case ExprKind::Get: v = lower_get(e); break;
    case ExprKind::Assign: v = lower_assign(e, unused); break;
    case ExprKind::Set: sites_.unsupported("field assignment (= (.. o f) v) mutates an object every holder shares");
    case ExprKind::InitNext: v = SVal{}; break;  // registers nothing here: start-up did
    case ExprKind::TypeDecl:
      if (e.type->is_list && !declared_type(*e.type->elem) && !e.type->elem->is_list) {
        fail("unknown element type in a List type (types must be defined before use)");
        v = never();
        break;
      }
      if (scopes_.empty()) global_decls_[e.name] = e.type.get();
      else scopes_.innermost().declared.emplace_back(e.name, e.type.get());
      v = SVal{};
      break;
  }
  sites_.leave();
  if (ir_.dead() && v.type && v.type->k != TK::Never) return never();
  return v;
}

SVal Specialiser::lower_discarded(const Expr& e) {
  value_unused_ = true;
  return lower(e);
}

SVal Specialiser::lower_value(const Expr& e) {
  SVal v = lower(e);
  if (v.type && v.type->k != TK::Class) return v;
  sites_.enter(&e);
  if (!v.type) fail("this expression has no value (an initnext or type declaration cannot be used here)");
  else fail("the type '" + class_name(v.type->cls) + "' can only be called, not used as a value");
  sites_.leave();
  return never();
}

// ---------------------------------------------------------------------------

SVal Specialiser::lower_var(const Expr& e) {
  if (std::optional<int> c = type_named(e.name)) return SVal{T().cls(*c), nullptr};
  return read_name(e.name, e);
}

SVal Specialiser::lower_binary(const Expr& e) {
  SVal l = lower_value(*e.kids[0]);
  SVal r = lower_value(*e.kids[1]);
  if (ir_.dead()) return never();
  if (e.op == BinOp::Eq) return equals(l, r);
  if (e.op == BinOp::Ne) {
    SVal eq = equals(l, r);
    if (const_int(eq)) return SVal{T().bool_(), ir_.lit(T().bool_(), !*const_int(eq)), ir_.lit(T().bool_(), !*const_int(eq))};
    return let(SVal{T().bool_(), ir_.node(ir::Op::Not, T().bool_(), {eq.code})});
  }
  if (e.op == BinOp::Unknown) {
    fail("unknown binary operator '" + e.text + "'");
    return never();
  }
  return split(l, [&](const SVal& a) {
    return split(r, [&](const SVal& b) -> SVal {
      if (a.type->k != TK::Int || b.type->k != TK::Int) {
        fail("binary " + e.text + " needs two numbers, got " + shown(a.type) + " and " + shown(b.type));
        return never();
      }
      return arithmetic(e, a, b);
    });
  });
}

// Two numbers: folded when both are known, else one IR operation (division
// and modulo checked first, with runtime/arith.hpp's texts).
SVal Specialiser::arithmetic(const Expr& e, const SVal& a, const SVal& b) {
  const std::optional<int64_t> x = const_int(a), y = const_int(b);
  auto known_int = [&](int32_t v) { return SVal{T().int_(), ir_.lit(T().int_(), v), ir_.lit(T().int_(), v)}; };
  auto known_bool = [&](bool v) { return SVal{T().bool_(), ir_.lit(T().bool_(), v), ir_.lit(T().bool_(), v)}; };
  const int32_t xi = x ? static_cast<int32_t>(*x) : 0, yi = y ? static_cast<int32_t>(*y) : 0;
  ir::Op op = ir::Op::Add;
  TypeP result = T().int_();
  switch (e.op) {
    case BinOp::Add: if (x && y) return known_int(arith::add(xi, yi)); op = ir::Op::Add; break;
    case BinOp::Sub: if (x && y) return known_int(arith::sub(xi, yi)); op = ir::Op::Sub; break;
    case BinOp::Mul: if (x && y) return known_int(arith::mul(xi, yi)); op = ir::Op::Mul; break;
    case BinOp::Div:
    case BinOp::Mod: {
      if (x && y && arith::division_error(xi, yi, e.text).empty())
        return known_int(e.op == BinOp::Div ? arith::div_unchecked(xi, yi) : arith::mod_unchecked(xi, yi));
      SVal bb = let(b);
      SVal aa = let(a);
      if (!y || *y == 0) {
        ir::Stmt* s = ir_.emit(ir::SK::If);
        s->a = ir_.node(ir::Op::Eq, T().bool_(), {bb.code, ir_.lit(T().int_(), 0)});
        ir_.in_block(s->body, [&] { fail(arith::division_error(1, 0, e.text)); });
      }
      if (!y || *y == -1) {
        ir::Stmt* s = ir_.emit(ir::SK::If);
        s->a = ir_.node(ir::Op::And, T().bool_(),
                    {ir_.node(ir::Op::Eq, T().bool_(), {aa.code, ir_.lit(T().int_(), INT_MIN)}),
                     ir_.node(ir::Op::Eq, T().bool_(), {bb.code, ir_.lit(T().int_(), -1)})});
        ir_.in_block(s->body, [&] { fail(arith::division_error(INT_MIN, -1, e.text)); });
      }
      return let(SVal{T().int_(), ir_.node(e.op == BinOp::Div ? ir::Op::Div : ir::Op::Mod, T().int_(), {aa.code, bb.code})});
    }
    case BinOp::Lt: if (x && y) return known_bool(xi < yi); op = ir::Op::Lt; result = T().bool_(); break;
    case BinOp::Le: if (x && y) return known_bool(xi <= yi); op = ir::Op::Le; result = T().bool_(); break;
    case BinOp::Gt: if (x && y) return known_bool(xi > yi); op = ir::Op::Gt; result = T().bool_(); break;
    case BinOp::Ge: if (x && y) return known_bool(xi >= yi); op = ir::Op::Ge; result = T().bool_(); break;
    default: break;
  }
  return let(SVal{result, ir_.node(op, result, {a.code, b.code})});
}

// An operand of & or |: a function value is called with no arguments (the
// interpreter's eval of Logical). A value that may be a function or something
// else (a mixed list's head, an if's branches) is called only when it is one
// (found by a stress program, round z2: such a function was taken as true).
SVal Specialiser::auto_call(SVal v) {
  std::vector<SVal> none;
  if (is_function(v.type)) return call_value(v, none, sites_.innermost());
  if (!may_be_function(v.type)) return v;
  return split(v, [&](const SVal& a) -> SVal {
    if (a.type->k != TK::Func) return a;
    std::vector<SVal> args;
    return call_value(a, args, sites_.innermost());
  });
}

SVal Specialiser::lower_logical(const Expr& e) {
  SVal l = auto_call(lower_value(*e.kids[0]));
  if (ir_.dead()) return never();
  ir::Node* lt = truthy(l);
  if (lt->op == ir::Op::Lit && (lt->imm != 0) == e.is_or) return SVal{T().bool_(), ir_.lit(T().bool_(), e.is_or)};
  auto right = [&]() -> SVal {
    SVal r = auto_call(lower_value(*e.kids[1]));
    if (ir_.dead()) return never();
    return let(SVal{T().bool_(), truthy(r)});
  };
  if (lt->op == ir::Op::Lit) return right();
  ir::Node* go = e.is_or ? ir_.node(ir::Op::Not, T().bool_(), {lt}) : lt;
  return join_branches(go, right, [&] { return SVal{T().bool_(), ir_.lit(T().bool_(), e.is_or)}; }, true);
}

SVal Specialiser::lower_unary(const Expr& e) {
  SVal v = lower_value(*e.kids[0]);
  return split(v, [&](const SVal& x) -> SVal {
    if (x.type->k == TK::Never) return x;
    if (e.unary == UnOp::Not) {
      if (x.type->k != TK::Bool) {
        fail("'!' needs a Bool, got " + shown(x.type));
        return never();
      }
      if (auto c = const_int(x)) return SVal{T().bool_(), ir_.lit(T().bool_(), !*c), ir_.lit(T().bool_(), !*c)};
      return let(SVal{T().bool_(), ir_.node(ir::Op::Not, T().bool_(), {x.code})});
    }
    if (x.type->k != TK::Int) {
      fail("unary " + e.text + " needs a number, got " + shown(x.type));
      return never();
    }
    if (e.unary == UnOp::Plus) return x;
    if (auto c = const_int(x)) {
      int32_t n = arith::neg(static_cast<int32_t>(*c));
      return SVal{T().int_(), ir_.lit(T().int_(), n), ir_.lit(T().int_(), n)};
    }
    return let(SVal{T().int_(), ir_.node(ir::Op::Neg, T().int_(), {x.code})});
  });
}

SVal Specialiser::lower_if(const Expr& e, bool unused) {
  SVal c = lower_value(*e.kids[0]);
  if (ir_.dead()) return never();
  ir::Node* t = truthy(c);  // a function value is truthy and is not called
  auto branch = [&](const Expr& k) {
    return [&, kp = &k]() -> SVal { return unused ? lower_discarded(*kp) : lower(*kp); };
  };
  if (t->op == ir::Op::Lit) return branch(*e.kids[t->imm ? 1 : 2])();
  return join_branches(t, branch(*e.kids[1]), branch(*e.kids[2]), !unused);
}

SVal Specialiser::lower_let(const Expr& e, bool unused) {
  if (e.kids.empty()) {
    fail("empty let");
    return never();
  }
  scopes_.push(ScopeKind::Local, ir_.block());
  SVal last;
  for (size_t i = 0; i < e.kids.size() && !ir_.dead(); ++i)
    last = (i + 1 < e.kids.size() || unused) ? lower_discarded(*e.kids[i]) : lower(*e.kids[i]);
  scopes_.pop();
  if (ir_.dead()) return never();
  if (!last.type || last.type->k == TK::Class) {
    fail("the last expression of a let has no value");
    return never();
  }
  return last;
}

SVal Specialiser::lower_list(const Expr& e) {
  std::vector<SVal> items;
  for (const auto& k : e.kids) {
    items.push_back(let(lower_value(*k)));
    if (ir_.dead()) return never();
  }
  check_length(ir::kLengthIs, {ir_.lit(T().int_(), static_cast<int64_t>(items.size()))}, static_cast<int64_t>(items.size()));
  return make_list(items);
}

SVal Specialiser::lower_get(const Expr& e) {
  SVal o = lower_value(*e.kids[0]);
  if (ir_.dead()) return never();
  return get_field(o, e.name, e.text);
}

}  // namespace autumn::lower
