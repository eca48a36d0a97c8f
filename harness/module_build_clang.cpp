// module_build_clang — the in-process Clang build (see module_build_clang.hpp).
#include "harness/module_build_clang.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>
#include <vector>

#include "harness/clang_build/clang_build.h"
#include "harness/digest.hpp"
#include "harness/module_config.hpp"  // generated: build/config/
#include "harness/module_store.hpp"

namespace autumn::clang_build {
namespace {

namespace fs = std::filesystem;

using BuildFn = decltype(&autumn_clang_build);
using VersionFn = decltype(&autumn_clang_version);

// The plugin's entry points, loaded once (never unloaded: LLVM's statics).
struct Plugin {
  BuildFn build = nullptr;
  VersionFn version = nullptr;
  std::string why;  // "" when loaded
};

const Plugin& plugin() {
  static const Plugin p = [] {
    Plugin p;
    const std::string path = AUTUMN_CLANG_PLUGIN;
    if (path.empty()) {
      p.why = "this build has no in-process Clang (install libclang-14-dev, libclang-cpp14-dev and liblld-14-dev, then reconfigure)";
      return p;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      p.why = std::string("cannot load the in-process Clang plugin: ") + dlerror();
      return p;
    }
    p.build = reinterpret_cast<BuildFn>(dlsym(handle, "autumn_clang_build"));
    p.version = reinterpret_cast<VersionFn>(dlsym(handle, "autumn_clang_version"));
    if (!p.build || !p.version) p.why = "the in-process Clang plugin " + path + " lacks its entry points";
    return p;
  }();
  return p;
}

// A file descriptor closed on scope exit (which also releases its flock).
struct Fd {
  int fd = -1;
  explicit Fd(int f) : fd(f) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd >= 0) close(fd);
  }
};

int open_lock(const fs::path& path) { return open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0600); }

// A compile slot: the first free of SLOTS.0 .. SLOTS.(N-1), else waits on the one
// chosen by pid (the compile script's rule, so both kinds share the slots).
Fd take_slot(const fs::path& slots) {
  const int n = module_compile_slots();
  for (int i = 0; i < n; ++i) {
    Fd f(open_lock(slots.string() + "." + std::to_string(i)));
    if (f.fd >= 0 && flock(f.fd, LOCK_EX | LOCK_NB) == 0) return Fd(std::exchange(f.fd, -1));
  }
  Fd f(open_lock(slots.string() + "." + std::to_string(getpid() % n)));
  if (f.fd >= 0)
    while (flock(f.fd, LOCK_EX) < 0 && errno == EINTR) {
    }
  return Fd(std::exchange(f.fd, -1));
}

// Whether `a` was written after `b` (the compile script's `-nt`).
bool newer(const fs::path& a, const fs::path& b) {
  std::error_code ea, eb;
  const auto ta = fs::last_write_time(a, ea), tb = fs::last_write_time(b, eb);
  return !ea && !eb && ta > tb;
}

// -O3: Clang 14's -O2 modules stepped a median 0.90 of g++ -O2's, its -O3 ones
// 1.02 (docs/design.md, "The module's compiler, measured").
constexpr const char* kOptimisation = "-O3";

std::vector<std::string> command(const fs::path& cpp, const fs::path& out) {
  std::vector<std::string> args{AUTUMN_CLANG_DRIVER};
  for (const std::string& f : module_flags(kOptimisation)) args.push_back(f);
  if (const fs::path pch = AUTUMN_CLANG_PCH; !pch.empty() && module_pch_current(pch))
    args.insert(args.end(), {"-include-pch", pch.string()});
  args.insert(args.end(), {"-I", AUTUMN_MODULE_INCLUDE, cpp.string(), "-o", out.string()});
  std::istringstream libs(AUTUMN_MODULE_LIBS);
  for (std::string lib; libs >> lib;) args.push_back(lib);
  args.push_back("-Wl,-Bsymbolic");
  return args;
}

// Runs the plugin; "" or its messages.
bool run_plugin(const std::vector<std::string>& args, std::string* log) {
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::vector<char> buffer(16000);
  const int rc = plugin().build(static_cast<int>(argv.size()), argv.data(), buffer.data(), buffer.size());
  *log = buffer.data();
  return rc == 0;
}

// The library (lld made it in the 0700 cache directory) made 0600, digested into its manifest, both renamed into place
// (the manifest first, as the script does); "" or the reason.
std::string publish(const fs::path& tmp, const fs::path& so, const std::string& head, const fs::path& manifest_tmp,
                    const fs::path& manifest) {
  if (chmod(tmp.c_str(), 0600) != 0) return "chmod " + tmp.string() + ": " + std::strerror(errno);
  std::string bytes;
  if (std::string e = store::read_private_file(tmp, size_t(1) << 31, &bytes); !e.empty()) return e;
  if (std::string e = store::write_new_file(manifest_tmp, head + "so " + sha256_hex(bytes) + "\n"); !e.empty()) return e;
  if (rename(manifest_tmp.c_str(), manifest.c_str()) != 0) return "rename " + manifest.string() + ": " + std::strerror(errno);
  if (rename(tmp.c_str(), so.c_str()) != 0) return "rename " + so.string() + ": " + std::strerror(errno);
  return "";
}

}  // namespace

const std::string& unavailable() { return plugin().why; }

std::string signature() {
  std::string s = std::string("clang-in-process ") + (plugin().version ? plugin().version() : "?");
  for (const std::string& f : module_flags(kOptimisation)) s += " " + f;
  return s + " " + AUTUMN_MODULE_LIBS;
}

CompileOutcome compile(const fs::path& cpp, const fs::path& tmp, const fs::path& so, const std::string& manifest_head,
                       const fs::path& manifest_tmp, const fs::path& manifest, const fs::path& slots,
                       const fs::path& lock) {
  CompileOutcome out;
  Fd slot = take_slot(slots);
  Fd entry(open_lock(lock));
  if (entry.fd >= 0) {
    while (flock(entry.fd, LOCK_EX) < 0 && errno == EINTR) {
    }
    // Another process built it while this one waited, for the entry or for a
    // slot behind that compile (module_build.cpp, kSlotScript).
    if (newer(so, cpp) && newer(manifest, cpp)) {
      unlink(cpp.c_str());
      out.ok = out.built_elsewhere = true;
      return out;
    }
  }
  out.ok = run_plugin(command(cpp, tmp), &out.output);
  if (out.ok) {
    if (std::string e = publish(tmp, so, manifest_head, manifest_tmp, manifest); !e.empty()) {
      out.ok = false;
      out.output += e;
    }
  }
  unlink(cpp.c_str());
  unlink(manifest_tmp.c_str());
  if (!out.ok) unlink(tmp.c_str());
  return out;
}

}  // namespace autumn::clang_build
