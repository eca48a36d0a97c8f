// Reader and parser: each case is source text and the tree it must parse to, in
// the reference's AstPrinter notation (see compiler/parse/ast_print.hpp). The
// cases pin down the reference's reader quirks (docs/autumn-semantics.md §2).
#include <gtest/gtest.h>

#include "compiler/parse/ast_print.hpp"
#include "compiler/parse/parser.hpp"
#include "compiler/read/sexpr.hpp"

namespace autumn::parser_test {
namespace {

std::string parse_one(const std::string& text) {
  SourceFile f{"t.au", text};
  SymbolTable syms;
  Parser p(f, syms);
  Sexp root = read_sexprs(f);
  return ast_to_string(syms, *p.parse_expr(root.items.at(0)));
}

struct Case {
  const char* source;
  const char* tree;
};

class ParseCase : public ::testing::TestWithParam<Case> {};

TEST_P(ParseCase, ParsesToTree) { EXPECT_EQ(parse_one(GetParam().source), GetParam().tree) << GetParam().source; }

INSTANTIATE_TEST_SUITE_P(
    Reader, ParseCase,
    ::testing::Values(
        Case{"(+ 1 2)", "(+ (NUMBER 1) (NUMBER 2))"},
        Case{"foo-bar", "(var foo)"},                      // identifiers stop at '-'
        Case{"alive?", "(var alive)"},                     // ... and at '?'
        Case{"4.9", "(NUMBER 4)"},                         // no floats: stoi truncation
        Case{"3abc", "(NUMBER 3)"},
        Case{"-3", "(- (NUMBER 3))"},                      // negative atoms are unary minus
        Case{"+7", "(+ (NUMBER 7))"},
        Case{"(- x)", "(- (var x))"},
        Case{"(f)", "(var f)"},                            // a one-element list is a variable
        Case{"((f))", "(<call> (var f))"},                 // zero-argument call
        Case{"(f 1 x)", "(<call> (var f) (NUMBER 1) (var x))"},
        Case{"(if c then a else b)", "(if (var c) (var a) (var b))"},
        Case{"(if c foo a bar b)", "(if (var c) (var a) (var b))"},  // then/else are positional
        Case{"(and a b)", "(and (var a) (var b))"},
        Case{"(&& a b)", "(&& (var a) (var b))"},
        Case{"(.. o alive?)", "(<get>alive\\? (var o))"},  // raw, re-escaped field name
        Case{"(.. o \"x\")", "(<get>\"x\" (var o))"},
        Case{"(12 13)", "(NUMBER 12)"},                    // the tail after a literal is ignored
        Case{"(true 1 2)", "(BOOL true)"},
        Case{"\"red\"", "(STRING \"red\")"},               // strings keep their quotes
        Case{"(list)", "[]"},
        Case{"list", "[]"},
        Case{"(list 1 (list))", "[(NUMBER 1)[]]"},
        Case{"(fn (x y) x)", "(lambda (x y ) (var x))"},
        Case{"(--> x (+ x 1))", "(lambda (x ) (+ (var x) (NUMBER 1)))"},
        Case{"(--> () 1)", "(lambda () (NUMBER 1))"},
        Case{"(let (= x 1) x)", "{(<assign> x (NUMBER 1))(var x)}"},
        Case{"(= (.. o x) 3)", "(<set>x (var o) (NUMBER 3))"},
        Case{"(initnext 0 (+ (prev t) 1))",
             "(initnext (NUMBER 0) (+ (<call> (var prev) (var t)) (NUMBER 1)))"},
        Case{"(; a comment\n 1)", "(NUMBER 1)"},          // ';' at the start of an item
        Case{"abc;def", "(var abc)"},                      // ... but not inside an atom
        Case{"((.. e x))", "(<call> (<get>x (var e)))"}));

TEST(Parser, LogicalOperatorSpellings) {
  SourceFile f{"t.au", "(or a b) (| a b) (|| a b) (& a b)"};
  SymbolTable syms;
  Parser p(f, syms);
  Sexp root = read_sexprs(f);
  EXPECT_TRUE(p.parse_expr(root.items[0])->is_or);
  EXPECT_TRUE(p.parse_expr(root.items[1])->is_or);
  EXPECT_FALSE(p.parse_expr(root.items[2])->is_or);  // `||` is AND in the reference
  EXPECT_FALSE(p.parse_expr(root.items[3])->is_or);
}

TEST(Parser, CellCallsRecordTheNamesTheyMention) {
  SourceFile f{"t.au", "(Cell (+ x 1) (.. origin y) (if day then \"a\" else c))"};
  SymbolTable syms;
  Parser p(f, syms);
  ExprPtr e = p.parse_expr(read_sexprs(f).items[0]);
  std::vector<std::string> names;
  for (Sym s : e->cell_names) names.push_back(syms.name(s));
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"c", "day", "origin", "x", "y"}));
}

TEST(Parser, ProgramIgnoresLaterTopLevelFormsWithAWarning) {
  SourceFile f{"t.au", "(program (= x 1))\n(program (= y 2))"};
  SymbolTable syms;
  Parser p(f, syms);
  ParsedProgram prog = p.parse_program(read_sexprs(f));
  EXPECT_EQ(prog.stmts.size(), 1u);
  ASSERT_EQ(prog.warnings.size(), 1u);
  EXPECT_NE(prog.warnings[0].find("t.au:2:1: warning:"), std::string::npos);
}

}  // namespace
}  // namespace autumn::parser_test
