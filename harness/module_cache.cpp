// module_cache — lookup order, keys and builds of the compiled engine's modules
// (module_cache.hpp); the store's checks are harness/module_store's.
#include "harness/module_cache.hpp"

#include <dlfcn.h>
#include <fmt/core.h>
#include <sys/stat.h>
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
#include "harness/digest.hpp"
#include "harness/module_build.hpp"
#include "harness/module_config.hpp"  // generated: build/config/
#include "harness/module_key.hpp"
#include "harness/module_store.hpp"
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
  bool built_elsewhere = false;  // another process built it while this one waited (EntryLock)
};
using ModulePtr = std::shared_ptr<const Module>;
using ModuleFuture = std::shared_future<ModulePtr>;

// Process-wide and never destroyed: a compile thread may still be waiting for
// its compiler when the process exits.
struct CacheState {
  std::mutex mu;
  std::unordered_map<std::string, ModuleFuture> by_text;  // program_digest of the exact text
  std::unordered_map<std::string, ModuleFuture> by_key;   // cache key
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

// ---------------------------------------------------------------------------- keys

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The compiler, its flags, the libraries a module links, the lowering that wrote
// it (autumn_emit) and the runtime headers it includes all decide what a cached
// module contains; a rebuilt library changes its size or time stamp, an edited
// header its text. The lowering is the one linked into this binary, named by
// its digest (generated at build time): the archive on disk may be newer than
// the binary after a partial rebuild, and a key from it filed the old
// lowering's modules under the new one's name. Computed once per process.
const std::string& key_salt() {
  static const std::string salt = [] {
    std::string s = module_compiler_signature() + " abi " + std::to_string(AUTUMN_MODULE_ABI_VERSION);
    s += std::string(" lowering ") + linked_emit_digest();
    std::istringstream libs(AUTUMN_MODULE_LIBS);
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
    for (const auto& h : headers) s += " " + h.filename().string() + ":" + sha256_hex(read_text(h));
    return s;
  }();
  return salt;
}

// The SHA-256 of the salt and the program's canonical form (its exact text when
// it does not read): the module's file name.
std::string cache_key(const std::string& text, const std::optional<std::string>& trigger) {
  Sha256 d;
  d.piece("autumn module key v2");
  d.piece(key_salt());
  const auto canonical = canonical_program_hash(text, trigger);
  d.piece(canonical ? "canonical " + *canonical : "exact " + program_digest(text, trigger));
  return d.hex();
}

std::string hex(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// ---------------------------------------------------------------------------- loading

// The files of one cache entry: mKEY.so, mKEY.manifest, and the program text it
// was built from, mKEY-PROGRAMDIGEST.au.
struct Entry {
  fs::path so;
  std::string key;
  fs::path manifest() const { return store::manifest_path(so); }
  fs::path text(const std::string& program) const {
    return so.parent_path() / (so.stem().string() + "-" + program + ".au");
  }
};

ModulePtr refused(const std::string& why) {
  auto m = std::make_shared<Module>();
  m->why = why;
  return m;
}

// Checks the manifest and the program text against the program being run: the
// module must have been built for this program (the same canonical form) by
// this ABI. "" or the reason.
std::string check_origin(const Entry& e, const std::optional<std::string>& trigger, store::Manifest* mf,
                         std::string* built_from) {
  std::string text;
  if (std::string w = store::read_private_file(e.manifest(), 4096, &text); !w.empty()) return w;
  auto parsed = store::parse_manifest(text);
  if (!parsed) return e.manifest().string() + ": not a module manifest";
  *mf = *parsed;
  if (mf->abi != AUTUMN_MODULE_ABI_VERSION) return "built for ABI version " + std::to_string(mf->abi);
  if (std::string w = store::read_private_file(e.text(mf->program), 64 << 20, built_from); !w.empty()) return w;
  if (program_digest(*built_from, trigger) != mf->program) return "its program text does not match the manifest";
  if (cache_key(*built_from, trigger) != e.key) return "it was built for another program";
  return "";
}

// A module's bytes against its manifest ("" or why not): every cache entry read
// and every module shipped from another node (install_module) passes this.
std::string verify_module_bytes(const std::string& bytes, const store::Manifest& mf) {
  if (sha256_hex(bytes) != mf.so) return "its bytes do not match the digest in its manifest (truncated or changed)";
  if (bytes.size() < 4 || bytes.compare(0, 4, "\x7f" "ELF") != 0) return "not an ELF shared library";
  return "";
}

// Reads the module's bytes and checks them against the manifest ("" or why not).
std::string read_verified(const Entry& e, const store::Manifest& mf, std::string* bytes) {
  if (std::string w = store::read_private_file(e.so, size_t(1) << 30, bytes); !w.empty()) return w;
  return verify_module_bytes(*bytes, mf);
}

// The module of a verified entry, checked once more through its own table.
ModulePtr open_module(const Entry& e, const std::string& bytes, std::string built_from,
                      const std::optional<std::string>& trigger) {
  auto m = std::make_shared<Module>();
  m->handle = store::load_from_memory(bytes, "autumn-m" + e.key.substr(0, 16), &m->why);
  if (!m->handle) return m;
  auto entry = reinterpret_cast<autumn_module_entry_fn>(dlsym(m->handle.get(), "autumn_module_v1_entry"));
  if (!entry) return refused("compiled module " + e.so.string() + " has no autumn_module_v1_entry");
  const autumn_module_v1* table = entry();
  if (table->abi_version != AUTUMN_MODULE_ABI_VERSION)
    return refused("compiled module " + e.so.string() + " has ABI version " + std::to_string(table->abi_version) +
                   ", expected " + std::to_string(AUTUMN_MODULE_ABI_VERSION));
  if (table->source_hash != module_source_hash(built_from, trigger))
    return refused("compiled module " + e.so.string() + " was not built from the program text beside it");
  m->table = table;
  m->built_from = std::move(built_from);
  return m;
}

// Loads a cache entry only after checking it: the module for this program, or
// why it was refused.
ModulePtr load_entry(const Entry& e, const std::optional<std::string>& trigger) {
  store::Manifest mf;
  std::string built_from, bytes;
  if (std::string w = check_origin(e, trigger, &mf, &built_from); !w.empty()) return refused(w);
  if (std::string w = read_verified(e, mf, &bytes); !w.empty()) return refused(w);
  return open_module(e, bytes, std::move(built_from), trigger);
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
// does not compile, unless AUTUMN_STRICT_MODULES); the outcome of the last compile.
CompileOutcome compile_both_ways(const Program& p, const Entry& e, const std::string& tag, const std::string& head,
                                 EmitGuard& guard) {
  const std::string name = e.so.stem().string();
  CompileOutcome c = compile_module(emit(p, name, false), e.so, tag, head, [&] { guard.release(); });
  if (c.ok || !c.store_error.empty() || std::getenv("AUTUMN_STRICT_MODULES")) return c;  // strict: the tests
  // A specialised module that does not compile is a bug in the lowering; the
  // embedded lowering keeps the engine usable (and exact) meanwhile.
  std::cerr << "autumn: warning: the specialised module for " << p.file.name
            << " did not compile; using the embedded interpreter. Compiler output:\n"
            << c.output.substr(0, 2000) << "\n";
  EmitGuard again;
  c = compile_module(emit(p, name, true), e.so, tag, head, [&] { again.release(); });
  return c;
}

// Writes the program text beside the entry, compiles, then loads the entry
// through the same checks as any other. The compile script holds the entry's
// lock (module_build): when another process was building it, its build is used.
ModulePtr build(std::shared_ptr<const Program> p, Entry e, EmitGuard& guard) {
  const auto trigger = trigger_of(*p);
  const std::string tag = std::to_string(getpid()) + "-" + hex(std::hash<std::thread::id>()(std::this_thread::get_id()));
  const std::string program = program_digest(p->file.text, trigger);
  if (std::string w = store::publish_file(e.text(program), p->file.text, tag); !w.empty())
    return refused("cannot build the module for " + p->file.name + ": " + w);
  const CompileOutcome c =
      compile_both_ways(*p, e, tag, store::manifest_head(AUTUMN_MODULE_ABI_VERSION, program), guard);
  if (!c.store_error.empty()) return refused("cannot build the module for " + p->file.name + ": " + c.store_error);
  if (!c.ok && std::getenv("AUTUMN_STRICT_MODULES"))
    return refused("the specialised module for " + p->file.name + " did not compile:\n" + c.output);
  if (!c.ok) return refused("the C++ compiler failed on the module for " + p->file.name + ":\n" + c.output);
  if (c.built_elsewhere) {  // another process built it while this one waited for the entry
    ModulePtr theirs = load_entry(e, trigger);
    if (!theirs->table) return refused("the module another process built for " + p->file.name + " was refused: " + theirs->why);
    auto m = std::make_shared<Module>(*theirs);
    m->built_elsewhere = true;
    return m;
  }
  return load_entry(e, trigger);
}

ModuleFuture start_build(const std::shared_ptr<const Program>& p, const Entry& e) {
  static const bool registered = [] { return std::atexit(wait_for_emitters) == 0; }();
  (void)registered;
  auto promise = std::make_shared<std::promise<ModulePtr>>();
  ModuleFuture f = promise->get_future().share();
  auto guard = std::make_shared<EmitGuard>();  // counted before the thread starts: exit may come first
  std::thread([promise, p, e, guard] {
    try {
      promise->set_value(build(p, e, *guard));
    } catch (const std::exception& ex) {
      auto m = std::make_shared<Module>();
      m->why = std::string("building the module failed: ") + ex.what();
      promise->set_value(m);
    }
  }).detach();
  return f;
}

// A module built into this binary, matched on the program's full text (and no
// trigger), not on a hash alone.
const autumn_module_v1* builtin_table(const Program& p) {
  if (trigger_of(p)) return nullptr;
  BuiltinModules builtins = builtin_modules();
  for (size_t i = 0; i < builtins.count; ++i) {
    if (builtins.texts[i] != p.file.text) continue;
    const autumn_module_v1* t = builtins.entries[i]();
    if (t->source_hash == module_source_hash(p.file.text, std::nullopt) && t->abi_version == AUTUMN_MODULE_ABI_VERSION)
      return t;
  }
  return nullptr;
}

// The cached module of a program when its entry exists and passes every check;
// null when there is none. A refused entry is named on stderr (it is rebuilt).
ModulePtr cached_module(const Entry& e, const Program& p) {
  struct stat st;
  if (lstat(e.so.c_str(), &st) != 0) return nullptr;
  ModulePtr m = load_entry(e, trigger_of(p));
  if (m->table) return m;
  std::cerr << ("autumn: cache entry " + e.so.string() + " refused (" + m->why + "); rebuilding\n");
  return nullptr;
}

ModuleFuture no_cache(const std::string& why) {
  auto m = std::make_shared<Module>();
  m->why = why;
  m->no_cache = true;
  return ready(m);
}

// What this process knows of a program's module without building it: the
// future it already holds (by the program's exact text, then by cache key), a
// built-in module, a store entry that passes every check, or no store at all
// (a ready future saying why). `found` is empty when the module must be built,
// into `entry`. Called with the cache's mutex held; what it finds is remembered.
struct Lookup {
  std::optional<ModuleFuture> found;
  Entry entry;
  std::string exact;  // the program's exact digest (program_digest)
};
Lookup look_up(CacheState& s, const std::shared_ptr<const Program>& p) {
  const auto trigger = trigger_of(*p);
  const std::string exact = program_digest(p->file.text, trigger);
  if (auto it = s.by_text.find(exact); it != s.by_text.end()) return {it->second, {}};
  if (const autumn_module_v1* t = builtin_table(*p))
    return {s.by_text[exact] = ready(std::make_shared<Module>(Module{t, nullptr, p->file.text, "", false})), {}};
  const std::string key = cache_key(p->file.text, trigger);
  if (auto it = s.by_key.find(key); it != s.by_key.end()) return {s.by_text[exact] = it->second, {}};
  std::string why;
  const fs::path dir = store::cache_dir(&why);
  if (dir.empty()) return {s.by_text[exact] = no_cache(why), {}};
  const Entry e{dir / ("m" + key + ".so"), key};
  if (ModulePtr m = cached_module(e, *p)) return {s.by_text[exact] = s.by_key[key] = ready(m), {}};
  return {std::nullopt, e, exact};  // not remembered: a module installed later (install_module) is then found
}

// The module of a program: at hand (ready future), or being built (*started
// says whether this call started the build).
ModuleFuture request_module(const std::shared_ptr<const Program>& p, bool* started) {
  *started = false;
  CacheState& s = state();
  std::lock_guard<std::mutex> lock(s.mu);
  Lookup l = look_up(s, p);
  if (l.found) return *l.found;
  if (compiling_forbidden())
    return ready(refused("no module for " + p->file.name +
                         " on this node, which does not compile (AUTUMN_NO_COMPILE is set); ship it from a node "
                         "that does (autumnc.distributed) or unset the variable"));
  *started = true;
  return s.by_text[l.exact] = s.by_key[l.entry.key] = start_build(p, l.entry);
}

std::unique_ptr<Environment> instantiate(const Module& m, const Program& p) {
  auto env = std::make_unique<ModuleEnvironment>(m.table, m.handle);
  env->set_source_name(p.file.name);
  if (m.built_from != p.file.text) env->set_relocation(relocation_between(m.built_from, p.file.text));
  return env;
}

std::unique_ptr<Environment> from_module(const Module& m, std::shared_ptr<const Program> p, std::string* why) {
  if (m.table) return instantiate(m, *p);
  if (m.no_cache) {
    std::cerr << ("autumn: warning: " + m.why + "; running " + p->file.name + " on the interpreter\n");
    return std::make_unique<InterpretedEnvironment>(std::move(p));
  }
  if (why) *why = m.why;
  return nullptr;
}

bool usable(const ModuleFuture& f) {
  return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready && f.get()->table;
}

}  // namespace

bool compiling_forbidden() {
  const char* v = std::getenv("AUTUMN_NO_COMPILE");
  return v && *v && std::string(v) != "0";
}

bool module_at_hand(const std::shared_ptr<const Program>& p) {
  CacheState& s = state();
  std::lock_guard<std::mutex> lock(s.mu);
  Lookup l = look_up(s, p);
  return l.found && usable(*l.found);
}

bool package_module(const std::shared_ptr<const Program>& p, ModulePackage* out, std::string* why) {
  double seconds = 0;
  if (!prepare_compiled_module(p, &seconds, why)) return false;
  bool started = false;
  ModulePtr m = request_module(p, &started).get();
  *out = ModulePackage{};
  if (!m->handle) {  // built into the binary: every node has it
    out->builtin = true;
    return true;
  }
  const auto trigger = trigger_of(*p);
  const fs::path dir = store::cache_dir(why);
  if (dir.empty()) return false;
  const std::string key = cache_key(p->file.text, trigger);
  const Entry e{dir / ("m" + key + ".so"), key};
  store::Manifest mf;
  std::string w = check_origin(e, trigger, &mf, &out->built_from);
  if (w.empty()) w = read_verified(e, mf, &out->so);
  if (w.empty()) w = store::read_private_file(e.manifest(), 4096, &out->manifest);
  if (!w.empty()) {
    *why = "cannot package " + e.so.string() + ": " + w;
    return false;
  }
  out->key = key;
  return true;
}

std::string install_module(const std::shared_ptr<const Program>& p, const std::string& so, const std::string& manifest,
                           const std::string& built_from) {
  const auto trigger = trigger_of(*p);
  const auto mf = store::parse_manifest(manifest);
  if (!mf) return "its manifest is not a module manifest";
  if (mf->abi != AUTUMN_MODULE_ABI_VERSION)
    return "built for ABI version " + std::to_string(mf->abi) + ", this node has " +
           std::to_string(AUTUMN_MODULE_ABI_VERSION);
  if (std::string w = verify_module_bytes(so, *mf); !w.empty()) return w;
  const std::string key = cache_key(p->file.text, trigger);
  if (cache_key(built_from, trigger) != key) return "it was built for another program";
  std::string why;
  const fs::path dir = store::cache_dir(&why);
  if (dir.empty()) return why;
  const Entry e{dir / ("m" + key + ".so"), key};
  const std::string tag = std::to_string(getpid()) + "-install";
  for (const auto& [path, bytes] : {std::pair<fs::path, const std::string*>{e.text(mf->program), &built_from},
                                    {e.so, &so},
                                    {e.manifest(), &manifest}})
    if (std::string w = store::publish_file(path, *bytes, tag); !w.empty()) return w;
  ModulePtr m = load_entry(e, trigger);  // the checks of any cache entry, on the files just written
  if (!m->table) {
    std::error_code ec;
    fs::remove(e.manifest(), ec);
    fs::remove(e.so, ec);
    return m->why;
  }
  CacheState& s = state();
  std::lock_guard<std::mutex> lock(s.mu);
  s.by_text[program_digest(p->file.text, trigger)] = s.by_key[key] = ready(m);
  return "";
}

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
    if (started) std::cerr << ("autumn: compiling " + program->file.name + " (first use)\n");  // one write
    f.wait();
    *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (started && f.get()->table)
      std::cerr << ("autumn: " + std::string(f.get()->built_elsewhere ? "another process compiled " : "compiled ") +
                    program->file.name + " in " + fmt::format("{:.1f}", *seconds) + " s\n");
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
    std::cerr << ("autumn: compiling " + program->file.name + " (first use); the interpreter runs meanwhile\n");
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
