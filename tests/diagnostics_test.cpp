// Bad programs give located errors, never crashes.
//
// tests/diagnostics/*.au: each file's "; expect-error: LINE:COL: TEXT" header
// names the location and (part of) the message that loading it must produce.
// tests/runtime_errors/*.au: "; actions:" are run after reset, and the episode
// must end with "FILE:LINE:COL: runtime error: ...TEXT...".
#include <gtest/gtest.h>

#include "compiler/analyse/program.hpp"
#include "compiler/interpret/interpreted_env.hpp"
#include "harness/engine.hpp"
#include "test_support.hpp"

namespace autumn::diagnostics_test {
namespace {

using testing::files_in;
using testing::header;
using testing::read_text;
using testing::source_dir;

std::string name_of(const ::testing::TestParamInfo<std::filesystem::path>& info) {
  std::string n = info.param.stem().string();
  for (char& c : n)
    if (!isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

class Diagnostic : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(Diagnostic, ReportsLocatedError) {
  const std::string path = GetParam().string();
  const std::string text = read_text(GetParam());
  const std::string expect = header(text, "expect-error");
  ASSERT_FALSE(expect.empty()) << path << " has no '; expect-error:' header";
  try {
    load_program(SourceFile{path, text});
    FAIL() << path << ": loaded without error, expected " << expect;
  } catch (const CompileError& e) {
    const std::string got = e.formatted();
    const size_t colon = expect.find(": ");
    const std::string where = path + ":" + expect.substr(0, colon) + ": error: ";
    EXPECT_EQ(got.rfind(where, 0), 0u) << "got: " << got << "\nwant prefix: " << where;
    EXPECT_NE(got.find(expect.substr(colon + 2)), std::string::npos) << "got: " << got;
    EXPECT_EQ(got.find('\n'), std::string::npos) << "one line: " << got;
    EXPECT_EQ(got.find('\r'), std::string::npos) << "one line: " << got;
  }
}

INSTANTIATE_TEST_SUITE_P(Files, Diagnostic, ::testing::ValuesIn(files_in(source_dir() / "tests/diagnostics", ".au")),
                         name_of);

class RuntimeFailure : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(RuntimeFailure, EndsEpisodeWithLocatedMessage) {
  const std::string path = GetParam().string();
  const std::string text = read_text(GetParam());
  const std::string expect = header(text, "expect-runtime-error");
  ASSERT_FALSE(expect.empty());
  std::string why;
  auto actions = parse_action_list(header(text, "actions"), &why);
  ASSERT_TRUE(actions) << why;
  auto program = load_program(SourceFile{path, text});
  // Both engines, with the same text: the compiled module carries its source's locations.
  for (const std::string& engine : testing::test_engines()) {
    std::string why;
    auto env = make_environment(engine, program, &why);
    ASSERT_TRUE(env) << why;
    bool ok = env->reset(7);
    for (size_t i = 0; ok && i < actions->size(); ++i) ok = env->step((*actions)[i]);
    ASSERT_FALSE(ok) << path << " (" << engine << "): expected a runtime error";
    EXPECT_TRUE(env->failed());
    EXPECT_FALSE(env->step(Action::noop())) << "a failed episode must refuse further steps";
    const size_t colon = expect.find(": ");
    const std::string where = path + ":" + expect.substr(0, colon) + ": runtime error: ";
    EXPECT_EQ(env->error().rfind(where, 0), 0u) << engine << " got: " << env->error() << "\nwant prefix: " << where;
    EXPECT_NE(env->error().find(expect.substr(colon + 2)), std::string::npos) << engine << " got: " << env->error();
  }
}

INSTANTIATE_TEST_SUITE_P(Files, RuntimeFailure,
                         ::testing::ValuesIn(files_in(source_dir() / "tests/runtime_errors", ".au")), name_of);

TEST(Diagnostics, MissingFileIsAnError) {
  EXPECT_THROW(load_program_file("/nonexistent/prog.au"), CompileError);
}

TEST(Diagnostics, UnboundNamesAreWarnedWithLocation) {
  auto p = load_program(SourceFile{"w.au", "(program\n  (= x (initnext 0 (+ (prev x) speed))))"});
  ASSERT_EQ(p->warnings.size(), 1u);
  EXPECT_EQ(p->warnings[0], "w.au:2:32: warning: 'speed' is not defined anywhere; evaluating it is a runtime error");
}

// A NUL, a byte-order mark or a 5 MB name in a program: every message stays whole,
// one line, escaped and short, in warnings, errors and both engines' runtime errors.
TEST(Diagnostics, InvisibleAndHugeTextIsShownSafely) {
  using namespace std::string_literals;
  auto nul = load_program(SourceFile{"w.au", "(program\n  (= x (initnext 0 (+ (prev x) sp\0eed))))"s});
  ASSERT_EQ(nul->warnings.size(), 2u);
  EXPECT_EQ(nul->warnings[1],
            "w.au:2:32: warning: 'sp\\x00eed' reads as the name 'sp' (names end at the first character that is not a "
            "letter, digit or underscore)");

  try {
    load_program(SourceFile{"b.au", "\xEF\xBB\xBF(program (= GRID_SIZE 4))"});
    FAIL() << "a byte-order mark before the program loaded";
  } catch (const CompileError& e) {
    EXPECT_NE(e.formatted().find("\\ufeff"), std::string::npos) << e.formatted();
  }

  const std::string huge(5'000'000, 'q');
  auto big = load_program(SourceFile{"h.au", "(program\n  (= x (initnext 0 (+ (prev x) " + huge + "))))"});
  ASSERT_EQ(big->warnings.size(), 1u);
  EXPECT_LT(big->warnings[0].size(), 400u);
  EXPECT_NE(big->warnings[0].find("'qqqq"), std::string::npos) << big->warnings[0].substr(0, 400);
  EXPECT_NE(big->warnings[0].find("...(5000002 bytes)..."), std::string::npos) << big->warnings[0].substr(0, 400);

  // At run time, on both engines: the same elided text.
  const std::string name(300, 'q');
  auto program = load_program(SourceFile{"r.au", "(program\n  (= GRID_SIZE 4)\n  (= x (initnext 0 (+ (prev x) " + name + "))))"});
  std::vector<std::string> errors;
  for (const std::string& engine : testing::test_engines()) {
    std::string why;
    auto env = make_environment(engine, program, &why);
    ASSERT_TRUE(env) << why;
    bool ok = env->reset(0) && env->step(Action::noop());
    ASSERT_FALSE(ok) << engine;
    EXPECT_EQ(env->error().rfind("r.au:3:32: runtime error: undefined variable 'qqq", 0), 0u) << engine << ": " << env->error();
    EXPECT_NE(env->error().find("q...(302 bytes)...q"), std::string::npos) << engine << ": " << env->error();
    EXPECT_LT(env->error().size(), 250u) << engine;
    errors.push_back(env->error());
  }
  for (const std::string& e : errors) EXPECT_EQ(e, errors[0]);
}

}  // namespace
}  // namespace autumn::diagnostics_test
