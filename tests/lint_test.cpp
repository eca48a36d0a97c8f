// Warnings that teach (compiler/analyse/lint): each mistake the reference accepts
// silently gets one located warning that says what will happen; correct programs
// (programs/, the conformance corpus) get none of the new kinds; autumnc refuses
// programs that cannot run, and --Werror makes warnings errors.
#include <gtest/gtest.h>

#include "compiler/analyse/did_you_mean.hpp"
#include "compiler/analyse/program.hpp"
#include "harness/engine.hpp"
#include "runtime/diagnostic.hpp"
#include "test_support.hpp"

namespace autumn::lint_test {
namespace {

std::vector<std::string> warnings_of(const std::string& body) {
  return load_program(SourceFile{"w.au", "(program\n" + body + ")"})->warnings;
}

void expect_warning(const std::string& body, const std::string& want) {
  auto w = warnings_of(body);
  ASSERT_EQ(w.size(), 1u) << body << (w.empty() ? "" : "\n" + w[0] + (w.size() > 1 ? "\n" + w[1] : ""));
  EXPECT_EQ(w[0], want);
}

TEST(Lint, TruncatedAtoms) {
  expect_warning("(= p (Position 1.7 1))",
                 "w.au:2:16: warning: '1.7' reads as the integer 1 (Autumn numbers are whole numbers)");
  expect_warning("(= x 3px)", "w.au:2:6: warning: '3px' reads as the integer 3 (Autumn numbers are whole numbers)");
  expect_warning("(= x -2.5)", "w.au:2:6: warning: '-2.5' reads as the integer -2 (Autumn numbers are whole numbers)");
  expect_warning("(= move-up 1)",
                 "w.au:2:4: warning: 'move-up' reads as the name 'move' (names end at the first character that is "
                 "not a letter, digit or underscore)");
  EXPECT_TRUE(warnings_of("(= x -3) (= y (.. (Position 1 2) x)) (= z \"a-b 1.5\")").empty());
}

TEST(Lint, ColourNames) {
  expect_warning("(object A (Cell 0 0 \"brwn\"))",
                 "w.au:2:21: warning: \"brwn\" is not a colour the benchmark draws (it is drawn black); did you "
                 "mean \"brown\"?");
  expect_warning("(object A (: lit Bool) (Cell 0 0 (if lit then \"Red\" else \"zzzzzz\")))",
                 "w.au:2:58: warning: \"zzzzzz\" is not a colour the benchmark draws (it is drawn black)");
  expect_warning("(= background \"blak\")",
                 "w.au:2:15: warning: \"blak\" is not a colour the benchmark draws (it is drawn black); did you mean "
                 "\"black\"?");
  EXPECT_TRUE(warnings_of("(object A (Cell 0 0 \"DarkGray\")) (= background \"white\")").empty());
}

TEST(Lint, DuplicateObjects) {
  expect_warning("(object A (Cell 0 0 \"red\"))\n(object A (Cell 0 0 \"blue\"))",
                 "w.au:3:1: warning: object 'A' is defined again (first at line 2); this definition replaces the "
                 "earlier one");
}

TEST(Lint, CallArity) {
  expect_warning("(= f (fn (a b) (+ a b))) (= x (f 1 2 3))",
                 "w.au:2:31: warning: 'f' takes 2 arguments but is given 3; the extra ones are ignored");
  expect_warning("(= f (fn (a b) (+ a b))) (= x (f 1 2)) (on left (= x (f 1)))",
                 "w.au:2:54: warning: 'f' takes 2 arguments but is given 1; the call is an error at run time");
  expect_warning("(object A (: k Number) (Cell 0 0 \"red\")) (= a (A (Position 0 0)))",
                 "w.au:2:47: warning: object 'A' is made from 1 field and an origin Position (2 arguments) but is "
                 "given 1; that is an error at run time");
  expect_warning("(= x (length (list 1) (list 2)))",
                 "w.au:2:6: warning: 'length' takes 1 argument but is given 2; that is an error at run time");
  // A name bound to something else somewhere (a parameter, another value) is not judged.
  EXPECT_TRUE(warnings_of("(= f (fn (a) a)) (= g (fn (f) (f 1 2))) (= x (g 1))").empty());
}

TEST(Lint, FunctionNamedButNotCalled) {
  expect_warning("(= step (fn () 1)) (= x (initnext 0 (prev x))) (on left (step))",
                 "w.au:2:57: warning: '(step)' is the function 'step' itself, not a call (a call with no arguments "
                 "is written '((step))')");
  // Where function values are called: on-clause conditions and and/or operands; and ((f)).
  EXPECT_TRUE(warnings_of("(= x (initnext 0 (prev x))) (on (clicked) (= x 1)) (on (& (left) true) (= x 2))").empty());
  EXPECT_TRUE(warnings_of("(= step (fn () 1)) (= x (initnext 0 (prev x))) (on left (= x ((step))))").empty());
  EXPECT_TRUE(warnings_of("(= f (fn (a) (+ a 1))) (= g (map (fn (y) (f y)) (list 1)))").empty());
}

TEST(Lint, Types) {
  expect_warning("(object A (: speed Float) (Cell 0 0 \"red\"))",
                 "w.au:2:11: warning: 'Float' is not a type (Bool, String, Number, Int, Position, Cell, RenderedElem, "
                 "or an object defined above); printing an object of this class fails at run time");
  expect_warning("(: lives Int) (= lives (initnext \"three\" (prev lives)))",
                 "w.au:2:34: warning: 'lives' is declared Int but is given a String; assigning it is an error at "
                 "run time");
  EXPECT_TRUE(warnings_of("(object B (Cell 0 0 \"red\")) (object A (: b B) (: l (List Position)) (Cell 0 0 \"red\")) "
                          "(: n Int) (= n 3)")
                  .empty());
}

// What the syntax proves about types (lint.cpp, static types): an operator given
// a value of the wrong type, a declared global given another class. Each is the
// runtime error both engines raise when the expression is evaluated.
TEST(Lint, ProvenTypeErrors) {
  expect_warning("(= steps (initnext 0 (+ (prev steps) \"one\")))",
                 "w.au:2:22: warning: '(+ ...)' needs two numbers, but its second operand is always a String: "
                 "evaluating it is an error at run time");
  expect_warning("(object Ball (Cell 0 0 \"red\")) (object Paint (Cell 0 0 \"blue\")) (: b Paint) "
                 "(= b (initnext (Ball (Position 1 1)) (prev b)))",
                 "w.au:2:92: warning: 'b' is declared Paint but is given a Ball; assigning it is an error at run time");
  // Through names every value of which has one type, builtins' results and if.
  expect_warning("(= label \"hi\") (= n (initnext 0 (- 1 label)))",
                 "w.au:2:33: warning: '(- ...)' needs two numbers, but its second operand is always a String: "
                 "evaluating it is an error at run time");
  expect_warning("(= n (! (length (list 1))))",
                 "w.au:2:6: warning: '(! ...)' needs a Bool, but its operand is always a Number: evaluating it is an "
                 "error at run time");
  expect_warning("(= n (< (if (== 1 2) then true else false) 3))",
                 "w.au:2:6: warning: '(< ...)' needs two numbers, but its first operand is always a Bool: evaluating "
                 "it is an error at run time");
  // (f) is the function f itself, not a call: a Function.
  auto w = warnings_of("(= f (fn () \"s\")) (= y (+ (f) 1))");
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NE(w[0].find("its first operand is always a Function"), std::string::npos) << w[0];
  // Nothing where a value's type is not proven: a name given values of two types,
  // one a parameter shadows, a field, an if whose branches differ, a
  // function's result.
  EXPECT_TRUE(warnings_of("(= x (initnext 0 \"s\")) (= y (+ x 1))").empty());
  EXPECT_TRUE(warnings_of("(= x \"s\") (= f (fn (x) (+ x 1))) (= y (f 2))").empty());
  // Inside a function scope is dynamic: the stdlib's parameters named x (and any
  // caller's) may be the x in scope. At the top level x is the global.
  EXPECT_TRUE(warnings_of("(= x \"s\") (= f (fn (a) (+ x a))) (= y (f 2))").empty());
  EXPECT_EQ(warnings_of("(= x \"s\") (= y (+ x 1))").size(), 1u);
  EXPECT_TRUE(warnings_of("(object A (: x Number) (Cell x 0 \"red\")) (= x \"s\") (= a (A 1 (Position 0 0)))").empty());
  EXPECT_TRUE(warnings_of("(= y (+ 1 (if (== 1 2) then 1 else \"s\")))").empty());
  EXPECT_TRUE(warnings_of("(= x (initnext 0 (prev x))) (= y (+ (prev x) 1))").empty());
  expect_warning("(= x (initnext \"a\" (prev x))) (= y (initnext 0 (+ (prev x) 1)))",
                 "w.au:2:48: warning: '(+ ...)' needs two numbers, but its first operand is always a String: "
                 "evaluating it is an error at run time");
  EXPECT_TRUE(warnings_of("(= f (fn (a) \"s\")) (= y (+ (f 1) 1))").empty());
  EXPECT_TRUE(warnings_of("(: n Int) (= n (initnext (+ 1 2) (prev n))) (= t (! (< n 3)))").empty());
}

// Runtime errors name types as the author writes them (shown_type), on both
// engines: a class by its name, not the reference's dump of every field.
TEST(Lint, RuntimeErrorsNameTypesAsWritten) {
  EXPECT_EQ(shown_type("class Ball {speed: Number, origin: class Position {x: Number, y: Number, }, elems: "
                       "List<class Cell {x: Expr, y: Expr, color: Expr, }>, }"),
            "Ball");
  EXPECT_EQ(shown_type("List<List<class Position {x: Number, y: Number, }>>"), "(List (List Position))");
  EXPECT_EQ(shown_type("List<Unknown>"), "List");
  EXPECT_EQ(shown_type("AutumnFunc"), "Function");
  EXPECT_EQ(shown_type("Number"), "Number");
  const auto p = load_program(SourceFile{"t.au", "(program\n  (= GRID_SIZE 4)\n  (object Ball (: speed Number) (Cell 0 0 "
                                                 "\"red\"))\n  (= b (Ball 1 (Position 0 0)))\n  (= n (initnext 0 (+ (prev n) b))))"});
  for (const std::string& engine : testing::test_engines()) {
    std::string why;
    auto env = make_environment(engine, p, &why);
    ASSERT_TRUE(env) << why;
    EXPECT_FALSE(env->reset(0) && env->step(Action::noop())) << engine;
    EXPECT_EQ(env->error(), "t.au:5:20: runtime error: binary + needs two numbers, got Number and Ball") << engine;
  }
}

// Correct programs stay quiet: no program of programs/ draws any warning.
TEST(Lint, OrSpelledAsAnd) {
  expect_warning("(= t (|| true false))",
                 "w.au:2:6: warning: '(|| ...)' is AND in Autumn, as in the reference interpreter; OR is written "
                 "(or ...) or (| ...)");
  EXPECT_TRUE(warnings_of("(= t (or true false)) (= u (| true false)) (= v (&& true true))").empty());
}

TEST(Lint, GlobalsTheLibraryOrConstructionOverwrite) {
  expect_warning("(= delta 3)",
                 "w.au:2:1: warning: the global 'delta' is overwritten whenever the standard library's "
                 "'adjacentElem' runs (that assigns the name: `let` does not make a new one)");
  auto w = warnings_of("(object A (Cell 0 0 \"red\")) (= allCells 2)");
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0], "w.au:2:29: warning: the global 'allCells' is overwritten whenever an object is made (that "
                  "assigns the name: `let` does not make a new one)");
  EXPECT_TRUE(warnings_of("(= allCells 2) (= deltaX 1)").empty()) << "no objects: nothing assigns allCells";
}

TEST(Lint, DidYouMean) {
  EXPECT_EQ(did_you_mean("moveLeftNoColision", {"moveLeft", "moveLeftNoCollision"}), "moveLeftNoCollision");
  EXPECT_EQ(did_you_mean("x", {"y", "xs"}), std::nullopt) << "one letter is never corrected";
  EXPECT_EQ(did_you_mean("rd", {"red"}), "red");
  EXPECT_EQ(did_you_mean("zzzzzz", {"red", "blue"}), std::nullopt);
  EXPECT_EQ(did_you_mean("abcd", {"abce", "abcf"}), "abce") << "of equally near, the first";
  expect_warning("(object Ball (Cell 0 0 \"red\")) (= b (initnext (Ball (Position 1 1)) (moveLeftNoColision (prev b))))",
                 "w.au:2:70: warning: 'moveLeftNoColision' is not defined anywhere; evaluating it is a runtime "
                 "error; did you mean 'moveLeftNoCollision'?");
}

TEST(Lint, ProgramsAreClean) {
  for (const auto& f : testing::files_in(testing::source_dir() / "programs", ".au")) {
    auto p = load_program_file(f.string());
    EXPECT_TRUE(p->warnings.empty()) << f << ": " << (p->warnings.empty() ? "" : p->warnings[0]);
  }
}

struct Cmd {
  int status;
  std::string out;
};
Cmd run(const std::string& cmd) {
  Cmd r{0, ""};
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) r.out.append(buf.data(), n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

TEST(Lint, AutumncRefusesProgramsThatCannotRun) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("autumn_lint_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string grid = write("grid.au", "(program (= GRID_SIZE -4))");
  Cmd g = run(std::string(AUTUMNC_CLI) + " " + grid + " -o " + dir.string());
  EXPECT_EQ(g.status, 1);
  EXPECT_NE(g.out.find(grid + ":1:10: error: GRID_SIZE must be a number from 1 to 4096, got -4"), std::string::npos)
      << g.out;
  const std::string type = write("type.au", "(program\n  (= x (+ 1 \"two\")))");
  Cmd t = run(std::string(AUTUMNC_CLI) + " " + type + " -o " + dir.string());
  EXPECT_EQ(t.status, 1);
  EXPECT_NE(t.out.find(type + ":2:8: runtime error: binary + needs two numbers"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("fails at start-up (seed 0), so it cannot run"), std::string::npos) << t.out;
  const std::string warn = write("warn.au", "(program (= p (Position 1.7 1)))");
  Cmd ok = run(std::string(AUTUMNC_CLI) + " " + warn + " -o " + dir.string());
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("warning: '1.7' reads as the integer 1"), std::string::npos) << ok.out;
  EXPECT_EQ(run(std::string(AUTUMNC_CLI) + " --Werror " + warn + " -o " + dir.string()).status, 1);
  Cmd cli = run(std::string(AUTUMN_CLI) + " --Werror run " + warn);
  EXPECT_EQ(cli.status, 1);
  EXPECT_NE(cli.out.find("1 warning treated as errors (--Werror)"), std::string::npos) << cli.out;
  Cmd after = run(std::string(AUTUMN_CLI) + " run " + warn + " --Werror");  // after the subcommand too
  EXPECT_EQ(after.status, 1) << after.out;
  EXPECT_NE(after.out.find("1 warning treated as errors (--Werror)"), std::string::npos) << after.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace autumn::lint_test
