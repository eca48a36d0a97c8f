// module_build — one C++ compile of an emitted module into the module cache.
//
// The compiler runs in a process of its own (a new session, through /bin/sh,
// umask 077): it writes a temporary shared library, records its SHA-256 in the
// entry's manifest (harness/module_store) and renames both into place, so a cache
// entry appears whole or not at all, and a compile started by a short-lived
// command (`autumn run --steps 3`) still finishes and fills the cache after that
// command exits. The caller's thread waits for it when it wants the result.
// AUTUMN_MODULE_COMPILER=clang compiles in this process instead, with Clang and
// lld as libraries (module_build_clang.hpp); the same protocol, the same files.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace autumn {

// The compiler and flags every module is built with (part of the cache key).
std::string module_compiler_signature();

// The flags of every module compile, whichever compiler: the language, position
// independence, hidden symbols, the shared-module define, and `optimisation`.
std::vector<std::string> module_flags(const char* optimisation);

// Whether the precompiled runtime header `pch` (g++'s .gch or Clang's .pch) is
// newer than every runtime header, so a compile may use it.
bool module_pch_current(const std::filesystem::path& pch);

// How many compiles run at once per cache directory (AUTUMN_COMPILE_JOBS, else
// the number of CPUs); a compile beyond them waits for a slot, which the compile
// holds through a lock on CACHE/compile-slot.K (K below this count).
int module_compile_slots();

struct CompileOutcome {
  bool ok = false;
  std::string output;       // the compiler's messages (first few thousand characters)
  std::string store_error;  // set when the cache could not be written (ENOSPC, EACCES), not the compiler's fault
  bool built_elsewhere = false;  // another process built the entry while this one waited for it: not compiled
};

// Compiles `source` into the shared library `so` and writes its manifest
// (`manifest_head` plus the digest of the library's bytes); temporary files
// beside it are named with `tag`. Calls `started` once the compiler process runs
// (or could not be started), then blocks until it ends.
CompileOutcome compile_module(const std::string& source, const std::filesystem::path& so, const std::string& tag,
                              const std::string& manifest_head, const std::function<void()>& started);

}  // namespace autumn
