#include "harness/module_cache.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <unordered_map>

#include "compiler/emit/emit_module.hpp"
#include "runtime/module_env.hpp"

namespace autumn {
namespace {

namespace fs = std::filesystem;

struct Loaded {
  const autumn_module_v1* table = nullptr;
  std::shared_ptr<void> handle;
};

std::mutex cache_mutex;
std::unordered_map<uint64_t, Loaded> loaded_modules;

fs::path cache_dir() {
  if (const char* d = std::getenv("AUTUMN_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "autumnc";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "autumnc";
  return fs::temp_directory_path() / "autumnc-cache";
}

std::string compile_command(const fs::path& cpp, const fs::path& so) {
  return std::string(AUTUMN_CXX) + " -std=c++20 -O2 -fPIC -shared -fvisibility=hidden -DAUTUMN_MODULE_SHARED -I" +
         AUTUMN_MODULE_INCLUDE + " '" + cpp.string() + "' -o '" + so.string() + "' " + AUTUMN_MODULE_LIBS +
         " -Wl,-Bsymbolic 2>&1";
}

// The compiler, its flags, the libraries a module links, the lowering that wrote
// it (autumn_emit) and the runtime headers it includes all decide what a cached
// module contains; a rebuilt library changes its size or time stamp, an edited
// header its text.
uint64_t cache_key(uint64_t source_hash) {
  std::string salt = std::string(AUTUMN_CXX) + " " + AUTUMN_CXX_VERSION + " " + AUTUMN_MODULE_LIBS + " abi " +
                     std::to_string(AUTUMN_MODULE_ABI_VERSION);
  std::istringstream libs(std::string(AUTUMN_MODULE_LIBS) + " " + AUTUMN_EMIT_LIB);
  for (std::string lib; libs >> lib;) {
    std::error_code ec;
    auto size = fs::file_size(lib, ec);
    auto stamp = fs::last_write_time(lib, ec).time_since_epoch().count();
    salt += " " + std::to_string(size) + ":" + std::to_string(stamp);
  }
  std::vector<fs::path> headers;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(AUTUMN_MODULE_INCLUDE) / "runtime", ec))
    if (entry.path().extension() == ".hpp" || entry.path().extension() == ".h") headers.push_back(entry.path());
  std::sort(headers.begin(), headers.end());
  for (const auto& h : headers) {
    std::ifstream in(h, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    salt += " " + h.filename().string() + ":" + std::to_string(module_source_hash(text.str(), std::nullopt));
  }
  return module_source_hash(std::to_string(source_hash), salt);
}

std::string run_command(const std::string& cmd, int* status) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) {
    *status = -1;
    return "cannot start the C++ compiler";
  }
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  *status = pclose(p);
  return out;
}

Loaded load_shared(const fs::path& so, uint64_t source_hash, std::string* why) {
  void* h = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    *why = std::string("cannot load compiled module: ") + dlerror();
    return {};
  }
  std::shared_ptr<void> handle(h, [](void* p) { dlclose(p); });
  auto entry = reinterpret_cast<autumn_module_entry_fn>(dlsym(h, "autumn_module_v1_entry"));
  if (!entry) {
    *why = "compiled module " + so.string() + " has no autumn_module_v1_entry";
    return {};
  }
  const autumn_module_v1* table = entry();
  if (table->abi_version != AUTUMN_MODULE_ABI_VERSION) {
    *why = "compiled module " + so.string() + " has ABI version " + std::to_string(table->abi_version) +
           ", expected " + std::to_string(AUTUMN_MODULE_ABI_VERSION);
    return {};
  }
  if (table->source_hash != source_hash) {
    *why = "compiled module " + so.string() + " was built from another program";
    return {};
  }
  return {table, handle};
}

Loaded find_or_build(const Program& program, std::string* why) {
  std::optional<std::string> trigger;
  if (!program.trigger_text.empty()) trigger = program.trigger_text;
  const uint64_t source_hash = module_source_hash(program.file.text, trigger);

  std::lock_guard<std::mutex> lock(cache_mutex);
  if (auto it = loaded_modules.find(source_hash); it != loaded_modules.end()) return it->second;

  BuiltinModules builtins = builtin_modules();
  for (size_t i = 0; i < builtins.count; ++i) {
    const autumn_module_v1* t = builtins.entries[i]();
    if (t->source_hash == source_hash && t->abi_version == AUTUMN_MODULE_ABI_VERSION)
      return loaded_modules[source_hash] = Loaded{t, nullptr};
  }

  char key[17];
  std::snprintf(key, sizeof key, "%016llx", static_cast<unsigned long long>(cache_key(source_hash)));
  fs::path dir = cache_dir();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    *why = "cannot create the module cache " + dir.string() + ": " + ec.message();
    return {};
  }
  fs::path so = dir / (std::string("m") + key + ".so");
  if (!fs::exists(so)) {
    ModuleSource src;
    src.name = std::string("m") + key;
    src.program_path = program.file.name;
    src.program_text = program.file.text;
    src.trigger = trigger;
    const std::string tag = std::to_string(getpid());
    fs::path cpp = dir / (src.name + "." + tag + ".cpp");
    fs::path tmp_so = dir / (src.name + "." + tag + ".so");
    std::ofstream(cpp, std::ios::binary) << emit_module(src);
    int status = 0;
    std::string out = run_command(compile_command(cpp, tmp_so), &status);
    if (status != 0 && std::getenv("AUTUMN_STRICT_MODULES")) {  // the tests: a lowering bug must fail
      fs::remove(cpp, ec);
      *why = "the specialised module for " + program.file.name + " did not compile:\n" + out.substr(0, 4000);
      return {};
    }
    if (status != 0) {
      // A specialised module that does not compile is a bug in the lowering; the
      // embedded lowering keeps the engine usable (and exact) meanwhile.
      std::cerr << "autumn: warning: the specialised module for " << program.file.name
                << " did not compile; using the embedded interpreter. Compiler output:\n"
                << out.substr(0, 2000) << "\n";
      src.force_embedded = true;
      std::ofstream(cpp, std::ios::binary | std::ios::trunc) << emit_module(src);
      out = run_command(compile_command(cpp, tmp_so), &status);
    }
    fs::remove(cpp, ec);
    if (status != 0) {
      fs::remove(tmp_so, ec);
      *why = "the C++ compiler failed on the module for " + program.file.name + ":\n" + out;
      return {};
    }
    fs::rename(tmp_so, so, ec);  // atomic: concurrent builders agree on the result
    if (ec) {
      *why = "cannot place the compiled module in the cache: " + ec.message();
      return {};
    }
  }
  Loaded l = load_shared(so, source_hash, why);
  if (l.table) loaded_modules[source_hash] = l;
  return l;
}

}  // namespace

std::unique_ptr<Environment> make_compiled_environment(std::shared_ptr<const Program> program, std::string* why) {
  std::string reason;
  Loaded l = find_or_build(*program, &reason);
  if (!l.table) {
    if (why) *why = reason;
    return nullptr;
  }
  auto env = std::make_unique<ModuleEnvironment>(l.table, l.handle);
  env->set_source_name(program->file.name);
  return env;
}

}  // namespace autumn
