// render_order — the order in which the host render draws globals.
//
// The reference draws the initnext variables in declaration order (duplicates
// dropped), then every other global in the order it was first defined: builtins
// and stdlib names (which draw nothing), SpecialConditionTriggered, the program's
// top-level definitions, cacheRendered (defined by the first render), then
// whatever is first defined later (click, globals an on-clause creates). Later
// draws overwrite earlier ones, so this order is the frame's z-order.
//
// RenderOrder applies that rule to a history of declarations and definitions.
// The interpreter feeds it as it runs; analyse feeds it the definitions start-up
// makes unconditionally (Program::render_order), which the lowering bakes in.
#pragma once
#include <algorithm>
#include <vector>

#include "compiler/parse/ast.hpp"

namespace autumn {

class RenderOrder {
 public:
  explicit RenderOrder(size_t symbols = 0) : placed_(symbols, 0) {}
  void note_initnext(Sym s) {
    grow(s);
    if (placed_[s] == kInitnext) return;
    // An initnext declaration outranks an earlier plain definition of the name.
    if (placed_[s] == kDefined) defined_.erase(std::find(defined_.begin(), defined_.end(), s));
    placed_[s] = kInitnext;
    initnext_.push_back(s);
  }
  void note_definition(Sym s) {
    grow(s);
    if (placed_[s]) return;
    placed_[s] = kDefined;
    defined_.push_back(s);
  }
  // Initnext declarations, then first definitions.
  std::vector<Sym> order() const {
    std::vector<Sym> out = initnext_;
    out.insert(out.end(), defined_.begin(), defined_.end());
    return out;
  }

 private:
  static constexpr char kDefined = 1, kInitnext = 2;
  void grow(Sym s) {
    if (s >= static_cast<Sym>(placed_.size())) placed_.resize(s + 1, 0);
  }
  std::vector<char> placed_;  // by symbol: 0, kDefined or kInitnext
  std::vector<Sym> initnext_, defined_;
};

}  // namespace autumn
