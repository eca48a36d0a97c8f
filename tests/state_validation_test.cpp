// State validation: load_state() of a compiled module trusts no byte of a
// snapshot. Real snapshots of built-in modules (generated/), taken after a few
// steps, are changed one byte at a time at every offset, truncated at every
// length and given huge length fields; each load either succeeds (the bytes
// still describe a valid state) and then steps without a crash, or fails with a
// reason and leaves the environment refusing to step. The interpreter engine
// declines snapshots, so any bytes given to it are refused. Run under ASan
// (scripts/sanitize.sh) a wrong index shows as a report, not a lucky pass.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <memory>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/lower.hpp"
#include "harness/digest.hpp"
#include "harness/engine.hpp"
#include "harness/module_cache.hpp"
#include "runtime/module_env.hpp"
#include "runtime/snapshot_header.hpp"
#include "test_support.hpp"

namespace autumn::state_validation_test {
namespace {

std::unique_ptr<Environment> builtin_env(const std::string& name) {
  const BuiltinModules b = builtin_modules();
  for (size_t i = 0; i < b.count; ++i) {
    const autumn_module_v1* t = b.entries[i]();
    if (name == t->program_name) return std::make_unique<ModuleEnvironment>(t, nullptr);
  }
  return nullptr;
}

// A valid snapshot after a few steps of clicks and moves.
std::vector<uint8_t> snapshot_after_steps(Environment& env) {
  EXPECT_TRUE(env.reset(3)) << env.error();
  const int g = env.frame().size;
  for (int k = 0; k < 6; ++k) env.step(k % 2 ? Action::click(k % g, (3 * k) % g) : Action{Action::Kind(1 + k % 4)});
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(env.save_state(bytes));
  return bytes;
}

// Loads `bytes`; on success steps a few times (must not crash), on failure
// there must be a reason and the environment must refuse to step. True if loaded.
bool load_and_step(Environment& env, const std::vector<uint8_t>& bytes) {
  if (env.load_state(bytes.data(), bytes.size())) {
    for (int k = 0; k < 3; ++k) env.step(Action::click(k, k)), env.step(Action{Action::Kind::Left});
    return true;
  }
  EXPECT_FALSE(env.error().empty());
  EXPECT_FALSE(env.step(Action{Action::Kind::Up}));
  return false;
}

class StateValidation : public ::testing::TestWithParam<const char*> {};

TEST_P(StateValidation, EveryChangedByteLoadsCleanlyOrFails) {
  auto env = builtin_env(GetParam());
  ASSERT_TRUE(env);
  const std::vector<uint8_t> good = snapshot_after_steps(*env);
  ASSERT_GT(good.size(), 40u);
  size_t loaded = 0, refused = 0;
  for (size_t i = 0; i < good.size(); ++i)
    for (uint8_t x : {uint8_t{0x01}, uint8_t{0x80}, uint8_t{0xff}}) {
      std::vector<uint8_t> bad = good;
      bad[i] ^= x;
      ++(load_and_step(*env, bad) ? loaded : refused);
    }
  EXPECT_GT(loaded, 0u);  // most bytes are coordinates: still a state
  EXPECT_GT(refused, 0u);
  ASSERT_TRUE(env->load_state(good.data(), good.size())) << env->error();  // still loads after all that
}

TEST_P(StateValidation, EveryTruncationFails) {
  auto env = builtin_env(GetParam());
  ASSERT_TRUE(env);
  const std::vector<uint8_t> good = snapshot_after_steps(*env);
  for (size_t n = 0; n < good.size(); ++n) {
    std::vector<uint8_t> cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_FALSE(env->load_state(cut.data(), cut.size())) << n;
    EXPECT_NE(env->error().find("snapshot"), std::string::npos) << env->error();
  }
  std::vector<uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_FALSE(env->load_state(longer.data(), longer.size()));
}

// Every aligned 32-bit word set to a huge count (list lengths among them).
TEST_P(StateValidation, HugeLengthFieldsFail) {
  auto env = builtin_env(GetParam());
  ASSERT_TRUE(env);
  const std::vector<uint8_t> good = snapshot_after_steps(*env);
  for (uint32_t huge : {0xffffffffu, 0x7fffffffu, 0x10000000u})
    for (size_t i = 0; i + 4 <= good.size(); ++i) {
      std::vector<uint8_t> bad = good;
      std::memcpy(bad.data() + i, &huge, 4);
      load_and_step(*env, bad);
    }
}

INSTANTIATE_TEST_SUITE_P(Builtin, StateValidation,
                         ::testing::Values("sokoban", "breakout", "garden", "flood_defense", "blockfall",
                                           "color_flood"));

TEST(StateValidationMisc, ForeignAndEmptyBytesFail) {
  auto soko = builtin_env("sokoban"), garden = builtin_env("garden");
  ASSERT_TRUE(soko && garden);
  const std::vector<uint8_t> g = snapshot_after_steps(*garden);
  EXPECT_FALSE(load_and_step(*soko, g));  // another program's snapshot: refused by its header (below)
  EXPECT_FALSE(soko->load_state(nullptr, 0));
  auto program = load_program_file((testing::source_dir() / "programs/sokoban.au").string());
  std::string why;
  auto interp = make_environment("interp", program, &why);
  ASSERT_TRUE(interp) << why;
  ASSERT_TRUE(interp->reset(1));
  EXPECT_FALSE(interp->load_state(g.data(), g.size()));
}

// Every snapshot opens with "AUTS", the runtime's snapshot format and the
// module's layout digest; bytes that do not match are refused with that reason
// before a field is read.
TEST(StateValidationMisc, TheHeaderNamesTheLayout) {
  auto source = builtin_env("sokoban"), garden = builtin_env("garden");
  ASSERT_TRUE(source && garden);
  const std::vector<uint8_t> own = snapshot_after_steps(*source), foreign = snapshot_after_steps(*garden);
  ASSERT_GE(own.size(), 16u);
  EXPECT_EQ(std::string(own.begin(), own.begin() + 4), "AUTS");
  auto refused_with = [](const std::vector<uint8_t>& bytes) {
    auto env = builtin_env("sokoban");
    EXPECT_FALSE(load_and_step(*env, bytes));
    return env->error();
  };
  EXPECT_NE(refused_with(foreign).find("a state snapshot of another program, or of another build"), std::string::npos);
  std::vector<uint8_t> b = own;
  b[4] ^= 2;  // the format
  EXPECT_NE(refused_with(b).find("a state snapshot of another autumnc version (snapshot format " +
                                 std::to_string(rt::kSnapshotFormat ^ 2) + ";"),
            std::string::npos);
  b = own;
  b[0] = 'X';
  EXPECT_NE(refused_with(b).find("not a state snapshot of a compiled module (no AUTS header)"), std::string::npos);
  b = own;
  b[9] ^= 1;  // the layout
  EXPECT_NE(refused_with(b).find("another build of this program's module"), std::string::npos);
  b.assign(own.begin(), own.begin() + 15);
  EXPECT_NE(refused_with(b).find("too short for its header"), std::string::npos);
  auto env = builtin_env("sokoban");
  EXPECT_TRUE(env->load_state(own.data(), own.size())) << env->error();
}

// kSnapshotFormat is raised by hand when the encoding of the core or of values
// changes; this test is what notices a change that forgot to. Every built-in
// module's snapshot after a fixed episode is recorded in
// tests/snapshot_formats.txt by its program's text, the format and the layout
// (the header). Bytes that differ under the same three are a new encoding
// passing as the old one: a state saved by one build would load into the
// other as another state. AUTUMN_BLESS=1 records changed programs, layouts and
// formats, and refuses that case.
TEST(StateValidationMisc, TheEncodingChangesOnlyWithTheFormat) {
  const std::filesystem::path file = testing::source_dir() / "tests/snapshot_formats.txt";
  struct Entry {
    std::string program, format, layout, bytes;
  };
  std::map<std::string, Entry> recorded;
  {
    std::istringstream in(testing::read_text(file));
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream f(line);
      std::string name;
      Entry e;
      f >> name >> e.program >> e.format >> e.layout >> e.bytes;
      recorded[name] = e;
    }
  }
  std::map<std::string, Entry> now;
  const BuiltinModules b = builtin_modules();
  for (size_t i = 0; i < b.count; ++i) {
    const autumn_module_v1* t = b.entries[i]();
    ModuleEnvironment env(t, nullptr);
    std::vector<uint8_t> bytes = snapshot_after_steps(env);
    ASSERT_GE(bytes.size(), rt::kSnapshotHeaderBytes) << t->program_name;
    uint64_t layout = 0;
    std::memcpy(&layout, bytes.data() + 8, 8);
    char hex[32];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(layout));
    const std::string text = testing::read_text(testing::source_dir() / "programs" / (std::string(t->program_name) + ".au"));
    now[t->program_name] = Entry{sha256_hex(text).substr(0, 16), std::to_string(rt::kSnapshotFormat), hex,
                                 sha256_hex(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()))};
  }
  ASSERT_GT(now.size(), 5u);
  int checked = 0;
  for (const auto& [name, e] : now) {
    auto r = recorded.find(name);
    const bool same_key = r != recorded.end() && r->second.program == e.program && r->second.format == e.format &&
                          r->second.layout == e.layout;
    if (same_key) {
      ++checked;
      EXPECT_EQ(r->second.bytes, e.bytes)
          << name << ": its snapshot's bytes changed under the same program, snapshot format (" << e.format
          << ") and layout: the encoding changed; raise kSnapshotFormat (runtime/snapshot_header.hpp), then "
             "AUTUMN_BLESS=1 records the new bytes";
    } else if (!std::getenv("AUTUMN_BLESS")) {
      ADD_FAILURE() << name << ": tests/snapshot_formats.txt records another program text, format or layout "
                    << "(or none): after an intended change, AUTUMN_BLESS=1 records this one";
    }
  }
  if (std::getenv("AUTUMN_BLESS") && !HasFailure()) {
    std::ofstream out(file);
    out << "# snapshot_formats.txt: the snapshot of every built-in module after a fixed episode\n"
           "# (tests/state_validation_test.cpp, TheEncodingChangesOnlyWithTheFormat). Columns: module,\n"
           "# digest of its program's text, snapshot format, layout, SHA-256 of the bytes.\n"
           "# Re-bless: AUTUMN_BLESS=1 ctest -R TheEncodingChangesOnlyWithTheFormat\n";
    for (const auto& [name, e] : now) out << name << ' ' << e.program << ' ' << e.format << ' ' << e.layout << ' ' << e.bytes << '\n';
  } else {
    EXPECT_EQ(checked, static_cast<int>(now.size())) << "modules not checked against a recorded snapshot";
  }
}

// The layout digest follows what a snapshot holds and nothing else: the saved
// slots' types, the classes' fields and the string table (a string slot holds
// an index into it), not the code of the step.
TEST(StateValidationMisc, TheLayoutFollowsWhatSnapshotsHold) {
  auto layout = [](const std::string& text) {
    auto program = load_program(SourceFile{"layout.au", text});
    const Lowered l = lower_program(*program, "layout");
    EXPECT_TRUE(l.ok) << l.reason;
    return l.snapshot_layout;
  };
  auto program = [](const std::string& field, const std::string& init, const std::string& next,
                    const std::string& colour, const std::string& extra) {
    return "(program (= GRID_SIZE 8)\n(object A (: n " + field + ") (Cell 0 0 \"" + colour + "\"))\n" +
           "(: a A) (= a (initnext (A " + init + " (Position 1 1)) (prev a)))\n" + extra +
           "(on left (= a (updateObj a \"n\" " + next + "))))\n";
  };
  const uint64_t base = layout(program("Number", "1", "(+ (.. a n) 1)", "red", ""));
  EXPECT_NE(base, 0u);
  EXPECT_EQ(layout(program("Number", "1", "(+ (.. a n) 1)", "red", "")), base);
  EXPECT_EQ(layout(program("Number", "1", "(+ (.. a n) 2)", "red", "")), base);  // the step's code only
  EXPECT_NE(layout(program("Number", "1", "(+ (.. a n) 1)", "blue", "")), base);  // the string table
  EXPECT_NE(layout(program("Bool", "true", "(! (.. a n))", "red", "")), base);     // a field's type
  EXPECT_NE(layout(program("Number", "1", "(+ (.. a n) 1)", "red", "(: k Number) (= k (initnext 0 (+ (prev k) 1)))\n")),
            base);  // one more global
}

}  // namespace
}  // namespace autumn::state_validation_test
