#include "harness/module_cache.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cerrno>
#include <cstring>
#include <future>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>
#include <unordered_map>

#include "compiler/emit/emit_module.hpp"
#include "compiler/interpret/interpreted_env.hpp"
#include "harness/module_build.hpp"
#include "harness/module_key.hpp"
#include "harness/warm_env.hpp"
#include "runtime/module_env.hpp"

namespace autumn {
namespace {

namespace fs = std::filesystem;

// A loaded module, or why there is none.
struct Module {
  const autumn_module_v1* table = nullptr;
  std::shared_ptr<void> handle;
  std::string built_from;  // the program text the module was built from
  std::string why;
  bool no_cache = false;   // no writable cache directory: the interpreter stands in
};
using ModulePtr = std::shared_ptr<const Module>;
using ModuleFuture = std::shared_future<ModulePtr>;

// Process-wide and never destroyed: a compile thread may still be waiting for
// its compiler when the process exits.
struct CacheState {
  std::mutex mu;
  std::unordered_map<uint64_t, ModuleFuture> by_text;  // exact source hash
  std::unordered_map<uint64_t, ModuleFuture> by_key;   // cache key
  std::mutex emit_mu;
  std::condition_variable emit_cv;
  int emitting = 0;  // background threads inside the emitter (exit waits for them)
};
CacheState& state() {
  static auto* s = new CacheState();
  return *s;
}

ModuleFuture ready(ModulePtr m) {
  std::promise<ModulePtr> p;
  p.set_value(std::move(m));
  return p.get_future().share();
}

std::optional<std::string> trigger_of(const Program& p) {
  if (p.trigger_text.empty()) return std::nullopt;
  return p.trigger_text;
}

// ---------------------------------------------------------------------------- the cache directory

// The system's temporary directory ($TMPDIR, else /tmp); empty when that is not a directory.
fs::path temp_dir() {
  std::error_code ec;
  fs::path t = fs::temp_directory_path(ec);
  return ec ? fs::path() : t;
}

fs::path configured_cache_dir() {
  if (const char* d = std::getenv("AUTUMN_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "autumnc";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "autumnc";
  return (temp_dir().empty() ? fs::path("/tmp") : temp_dir()) / "autumnc-cache";
}

// Creates `dir` and proves it writable with a probe file ("" or why not).
std::string check_writable(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return ec.message();
  std::string probe = (dir / "probe.XXXXXX").string();
  int fd = mkstemp(probe.data());
  if (fd < 0) return std::strerror(errno);
  close(fd);
  fs::remove(probe, ec);
  return "";
}

// The configured directory, else a private temporary one (warned about once);
// empty, with *why, when neither can be written.
fs::path usable_cache_dir(std::string* why) {
  static const auto chosen = [] {
    std::pair<fs::path, std::string> r;
    const fs::path dir = configured_cache_dir();
    const std::string problem = check_writable(dir);
    if (problem.empty()) return r.first = dir, r;
    const fs::path tmp = temp_dir().empty() ? fs::path("$TMPDIR") : temp_dir() / ("autumnc-cache-" + std::to_string(getuid()));
    const std::string tmp_problem = temp_dir().empty() ? "not a directory" : check_writable(tmp);
    if (tmp_problem.empty()) {
      std::cerr << "autumn: warning: cannot write the module cache " << dir.string() << " (" << problem << "); using "
                << tmp.string() << "\n";
      return r.first = tmp, r;
    }
    r.second = "no writable module cache (" + dir.string() + ": " + problem + "; " + tmp.string() + ": " +
               tmp_problem + ")";
    return r;
  }();
  if (chosen.first.empty()) *why = chosen.second;
  return chosen.first;
}

// ---------------------------------------------------------------------------- keys

// The compiler, its flags, the libraries a module links, the lowering that wrote
// it (autumn_emit) and the runtime headers it includes all decide what a cached
// module contains; a rebuilt library changes its size or time stamp, an edited
// header its text. Computed once per process.
const std::string& key_salt() {
  static const std::string salt = [] {
    std::string s = module_compiler_signature() + " abi " + std::to_string(AUTUMN_MODULE_ABI_VERSION);
    std::istringstream libs(std::string(AUTUMN_MODULE_LIBS) + " " + AUTUMN_EMIT_LIB);
    for (std::string lib; libs >> lib;) {
      std::error_code ec;
      auto size = fs::file_size(lib, ec);
      auto stamp = fs::last_write_time(lib, ec).time_since_epoch().count();
      s += " " + std::to_string(size) + ":" + std::to_string(stamp);
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
      s += " " + h.filename().string() + ":" + std::to_string(module_source_hash(text.str(), std::nullopt));
    }
    return s;
  }();
  return salt;
}

uint64_t cache_key(const Program& p) {
  const auto trigger = trigger_of(p);
  const uint64_t program = canonical_program_hash(p.file.text, trigger).value_or(module_source_hash(p.file.text, trigger));
  return module_source_hash(std::to_string(program), key_salt());
}

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// ---------------------------------------------------------------------------- loading

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The text a cached module was built from sits beside it, named by its source hash.
fs::path text_path(const fs::path& so, uint64_t source_hash) {
  return so.parent_path() / (so.stem().string() + "-" + hex(source_hash) + ".au");
}

ModulePtr load_shared(const fs::path& so, const std::optional<std::string>& trigger) {
  auto m = std::make_shared<Module>();
  void* h = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h) return m->why = std::string("cannot load compiled module: ") + dlerror(), m;
  m->handle = std::shared_ptr<void>(h, [](void* p) { dlclose(p); });
  auto entry = reinterpret_cast<autumn_module_entry_fn>(dlsym(h, "autumn_module_v1_entry"));
  if (!entry) return m->why = "compiled module " + so.string() + " has no autumn_module_v1_entry", m;
  const autumn_module_v1* table = entry();
  if (table->abi_version != AUTUMN_MODULE_ABI_VERSION)
    return m->why = "compiled module " + so.string() + " has ABI version " + std::to_string(table->abi_version) +
                    ", expected " + std::to_string(AUTUMN_MODULE_ABI_VERSION),
           m;
  m->built_from = read_text(text_path(so, table->source_hash));
  if (module_source_hash(m->built_from, trigger) != table->source_hash)
    return m->why = "compiled module " + so.string() + " lacks the program text it was built from", m;
  m->table = table;
  return m;
}

// ---------------------------------------------------------------------------- building

// Counts a thread that is writing the cache or emitting (until its compiler
// process has started), for wait_for_emitters().
class EmitGuard {
 public:
  EmitGuard() {
    std::lock_guard<std::mutex> lock(state().emit_mu);
    ++state().emitting;
  }
  ~EmitGuard() { release(); }
  void release() {
    if (released_) return;
    released_ = true;
    std::lock_guard<std::mutex> lock(state().emit_mu);
    if (--state().emitting == 0) state().emit_cv.notify_all();
  }

 private:
  bool released_ = false;
};

// At exit: let emitter threads finish (they use the process's statics); the
// compiler processes they started run on by themselves.
void wait_for_emitters() {
  std::unique_lock<std::mutex> lock(state().emit_mu);
  state().emit_cv.wait(lock, [] { return state().emitting == 0; });
}

}  // namespace

void finish_module_emits() { wait_for_emitters(); }

namespace {

std::string emit(const Program& p, const std::string& name, bool embedded) {
  ModuleSource src;
  src.name = name;
  src.program_path = p.file.name;
  src.program_text = p.file.text;
  src.trigger = trigger_of(p);
  src.force_embedded = embedded;
  return emit_module(src);
}

// Emits and compiles the module (the embedded lowering if the specialised code
// does not compile, unless AUTUMN_STRICT_MODULES), then loads it.
ModulePtr build(std::shared_ptr<const Program> p, fs::path so, EmitGuard& guard) {
  const auto trigger = trigger_of(*p);
  const std::string tag = std::to_string(getpid()) + "-" + hex(std::hash<std::thread::id>()(std::this_thread::get_id()));
  const fs::path text = text_path(so, module_source_hash(p->file.text, trigger));
  const fs::path text_tmp = text.string() + "." + tag;
  std::ofstream(text_tmp, std::ios::binary) << p->file.text;
  std::error_code ec;
  fs::rename(text_tmp, text, ec);
  CompileOutcome c = compile_module(emit(*p, so.stem().string(), false), so, tag, [&] { guard.release(); });
  if (!c.ok && std::getenv("AUTUMN_STRICT_MODULES")) {  // the tests: a lowering bug must fail
    auto m = std::make_shared<Module>();
    m->why = "the specialised module for " + p->file.name + " did not compile:\n" + c.output;
    return m;
  }
  if (!c.ok) {
    // A specialised module that does not compile is a bug in the lowering; the
    // embedded lowering keeps the engine usable (and exact) meanwhile.
    std::cerr << "autumn: warning: the specialised module for " << p->file.name
              << " did not compile; using the embedded interpreter. Compiler output:\n"
              << c.output.substr(0, 2000) << "\n";
    EmitGuard again;
    c = compile_module(emit(*p, so.stem().string(), true), so, tag, [&] { again.release(); });
  }
  if (!c.ok) {
    auto m = std::make_shared<Module>();
    m->why = "the C++ compiler failed on the module for " + p->file.name + ":\n" + c.output;
    return m;
  }
  return load_shared(so, trigger);
}

ModuleFuture start_build(const std::shared_ptr<const Program>& p, const fs::path& so) {
  static const bool registered = [] { return std::atexit(wait_for_emitters) == 0; }();
  (void)registered;
  auto promise = std::make_shared<std::promise<ModulePtr>>();
  ModuleFuture f = promise->get_future().share();
  auto guard = std::make_shared<EmitGuard>();  // counted before the thread starts: exit may come first
  std::thread([promise, p, so, guard] {
    try {
      promise->set_value(build(p, so, *guard));
    } catch (const std::exception& e) {
      auto m = std::make_shared<Module>();
      m->why = std::string("building the module failed: ") + e.what();
      promise->set_value(m);
    }
  }).detach();
  return f;
}

const autumn_module_v1* builtin_table(uint64_t source_hash) {
  BuiltinModules builtins = builtin_modules();
  for (size_t i = 0; i < builtins.count; ++i) {
    const autumn_module_v1* t = builtins.entries[i]();
    if (t->source_hash == source_hash && t->abi_version == AUTUMN_MODULE_ABI_VERSION) return t;
  }
  return nullptr;
}

// The module of a program: at hand (ready future), or being built (*started
// says whether this call started the build).
ModuleFuture request_module(const std::shared_ptr<const Program>& p, bool* started) {
  *started = false;
  const uint64_t source_hash = module_source_hash(p->file.text, trigger_of(*p));
  CacheState& s = state();
  std::lock_guard<std::mutex> lock(s.mu);
  if (auto it = s.by_text.find(source_hash); it != s.by_text.end()) return it->second;
  if (const autumn_module_v1* t = builtin_table(source_hash))
    return s.by_text[source_hash] = ready(std::make_shared<Module>(Module{t, nullptr, p->file.text, "", false}));
  const uint64_t key = cache_key(*p);
  if (auto it = s.by_key.find(key); it != s.by_key.end()) return s.by_text[source_hash] = it->second;
  std::string why;
  const fs::path dir = usable_cache_dir(&why);
  if (dir.empty()) {
    auto m = std::make_shared<Module>();
    m->why = why;
    m->no_cache = true;
    return s.by_text[source_hash] = ready(m);
  }
  const fs::path so = dir / ("m" + hex(key) + ".so");
  std::error_code ec;
  if (fs::exists(so, ec)) {
    ModulePtr m = load_shared(so, trigger_of(*p));
    if (m->table) return s.by_text[source_hash] = s.by_key[key] = ready(m);
  }
  *started = true;
  return s.by_text[source_hash] = s.by_key[key] = start_build(p, so);
}

std::unique_ptr<Environment> instantiate(const Module& m, const Program& p) {
  auto env = std::make_unique<ModuleEnvironment>(m.table, m.handle);
  env->set_source_name(p.file.name);
  if (m.built_from != p.file.text) {
    auto map = std::make_shared<const LocationMap>(m.built_from, p.file.text);
    env->set_error_rewriter(std::make_shared<const ModuleEnvironment::ErrorRewriter>(
        [map, path = p.file.name](const std::string& e) { return map->rewrite(e, path); }));
  }
  return env;
}

std::unique_ptr<Environment> from_module(const Module& m, std::shared_ptr<const Program> p, std::string* why) {
  if (m.table) return instantiate(m, *p);
  if (m.no_cache) {
    std::cerr << "autumn: warning: " << m.why << "; running " << p->file.name << " on the interpreter\n";
    return std::make_unique<InterpretedEnvironment>(std::move(p));
  }
  if (why) *why = m.why;
  return nullptr;
}

}  // namespace

std::unique_ptr<Environment> make_compiled_environment(std::shared_ptr<const Program> program, std::string* why) {
  double seconds = 0;
  std::string reason;
  prepare_compiled_module(program, &seconds, &reason);  // says "compiling ..." when it has to wait
  bool started = false;
  ModulePtr m = request_module(program, &started).get();
  return from_module(*m, std::move(program), why);
}

bool prepare_compiled_module(const std::shared_ptr<const Program>& program, double* seconds, std::string* why) {
  *seconds = 0;
  bool started = false;
  ModuleFuture f = request_module(program, &started);
  const auto t0 = std::chrono::steady_clock::now();
  if (f.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    if (started) std::cerr << "autumn: compiling " << program->file.name << " (first use)\n";
    f.wait();
    *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (started && f.get()->table)
      std::cerr << "autumn: compiled " << program->file.name << " in " << std::fixed << std::setprecision(1)
                << *seconds << " s\n";
  }
  if (!f.get()->table && why) *why = f.get()->why;
  return f.get()->table != nullptr;
}

std::unique_ptr<Environment> make_compiled_episode_environment(std::shared_ptr<const Program> program,
                                                               std::string* why) {
  bool started = false;
  ModuleFuture f = request_module(program, &started);
  if (f.wait_for(std::chrono::seconds(0)) == std::future_status::ready) return from_module(*f.get(), program, why);
  if (started)
    std::cerr << "autumn: compiling " << program->file.name << " (first use); the interpreter runs meanwhile\n";
  CompiledSource source = [f, program](std::string* never) -> std::unique_ptr<Environment> {
    if (f.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return nullptr;
    if (!f.get()->table) {
      *never = f.get()->why;
      return nullptr;
    }
    return instantiate(*f.get(), *program);
  };
  return std::make_unique<WarmingEnvironment>(program, std::move(source));
}

}  // namespace autumn
