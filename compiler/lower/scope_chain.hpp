// scope_chain — the specialiser's static scope chain: the scopes a name lookup
// sees at the point being lowered.
//
// The interpreter's scope chain is dynamic; the specialiser inlines every call,
// so at each point it is a list of static scopes, outermost first, over the
// globals (spec_scope.cpp resolves names against it). A scope is pushed where
// the interpreter would make one (a let, an inlined lambda, a constructor's
// instance scope, a cell's capture scope) and popped when that construct ends.
// A cell argument's trial and a colour function see other chains for a while:
// `replace` swaps the visible chain and gives the old one back to restore.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/ir.hpp"
#include "compiler/lower/types.hpp"

namespace autumn::lower {

enum class ScopeKind : uint8_t { Local, Instance };

struct Binding {
  Sym sym = -1;
  TypeP type = nullptr;      // the slot's static type
  ir::Node* place = nullptr; // a Local (mutable) or an immutable value
  ir::Var* flag = nullptr;   // maybe-bound: this bool says whether it is bound now
  bool mut = false;
  std::pair<const void*, Sym> key;
  ir::Node* konst = nullptr;   // the value when known at compile time...
  ir::Block* home = nullptr;   // ...valid in this block only, for a mutable binding
};

struct SScope {
  ScopeKind kind = ScopeKind::Local;
  std::vector<Binding> vars;
  std::vector<std::pair<Sym, const TypeExpr*>> declared;
  ir::Block* block = nullptr;  // declarations of names this scope defines go here...
  size_t hoist = 0;            // ...before this statement (so every branch sees them)
  Binding* find(Sym s) {
    for (auto it = vars.rbegin(); it != vars.rend(); ++it)
      if (it->sym == s) return &*it;
    return nullptr;
  }
};

class ScopeChain {
 public:
  using Chain = std::vector<SScope*>;

  // A new innermost scope whose hoisted declarations go at the current end of `block`.
  SScope* push(ScopeKind k, ir::Block* block) {
    owned_.push_back(std::make_unique<SScope>());
    SScope* sc = owned_.back().get();
    sc->kind = k;
    sc->block = block;
    sc->hoist = block->size();
    chain_.push_back(sc);
    return sc;
  }
  // Ends the innermost scope push made.
  void pop() {
    chain_.pop_back();
    owned_.pop_back();
  }

  // The visible scopes, outermost first (empty: only the globals).
  const Chain& visible() const { return chain_; }
  bool empty() const { return chain_.empty(); }
  SScope& innermost() const { return *chain_.back(); }
  // Whether some visible scope binds `s`.
  bool binds(Sym s) const {
    for (SScope* sc : chain_)
      if (sc->find(s)) return true;
    return false;
  }
  // Makes `with` the visible chain; returns the chain it replaces.
  Chain replace(Chain with) {
    std::swap(chain_, with);
    return with;
  }

 private:
  // Invariant: every scope in chain_ is owned by owned_ or by a caller that
  // outlives its use in the chain (a cell's capture scope during its trial);
  // pop() removes the innermost of both, so pushes and pops must pair.
  std::vector<std::unique_ptr<SScope>> owned_;  // the scopes push made, innermost last
  Chain chain_;                                 // the scopes a lookup sees, outermost first
};

}  // namespace autumn::lower
