// Every golden trace in ../shared/conformance/traces must be reproduced exactly
// by the interpreter: every frame, and every trigger value where recorded.
// (Under the sanitizers, the first two episodes of each file: AUTUMN_TRACE_EPISODES,
// test_support.hpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "compiler/analyse/program.hpp"
#include "compiler/interpret/interpreted_env.hpp"
#include "harness/trace_check.hpp"
#include "test_support.hpp"

namespace autumn::conformance_test {
namespace {

using testing::trace_names;

// The library's own document builder (nlohmann's json_sax_dom_parser), told to
// stop once the top-level "traces" array holds `wanted` episodes: the lexer, not
// the replay, is most of a golden trace's time under the sanitizers (a 3 MB file
// took 2.2 s of ajl_chaos_game's 3.0), and what follows the last episode wanted
// is never read. The builder fills the document in place, so a stop leaves every
// value read so far where the whole parse would have put it.
struct FirstEpisodes : nlohmann::detail::json_sax_dom_parser<nlohmann::json> {
  using Builder = nlohmann::detail::json_sax_dom_parser<nlohmann::json>;
  size_t depth = 0;        // containers open
  bool traces_key = false;  // the root's member being read is "traces"
  bool in_traces = false;   // inside the root's "traces" array
  size_t wanted, done = 0;

  FirstEpisodes(nlohmann::json& root, size_t k) : Builder(root), wanted(k) {}
  bool key(std::string& k) {
    if (depth == 1) traces_key = k == "traces";
    return Builder::key(k);
  }
  bool start_object(size_t n) {
    ++depth;
    return Builder::start_object(n);
  }
  bool end_object() {  // false (stop) when this closed the last episode wanted
    --depth;
    const bool last = in_traces && depth == 2 && ++done == wanted;
    return Builder::end_object() && !last;
  }
  bool start_array(size_t n) {
    in_traces = in_traces || (depth == 1 && traces_key);
    ++depth;
    return Builder::start_array(n);
  }
  bool end_array() {
    if (--depth == 1) in_traces = false;
    return Builder::end_array();
  }
  bool parse_error(size_t, const std::string&, const nlohmann::detail::exception& e) {
    throw std::runtime_error(std::string("not valid JSON: ") + e.what());
  }
};

// The golden trace file at `path` with at most `wanted` episodes. The parse stops
// early only when "traces" is the file's last member (its text ends "]}"; every
// corpus file is written so), so no member after it is lost.
TraceFile load_episodes(const std::string& path, size_t wanted) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::string text(in ? static_cast<size_t>(in.tellg()) : 0, '\0');
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));  // at once: by the character, 56% of the load
  const size_t last = text.find_last_not_of(" \t\r\n");
  const size_t before = last == std::string::npos || last == 0 ? std::string::npos : text.find_last_not_of(" \t\r\n", last - 1);
  if (wanted == SIZE_MAX || before == std::string::npos || text[last] != '}' || text[before] != ']') {
    TraceFile f = load_trace_file(path);
    f.traces.resize(std::min(f.traces.size(), wanted));
    return f;
  }
  nlohmann::json root;
  FirstEpisodes sax(root, wanted);
  nlohmann::json::sax_parse(text, &sax);
  return trace_file_from_json(root, path);
}

class Conformance : public ::testing::TestWithParam<std::string> {};

TEST_P(Conformance, InterpreterMatchesEveryFrame) {
  if (GetParam() == "MISSING_SHARED_CORPUS")
    GTEST_SKIP() << "SKIPPED LOUDLY: no conformance corpus at " << testing::shared_dir()
                 << " (set AUTUMN_SHARED_DIR); the golden traces were NOT checked";
  const auto dir = testing::shared_dir() / "conformance";
  TraceFile file = load_episodes((dir / "traces" / (GetParam() + ".json")).string(), testing::trace_episodes(SIZE_MAX));
  auto program = load_program_file((dir / "programs" / (GetParam() + ".sexp")).string(), file.triggering_condition);
  InterpretedEnvironment env(program);
  CheckResult r = check_traces(env, file);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.frames_matched, r.frames_total);
  EXPECT_EQ(r.triggers_matched, r.triggers_total);
  EXPECT_GT(r.frames_total, 0u);
}

// The early stop keeps the first episodes whole and every member before them,
// and never applies to a file with a member after "traces".
TEST(TraceEpisodes, FirstEpisodesAreTheWholeFilesFirst) {
  const std::vector<std::string> names = trace_names();
  if (names.front() == "MISSING_SHARED_CORPUS") GTEST_SKIP() << "SKIPPED LOUDLY: no conformance corpus";
  for (const std::string& name : {names.front(), names.back()}) {
    const std::string path = (testing::shared_dir() / "conformance/traces" / (name + ".json")).string();
    const TraceFile all = load_trace_file(path), two = load_episodes(path, 2);
    ASSERT_GT(all.traces.size(), 2u) << path;
    ASSERT_EQ(two.traces.size(), 2u) << path;
    EXPECT_EQ(two.program, all.program);
    EXPECT_EQ(two.grid_size, all.grid_size);
    EXPECT_EQ(two.background, all.background);
    EXPECT_EQ(two.triggering_condition, all.triggering_condition);
    for (size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(two.traces[i].seed, all.traces[i].seed);
      EXPECT_EQ(two.traces[i].actions.size(), all.traces[i].actions.size());
      EXPECT_EQ(two.traces[i].frames, all.traces[i].frames);
      EXPECT_EQ(two.traces[i].trigger, all.traces[i].trigger);
    }
  }
  const auto dir = testing::scratch_dir("conformance", "trace_episodes");
  const std::string episode = R"({"seed": 1, "actions": ["left"], "frames": [["a"], ["b"]]})";
  const std::string later = (dir / "later.json").string();
  std::ofstream(later) << R"({"program": "p", "traces": [)" << episode << "," << episode << "," << episode
                       << R"j(], "triggering_condition": "(== 1 1)"})j";
  const TraceFile f = load_episodes(later, 1);
  EXPECT_EQ(f.traces.size(), 1u);
  EXPECT_EQ(f.triggering_condition, std::optional<std::string>("(== 1 1)"));
}

INSTANTIATE_TEST_SUITE_P(Traces, Conformance, ::testing::ValuesIn(trace_names()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace autumn::conformance_test
