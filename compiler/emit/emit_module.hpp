// emit_module — C++ source for one Autumn environment module (back end: emit).
//
// The emitted file defines the module's C ABI table (runtime/module_abi.h) under
// a per-module name, and under autumn_module_v1_entry when built as a shared
// library (-DAUTUMN_MODULE_SHARED).
//
// The module is specialised code from compiler/lower when the lowering can
// express the program (every known program; values whose type is only known at
// run time are tagged variants there), else "embedded": the program text run by
// the reference-exact interpreter inside the module. Either way it is exact.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

namespace autumn {

struct ModuleSource {
  std::string name;          // C identifier part: autumn_module_<name>
  std::string program_path;  // for the header comment (as given)
  std::string program_text;
  std::optional<std::string> trigger;
  bool force_embedded = false;  // skip the specialiser (the fallback when its output fails)
};

// FNV-1a over the program text and trigger: identifies the source of a module.
uint64_t module_source_hash(const std::string& program_text, const std::optional<std::string>& trigger);

// Turns a file stem into a valid C identifier ("ajl-snake" -> "ajl_snake").
std::string module_identifier(const std::string& stem);

struct Lowered;
// The module's source; *report (if given) says whether it specialised, why not,
// and its dynamic sites.
std::string emit_module(const ModuleSource& src, Lowered* report = nullptr);

}  // namespace autumn
