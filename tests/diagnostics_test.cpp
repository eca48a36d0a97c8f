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

namespace autumn {
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

}  // namespace
}  // namespace autumn
