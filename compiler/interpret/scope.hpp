// scope — one frame of the interpreter's dynamic scope chain.
//
// Kinds matter: cell capture skips the outermost Instance scope (a constructor or
// render-method scope), and only the Global scope's map order is observable. The
// global scope's bindings live in the Interpreter (indexed by symbol); every other
// scope keeps a short vector, searched linearly (they hold a handful of names).
#pragma once
#include <utility>
#include <vector>

#include "compiler/interpret/value.hpp"

namespace autumn::interp {

enum class ScopeKind { Global, Local, Instance };

struct Binding {
  Sym sym;
  Value value;
  bool updated = false;
};

struct Scope : Obj {
  ScopeKind kind = ScopeKind::Local;
  Ref<Scope> parent;
  std::vector<Binding> vars;                          // unused for the global scope
  std::vector<std::pair<Sym, TypeRef>> declared;      // (: x T) in this scope

  Binding* find(Sym s) {
    for (auto& b : vars)
      if (b.sym == s) return &b;
    return nullptr;
  }
  void release_children(Dying& dying) override {
    parent.release_into(dying);
    for (auto& b : vars) b.value.obj.release_into(dying);
    for (auto& d : declared) d.second.release_into(dying);
  }
};

}  // namespace autumn::interp
