// lower — specialise a whole program into typed C++ (pass 4: lower).
//
// The lowering is a pipeline over a typed IR (docs/design.md, "The lowering"):
//
//   specialise      the staged interpreter: AST -> typed IR, every call inlined,
//                   dynamic scopes resolved, types found by repeated walks
//                   (specialise.hpp, spec_*.cpp)
//   passes          mark_occupancy_if_read, settle_references, resolve_aliases,
//                   remove_dead_names, move_last_uses, reuse_buffers,
//                   spare_short_loops (passes.hpp)
//   print           the one C++ printer (print_cpp.hpp)
//
// After each stage the IR can be verified (ir_verify.hpp) and printed as text
// (ir_print.hpp; `autumnc --dump-ir=STAGE`).
//
// Where a value's type can only be known at run time, that value alone is a
// tagged variant (a "dynamic site", listed in the report); the rest of the
// program stays typed. A few constructs cannot be expressed faithfully at all
// (field assignment, recursion, a program's own renderAll, ...; docs/design.md,
// "What is not specialised"): for those the whole program is not specialised,
// with the located reason, and the emitter embeds the interpreter.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"

namespace autumn {

struct Lowered {
  bool ok = false;
  std::string reason;                       // why not, located, when !ok
  std::string code;                         // the `struct Prog { ... };` definition and its tables
  std::vector<std::string> dynamic_sites;   // "file:line:col: why" for each dynamic site
  std::string ir;                           // the IR's text after LowerOptions::dump_ir_after (ir_print.hpp)
  uint64_t snapshot_layout = 0;             // Prog::kSnapshotLayout: what its state snapshots hold (print_cpp.hpp)
};

struct LowerOptions {
  std::string dump_ir_after;  // a stage of lowering_stages(): keep the IR's text after it (Lowered::ir)
};

// The stages in order: "specialise", then each IR pass (passes.hpp).
const std::vector<std::string>& lowering_stages();

// Runs the stages, then the C++ printer. With AUTUMN_VERIFY_IR set (not empty or 0), the IR is
// verified after every stage (ir_verify.hpp); a broken invariant is an
// internal error (std::logic_error naming the stage).
Lowered lower_program(const Program& program, const std::string& program_name, const LowerOptions& options = {});

}  // namespace autumn
