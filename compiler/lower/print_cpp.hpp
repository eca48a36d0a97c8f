// print_cpp — prints a lowered Module as C++ (the `struct Prog` of a module).
// The only place in the lowering that produces C++ text.
#pragma once
#include <string>

#include "compiler/lower/module.hpp"

namespace autumn::lower {

std::string print_cpp(const Module& m);

}  // namespace autumn::lower
