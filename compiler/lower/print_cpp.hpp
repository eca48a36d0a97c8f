// print_cpp — prints a lowered Module as C++ (the `struct Prog` of a module).
// The only place in the lowering that produces C++ text.
#pragma once
#include <cstdint>
#include <string>

#include "compiler/lower/module.hpp"

namespace autumn::lower {

std::string print_cpp(const Module& m);

// What the module's state snapshots hold, as a digest (printed as
// Prog::kSnapshotLayout; runtime/compiled_support.hpp, "Snapshots"): the saved
// slots and their types, the classes' members, the run-time orders and the
// string table. Equal for two lowerings whose snapshots mean the same bytes.
uint64_t snapshot_layout(const Module& m);

// A C++ string literal holding exactly these bytes (every byte outside printable
// ASCII, and ? " \\, escaped in octal: no trigraph, no escape can run on).
std::string cpp_string_literal(const std::string& s);

}  // namespace autumn::lower
