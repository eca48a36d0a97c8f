// module_cache — the "compiled" engine: find or build a module for any program.
//
// Order of lookup:
//  1. modules already loaded in this process, by the exact program text;
//  2. modules built into this binary from generated/, matched on the full
//     program text (no compile at run time);
//  3. the on-disk cache (harness/module_store: $AUTUMN_CACHE_DIR, else
//     $XDG_CACHE_HOME/autumnc, else ~/.cache/autumnc; if that is unsafe or cannot
//     be written, the private $TMPDIR/autumnc-cache-$UID, with a warning), keyed
//     by the SHA-256 of the program's s-expressions (harness/module_key: comments
//     and layout are not part of the key), the compiler, its flags, the libraries
//     linked and the runtime headers. An entry is loaded only after its bytes,
//     its program and its ABI are checked; one that fails is named on stderr and
//     rebuilt;
//  4. otherwise the module is emitted with the emitter autumnc uses and compiled
//     by the C++ compiler this project was built with ("autumn: compiling
//     prog.au (first use)" on stderr), against the precompiled runtime header
//     when the build made one. The compile runs as a separate process that
//     finishes and fills the cache even if this process exits first.
// A module built from a text that differs only in layout reports runtime errors
// at the locations of the text being run (module_key's relocation_between).
// Failures (a compiler error, a module with another ABI version) come back as a
// message, never a crash; with no writable cache at all the engine falls back to
// the interpreter, with a warning. With AUTUMN_NO_COMPILE set (to anything but
// "" or "0") this process never starts the compiler: a module that is not at hand
// (built in, cached, or installed from another machine by install_module) is an
// error naming the variable, except where the interpreter may serve while a
// module compiles (an `autumn run` episode): there it serves throughout. Such a
// node needs no compiler or headers.
//
// Shipping modules between machines (autumnc.distributed): package_module()
// gives a built module's cache entry (its bytes, manifest and program text);
// install_module() on the receiving node files it under that node's own key for
// the program and loads it through exactly the checks of any cache entry (digest
// of the bytes against the manifest, the program, the ABI, the module's table),
// so a corrupt transfer is refused, never loaded.
#pragma once
#include <memory>
#include <string>
#include <string_view>

#include "compiler/analyse/program.hpp"
#include "runtime/environment.hpp"
#include "runtime/module_abi.h"

namespace autumn {

// Waits for a compile when one is needed.
std::unique_ptr<Environment> make_compiled_environment(std::shared_ptr<const Program> program, std::string* why);

// For one episode: never waits. When the module is not at hand it starts the
// compile and returns an environment whose first steps the interpreter runs;
// it switches to the module, state carried over, once that is loaded
// (harness/warm_env.hpp).
std::unique_ptr<Environment> make_compiled_episode_environment(std::shared_ptr<const Program> program,
                                                               std::string* why);

// Builds and loads the module if needed, before timed work (solve): *seconds is
// the time spent waiting for a compile (0 when the module was at hand).
bool prepare_compiled_module(const std::shared_ptr<const Program>& program, double* seconds, std::string* why);

// A built module's cache entry, as shipped to another node.
struct ModulePackage {
  bool builtin = false;   // built into this binary (generated/): nothing to ship
  std::string key;        // this process's cache key of the program
  std::string so;         // the module's bytes
  std::string manifest;   // its manifest: ABI, program digest, SHA-256 of `so`
  std::string built_from; // the program text it was built from (the entry's .au)
};
// Builds the module when needed (as prepare_compiled_module); false with *why
// when there is none (a compile error, no cache directory).
bool package_module(const std::shared_ptr<const Program>& program, ModulePackage* out, std::string* why);

// Whether this process has the program's module without compiling: built in,
// loaded, or a cache entry that passes its checks (which is then loaded).
bool module_at_hand(const std::shared_ptr<const Program>& program);

// Files a shipped module (its bytes, manifest and built_from text) in this
// process's cache under this process's key for `program`, then loads it through
// the store's checks; "" when it is now the program's module, else why it was
// refused (nothing of it is kept, and a later use compiles as usual).
std::string install_module(const std::shared_ptr<const Program>& program, const std::string& so,
                           const std::string& manifest, const std::string& built_from);

// Whether AUTUMN_NO_COMPILE forbids starting the compiler in this process.
bool compiling_forbidden();

// Waits until no thread is emitting a module (the compiler processes they
// started run on by themselves). A program's main calls it before returning:
// emitter threads use function-local statics, and those first built after the
// atexit handler that also waits was registered are destroyed before it runs.
void finish_module_emits();

// The modules built into this binary (generated/), by entry function, each with
// the text of the program it was built from (programs/NAME.au; empty when there
// is none, and then the module is never used).
struct BuiltinModules {
  const autumn_module_entry_fn* entries;
  const std::string_view* texts;
  size_t count;
};
BuiltinModules builtin_modules();

// The SHA-256 of the lowering library (libautumn_emit) linked into this binary,
// part of every cache key: generated at build time (cmake/file_digest.cmake).
const char* linked_emit_digest();

}  // namespace autumn
