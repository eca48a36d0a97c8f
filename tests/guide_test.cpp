// The language guide's examples are tests: docs/language.md holds programs in
// ```autumn blocks, each followed by a ```frames block that gives the seed and
// the actions ("seed: N", "actions: a,b,...") and the frames the program must
// show, as `autumn run` prints them. Every example runs on the interpreter and
// on the compiled engine; both must print exactly the block. AUTUMN_BLESS=1
// rewrites the blocks from the interpreter (the compiled engine must still agree).
// An ```autumn block without a ```frames block after it is a failure, not a
// fragment to skip: fragments use a plain ``` fence. Examples stay small (at most
// 8x8) so that compiling each on demand keeps the test to seconds.
//
// The guide's reference must also name every builtin of the builtin table
// (compiler/analyse/builtins.hpp) and every function of the standard library, so
// a builtin added to the table without a line in the guide fails here.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "compiler/analyse/builtins.hpp"
#include "compiler/analyse/program.hpp"
#include "harness/engine.hpp"
#include "harness/episode.hpp"
#include "test_support.hpp"

namespace autumn::guide_test {
namespace {

const std::filesystem::path kGuide = testing::source_dir() / "docs/language.md";

struct Example {
  std::string program;
  uint64_t seed = 0;
  std::string actions;
  std::string expected;                  // the frames, as `autumn run` prints them
  size_t frames_begin = 0, frames_end = 0;  // the ```frames block's body in the guide's text
  int line = 0;                          // of the program, for messages
  bool has_frames = false;
};

std::vector<Example> examples(const std::string& text) {
  std::vector<Example> out;
  const std::string open = "```autumn\n", frames_open = "```frames\n", close = "```\n";
  for (size_t at = text.find(open); at != std::string::npos; at = text.find(open, at + 1)) {
    Example ex;
    const size_t body = at + open.size(), end = text.find(close, body);
    if (end == std::string::npos) break;
    ex.program = text.substr(body, end - body);
    ex.line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(body), '\n'));
    size_t next = end + close.size();
    while (next < text.size() && text[next] == '\n') ++next;
    ex.has_frames = text.compare(next, frames_open.size(), frames_open) == 0;
    if (!ex.has_frames) {
      out.push_back(ex);
      continue;
    }
    ex.frames_begin = next + frames_open.size();
    ex.frames_end = text.find(close, ex.frames_begin);
    std::istringstream block(text.substr(ex.frames_begin, ex.frames_end - ex.frames_begin));
    std::string row;
    while (std::getline(block, row)) {
      if (row.rfind("seed: ", 0) == 0) ex.seed = std::stoull(row.substr(6));
      else if (row.rfind("actions:", 0) == 0) ex.actions = row.size() > 9 ? row.substr(9) : "";
      else ex.expected += row + "\n";
    }
    out.push_back(ex);
  }
  return out;
}

// What `autumn run` prints for the example on `engine` (an error ends it).
std::string run_example(const Example& ex, const std::string& engine) {
  auto program = load_program(SourceFile{"example.au", ex.program});
  std::string why;
  auto env = make_environment(engine, program, &why);
  if (!env) return "no " + engine + " engine: " + why + "\n";
  auto actions = parse_action_list(ex.actions, &why);
  if (!actions) return "bad actions: " + why + "\n";
  std::string out;
  EpisodeFrames ep = run_episode(*env, ex.seed, *actions, [&](size_t i, const std::string& label, const auto& rows) {
    out += "# frame " + std::to_string(i) + " (" + label + ")\n";
    for (const auto& r : rows) out += r + "\n";
  });
  if (!ep.ok()) out += "# error: " + ep.error + "\n";
  return out;
}

std::string header(const Example& ex) {
  return "seed: " + std::to_string(ex.seed) + "\nactions: " + ex.actions + "\n";
}

TEST(Guide, EveryExampleShowsItsFramesOnBothEngines) {
  std::string text = testing::read_text(kGuide);
  std::vector<Example> all = examples(text);
  ASSERT_GE(all.size(), 8u) << "the guide's examples were not found in " << kGuide;
  const bool bless = std::getenv("AUTUMN_BLESS") != nullptr;
  // Blessing rewrites from the last block back, so earlier offsets stay valid.
  for (auto it = all.rbegin(); it != all.rend(); ++it) {
    const Example& ex = *it;
    SCOPED_TRACE("example at docs/language.md:" + std::to_string(ex.line));
    if (!ex.has_frames) {
      ADD_FAILURE() << "an ```autumn block needs a ```frames block after it (a fragment takes a plain ``` fence)";
      continue;
    }
    std::string interp;
    try {
      interp = run_example(ex, "interp");
    } catch (const CompileError& e) {
      FAIL() << e.formatted();
    }
    // The other engines under test (AUTUMN_TEST_ENGINES; the sanitizer run
    // checks the interpreter only, scripts/sanitize.sh) print the same.
    for (const std::string& engine : testing::test_engines()) {
      if (engine != "interp") {
        EXPECT_EQ(run_example(ex, engine), interp) << engine;
      }
    }
    if (bless) text.replace(ex.frames_begin, ex.frames_end - ex.frames_begin, header(ex) + interp);
    else EXPECT_EQ(interp, ex.expected) << "(AUTUMN_BLESS=1 rewrites the frames from the interpreter)";
    EXPECT_EQ(interp.find("# error"), std::string::npos) << "examples run without errors";
    std::istringstream frames(interp);
    int rows = 0;
    for (std::string row; std::getline(frames, row) && (rows == 0 || row[0] != '#');) rows += row[0] != '#';
    EXPECT_LE(rows, 8) << "examples stay within 8x8 grids";
  }
  if (bless) std::ofstream(kGuide, std::ios::binary) << text;
}

// The reference tables: "| `name` |" rows.
bool listed(const std::string& text, const std::string& name) {
  for (const std::string& row : {"| `" + name + "`", "| `(" + name + " ", "| `(" + name + ")`"})
    if (text.find(row) != std::string::npos) return true;
  return false;
}

TEST(Guide, ReferenceNamesEveryBuiltin) {
  const std::string text = testing::read_text(kGuide);
  for (int i = 0; i < kBuiltinCount; ++i) {
    const char* name = builtin_table()[i].name;
    EXPECT_TRUE(listed(text, name)) << "docs/language.md has no reference row for the builtin '" << name << "'";
  }
}

TEST(Guide, ReferenceNamesEveryStandardLibraryFunction) {
  const std::string text = testing::read_text(kGuide);
  auto program = load_program(SourceFile{"p.au", "(program (= GRID_SIZE 4))"});
  int functions = 0;
  for (const Stmt& st : program->stdlib_stmts) {
    if (st.kind != StmtKind::Expr || st.expr->kind != ExprKind::Assign) continue;
    if (st.expr->kids.empty() || st.expr->kids[0]->kind != ExprKind::Lambda) continue;
    ++functions;
    const std::string name = program->name(st.expr->name);
    EXPECT_TRUE(listed(text, name)) << "docs/language.md has no reference row for the stdlib function '" << name
                                    << "'";
  }
  EXPECT_GE(functions, 40) << "the standard library's functions were not found";
}

}  // namespace
}  // namespace autumn::guide_test
