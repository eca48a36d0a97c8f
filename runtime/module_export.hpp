// module_export — implements the C ABI table (module_abi.h) for any Environment
// subclass. Emitted modules call ModuleExporter<MakeEnv>::table once; the entries
// are compiled once, in module_export.cpp; the host side wraps a table back into
// an Environment with ModuleEnvironment (module_env.hpp).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "runtime/environment.hpp"
#include "runtime/module_abi.h"

namespace autumn {

struct ExportedEnv {
  std::unique_ptr<Environment> env;
  mutable std::vector<uint8_t> snapshot;  // the last save_state result
  std::string json;                        // the last render_json result
};

// An Environment as the C ABI's handle (freed by the table's destroy).
autumn_env* export_env(std::unique_ptr<Environment> e);

// The table: every entry but `create` forwards to the Environment a handle
// wraps, the same for every module (module_export.cpp); `create` alone knows
// the module's Environment type.
autumn_module_v1 module_table(const char* name, uint64_t source_hash, autumn_env* (*create)());

template <class MakeEnv>
struct ModuleExporter {
  static autumn_module_v1 table(const char* name, uint64_t source_hash) {
    return module_table(name, source_hash, [] { return export_env(MakeEnv{}()); });
  }
};

}  // namespace autumn
