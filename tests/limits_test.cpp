// Limits and robustness (runtime/limits.hpp): inputs that used to crash, hang or
// report no location end with one located message, on both engines.
//
// tests/limits/*.au: each file's "; limits:" header (the --limits syntax) is the
// budget, "; actions:" run after reset, and the episode must end with
// "FILE:LINE:COL: runtime error: ...TEXT..." from "; expect-runtime-error:
// LINE:COL: TEXT" ("nowhere: TEXT" for an error without a place: "FILE: runtime
// error: TEXT").
// Programs the interpreter runs inside the compiled module (recursion makes the
// lowering give up) pass on the compiled engine as they are. Specialised code
// enforces list-length, objects, the state's cells and the fixed limits, locates
// render errors, counts the calls budget as the elements its loops visit (its
// functions are inlined): "; expect-runtime-error-specialised:" states what it
// says then. It counts the cells a step creates as the elements its program
// constructs put into new lists, with the interpreter's message. Every file
// runs on every engine under test; any miss fails.
#include <gtest/gtest.h>

#include <pthread.h>

#include "compiler/analyse/program.hpp"
#include "compiler/interpret/interpreted_env.hpp"
#include "compiler/lower/lower.hpp"
#include "harness/agent/task_file.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"
#include "harness/trace_check.hpp"
#include "runtime/limits.hpp"
#include "test_support.hpp"

namespace autumn::limits_test {
namespace {

using testing::header;
using testing::read_text;

struct Outcome {
  bool failed = false;
  std::string error;
};

Outcome run_episode(Environment& env, const std::vector<Action>& actions) {
  bool ok = env.reset(3);
  for (size_t i = 0; ok && i < actions.size(); ++i) ok = env.step(actions[i]);
  return {!ok, ok ? "" : env.error()};
}

class LimitProgram : public ::testing::TestWithParam<std::filesystem::path> {};

TEST_P(LimitProgram, EndsWithLocatedMessageOnBothEngines) {
  const std::string path = GetParam().string();
  const std::string text = read_text(GetParam());
  const std::string expect = header(text, "expect-runtime-error");
  ASSERT_FALSE(expect.empty()) << path;
  std::string why;
  auto limits = limits::parse(header(text, "limits"), &why);
  ASSERT_TRUE(limits) << why;
  auto actions = parse_action_list(header(text, "actions"), &why);
  ASSERT_TRUE(actions) << why;
  auto program = load_program(SourceFile{path, text});
  // Specialised code counts the calls budget as loop elements (limits.hpp): a
  // program may state what it says instead.
  const std::string specialised = header(text, "expect-runtime-error-specialised");
  const bool is_specialised = lower_program(*program, "p").ok;
  for (const std::string& engine : testing::test_engines()) {
    const std::string& want = engine == "compiled" && is_specialised && !specialised.empty() ? specialised : expect;
    // "line:col: message", or "nowhere: message" for an error without a place,
    // which format_diagnostic prints as "file: runtime error: message".
    const size_t colon = want.find(": ");
    const std::string place = want.substr(0, colon);
    const std::string where = path + (place == "nowhere" ? "" : ":" + place) + ": runtime error: ";
    const std::string message = want.substr(colon + 2);
    auto env = make_environment(engine, program, &why);
    ASSERT_TRUE(env) << why;
    env->set_limits(*limits);
    Outcome o = run_episode(*env, *actions);
    ASSERT_TRUE(o.failed) << engine << ": expected a runtime error";
    EXPECT_EQ(o.error.rfind(where, 0), 0u) << engine << " got: " << o.error << "\nwant prefix: " << where;
    EXPECT_NE(o.error.find(message), std::string::npos) << engine << " got: " << o.error;
    EXPECT_EQ(o.error.find('\n'), std::string::npos) << "one line: " << o.error;
    auto copy = env->clone();  // a failed episode clones (and is destroyed) without trouble
    EXPECT_TRUE(copy->failed());
  }
}

std::string name_of(const ::testing::TestParamInfo<std::filesystem::path>& info) { return info.param.stem().string(); }

INSTANTIATE_TEST_SUITE_P(Files, LimitProgram,
                         ::testing::ValuesIn(testing::files_in(testing::source_dir() / "tests/limits", ".au")),
                         name_of);

// --- the limits raise as documented, and evaluation does not use the caller's stack

std::shared_ptr<const Program> limits_program(const char* name) {
  return load_program_file((testing::source_dir() / "tests/limits" / name).string());
}

// Runs f on a thread with a 256 KiB stack: a deep evaluation must not need it.
template <class F>
void on_small_stack(F f) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, 256 << 10);
  pthread_t t;
  auto body = [](void* p) -> void* {
    (*static_cast<F*>(p))();
    return nullptr;
  };
  ASSERT_EQ(pthread_create(&t, &attr, body, &f), 0);
  pthread_join(t, nullptr);
  pthread_attr_destroy(&attr);
}

TEST(Limits, DeepRecursionRunsWhenTheLimitAllowsIt) {
  auto program = limits_program("call_depth_finite.au");
  bool ok = false;
  std::string error;
  on_small_stack([&] {
    InterpretedEnvironment env(program);
    Limits l;
    l.call_depth = 10'001;
    env.set_limits(l);
    ok = env.reset(0) && env.step(Action::noop());
    error = env.error();
  });
  EXPECT_TRUE(ok) << error;
}

TEST(Limits, UnboundedRecursionOnASmallStackIsAnError) {
  auto program = limits_program("call_depth_unbounded.au");
  std::string error;
  on_small_stack([&] {
    InterpretedEnvironment env(program);
    EXPECT_FALSE(env.reset(0));
    error = env.error();
  });
  EXPECT_NE(error.find("call depth limit exceeded"), std::string::npos) << error;
}

// The cells budget's per-step part on specialised code (runtime/limits.hpp,
// cells): the compiled engine counts the elements its program constructs put
// into new lists, a part of what the interpreter counts. So with the smallest
// budget under which the interpreter finishes the episode (found by bisection),
// the compiled engine finishes it too, frame for frame; and a small budget stops
// it, so it does count. tests/budget/list_constructs.au uses every construct
// that is charged.
TEST(CellsBudget, CompiledFinishesEveryEpisodeTheInterpreterFinishes) {
  const auto path = testing::source_dir() / "tests/budget/list_constructs.au";
  const std::string text = read_text(path);
  auto program = load_program(SourceFile{path.string(), text});
  ASSERT_TRUE(lower_program(*program, "p").ok) << "the program must be specialised";
  std::string why;
  auto actions = parse_action_list(header(text, "actions"), &why);
  ASSERT_TRUE(actions) << why;
  auto frames_under = [&](const std::string& engine, int64_t cells, std::string* error) {
    using Frames = std::vector<std::vector<std::string>>;  // as text: palette ids are each environment's own
    auto env = make_environment(engine, program, &why);
    if (!env) {
      ADD_FAILURE() << engine << ": " << why;
      *error = why;
      return std::optional<Frames>();
    }
    Limits l;
    l.cells = cells;
    env->set_limits(l);
    Frames frames;
    bool ok = env->reset(5);
    if (ok) frames.push_back(frame_rows(env->frame(), env->palette()));
    for (size_t i = 0; ok && i < actions->size(); ++i)
      if ((ok = env->step((*actions)[i]))) frames.push_back(frame_rows(env->frame(), env->palette()));
    *error = ok ? "" : env->error();
    return ok ? std::optional<Frames>(frames) : std::nullopt;
  };
  std::string error;
  int64_t lo = 1, hi = 1'000'000;  // the interpreter fails under lo and finishes under hi
  ASSERT_FALSE(frames_under("interp", lo, &error));
  ASSERT_TRUE(frames_under("interp", hi, &error)) << error;
  while (hi - lo > 1) {
    const int64_t mid = lo + (hi - lo) / 2;
    (frames_under("interp", mid, &error) ? hi : lo) = mid;
  }
  auto interp = frames_under("interp", hi, &error);
  ASSERT_TRUE(interp) << error;
  auto compiled = frames_under("compiled", hi, &error);
  ASSERT_TRUE(compiled) << "with cells=" << hi << " the interpreter finishes, the compiled engine says: " << error;
  EXPECT_TRUE(*compiled == *interp) << "the frames differ under cells=" << hi;
  EXPECT_FALSE(frames_under("compiled", 20, &error));
  EXPECT_NE(error.find("memory budget exceeded: this step created more than 20 list elements"), std::string::npos)
      << error;
}

// The same allowance, as difftest applies it (harness/difftest.cpp): under
// budgets between the two engines' counts the interpreter stops in a step the
// compiled engine finishes; difftest replays the episode with the per-step
// budgets raised, finds the two agree there, and counts the episode as ended
// on a budget, not as a divergence. The allowance is the interpreter's alone:
// with the engines the other way round (the compiled engine as the reference)
// the same episodes are divergences.
TEST(CellsBudget, DifftestAllowsOnlyTheInterpretersLargerCount) {
  const auto path = testing::source_dir() / "tests/budget/list_constructs.au";
  auto program = load_program(SourceFile{path.string(), read_text(path)});
  DiffOptions o;
  o.seeds = 2;
  o.steps = 12;
  int64_t allowed_at = 0;  // a budget under which some episode ended on the allowance
  for (int64_t cells = 100; cells <= 3000; cells += 100) {
    o.limits.cells = cells;
    const DiffResult r = diff_engines(program, o);
    ASSERT_FALSE(r.setup_failed) << r.divergence;
    EXPECT_EQ(r.divergence, "") << "cells=" << cells;
    if (r.budget_ended) {
      // The interpreter stopped and the compiled engine ran on, or both stopped
      // in that step at different constructs.
      const std::string& b = r.first_budget;
      const bool interpreter_alone =
          b.find("interp failed (" + path.string()) != std::string::npos && b.find("compiled ran on") != std::string::npos;
      EXPECT_TRUE(interpreter_alone || b.find("both failed, with different errors") != std::string::npos)
          << b;
      EXPECT_NE(b.find("memory budget exceeded"), std::string::npos) << b;
      if (b.find("compiled ran on") != std::string::npos && !allowed_at) allowed_at = cells;
    }
  }
  ASSERT_GT(allowed_at, 0) << "no budget from 100 to 3,000 cells stopped the interpreter alone: the test tests nothing";
  o.limits.cells = allowed_at;
  std::swap(o.engine_a, o.engine_b);  // compiled first: its stopping later is not the interpreter's allowance
  const DiffResult reversed = diff_engines(program, o);
  EXPECT_EQ(reversed.budget_ended, 0u);
  EXPECT_NE(reversed.divergence.find("compiled ran on but interp failed"), std::string::npos) << reversed.divergence;
}

TEST(Limits, ParseTheLimitsFlag) {
  std::string why;
  auto l = limits::parse("call-depth=50,cells=7", &why);
  ASSERT_TRUE(l) << why;
  EXPECT_EQ(l->call_depth, 50);
  EXPECT_EQ(l->cells, 7);
  EXPECT_EQ(l->list_length, Limits{}.list_length);
  EXPECT_TRUE(limits::parse("", &why));
  for (const char* bad : {"depth=3", "cells", "cells=0", "cells=-4", "cells=1x", "cells=99999999999999999999"}) {
    EXPECT_FALSE(limits::parse(bad, &why)) << bad;
    EXPECT_FALSE(why.empty());
  }
  // Lists the text spells out need no check at run time: the budget has a floor.
  EXPECT_FALSE(limits::parse("list-length=999", &why));
  EXPECT_EQ(why, "'list-length=999': list-length must be at least 1000");
  EXPECT_TRUE(limits::parse("list-length=1000", &why));
  Limits tiny;
  tiny.list_length = 3;
  EXPECT_EQ(limits::normalised(tiny).list_length, limits::kMinListLength);
}

// Both engines apply the floor to a budget set through the API: a literal list
// of four elements is within it on either.
TEST(Limits, ListLengthBelowTheFloorIsTheFloorOnBothEngines) {
  auto program = load_program(SourceFile{"four.au", "(program (= GRID_SIZE 4) (= xs (initnext (list 1 2 3 4) xs)))"});
  Limits l;
  l.list_length = 3;
  for (const std::string& engine : testing::test_engines()) {
    std::string why;
    auto env = make_environment(engine, program, &why);
    ASSERT_TRUE(env) << why;
    env->set_limits(l);
    EXPECT_TRUE(env->reset(0)) << engine << ": " << env->error();
  }
}

// A two-cell object turned once per step: both engines stop at the same step,
// the (kMaxRotations + 1)th turn (they once stopped at 1,001 and 2,001).
TEST(Limits, RotationsStopAtTheSameTurnOnBothEngines) {
  auto program = load_program(SourceFile{
      "turns.au",
      "(program (= GRID_SIZE 8) (object Bar (Cell 0 0 \"red\") (Cell 1 0 \"red\"))\n"
      "  (= bar (initnext (Bar (Position 3 3)) (rotate (prev bar)))))"});
  for (const std::string& engine : testing::test_engines()) {
    std::string why;
    auto env = make_environment(engine, program, &why);
    ASSERT_TRUE(env) << why;
    ASSERT_TRUE(env->reset(0)) << engine << ": " << env->error();
    int steps = 0;
    while (steps < limits::kMaxRotations + 10 && env->step(Action::noop())) ++steps;
    EXPECT_EQ(steps, limits::kMaxRotations) << engine << ": " << env->error();
    EXPECT_NE(env->error().find("rotate: a cell turned more than 2000 times"), std::string::npos) << engine;
  }
}

TEST(Limits, ClonesKeepTheLimits) {
  auto program = limits_program("list_length.au");
  InterpretedEnvironment env(program);
  Limits l;
  l.list_length = 1000;
  env.set_limits(l);
  ASSERT_TRUE(env.reset(0));
  auto copy = env.clone();
  bool ok = true;
  for (int i = 0; ok && i < 12; ++i) ok = copy->step(Action::noop());
  EXPECT_FALSE(ok);
  EXPECT_NE(copy->error().find("the limit is 1000"), std::string::npos) << copy->error();
}

// --- syntax nesting: the reader refuses what every pass would recurse over

std::string nested(int depth) {
  std::string s;
  for (int i = 0; i < depth; ++i) s += "(+ 1 ";
  s += "1";
  for (int i = 0; i < depth; ++i) s += ")";
  return s;
}

TEST(Limits, DeeplyNestedProgramIsALocatedLoadError) {
  const std::string text = "(program (= GRID_SIZE 4)\n  (= x " + nested(20'000) + "))";
  try {
    load_program(SourceFile{"deep.au", text});
    FAIL() << "loaded";
  } catch (const CompileError& e) {
    EXPECT_EQ(e.formatted().rfind("deep.au:2:", 0), 0u) << e.formatted();
    EXPECT_NE(e.formatted().find(limits::syntax_nesting_error()), std::string::npos) << e.formatted();
  }
}

TEST(Limits, DeeplyNestedTriggerIsALocatedLoadError) {
  try {
    load_program(SourceFile{"p.au", "(program (= GRID_SIZE 4))"}, nested(5'000));
    FAIL() << "loaded";
  } catch (const CompileError& e) {
    EXPECT_EQ(e.formatted().rfind("<trigger>:1:", 0), 0u) << e.formatted();
  }
}

TEST(Limits, NestingJustUnderTheLimitLoadsAndRuns) {
  // (program (= x NESTED)) puts NESTED's outermost list at depth 3.
  const std::string text = "(program (= GRID_SIZE 4) (= x " + nested(limits::kMaxSyntaxNesting - 2) + "))";
  auto program = load_program(SourceFile{"ok.au", text});
  InterpretedEnvironment env(program);
  EXPECT_TRUE(env.reset(0)) << env.error();
}

// --- loaders: every library exception is a one-line message naming the file

// Writes `text` to the temporary file `name`, loads it with `load` and returns
// the error's text ("loaded" when nothing was thrown).
template <class Load>
std::string load_error(const std::string& name, const std::string& text, Load load) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  try {
    load(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "loaded";
}

std::string task_error(const std::string& name, const std::string& text) {
  return load_error(name, text, [](const std::filesystem::path& p) { agent::load_task(p); });
}
std::string trace_error(const std::string& name, const std::string& text) {
  return load_error(name, text, [](const std::filesystem::path& p) { load_trace_file(p.string()); });
}
std::string temp(const std::string& name) { return (std::filesystem::temp_directory_path() / name).string(); }

TEST(Limits, TaskSeedOutOfRangeIsAOneLineError) {
  const std::string msg = task_error(
      "autumn_limits_seed.json",
      R"({"type": "change_detection", "program": "ice", "wrong_program": "ice_wrong", "seed": 1e400})");
  EXPECT_NE(msg.find("autumn_limits_seed.json"), std::string::npos) << msg;
  EXPECT_NE(msg, "loaded");
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_EQ(msg.find("[json.exception"), std::string::npos) << "no raw library text: " << msg;
}

TEST(Limits, TraceFileWithWrongTypesIsAOneLineError) {
  const std::string msg =
      trace_error("autumn_limits_trace.json", R"({"traces": [{"seed": 1e400, "actions": [], "frames": [[]]}]})");
  EXPECT_EQ(msg.rfind(temp("autumn_limits_trace.json") + ": ", 0), 0u) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

// Numbers the loaders would otherwise wrap silently (get<int>, get<uint64_t>).
TEST(Limits, TraceSeedThatIsNegativeIsAnError) {
  EXPECT_EQ(trace_error("autumn_limits_trace_seed.json", R"({"traces": [{"seed": -1, "actions": [], "frames": [[]]}]})"),
            temp("autumn_limits_trace_seed.json") + ": trace 0: \"seed\" must be a non-negative integer");
}

TEST(Limits, TaskClickOutOfTheIntRangeIsAnError) {
  const std::string msg = task_error("autumn_limits_click.json",
                                     R"({"type": "masked_frame_prediction", "program": "p", "choices": [[[1]], [[2]]],
    "observations": [{"masked_grid": [[1]]}, {"action": {"type": "click", "x": 1, "y": 99999999999},
    "masked_grid": [[1]]}]})");
  EXPECT_NE(msg.find("observations[1].action: click coordinates are out of the 32-bit range"), std::string::npos)
      << msg;
}

TEST(Limits, TaskThatIsAFolderIsAnError) {
  const auto dir = std::filesystem::temp_directory_path();
  EXPECT_EQ(load_error("unused", "", [&](const std::filesystem::path&) { agent::load_task(dir); }),
            dir.string() + ": is a folder, not a file");
}

TEST(Limits, AnswersOutOfTheIntRangeAreErrors) {
  auto answers = [](const std::filesystem::path& p) { agent::load_answers(p); };
  EXPECT_NE(load_error("autumn_limits_answers.json", R"({"correct_idx": 4294967296})", answers)
                .find("\"correct_idx\" must be a choice index"),
            std::string::npos);
  EXPECT_NE(load_error("autumn_limits_answers.json", R"({"t_star": 4294967297})", answers)
                .find("\"t_star\" must be a non-negative integer"),
            std::string::npos);
}

}  // namespace
}  // namespace autumn::limits_test
