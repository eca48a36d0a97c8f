// snapshot — cloning an interpreter and hashing its state.
//
// clone() copies the whole object graph (values, scopes, capture scopes, classes,
// type objects) through a memo table, so that sharing *within* the state is kept
// (shared cells still rotate together, identity numbers are unchanged) while
// nothing is shared between the copy and the original: reference counts are not
// atomic, and clones go to other threads.
//
// state_hash() walks the same graph in a fixed order. Identity numbers matter only
// through equality, so they are hashed as first-encounter indices: two states
// reached by different histories but with the same structure hash alike.
//
// Both walk iteratively (a work list, not the C++ stack): a failed episode may
// hold values nested as deep as memory allows, and clones run on any thread.
#include <algorithm>
#include <functional>
#include <unordered_map>

#include "compiler/interpret/interpreter.hpp"

namespace autumn::interp {
namespace {

// copy_obj() makes an object's shell (its plain fields) and queues it; finish()
// fills the queued shells' references, which queues their children in turn.
class GraphCopier {
 public:
  template <class T>
  Ref<T> copy(const Ref<T>& r) {
    return Ref<T>(static_cast<T*>(copy_obj(r.get())));
  }
  Value copy(const Value& v) {
    Value out = v;
    out.obj = Ref<Obj>(copy_obj(v.obj.get()));
    return out;
  }
  std::vector<Value> copy(const std::vector<Value>& vs) {
    std::vector<Value> out;
    out.reserve(vs.size());
    for (const Value& v : vs) out.push_back(copy(v));
    return out;
  }
  Obj* copy_obj(const Obj* o) {
    if (!o) return nullptr;
    if (auto it = memo_.find(o); it != memo_.end()) return it->second;
    Obj* n = shell(o);
    n->id = o->id;
    memo_[o] = n;
    queue_.emplace_back(o, n);
    return n;
  }
  // Fills every queued shell; call once after the roots are copied.
  void finish() {
    while (!queue_.empty()) {
      auto [o, n] = queue_.back();
      queue_.pop_back();
      fill(o, n);
    }
  }

 private:
  static Obj* shell(const Obj* o) {
    if (auto* t = dynamic_cast<const TypeObj*>(o)) {
      auto* n = new TypeObj;
      n->kind = t->kind;
      n->name = t->name;
      n->field_syms = t->field_syms;
      n->field_names = t->field_names;
      n->object = t->object;
      n->has_render = t->has_render;
      n->cached_str = t->cached_str;
      n->str_ready = t->str_ready;
      return n;
    }
    if (dynamic_cast<const ListObj*>(o)) return new ListObj;
    if (dynamic_cast<const InstanceObj*>(o)) return new InstanceObj;
    if (auto* f = dynamic_cast<const FuncObj*>(o)) {
      auto* n = new FuncObj;
      n->kind = f->kind;
      n->builtin = f->builtin;
      n->lambda = f->lambda;
      return n;
    }
    if (auto* d = dynamic_cast<const DeferredObj*>(o)) {
      auto* n = new DeferredObj;
      n->expr = d->expr;
      n->turns = d->turns;
      return n;
    }
    auto* n = new Scope;
    n->kind = dynamic_cast<const Scope*>(o)->kind;
    return n;
  }
  void fill(const Obj* o, Obj* to) {
    if (auto* t = dynamic_cast<const TypeObj*>(o)) {
      auto* n = static_cast<TypeObj*>(to);
      n->elem = copy(t->elem);
      for (const auto& ft : t->field_types) n->field_types.push_back(copy(ft));
      n->bound = copy(t->bound);
      n->render_method = copy(t->render_method);
    } else if (auto* l = dynamic_cast<const ListObj*>(o)) {
      auto* n = static_cast<ListObj*>(to);
      n->items = copy(l->items);
      n->tag = copy(l->tag);
    } else if (auto* in = dynamic_cast<const InstanceObj*>(o)) {
      auto* n = static_cast<InstanceObj*>(to);
      n->cls = copy(in->cls);
      n->fields = copy(in->fields);
    } else if (auto* f = dynamic_cast<const FuncObj*>(o)) {
      static_cast<FuncObj*>(to)->cls = static_cast<TypeObj*>(copy_obj(f->cls));
    } else if (auto* d = dynamic_cast<const DeferredObj*>(o)) {
      static_cast<DeferredObj*>(to)->env = copy(d->env);
    } else {
      auto* s = dynamic_cast<const Scope*>(o);
      auto* n = static_cast<Scope*>(to);
      n->parent = copy(s->parent);
      for (const auto& b : s->vars) n->vars.push_back(Binding{b.sym, copy(b.value), b.updated});
      for (const auto& [sym, t] : s->declared) n->declared.emplace_back(sym, copy(t));
    }
  }

  std::unordered_map<const Obj*, Obj*> memo_;
  std::vector<std::pair<const Obj*, Obj*>> queue_;
};

struct Hasher {
  uint64_t h = 0x9e3779b97f4a7c15ULL;
  std::unordered_map<int, int> ids;          // identity number -> first-encounter index
  std::unordered_map<const Obj*, int> seen;  // cycle and sharing guard
  void mix(uint64_t v) {
    h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
  }
  void mix_str(const std::string& s) { mix(std::hash<std::string>{}(s)); }
  void mix_id(int id) {
    auto [it, fresh] = ids.emplace(id, static_cast<int>(ids.size()));
    mix(static_cast<uint64_t>(it->second));
  }
  bool first_visit(const Obj* o) {
    auto [it, fresh] = seen.emplace(o, static_cast<int>(seen.size()));
    if (!fresh) mix(0xC0FFEE + static_cast<uint64_t>(it->second));
    return fresh;
  }
};

}  // namespace

Interpreter::Interpreter(const Interpreter& o, CopyOnly)
    : program_(o.program_),
      names_(o.names_),
      source_name_(o.source_name_),
      relocation_(o.relocation_),
      limits_(o.limits_),
      rng_(o.rng_),
      id_counter_(o.id_counter_) {
  GraphCopier c;
  t_number_ = c.copy(o.t_number_);
  t_string_ = c.copy(o.t_string_);
  t_bool_ = c.copy(o.t_bool_);
  t_unknown_ = c.copy(o.t_unknown_);
  t_func_ = c.copy(o.t_func_);
  t_expr_ = c.copy(o.t_expr_);
  t_default_list_ = c.copy(o.t_default_list_);
  c_position_ = c.copy(o.c_position_);
  c_cell_ = c.copy(o.c_cell_);
  c_rendered_ = c.copy(o.c_rendered_);
  global_ = c.copy(o.global_);
  env_ = c.copy(o.env_);
  gvalues_ = c.copy(o.gvalues_);
  gdefined_ = o.gdefined_;
  gupdated_ = o.gupdated_;
  gorder_ = o.gorder_;
  definition_order_ = o.definition_order_;
  render_order_ = o.render_order_;
  for (const auto& t : o.gtypes_) gtypes_.push_back(c.copy(t));
  init_expr_ = o.init_expr_;
  next_expr_ = o.next_expr_;
  init_map_order_ = o.init_map_order_;
  have_prev_ = o.have_prev_;
  prev_values_ = c.copy(o.prev_values_);
  prev_defined_ = o.prev_defined_;
  prev_keys_ = o.prev_keys_;
  on_clauses_ = o.on_clauses_;
  covered_ = o.covered_;
  click_ = o.click_;
  left_ = o.left_;
  right_ = o.right_;
  up_ = o.up_;
  down_ = o.down_;
  click_x_ = o.click_x_;
  click_y_ = o.click_y_;
  occupied_ = o.occupied_;
  for (const auto& t : o.classes_) classes_.push_back(c.copy(t));
  c.finish();
}

std::unique_ptr<Interpreter> Interpreter::clone() const {
  return std::unique_ptr<Interpreter>(new Interpreter(*this, CopyOnly{}));
}

// Deferred expressions are partly built at run time (constant cells, rotate), so
// they are hashed by content, not by address.
static uint64_t expr_hash(const Expr& e) {
  uint64_t h = static_cast<uint64_t>(e.kind) * 0x100000001b3ULL;
  h ^= static_cast<uint64_t>(static_cast<uint32_t>(e.number)) + 0x9e3779b97f4a7c15ULL + (h << 6);
  h ^= static_cast<uint64_t>(e.name) * 31 + static_cast<uint64_t>(e.unary) * 7 + static_cast<uint64_t>(e.op);
  h ^= std::hash<std::string>{}(e.text) + (h >> 3);
  for (const auto& k : e.kids) h = h * 0x100000001b3ULL ^ expr_hash(*k);
  return h;
}

namespace {

// The walk of one state: pre-order over a work list, where an item mixes a
// constant or visits a value whose children are pushed in reverse (so that they
// are visited in order).
class StateWalk {
 public:
  explicit StateWalk(std::function<const std::string&(TypeObj*)> type_name) : type_name_(std::move(type_name)) {}
  Hasher& hasher() { return hs_; }

  void value(const Value& root) {
    work_.push_back({&root, 0});
    while (!work_.empty()) {
      Item t = work_.back();
      work_.pop_back();
      if (t.v) visit(*t.v);
      else hs_.mix(t.constant);
    }
  }

 private:
  struct Item {
    const Value* v;
    uint64_t constant;
  };

  void push_all(const std::vector<Value>& vs) {
    for (auto it = vs.rbegin(); it != vs.rend(); ++it) work_.push_back({&*it, 0});
  }

  void visit(const Value& v) {
    hs_.mix(static_cast<uint64_t>(v.kind));
    switch (v.kind) {
      case VKind::Number:
      case VKind::Bool: return hs_.mix(static_cast<uint32_t>(v.num));
      case VKind::String: return hs_.mix_str(*v.str);
      case VKind::List: return list(v.as<ListObj>());
      case VKind::Instance: return instance(v.as<InstanceObj>());
      case VKind::Function: return function(v.as<FuncObj>());
      case VKind::Deferred: return deferred(v.as<DeferredObj>());
      default: return;
    }
  }

  void list(ListObj* l) {
    hs_.mix_id(l->id);
    if (!hs_.first_visit(l)) return;
    try {
      hs_.mix_str(type_name_(l->tag.get()));
    } catch (const RuntimeError&) {
      hs_.mix(1);
    }
    hs_.mix(l->items.size());
    push_all(l->items);
  }

  void instance(InstanceObj* in) {
    hs_.mix_id(in->id);
    if (!hs_.first_visit(in)) return;
    hs_.mix_str(in->cls->name);
    push_all(in->fields);
  }

  void function(FuncObj* f) {
    hs_.mix_id(f->id);
    hs_.mix(static_cast<uint64_t>(f->kind) * 131 + static_cast<uint64_t>(f->builtin));
    hs_.mix(reinterpret_cast<uintptr_t>(f->lambda));
    if (f->cls) hs_.mix_str(f->cls->name);
  }

  void deferred(DeferredObj* d) {
    hs_.mix_id(d->id);
    if (!hs_.first_visit(d)) return;
    hs_.mix(expr_hash(*d->expr));
    if (d->env && hs_.first_visit(d->env.get()))
      for (auto b = d->env->vars.rbegin(); b != d->env->vars.rend(); ++b) {
        work_.push_back({&b->value, 0});
        work_.push_back({nullptr, static_cast<uint64_t>(b->sym)});
      }
  }

  Hasher hs_;
  std::vector<Item> work_;
  std::function<const std::string&(TypeObj*)> type_name_;
};

}  // namespace

uint64_t Interpreter::state_hash() {
  StateWalk walk([this](TypeObj* t) -> const std::string& { return type_string(t); });
  Hasher& hs = walk.hasher();
  if (program_->uses_random) hs.mix(rng_.state());
  gorder_.for_each([&](int s) {
    hs.mix(static_cast<uint64_t>(s));
    walk.value(gvalues_[s]);
  });
  for (Sym s : render_order()) hs.mix(static_cast<uint64_t>(s) + 0x5000);
  std::vector<int64_t> occ(occupied_.begin(), occupied_.end());
  std::sort(occ.begin(), occ.end());
  for (int64_t k : occ) hs.mix(static_cast<uint64_t>(k));
  for (const auto& c : classes_)
    if (c->bound) hs.mix_id(c->bound->id);
  return hs.h;
}

}  // namespace autumn::interp
