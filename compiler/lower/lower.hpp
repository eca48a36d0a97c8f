// lower — specialise a whole program into typed C++ (pass 4: lower).
//
// The lowering is a pipeline over a typed IR (docs/design.md, "The lowering"):
//
//   specialise      the staged interpreter: AST -> typed IR, every call inlined,
//                   dynamic scopes resolved, types found by repeated walks
//                   (specialise.hpp, spec_*.cpp)
//   refs            names of places: references unless a store can intervene
//   scratch         short-lived lists reuse their storage
//   moves           last uses move
//   print           the one C++ printer (print_cpp.hpp)
//
// Where a value's type can only be known at run time, that value alone is a
// tagged variant (a "dynamic site", listed in the report); the rest of the
// program stays typed. A few constructs cannot be expressed faithfully at all
// (field assignment, rotate, recursion, ...): for those the whole program is not
// specialised, with the located reason, and the emitter embeds the interpreter.
#pragma once
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"

namespace autumn {

struct Lowered {
  bool ok = false;
  std::string reason;                       // why not, located, when !ok
  std::string code;                         // the `struct Prog { ... };` definition and its tables
  std::vector<std::string> dynamic_sites;   // "file:line:col: why" for each dynamic site
};

Lowered lower_program(const Program& program, const std::string& program_name);

}  // namespace autumn
