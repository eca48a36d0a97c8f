// ir_print — the lowering IR as text, for people and filetests.
//
// One line per statement, indented by nesting; a node prints as its operation
// and operands in prefix form, with its type after a colon where it has one:
//
//   fn step(s)
//     let v3: int = add(global g_x_4: int, lit 1: int)
//     if lt(local v3: int, lit 10: int): bool
//       set global g_x_4: int = local v3: int
//
// Marks in brackets are the passes' decisions: a Bind's [ref] or [copy]
// (settle_references), a [scratch] list (reuse_buffers), a [move] of a last use
// (move_last_uses), an [uncharged] loop (spare_short_loops), a loop counting
// the budget in a [local budget] (keep_budgets_local).
// Variables print as v<id>, slots by their C++ member name, strings by id
// (str#2), helpers and members by their enum names. `autumnc --dump-ir`
// prints it; tests/lowering_test.cpp (IrText) checks its shape. The printer
// of C++ is print_cpp.cpp; this one is for reading the IR, not compiling it.
#pragma once
#include <string>

#include "compiler/lower/module.hpp"

namespace autumn::lower {

std::string type_text(TypeP t);
const char* stmt_kind_name(ir::SK k);  // "let", "for_each", ...
std::string print_node(const Module& m, const ir::Node* n);
std::string print_ir(const Module& m);

}  // namespace autumn::lower
