// ir_verify — the IR's invariants, checked after every pass.
//
// What every pass may assume and must leave true (ir.hpp states the rules):
// operands are never null and fixed-arity operations have their arity; a node
// has a type unless it is error text (Text, Concat) or a call made for its effect; a variable
// is introduced once (Let, Decl, Bind, a loop, a parameter) and read only in
// its scope, after its introduction; slots, classes, functions and error sites
// named by index exist; a Break is inside a loop with no switch in between (a
// C++ `break` there would leave the switch); a function returns a value exactly
// when it has a result type.
//
// lower_program runs it after each pass when AUTUMN_VERIFY_IR is set (ctest
// and the fuzz smokes set it) and reports the first pass that broke the IR as
// an internal error. Test: tests/lowering_test.cpp (IrVerify).
#pragma once
#include <string>
#include <vector>

#include "compiler/lower/module.hpp"

namespace autumn::lower {

// The broken invariants, each "function NAME: what" (empty: the IR is sound).
std::vector<std::string> verify_ir(const Module& m);

}  // namespace autumn::lower
