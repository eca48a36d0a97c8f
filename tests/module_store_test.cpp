// module_store_test — the module cache trusts nothing it loads (harness/module_store).
//
// Each case runs the autumn CLI with AUTUMN_CACHE_DIR (and TMPDIR, where the
// private fallback cache goes) inside a fresh scratch directory. Compiles cost
// a second or two each, so the suite compiles two tiny 5x5 programs once per
// run (in the run's shared cache, AUTUMN_CACHE_DIR, when ctest gives one: ctest
// runs every case in a process of its own), copies their entries into a pristine
// cache, and every case tampers with its own copy of that cache; only
// the cases that must rebuild compile again (through `difftest`, which waits for
// the module and compares it with the interpreter, so another program's module
// would show as a divergence).
#include <dlfcn.h>
#include <fcntl.h>
#include <sys/file.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "compiler/emit/emit_module.hpp"
#include "harness/digest.hpp"
#include "harness/module_build.hpp"
#include "harness/module_config.hpp"  // generated: build/config/ (AUTUMN_CLANG_PLUGIN)
#include "harness/module_cache.hpp"
#include "harness/module_store.hpp"
#include "test_support.hpp"

namespace module_store_test {
namespace {

namespace fs = std::filesystem;
using autumn::testing::run_cli;

const char kProgramA[] = R"((program
  (= GRID_SIZE 5)
  (object Dot (Cell 0 0 "blue"))
  (: dot Dot)
  (= dot (initnext (Dot (Position 1 1)) (prev dot)))
  (on left (= dot (moveLeftNoCollision (prev dot))))
  (on right (= dot (moveRightNoCollision (prev dot)))))
)";

const char kProgramB[] = R"((program
  (= GRID_SIZE 5)
  (object Bar (list (Cell 0 0 "red") (Cell 1 0 "red")))
  (: bar Bar)
  (= bar (initnext (Bar (Position 2 3)) (prev bar)))
  (on left (= bar (moveLeftNoCollision (prev bar))))
  (on up (= bar (moveUpNoCollision (prev bar)))))
)";

fs::path root() { return fs::temp_directory_path() / ("autumn_module_store_test_" + std::to_string(getpid())); }
// The per-process directory goes when the process ends, if its cases removed
// what they made (a failed case's files stay, to be read).
struct RemoveRootIfEmpty {
  ~RemoveRootIfEmpty() {
    std::error_code ec;
    fs::remove(root() / "pristine", ec);
    fs::remove(root(), ec);
  }
} remove_root_if_empty;
fs::path pristine() { return root() / "pristine"; }
std::string program(const char* name) { return (root() / name).string(); }

std::string env_for(const fs::path& cache, const fs::path& tmp) {
  return "AUTUMN_CACHE_DIR=" + cache.string() + " TMPDIR=" + tmp.string();
}

// The entry of the program whose text is `text`: "<cache>/m<key>" (its .so, its
// .manifest and its program text m<key>-<digest>.au).
// In a long-lived shared cache the same text may also have entries under the
// keys of earlier builds (another runtime): the newest module is this build's.
fs::path entry_of(const fs::path& cache, const std::string& text) {
  fs::path best;
  fs::file_time_type newest{};
  for (const auto& f : autumn::testing::files_in(cache, ".au")) {
    if (autumn::testing::read_text(f) != text) continue;
    const std::string stem = f.stem().string();
    const fs::path entry = cache / stem.substr(0, stem.find('-'));
    std::error_code ec;
    const auto made = fs::last_write_time(entry.string() + ".so", ec);
    if (!ec && (best.empty() || made > newest)) best = entry, newest = made;
  }
  return best;
}

fs::path with(const fs::path& entry, const std::string& suffix) { return entry.string() + suffix; }

// The cache the store compiled A and B into: the run's shared cache under
// ctest, else the pristine cache itself.
fs::path built_in() {
  const char* shared = std::getenv("AUTUMN_CACHE_DIR");
  return shared && *shared ? fs::path(shared) : pristine();
}

// The three files of the entry `entry` ("<cache>/m<key>"): module, manifest, program text.
std::vector<fs::path> files_of(const fs::path& entry) {
  std::vector<fs::path> out = {with(entry, ".so"), with(entry, ".manifest")};
  for (const auto& f : autumn::testing::files_in(entry.parent_path(), ".au"))
    if (f.string().starts_with(entry.string() + "-")) out.push_back(f);
  return out;
}

class ModuleStore : public ::testing::Test {
 protected:
  // Compiles A and B (once per run where the run shares a cache), and puts
  // their entries in the pristine cache.
  static void SetUpTestSuite() {
    fs::remove_all(root());
    fs::create_directories(root() / "tmp");
    std::ofstream(root() / "a.au") << kProgramA;
    std::ofstream(root() / "b.au") << kProgramB;
    for (const char* p : {"a.au", "b.au"}) {
      auto r = run_cli("difftest " + program(p) + " --seeds 1 --steps 3", false, env_for(built_in(), root() / "tmp"));
      ASSERT_EQ(r.status, 0) << r.out;
    }
    if (built_in() == pristine()) return;
    fs::create_directories(pristine());
    ASSERT_EQ(chmod(pristine().c_str(), 0700), 0);
    for (const char* text : {kProgramA, kProgramB}) {
      const fs::path entry = entry_of(built_in(), text);
      ASSERT_FALSE(entry.empty()) << "no entry in " << built_in();
      for (const fs::path& f : files_of(entry)) fs::copy_file(f, pristine() / f.filename());  // modes kept
    }
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(root(), ec);
  }

  // A copy of the pristine cache (modes kept) at <case>/cache, and <case>/tmp.
  fs::path fresh(const std::string& name) {
    const fs::path dir = root() / name;
    fs::create_directories(dir / "tmp");
    fs::copy(pristine(), dir / "cache", fs::copy_options::recursive);
    return dir;
  }

  // `run` of A on both engines prints the same frames.
  static void expect_frames_of_a(const std::string& env) {
    const std::string run = "run " + program("a.au") + " --actions right,left,left";
    auto compiled = run_cli(run + " --engine compiled", true, env);
    auto interp = run_cli(run + " --engine interp", true);
    EXPECT_EQ(compiled.status, 0);
    EXPECT_EQ(compiled.out, interp.out);
  }

  // A tampered entry of A: refused with `reason` on one line, rebuilt, no signal;
  // afterwards the entry loads without a word.
  static void expect_rebuilt(const fs::path& dir, const fs::path& so, const std::string& reason) {
    const std::string env = env_for(dir / "cache", dir / "tmp");
    auto r = run_cli("difftest " + program("a.au") + " --seeds 1 --steps 3", false, env);
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("0 programs failed"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("autumn: cache entry " + so.string() + " refused ("),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(reason), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("); rebuilding\n"), std::string::npos) << r.out;
    auto again = run_cli("run " + program("a.au") + " --engine compiled --steps 1", false, env);
    EXPECT_EQ(again.status, 0) << again.out;
    EXPECT_EQ(again.out.find("autumn:"), std::string::npos) << again.out;
    expect_frames_of_a(env);
  }

  // An unsafe cache directory is refused; the private fallback under TMPDIR
  // (holding a copy of the pristine cache) serves A without a compile.
  static void expect_refused(const fs::path& dir, const fs::path& unsafe, const std::string& reason) {
    const fs::path fallback = dir / "tmp" / ("autumnc-cache-" + std::to_string(geteuid()));
    fs::copy(pristine(), fallback, fs::copy_options::recursive);
    const std::string env = env_for(unsafe, dir / "tmp");
    auto r = run_cli("run " + program("a.au") + " --engine compiled --steps 1", false, env);
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("autumn: warning: refusing the module cache " + unsafe.string() + " (" + reason +
                         "); using " + fallback.string() + "\n"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("compiling"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::is_empty(unsafe)) << "nothing is written into a refused directory";
    expect_frames_of_a(env);
  }
};

mode_t mode_of(const fs::path& p) {
  struct stat st;
  EXPECT_EQ(lstat(p.c_str(), &st), 0) << p;
  return st.st_mode & 07777;
}

// As the store made them (in the cache A and B were compiled into).
TEST_F(ModuleStore, DirectoriesAre0700AndFiles0600) {
  EXPECT_EQ(mode_of(built_in()), 0700u);
  for (const char* text : {kProgramA, kProgramB}) {
    const fs::path entry = entry_of(built_in(), text);
    ASSERT_FALSE(entry.empty());
    const auto files = files_of(entry);
    EXPECT_EQ(files.size(), 3u) << "per program: the module, its manifest and its program text";
    for (const fs::path& f : files) EXPECT_EQ(mode_of(f), 0600u) << f;
  }
}

TEST_F(ModuleStore, WorldWritableDirectoryRefused) {
  const fs::path dir = fresh("world_writable"), shared = dir / "shared";
  fs::create_directories(shared);
  ASSERT_EQ(chmod(shared.c_str(), 0777), 0);
  expect_refused(dir, shared, "writable by other users (mode 0777)");
}

TEST_F(ModuleStore, DirectoryOfAnotherUserRefused) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to give a directory to uid 65534";
  const fs::path dir = fresh("other_user"), theirs = dir / "theirs";
  fs::create_directories(theirs);
  ASSERT_EQ(chmod(theirs.c_str(), 0700), 0);
  ASSERT_EQ(chown(theirs.c_str(), 65534, 65534), 0);
  expect_refused(dir, theirs, "owned by uid 65534, not by this user (uid 0)");
}

TEST_F(ModuleStore, SymlinkedModuleNotFollowed) {
  const fs::path dir = fresh("symlink");
  const fs::path so = with(entry_of(dir / "cache", kProgramA), ".so"), elsewhere = dir / "elsewhere.so";
  fs::rename(so, elsewhere);
  fs::create_symlink(elsewhere, so);
  const std::string before = autumn::testing::read_text(elsewhere);
  expect_rebuilt(dir, so, "a symbolic link (not followed)");
  EXPECT_FALSE(fs::is_symlink(so));
  EXPECT_EQ(autumn::testing::read_text(elsewhere), before) << "the link's target is left alone";
}

TEST_F(ModuleStore, ModuleOfAnotherProgramRefused) {
  const fs::path dir = fresh("other_program"), cache = dir / "cache";
  const fs::path a = entry_of(cache, kProgramA), b = entry_of(cache, kProgramB);
  // B's module, manifest and program text, under A's key.
  for (const char* suffix : {".so", ".manifest"}) fs::copy_file(with(b, suffix), with(a, suffix), fs::copy_options::overwrite_existing);
  for (const auto& f : autumn::testing::files_in(cache, ".au"))
    if (f.string().starts_with(b.string() + "-"))
      fs::copy_file(f, a.string() + f.string().substr(b.string().size()));
  expect_rebuilt(dir, with(a, ".so"), "it was built for another program");
}

TEST_F(ModuleStore, TruncatedModuleRebuilt) {
  const fs::path dir = fresh("truncated");
  const fs::path so = with(entry_of(dir / "cache", kProgramA), ".so");
  fs::resize_file(so, fs::file_size(so) / 2);
  expect_rebuilt(dir, so, "do not match the digest in its manifest");
}

TEST_F(ModuleStore, CorruptModuleRebuilt) {
  const fs::path dir = fresh("corrupt");
  const fs::path so = with(entry_of(dir / "cache", kProgramA), ".so");
  std::string bytes = autumn::testing::read_text(so);
  bytes[bytes.size() / 2] ^= 0x5a;
  std::ofstream(so, std::ios::binary | std::ios::trunc) << bytes;
  expect_rebuilt(dir, so, "do not match the digest in its manifest");
}

// In one process: A's module loaded (and kept), then B's from a new memory file
// that may get the descriptor number A was loaded from; B must be B, not A's
// handle again.
TEST_F(ModuleStore, EveryLoadIsANewLibrary) {
  const autumn_module_v1* tables[2] = {nullptr, nullptr};
  std::shared_ptr<void> handles[2];
  const char* texts[2] = {kProgramA, kProgramB};
  for (int i = 0; i < 2; ++i) {
    std::string why;
    handles[i] = autumn::store::load_from_memory(
        autumn::testing::read_text(with(entry_of(pristine(), texts[i]), ".so")), "test", &why);
    ASSERT_TRUE(handles[i]) << why;
    auto entry = reinterpret_cast<autumn_module_entry_fn>(dlsym(handles[i].get(), "autumn_module_v1_entry"));
    ASSERT_TRUE(entry);
    tables[i] = entry();
    EXPECT_EQ(tables[i]->source_hash, autumn::module_source_hash(texts[i], std::nullopt));
  }
  EXPECT_NE(handles[0].get(), handles[1].get());
}

TEST_F(ModuleStore, StaleTemporariesCleaned) {
  const fs::path dir = fresh("stale"), cache = dir / "cache";
  const auto hours_ago = fs::file_time_type::clock::now() - std::chrono::hours(2);
  for (const char* name : {"m1.9-1.cpp", "m1.9-1.log", "m1.9-1.so.part", "probe.abc123", "m2.9-1.cpp"}) {
    std::ofstream(cache / name) << "left by a killed compile";
    if (std::string(name) != "m2.9-1.cpp") fs::last_write_time(cache / name, hours_ago);
  }
  auto r = run_cli("run " + program("a.au") + " --engine compiled --steps 1", false, env_for(cache, dir / "tmp"));
  EXPECT_EQ(r.status, 0) << r.out;
  for (const char* name : {"m1.9-1.cpp", "m1.9-1.log", "m1.9-1.so.part", "probe.abc123"})
    EXPECT_FALSE(fs::exists(cache / name)) << name;
  EXPECT_TRUE(fs::exists(cache / "m2.9-1.cpp")) << "a compile may still be writing a recent one";
}

TEST_F(ModuleStore, FullDiskIsNamed) {
  const fs::path full = root() / "full";
  fs::create_directories(full);
  if (geteuid() != 0 || std::system(("mount -t tmpfs -o size=48k tmpfs " + full.string() + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "needs root and a tmpfs mount for a full disk";
  auto r = run_cli("difftest " + program("a.au") + " --seeds 1 --steps 3", false, env_for(full / "cache", root() / "tmp"));
  EXPECT_EQ(std::system(("umount " + full.string()).c_str()), 0);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("cannot write in " + (full / "cache").string() + ": No space left on device"), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("did not compile"), std::string::npos) << r.out;
}

// Processes sharing a cache build each module once (EntryLock): two processes
// asking at once for a module nobody has built, one compiles it and the other
// waits for that build and uses it.
TEST(ModuleBuild, TwoProcessesCompileAModuleOnce) {
  const fs::path dir = root() / "once";
  fs::remove_all(dir);
  fs::create_directories(dir / "cache");
  fs::create_directories(dir / "tmp");
  ASSERT_EQ(chmod((dir / "cache").c_str(), 0700), 0);
  // A program no cache has seen: its string literal names this run.
  const std::string text = "(program\n  (= tag \"" + std::to_string(getpid()) + "-" + std::to_string(time(nullptr)) +
                           "\")" + std::string(kProgramA).substr(std::string("(program").size());
  std::ofstream(dir / "once.au") << text;
  const std::string args = "bench " + (dir / "once.au").string() + " --only compiled --steps 3";
  autumn::testing::CliResult out[2];
  std::thread second([&] { out[1] = run_cli(args, false, env_for(dir / "cache", dir / "tmp")); });
  out[0] = run_cli(args, false, env_for(dir / "cache", dir / "tmp"));
  second.join();
  int compiled = 0, waited = 0;
  for (const auto& r : out) {
    ASSERT_EQ(r.status, 0) << r.out;
    compiled += r.out.find("autumn: compiled ") != std::string::npos;
    waited += r.out.find("autumn: another process compiled ") != std::string::npos;
  }
  EXPECT_EQ(compiled, 1) << out[0].out << "\n---\n" << out[1].out;
  EXPECT_EQ(waited, 1) << out[0].out << "\n---\n" << out[1].out;
  EXPECT_EQ(autumn::testing::files_in(dir / "cache", ".so").size(), 1u);
  fs::remove_all(dir);
}

// `dir` made afresh, empty and private to this user, as a module cache must be.
bool fresh_private_dir(const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  return chmod(dir.c_str(), 0700) == 0;
}

// Locks every compile slot of `cache`, as compiles running there would; the
// descriptors (closing one frees its slot). Stops at the first that fails.
std::vector<int> hold_every_slot(const fs::path& cache) {
  std::vector<int> held;
  for (int k = 0; k < autumn::module_compile_slots(); ++k) {
    const std::string slot = (cache / ("compile-slot." + std::to_string(k))).string();
    const int fd = open(slot.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0600);
    if (fd < 0 || flock(fd, LOCK_EX) != 0) {
      ADD_FAILURE() << "cannot lock " << slot << ": " << std::strerror(errno);
      break;
    }
    held.push_back(fd);
  }
  return held;
}

// However many compiles are asked for, at most module_compile_slots() run at
// once per cache: each takes a lock on one of the cache's compile-slot files
// first. With every slot held here, a compile waits; once they are free, it runs.
TEST(ModuleBuild, ACompileWaitsForAFreeSlot) {
  const fs::path cache = root() / "slots";
  ASSERT_TRUE(fresh_private_dir(cache));
  const std::vector<int> held = hold_every_slot(cache);
  ASSERT_EQ(held.size(), static_cast<size_t>(autumn::module_compile_slots()));
  const fs::path so = cache / "mslot.so";
  std::atomic<bool> done{false};
  autumn::CompileOutcome outcome;
  std::thread compile([&] {
    outcome = autumn::compile_module("extern \"C\" int autumn_slot_test() { return 7; }\n", so, "t",
                                     "autumn module manifest v1\n", [] {});
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::seconds(3));  // a compile of this file takes well under a second
  EXPECT_FALSE(done) << "the compile ran with every slot taken";
  EXPECT_FALSE(fs::exists(so));
  for (int fd : held) close(fd);
  compile.join();
  EXPECT_TRUE(outcome.ok) << outcome.output;
  EXPECT_TRUE(fs::exists(so));
  fs::remove_all(cache);
}

// A compile queued behind every slot, whose module another process builds
// meanwhile (here the test writes the library and its manifest, as that process
// would), finds it when it gets a slot and does not compile it again: the
// entry is free by then, and the check after taking it is what stops it.
// Before, only a compile that had waited for the entry itself looked: the
// release suite built modules a second time when two tests asked for one.
TEST(ModuleBuild, ACompileQueuedOnASlotFindsTheModuleBuilt) {
  const fs::path cache = root() / "queued";
  ASSERT_TRUE(fresh_private_dir(cache));
  const std::vector<int> held = hold_every_slot(cache);
  ASSERT_EQ(held.size(), static_cast<size_t>(autumn::module_compile_slots()));
  const fs::path so = cache / "mqueued.so";
  std::atomic<bool> started{false};
  autumn::CompileOutcome outcome;
  std::thread compile([&] {
    outcome = autumn::compile_module("extern \"C\" int autumn_queued_test() { return 7; }\n", so, "t",
                                     "autumn module manifest v1\n", [&] { started = true; });
  });
  while (!started) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // its source file is older than what follows
  const std::string built = "what the other process built";
  std::ofstream(autumn::store::manifest_path(so)) << "autumn module manifest v1\nso other\n";
  std::ofstream(so) << built;
  for (int fd : held) close(fd);
  compile.join();
  EXPECT_TRUE(outcome.ok) << outcome.output;
  EXPECT_TRUE(outcome.built_elsewhere) << "the queued compile built the module a second time";
  EXPECT_EQ(autumn::testing::read_text(so), built);
  EXPECT_TRUE(autumn::testing::files_in(cache, ".cpp").empty());
  fs::remove_all(cache);
}

// AUTUMN_MODULE_COMPILER=clang compiles modules with Clang and lld inside the
// process (harness/module_build_clang): the entry is complete (manifest, digest
// checked on load), it was linked by lld, and its frames are the golden traces'
// on two conformance programs (difftest first waits for the module and
// compares it with the interpreter; check then runs it from the first step).
TEST(ModuleBuild, ClangInProcessModulesAreExact) {
  if (std::string(AUTUMN_CLANG_PLUGIN).empty()) GTEST_SKIP() << "this build has no in-process Clang plugin";
  const fs::path shared = autumn::testing::shared_dir() / "conformance";
  const fs::path dir = root() / "clang";
  fs::remove_all(dir);
  fs::create_directories(dir / "cache");
  fs::create_directories(dir / "tmp");
  ASSERT_EQ(chmod((dir / "cache").c_str(), 0700), 0);
  const std::string env = env_for(dir / "cache", dir / "tmp") + " AUTUMN_MODULE_COMPILER=clang";
  for (const std::string name : {"ab_grow", "ants"}) {
    const std::string prog = (shared / "programs" / (name + ".sexp")).string();
    auto d = run_cli("difftest " + prog + " --seeds 2 --steps 40", false, env);
    ASSERT_EQ(d.status, 0) << d.out;
    EXPECT_NE(d.out.find("autumn: compiled "), std::string::npos) << d.out;
    auto c = run_cli("check " + prog + " " + (shared / "traces" / (name + ".json")).string() + " --engine compiled", false, env);
    EXPECT_EQ(c.status, 0) << c.out;
    EXPECT_EQ(c.out.find("first use"), std::string::npos) << "the module was not in the cache:\n" << c.out;
    EXPECT_NE(c.out.find("matched "), std::string::npos) << c.out;
  }
  const auto modules = autumn::testing::files_in(dir / "cache", ".so");
  ASSERT_EQ(modules.size(), 2u);
  for (const auto& so : modules) {
    EXPECT_TRUE(fs::exists(autumn::store::manifest_path(so))) << so;
    EXPECT_NE(autumn::testing::read_text(so).find("LLD 14"), std::string::npos) << so << " was not linked by lld"; // .comment: "Linker: Debian LLD 14.0.6"
    EXPECT_EQ(fs::status(so).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write) << so;
  }
  EXPECT_TRUE(autumn::testing::files_in(dir / "cache", ".part").empty());
  EXPECT_TRUE(autumn::testing::files_in(dir / "cache", ".cpp").empty());
  fs::remove_all(dir);
}

// Built-in modules are used for the exact text of their program only: each one
// carries that text, and its table was built from it.
// The cache key names the lowering by the archive linked into the binary: its
// digest, generated when the archive is built, is that of the archive this test
// binary linked (the one the build just wrote).
TEST(ModuleKey, NamesTheLoweringLinkedIn) {
  std::ifstream in(AUTUMN_EMIT_ARCHIVE, std::ios::binary);
  ASSERT_TRUE(in) << AUTUMN_EMIT_ARCHIVE;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(autumn::linked_emit_digest(), autumn::sha256_hex(bytes));
}

TEST(BuiltinModules, CarryTheFullTextOfTheirProgram) {
  const autumn::BuiltinModules builtins = autumn::builtin_modules();
  ASSERT_GT(builtins.count, 0u);
  for (size_t i = 0; i < builtins.count; ++i) {
    const autumn_module_v1* table = builtins.entries[i]();
    const std::string text(builtins.texts[i]);
    EXPECT_EQ(text, autumn::testing::read_text(autumn::testing::source_dir() / "programs" /
                                               (std::string(table->program_name) + ".au")));
    EXPECT_EQ(table->source_hash, autumn::module_source_hash(text, std::nullopt)) << table->program_name;
  }
}

}  // namespace
}  // namespace module_store_test
