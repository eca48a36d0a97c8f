// value — run-time values of the reference-exact interpreter.
//
// Mirrors the reference's value model where it is observable:
//  * Numbers are 32-bit ints (wrapping), Strings keep their quotes, Bools.
//  * Lists, instances, functions and deferred cell expressions are shared heap
//    objects with a mutable identity number (`id`): assigning to an existing
//    variable writes the old value's id onto the new object, and removeObj / prev
//    compare ids. Primitive values carry no id (see docs/conformance-notes.md).
//  * Every list carries a type tag object; list equality compares printed forms,
//    which include the tag, and tag inference compares tag objects by identity.
//  * Types (classes, primitive type names) appear as values only as callees.
// Heap objects use a non-atomic intrusive reference count: an interpreter and all
// its values belong to one thread. Destruction is iterative (destroy()): a list
// nested a million deep, which a program can build in one step, dies without
// recursing once per level.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "compiler/analyse/builtins.hpp"
#include "compiler/parse/ast.hpp"

namespace autumn::interp {

struct Obj;

// The objects waiting to be deleted by destroy(): a few inline, more on the heap.
class Dying {
 public:
  void push_back(Obj* o) {
    if (n_ < kInline) inline_[n_++] = o;
    else more_.push_back(o);
  }
  bool empty() const { return n_ == 0 && more_.empty(); }
  Obj* pop() {
    if (!more_.empty()) {
      Obj* o = more_.back();
      more_.pop_back();
      return o;
    }
    return inline_[--n_];
  }

 private:
  static constexpr size_t kInline = 32;
  Obj* inline_[kInline];
  size_t n_ = 0;
  std::vector<Obj*> more_;
};

struct Obj {
  int refs = 0;
  int id = 0;
  virtual ~Obj() = default;
  // Gives up every reference this object holds: those it holds last are
  // appended to `dying` (still counted as one reference), the others released.
  virtual void release_children(Dying& dying) { (void)dying; }
};

// Deletes `root` (whose count reached zero) and whatever dies with it, without
// recursion.
inline void destroy(Obj* root) {
  Dying dying;
  root->release_children(dying);
  delete root;
  while (!dying.empty()) {
    Obj* o = dying.pop();
    o->release_children(dying);
    delete o;
  }
}

template <class T>
class Ref {
 public:
  Ref() = default;
  Ref(T* p) : p_(p) { if (p_) ++p_->refs; }  // NOLINT: implicit by design
  Ref(const Ref& o) : p_(o.p_) { if (p_) ++p_->refs; }
  Ref(Ref&& o) noexcept : p_(o.p_) { o.p_ = nullptr; }
  template <class U>
  Ref(const Ref<U>& o) : Ref(static_cast<T*>(o.get())) {}
  ~Ref() { reset(); }
  Ref& operator=(Ref o) noexcept { std::swap(p_, o.p_); return *this; }
  void reset() {
    if (p_ && --p_->refs == 0) destroy(p_);
    p_ = nullptr;
  }
  // reset() for an owner being destroyed: a last reference goes to `dying`.
  void release_into(Dying& dying) {
    if (!p_) return;
    if (p_->refs == 1) dying.push_back(p_);
    else --p_->refs;
    p_ = nullptr;
  }
  T* get() const { return p_; }
  T* operator->() const { return p_; }
  T& operator*() const { return *p_; }
  explicit operator bool() const { return p_ != nullptr; }
  bool operator==(const Ref& o) const { return p_ == o.p_; }

 private:
  T* p_ = nullptr;
};

struct TypeObj;
struct Scope;
using TypeRef = Ref<TypeObj>;

enum class VKind : uint8_t { None, Number, Bool, String, List, Instance, Function, Deferred, Type };

struct Value {
  VKind kind = VKind::None;
  int32_t num = 0;                  // Number, Bool (0/1)
  const std::string* str = nullptr; // String: points into the program's AST (quotes included)
  Ref<Obj> obj;                     // heap kinds

  static Value number(int32_t n) { Value v; v.kind = VKind::Number; v.num = n; return v; }
  static Value boolean(bool b) { Value v; v.kind = VKind::Bool; v.num = b; return v; }
  static Value string(const std::string* s) { Value v; v.kind = VKind::String; v.str = s; return v; }
  static Value heap(VKind k, Obj* o) { Value v; v.kind = k; v.obj = Ref<Obj>(o); return v; }

  bool is(VKind k) const { return kind == k; }
  bool is_heap() const { return kind >= VKind::List && kind <= VKind::Deferred; }
  template <class T> T* as() const { return static_cast<T*>(obj.get()); }
};

enum class TypeKind { Number, String, Bool, Unknown, Func, Expr, List, Class };

struct FuncObj;
struct InstanceObj;

// Types are objects because list tag inference compares them by identity.
struct TypeObj : Obj {
  TypeKind kind;
  TypeRef elem;  // List
  // Class
  std::string name;
  std::vector<Sym> field_syms;
  std::vector<std::string> field_names;
  std::vector<TypeRef> field_types;  // null: an unknown type name (crashes when printed)
  const Stmt* object = nullptr;      // user classes: the defining statement
  bool has_render = false;
  Ref<InstanceObj> bound;            // the instance whose `render` was fetched last
  Ref<FuncObj> render_method;
  mutable std::string cached_str;
  mutable bool str_ready = false;

  void release_children(Dying& dying) override {
    elem.release_into(dying);
    for (auto& t : field_types) t.release_into(dying);
    bound.release_into(dying);
    render_method.release_into(dying);
  }

  int field_index(Sym s) const {
    for (size_t i = 0; i < field_syms.size(); ++i)
      if (field_syms[i] == s) return static_cast<int>(i);
    return -1;
  }
};

struct ListObj : Obj {
  std::vector<Value> items;
  TypeRef tag;  // a List type, or the bare Unknown type (mixed literal)
  void release_children(Dying& dying) override {
    for (Value& v : items) v.obj.release_into(dying);
    tag.release_into(dying);
  }
};

struct InstanceObj : Obj {
  TypeRef cls;
  std::vector<Value> fields;  // in class field order
  void release_children(Dying& dying) override {
    for (Value& v : fields) v.obj.release_into(dying);
    cls.release_into(dying);
  }
};

struct FuncObj : Obj {
  enum class Kind { Native, Lambda, Method } kind;
  Builtin builtin = Builtin::Map;
  const Expr* lambda = nullptr;  // Lambda node (owned by the Program)
  TypeObj* cls = nullptr; // Method: the class whose bound instance renders
};

struct DeferredObj : Obj {
  ExprPtr expr;
  int turns = 0;   // rotations wrapped around the original expression (bounded)
  Ref<Scope> env;  // the capture scope; re-parented to the caller while evaluated
  void release_children(Dying& dying) override;  // values.cpp (needs Scope)
};

}  // namespace autumn::interp
