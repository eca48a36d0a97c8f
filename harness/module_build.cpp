// module_build — the compile of one module, as a detached shell process that
// compiles, digests and renames into place (see module_build.hpp).
#include "harness/module_build.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "harness/module_build_clang.hpp"
#include "harness/module_config.hpp"  // generated: build/config/
#include "harness/module_store.hpp"

extern char** environ;

namespace autumn {

namespace fs = std::filesystem;

// g++ does not check the headers a PCH was made from, so a stale one would
// compile modules against the old runtime (a partial rebuild that skipped the
// PCH target); Clang refuses a stale one outright. Either way: not used.
bool module_pch_current(const fs::path& pch) {
  std::error_code ec;
  const auto made = fs::last_write_time(pch, ec);
  if (ec) return false;
  for (const auto& entry : fs::directory_iterator(fs::path(AUTUMN_MODULE_INCLUDE) / "runtime", ec)) {
    std::error_code e2;
    if (fs::last_write_time(entry.path(), e2) > made && !e2) return false;
  }
  return true;
}

std::vector<std::string> module_flags(const char* optimisation) {
  return {"-std=c++20", optimisation, "-fPIC", "-shared", "-fvisibility=hidden", "-DAUTUMN_MODULE_SHARED"};
}

namespace {

// The precompiled runtime header, when the build made one (CMake:
// autumn_module_pch) and it is current (module_pch_current).
std::string pch_flag() {
  static const std::string flag = [] {
    const fs::path header = AUTUMN_MODULE_PCH;
    if (header.empty() || !module_pch_current(header.string() + ".gch")) return std::string();
    return " -include '" + header.string() + "'";
  }();
  return flag;
}

std::string compiler_flags() {
  std::string s = AUTUMN_CXX;
  for (const std::string& f : module_flags("-O2")) s += " " + f;
  return s;
}

}  // namespace

// At most this many compiles run at once per cache directory, however many
// programs a process (or several processes) asks for: the Python drop-in opening
// seventy programs in a row started seventy g++ processes side by side (gigabytes
// of memory, a third of the CPU lost to thrashing, every other process starved).
// AUTUMN_COMPILE_JOBS overrides; the default is the number of CPUs.
int module_compile_slots() {
  static const int slots = [] {
    if (const char* v = std::getenv("AUTUMN_COMPILE_JOBS")) {
      char* end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (end != v && *end == 0 && n >= 1 && n <= 1024) return static_cast<int>(n);
    }
    const unsigned cpus = std::thread::hardware_concurrency();
    const int n = cpus == 0 ? 2 : static_cast<int>(cpus);
    if (const char* v = std::getenv("AUTUMN_COMPILE_JOBS"))
      std::fprintf(stderr, "autumn: AUTUMN_COMPILE_JOBS='%s' is not a number from 1 to 1024; %d compiles at once\n", v, n);
    return n;
  }();
  return slots;
}

namespace {

// The script's first lines take a compile slot: a lock (flock(1), util-linux) on
// one of the files compile-slot.0 .. compile-slot.(N-1) in the cache directory, the first free
// one, or else waits on one chosen by pid. The lock is held by the shell and the
// compiler it starts, and ends with them (a killed compile frees its slot).
// Without flock(1) compiles are not limited.
//
// Then the entry's lock, mKEY.lock ($9), held to the end: processes that share
// a cache build each module once. Once it holds the lock, a script that finds
// the module another process built meanwhile (its library and manifest newer
// than this script's source file) exits 3 without compiling: whether it waited
// for the entry's lock or only for a slot, behind the compile that built it
// (before, a script queued on a slot found the entry unlocked and compiled the
// module a second time). The entry is locked
// only once a slot is held, so no process holds an entry it is not building
// while it waits for a slot (it would keep every other process from a module
// it has not begun).
constexpr const char* kSlotScript =
    "umask 077; if command -v flock >/dev/null 2>&1; then i=0; got=; "
    "while [ $i -lt @SLOTS@ ]; do exec 9>\"$8.$i\" && flock -n 9 && { got=1; break; }; i=$((i+1)); done; "
    "[ -n \"$got\" ] || { exec 9>\"$8.$(($$ % @SLOTS@))\" && flock 9; }; "
    "exec 8>\"$9\" && flock 8 && [ \"$3\" -nt \"$1\" ] && [ \"$7\" -nt \"$1\" ] && "
    "{ rm -f \"$1\"; exit 3; }; fi; ";

// sh -c SCRIPT sh CPP TMP_SO SO LOG HEAD TMP_MANIFEST MANIFEST SLOTS LOCK: take a slot and the entry, compile, make
// the library 0600 (the linker makes it executable; it is only ever read), digest
// it into its manifest, rename both into place (-T: never into a directory
// standing in their place), clean up. The manifest
// goes first: a new module never stands in the cache without its manifest (a
// module it replaces is refused, and rebuilt, until the new one follows).
constexpr const char* kScript =
    "CMD \"$1\" -o \"$2\" LIBS -Wl,-Bsymbolic >\"$4\" 2>&1 && "
    "{ chmod 600 \"$2\" && d=$(sha256sum <\"$2\") && printf '%sso %s\\n' \"$5\" \"${d%% *}\" >\"$6\" && mv -fT \"$6\" \"$7\" && "
    "mv -fT \"$2\" \"$3\"; } 2>>\"$4\"; s=$?; "
    "rm -f \"$1\" \"$6\"; if [ $s -eq 0 ]; then rm -f \"$4\"; else rm -f \"$2\"; fi; exit $s";

std::string script() {
  std::string slots = kSlotScript;
  for (size_t at; (at = slots.find("@SLOTS@")) != std::string::npos;) slots.replace(at, 7, std::to_string(module_compile_slots()));
  std::string s = slots + kScript;
  s.replace(s.find("CMD"), 3, compiler_flags() + pch_flag() + " -I'" + AUTUMN_MODULE_INCLUDE + "'");
  s.replace(s.find("LIBS"), 4, AUTUMN_MODULE_LIBS);
  return s;
}

// Starts the script in a new session, its standard streams on /dev/null (a
// caller reading our output to its end must not wait for the compiler); returns
// the pid, or -1.
pid_t spawn_compile(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSID);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&files, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  int rc = posix_spawn(&pid, "/bin/sh", &files, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attr);
  return rc == 0 ? pid : -1;
}

std::string read_log(const fs::path& log) {
  std::ifstream in(log, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str().substr(0, 4000);
}

}  // namespace

namespace {

// Which compiler builds modules, read once from AUTUMN_MODULE_COMPILER: "cxx"
// (the default: the configured C++ compiler, g++, in a detached process) or
// "clang" (Clang and lld in this process, harness/module_build_clang). A value
// that cannot be honoured says why on stderr and keeps the default.
bool clang_in_process() {
  static const bool clang = [] {
    const char* v = std::getenv("AUTUMN_MODULE_COMPILER");
    const std::string want = v ? v : "";
    if (want.empty() || want == "cxx") return false;
    if (want != "clang") {
      std::fprintf(stderr, "autumn: AUTUMN_MODULE_COMPILER='%s' is neither 'cxx' nor 'clang'; modules compiled by %s\n",
                   want.c_str(), AUTUMN_CXX);
      return false;
    }
    if (const std::string& why = clang_build::unavailable(); !why.empty()) {
      std::fprintf(stderr, "autumn: AUTUMN_MODULE_COMPILER=clang: %s; modules compiled by %s\n", why.c_str(), AUTUMN_CXX);
      return false;
    }
    return true;
  }();
  return clang;
}

}  // namespace

std::string module_compiler_signature() {
  if (clang_in_process()) return clang_build::signature();
  return compiler_flags() + " " + AUTUMN_CXX_VERSION + " " + AUTUMN_MODULE_LIBS;
}

namespace {

// Whether a failed compile failed for want of the cache directory (a full disk,
// a permission): "" or "cannot write in DIR: reason". The linker does not always
// say (collect2 alone reports its exit status), so a megabyte is written to see.
std::string store_problem(const fs::path& dir) { return store::probe_write(dir, 1 << 20); }

}  // namespace

CompileOutcome compile_module(const std::string& source, const fs::path& so, const std::string& tag,
                              const std::string& manifest_head, const std::function<void()>& started) {
  CompileOutcome out;
  const fs::path base = so.parent_path() / (so.stem().string() + "." + tag);
  // The module is written under a name that is not "*.so" and renamed into place
  // when whole: a reader listing or loading modules never sees a partial one.
  const fs::path cpp = base.string() + ".cpp", tmp = base.string() + ".so.part", log = base.string() + ".log";
  const fs::path manifest = store::manifest_path(so), manifest_tmp = base.string() + ".manifest.part";
  unlink(cpp.c_str());  // left by a killed compile whose pid and thread this one reuses
  if (std::string e = store::write_new_file(cpp, source); !e.empty()) {
    started();
    out.output = out.store_error = e;
    return out;
  }
  if (clang_in_process()) {  // the compile runs in this thread: the caller waits for it, at exit too
    out = clang_build::compile(cpp, tmp, so, manifest_head, manifest_tmp, manifest, so.parent_path() / "compile-slot",
                               store::entry_lock_path(so));
    started();
    if (!out.ok) out.store_error = store_problem(so.parent_path());
    return out;
  }
  pid_t pid = spawn_compile({"sh", "-c", script(), "sh", cpp.string(), tmp.string(), so.string(), log.string(),
                             manifest_head, manifest_tmp.string(), manifest.string(),
                             (so.parent_path() / "compile-slot").string(), store::entry_lock_path(so).string()});
  started();
  if (pid < 0) {
    out.output = std::string("cannot start the C++ compiler: ") + std::strerror(errno);
    return out;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  out.built_elsewhere = WIFEXITED(status) && WEXITSTATUS(status) == 3;
  out.ok = WIFEXITED(status) && (WEXITSTATUS(status) == 0 || out.built_elsewhere);
  out.output = read_log(log);
  std::error_code ec;
  fs::remove(log, ec);
  if (!out.ok) out.store_error = store_problem(so.parent_path());
  return out;
}

}  // namespace autumn
