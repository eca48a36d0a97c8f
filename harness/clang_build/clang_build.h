// clang_build — the C ABI of the in-process Clang plugin (libautumn_clang_build.so).
//
// harness/module_build loads the plugin with dlopen only when a module is to be
// compiled in process (AUTUMN_MODULE_COMPILER=clang), so no other use of
// `autumn`, `autumnc` or the Python extension pays for loading Clang and LLVM
// (about 90 MB of shared libraries). The plugin is built when CMake finds
// Debian's clang-14, LLVM-14 and lld-14 development packages.
#pragma once
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

// Compiles and links as `clang++ ARGS...` would (argv[0] is the clang++ whose
// installation, gcc toolchain and resource directory the driver uses), with no
// process started: Clang's driver plans the jobs, the compile runs in a
// CompilerInstance and the link in lld's ELF linker. Compiles may run in
// several threads at once; links take turns (lld keeps global state). Returns 0 on success; writes the
// diagnostics (NUL-terminated, cut at log_cap - 1 bytes) into `log`.
int autumn_clang_build(int argc, const char* const* argv, char* log, size_t log_cap);

// The Clang version the plugin was built with ("14.0.6"), for the cache key.
const char* autumn_clang_version(void);

#ifdef __cplusplus
}
#endif
