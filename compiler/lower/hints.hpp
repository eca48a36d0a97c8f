// hints — what the specialiser's walks have learnt about a program's types.
//
// The specialiser finds types by walking the program (specialise.hpp): a walk
// starts from the hints earlier walks left; where a value does not fit the type
// a slot was given, or the code depends on a fact not yet known (a global read
// through prev, an object whose identity is observed), the walk records the
// wider type or the fact here and calls learn(), and the driver walks again.
// The walk whose hints did not change is the module.
//
// Invariant (why the walks settle): hints only grow. Sets have no removal, and
// a type is replaced only by one the old type fits (set_* callers pass the join
// of the old type and the new value's). `shapes` is the exception: it is a
// cache of the last shape seen per class, not a fact the walks converge on.
// Keys of locals are their defining construct (an assignment, or a lambda for
// its parameters) and the name.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/ir.hpp"
#include "compiler/lower/types.hpp"

namespace autumn::lower {

class Hints {
 public:
  using LocalKey = std::pair<const void*, Sym>;

  // --- value types (null: nothing learnt) -------------------------------------
  TypeP global(Sym s) const { return find(globals_, s); }
  TypeP local(const LocalKey& k) const { return find(locals_, k); }
  TypeP field(int cls, int field) const { return find(fields_, std::make_pair(cls, field)); }
  void set_global(Sym s, TypeP t) { globals_[s] = t; }
  void set_local(const LocalKey& k, TypeP t) { locals_[k] = t; }
  void set_field(int cls, int field, TypeP t) { fields_[{cls, field}] = t; }

  // --- facts; each add_ says whether the fact is new ---------------------------
  bool tracked(TypeP t) const { return tracked_.count(t) > 0; }  // identity numbers of t are observed
  bool add_tracked(TypeP t) { return tracked_.insert(t).second; }
  bool erasable(Sym s) const { return erasable_.count(s) > 0; }  // removeObj may erase the global
  bool add_erasable(Sym s) { return erasable_.insert(s).second; }
  const std::set<Sym>& all_erasable() const { return erasable_; }
  bool runtime_defined(Sym s) const { return runtime_defined_.count(s) > 0; }  // first defined by a step
  bool add_runtime_defined(Sym s) { return runtime_defined_.insert(s).second; }
  const std::set<Sym>& all_runtime_defined() const { return runtime_defined_; }
  bool stored_in_step(Sym s) const { return stored_in_step_.count(s) > 0; }  // some step code assigns it
  bool add_stored_in_step(Sym s) { return stored_in_step_.insert(s).second; }
  bool prev_read(Sym s) const { return prev_read_.count(s) > 0; }  // read through prev
  bool add_prev_read(Sym s) { return prev_read_.insert(s).second; }
  const std::set<Sym>& all_prev_read() const { return prev_read_; }
  bool stored_cells(int cls) const { return stored_cells_.count(cls) > 0; }  // objects carry their cells
  bool add_stored_cells(int cls) { return stored_cells_.insert(cls).second; }
  bool rotated(int cls) const { return rotated_.count(cls) > 0; }  // rotate turns it (objects carry a cell group)
  bool add_rotated(int cls) { return rotated_.insert(cls).second; }
  bool mutable_binding(const LocalKey& k) const { return mutable_bindings_.count(k) > 0; }  // a parameter assigned to
  bool add_mutable_binding(const LocalKey& k) { return mutable_bindings_.insert(k).second; }
  // A (filter f ((allObjs))) whose function writes the state: allObjs' list is built first.
  bool unfused(const void* filter) const { return unfused_.count(filter) > 0; }
  bool add_unfused(const void* filter) { return unfused_.insert(filter).second; }
  bool runtime_order() const { return runtime_order_; }  // a step observes a map order steps change
  // Returns whether it was not yet set.
  bool set_runtime_order() { return !std::exchange(runtime_order_, true); }
  bool draw_order() const { return draw_order_; }  // two or more globals steps first define draw
  bool set_draw_order() { return !std::exchange(draw_order_, true); }

  // The cells every object of a class has, in Module::lasting (a cache, see above).
  const std::map<int, ir::Node*>& shapes() const { return shapes_; }
  void set_shape(int cls, ir::Node* shape) { shapes_[cls] = shape; }

  // --- the walk's verdict ----------------------------------------------------------
  // Something this walk's code depends on was learnt: walk again.
  // AUTUMN_LOWER_TRACE=1 prints what.
  void learn(const std::string& what) {
    changed_ = true;
    last_change_ = what;
    if (std::getenv("AUTUMN_LOWER_TRACE")) std::fprintf(stderr, "  learnt: %s\n", what.c_str());
  }
  void start_walk() { changed_ = false; }
  bool changed() const { return changed_; }
  const std::string& last_change() const { return last_change_; }  // for the report when walks do not settle

 private:
  template <class Map, class Key>
  static TypeP find(const Map& m, const Key& k) {
    auto it = m.find(k);
    return it == m.end() ? nullptr : it->second;
  }

  std::map<Sym, TypeP> globals_;
  std::map<LocalKey, TypeP> locals_;
  std::map<std::pair<int, int>, TypeP> fields_;  // (class, field)
  std::set<TypeP> tracked_;
  std::set<Sym> erasable_, runtime_defined_, stored_in_step_, prev_read_;
  std::set<int> stored_cells_, rotated_;
  std::set<LocalKey> mutable_bindings_;
  std::set<const void*> unfused_;
  bool runtime_order_ = false;
  bool draw_order_ = false;
  std::map<int, ir::Node*> shapes_;
  bool changed_ = false;  // set by learn, cleared by start_walk
  std::string last_change_;
};

}  // namespace autumn::lower
