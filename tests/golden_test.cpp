// Golden files: tests/golden/*.au are small programs, each pinning down one
// reference quirk, with their expected transcript stored in the file itself below
// a marker line (as ";; "-prefixed comments, so the file stays a valid program).
//
// One expectation, both engines: the transcript is produced by the interpreter
// and by the compiled engine, and each must equal the expected one.
//
// On a mismatch the test prints the first differing line with context. To accept
// new output after an intended change, re-bless:  AUTUMN_BLESS=1 ctest -R Golden
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "compiler/analyse/program.hpp"
#include "compiler/interpret/interpreted_env.hpp"
#include "harness/engine.hpp"
#include "harness/transcript.hpp"
#include "test_support.hpp"

namespace autumn::golden_test {
namespace {

constexpr const char* kMarker = ";; ---- expected transcript (re-bless: AUTUMN_BLESS=1 ctest -R Golden) ----";

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::string readable_diff(const std::string& want, const std::string& got) {
  auto a = lines_of(want), b = lines_of(got);
  size_t i = 0;
  while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
  std::ostringstream out;
  out << "first difference at transcript line " << i + 1 << "\n";
  for (size_t k = (i >= 3 ? i - 3 : 0); k < i; ++k) out << "    " << a[k] << "\n";
  out << "  - " << (i < a.size() ? a[i] : "<end>") << "\n";
  out << "  + " << (i < b.size() ? b[i] : "<end>") << "\n";
  return out.str();
}

class Golden : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(Golden, TranscriptMatches) {
  const auto path = GetParam();
  std::string text = testing::read_text(path);
  std::string source = text, expected;
  if (size_t m = text.find(kMarker); m != std::string::npos) {
    source = text.substr(0, m);
    for (const auto& l : lines_of(text.substr(m + std::string(kMarker).size())))
      if (l.rfind(";; ", 0) == 0) expected += l.substr(3) + "\n";
      else if (l == ";;") expected += "\n";
  }
  std::string why;
  auto actions = parse_action_list(testing::header(source, "actions"), &why);
  ASSERT_TRUE(actions) << why;
  uint64_t seed = std::stoull(testing::header(source, "seed").empty() ? "0" : testing::header(source, "seed"));
  auto program = load_program(SourceFile{path.filename().string(), source});
  InterpretedEnvironment env(program);
  Transcript t = run_transcript(env, seed, *actions, false);

  if (std::getenv("AUTUMN_BLESS")) {
    std::string out = source;
    if (!out.empty() && out.back() != '\n') out += '\n';
    out += std::string(kMarker) + "\n";
    for (const auto& l : lines_of(t.text)) out += ";; " + l + "\n";
    std::ofstream(path, std::ios::binary) << out;
    GTEST_SKIP() << "blessed " << path;
  }
  ASSERT_FALSE(expected.empty()) << path << " has no expected transcript; run with AUTUMN_BLESS=1";
  EXPECT_TRUE(t.ok) << t.text;
  EXPECT_EQ(t.text, expected) << "interpreter: " << readable_diff(expected, t.text);
  const auto engines = testing::test_engines();
  if (std::find(engines.begin(), engines.end(), "compiled") == engines.end()) return;
  auto compiled = make_environment("compiled", program, &why);
  ASSERT_TRUE(compiled) << why;
  Transcript c = run_transcript(*compiled, seed, *actions, false);
  EXPECT_EQ(c.text, expected) << "compiled: " << readable_diff(expected, c.text);
}

INSTANTIATE_TEST_SUITE_P(Files, Golden,
                         ::testing::ValuesIn(testing::files_in(testing::source_dir() / "tests/golden", ".au")),
                         [](const auto& info) { return info.param.stem().string(); });

}  // namespace
}  // namespace autumn::golden_test
