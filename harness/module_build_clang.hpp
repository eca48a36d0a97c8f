// module_build_clang — one module compiled by Clang inside this process.
//
// The alternative to module_build's detached g++ (AUTUMN_MODULE_COMPILER=clang):
// the plugin (harness/clang_build) compiles and links in the caller's thread, and
// this file keeps the cache's protocol around it (a compile slot, the entry's
// lock, the digest in the manifest, renames into place) exactly as the compile
// script does, with flock(2) and rename(2) in place of flock(1) and mv. The
// compile ends with the thread that runs it, not after the process exits, so
// the module cache waits for it at exit (module_cache: the emit guard).
// Why it is not the default: docs/design.md, "The module's compiler, measured".
#pragma once
#include <filesystem>
#include <string>

#include "harness/module_build.hpp"

namespace autumn::clang_build {

// Whether the plugin was built and loads ("" when ready, else the reason).
const std::string& unavailable();

// The compiler part of the cache key for in-process Clang builds.
std::string signature();

// As compile_module (module_build.hpp): compiles `cpp` (already written) into
// `so` and its manifest; `slots` names the compile-slot files, `lock` the entry's.
CompileOutcome compile(const std::filesystem::path& cpp, const std::filesystem::path& tmp, const std::filesystem::path& so,
                       const std::string& manifest_head, const std::filesystem::path& manifest_tmp,
                       const std::filesystem::path& manifest, const std::filesystem::path& slots,
                       const std::filesystem::path& lock);

}  // namespace autumn::clang_build
