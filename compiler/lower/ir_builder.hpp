// ir_builder — how the specialiser writes IR: nodes, variables and statements
// made in the module's arena, statements appended to the current block.
//
// The builder owns the insertion point (the function and block being written)
// and the dead-code flag; nothing else writes them. Dead code: after a
// statement that certainly raises an error (an undefined name, a type error
// the types already prove) the rest of the block never runs, so the builder is
// `kill()`ed: statements are still built, for the caller to fill in, but not
// attached. Entering a block (`in_block`) keeps the parent's flag and restores
// it on leaving, so a branch that dies does not kill the code after the branch.
//
// It also counts effects (helper calls that change state, stores to anything but
// a local): a cell argument whose trial adds none can be kept as a value.
//
// Tested through the lowering: tests/lowering_test.cpp ("IrBuilder") and every
// filetest under tests/ir/.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "compiler/lower/module.hpp"

namespace autumn::lower {

// Whether a node is a compile-time constant tree (Lit, or MakePos/MakeElem/MakeList of them).
bool is_const(const ir::Node* n);
// Whether a value cannot change while in use, so needs no temporary: constants,
// immutable locals and their members.
bool is_stable(const ir::Node* n);

class IrBuilder {
 public:
  // `location` gives the error site of the construct being lowered (a loop
  // charges the elements it visits there).
  IrBuilder(Module& m, std::function<int()> location);

  // --- nodes and variables (never attached; any block may use them) --------
  ir::Node* node(ir::Op op, TypeP t, std::vector<ir::Node*> a = {});
  ir::Node* lit(TypeP t, int64_t v);
  ir::Node* text(const std::string& s);
  ir::Node* local(ir::Var* v);
  ir::Node* slot(int s);
  ir::Node* member(ir::Node* base, ir::Member m, TypeP t, int index = 0);
  ir::Node* call(ir::Helper h, TypeP t, std::vector<ir::Node*> a);  // counts state-changing helpers
  ir::Var* var(TypeP t, const std::string& hint);

  // --- statements, appended to the current block unless dead ----------------
  ir::Stmt* emit(ir::SK k);
  ir::Stmt* emit_detached(ir::SK k);  // built, not attached to the current block
  void attach(ir::Stmt* s);           // a statement built detached, appended now (unless dead)
  void emit_set(ir::Node* place, ir::Node* value);
  void emit_eval(ir::Node* n);
  void emit_push(ir::Node* list, ir::Node* value);  // value computed (and emitted) before
  ir::Var* decl(TypeP t, ir::Node* init, const std::string& hint);  // a mutable variable
  void comment(const std::string& text);

  // --- the insertion point ---------------------------------------------------
  // Starts writing function `f` at the top of its body, alive.
  void begin_function(ir::Function* f);
  // Runs `f` with its statements going into `b`; the block and the dead flag
  // are restored afterwards.
  void in_block(ir::Block& b, const std::function<void()>& f);
  // Continues in `b` from here on (an else-if chain, a run of nested ifs).
  void continue_in(ir::Block& b) { block_ = &b; }
  // Everything that says where statements go, to write elsewhere and come back.
  struct Point {
    ir::Function* fn = nullptr;
    ir::Block* block = nullptr;
    bool dead = false;
  };
  Point point() const { return Point{fn_, block_, dead_}; }
  void restore(const Point& p);
  ir::Block* block() const { return block_; }
  bool at_function_top() const { return fn_ && block_ == &fn_->body; }

  // --- dead code -------------------------------------------------------------
  bool dead() const { return dead_; }
  void kill() { dead_ = true; }
  void set_dead(bool d) { dead_ = d; }

  // Effects emitted so far (compare two readings around a trial).
  size_t effects() const { return effects_; }

 private:
  Module& m_;
  std::function<int()> location_;
  // The insertion point. Invariant: block_ is fn_'s body or a block nested in
  // it, or a block the caller made to splice in later (in_block); null before
  // the first begin_function.
  ir::Function* fn_ = nullptr;
  ir::Block* block_ = nullptr;
  bool dead_ = false;    // the code being written never runs: statements are not attached
  size_t effects_ = 0;   // only grows
};

}  // namespace autumn::lower
