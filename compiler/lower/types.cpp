// types — interning and the join of static types (see types.hpp).
#include "compiler/lower/types.hpp"

#include <algorithm>
#include <map>
#include <string>

namespace autumn::lower {
namespace {

std::string key_of(const Type& t) {
  std::string k = std::to_string(static_cast<int>(t.k)) + ":" + std::to_string(t.cls) + ":" +
                  std::to_string(t.elem ? t.elem->id : -1) + ":";
  for (TypeP a : t.alts) k += std::to_string(a->id) + ",";
  k += ":" + std::to_string(t.fn.kind) + ":" + std::to_string(reinterpret_cast<uintptr_t>(t.fn.lambda)) + ":" +
       std::to_string(static_cast<int>(t.fn.builtin)) + ":" + std::to_string(t.fn.cls);
  return k;
}

}  // namespace

Types::Types() {
  auto basic = [&](TK k) {
    Type t;
    t.k = k;
    return intern(t);
  };
  int_t_ = basic(TK::Int);
  bool_t_ = basic(TK::Bool);
  str_t_ = basic(TK::Str);
  pos_t_ = basic(TK::Pos);
  elem_t_ = basic(TK::Elem);
  cell_t_ = basic(TK::Cell);
  empty_list_ = basic(TK::List);
  never_t_ = basic(TK::Never);
}

TypeP Types::intern(Type t) {
  std::string k = key_of(t);
  if (auto it = by_key_.find(k); it != by_key_.end()) return it->second;
  t.id = static_cast<int>(all_.size());
  all_.push_back(std::make_unique<Type>(std::move(t)));
  by_key_.emplace(std::move(k), all_.back().get());
  return all_.back().get();
}

TypeP Types::obj(int cls) {
  Type t;
  t.k = TK::Obj;
  t.cls = cls;
  return intern(t);
}

TypeP Types::list(TypeP elem) {
  Type t;
  t.k = TK::List;
  t.elem = elem;
  return intern(t);
}

TypeP Types::func(const FuncRef& f) {
  Type t;
  t.k = TK::Func;
  t.fn = f;
  return intern(t);
}

TypeP Types::cls(int cls) {
  Type t;
  t.k = TK::Class;
  t.cls = cls;
  return intern(t);
}

TypeP Types::deferred(int arg) {
  Type t;
  t.k = TK::Deferred;
  t.cls = arg;
  return intern(t);
}

TypeP Types::sum(std::vector<TypeP> alts) {
  // Flatten nested sums, then keep at most one list alternative (lists of any
  // element type are assignable to each other, so they share one slot).
  std::vector<TypeP> flat;
  TypeP list_alt = nullptr;
  for (TypeP a : alts)
    for (TypeP x : is_sum(a) ? a->alts : std::vector<TypeP>{a}) {
      if (is_list(x)) list_alt = list_alt ? join(list_alt, x) : x;
      else if (std::find(flat.begin(), flat.end(), x) == flat.end()) flat.push_back(x);
    }
  if (list_alt) flat.push_back(list_alt);
  std::sort(flat.begin(), flat.end(), [](TypeP a, TypeP b) { return a->id < b->id; });
  if (flat.size() == 1) return flat[0];
  Type t;
  t.k = TK::Sum;
  t.alts = std::move(flat);
  return intern(t);
}

TypeP Types::join(TypeP a, TypeP b) {
  if (a == b || b->k == TK::Never) return a;
  if (a->k == TK::Never) return b;
  if (is_list(a) && is_list(b)) {
    if (!a->elem) return b;
    if (!b->elem) return a;
    return list(join(a->elem, b->elem));
  }
  return sum({a, b});
}

bool Types::fits(TypeP v, TypeP slot) const {
  if (v == slot || v->k == TK::Never) return true;
  if (is_list(v) && is_list(slot)) return !v->elem || (slot->elem && fits(v->elem, slot->elem));
  if (is_sum(v)) {
    for (TypeP a : v->alts)
      if (!fits(a, slot)) return false;
    return true;
  }
  if (is_sum(slot))
    for (TypeP a : slot->alts)
      if (fits(v, a)) return true;
  return false;
}

bool is_typed_variant(TypeP t) {
  if (is_object_like(t)) return true;
  if (!is_sum(t)) return t->k == TK::Func;
  for (TypeP a : t->alts)
    if (a->k != TK::Func) return false;
  return true;
}

void classes_held(TypeP t, bool by_value, std::vector<int>& out) {
  if (!t) return;
  if (t->k == TK::Obj) out.push_back(t->cls);
  if (t->k == TK::Sum)
    for (TypeP a : t->alts) classes_held(a, by_value, out);
  if (t->k == TK::List && !by_value) classes_held(t->elem, by_value, out);
}

bool is_object_like(TypeP t) {
  if (t->k == TK::Obj) return true;
  if (!is_sum(t)) return false;
  for (TypeP a : t->alts)
    if (a->k != TK::Obj) return false;
  return true;
}

}  // namespace autumn::lower
