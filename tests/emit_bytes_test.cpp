// Emitted code always compiles: program text with every byte value in its
// string literals and comments (including the old raw-string terminator
// `)AUTUMN"`) goes through autumnc into a module that the project's compiler
// builds, for a specialised program and for an embedded one (recursion makes
// the lowering give up), and each module runs exactly as the interpreter.
#include <gtest/gtest.h>

#include "compiler/analyse/program.hpp"
#include "compiler/emit/emit_module.hpp"
#include "compiler/lower/lower.hpp"
#include "harness/difftest.hpp"
#include "harness/engine.hpp"

namespace autumn::emit_bytes_test {
namespace {

// Every byte a string literal can hold raw (all but newline, quote, backslash),
// then those three escaped.
std::string all_bytes_string() {
  std::string s = "\"";
  for (int b = 0; b < 256; ++b)
    if (b != '\n' && b != '"' && b != '\\') s += static_cast<char>(b);
  return s + "\\n\\\"\\\\\"";
}

// A comment line with every byte but the two that end it (newline, CR).
std::string all_bytes_comment() {
  std::string s = "  ;";
  for (int b = 0; b < 256; ++b)
    if (b != '\n' && b != '\r') s += static_cast<char>(b);
  return s + " )AUTUMN\" )AUTUMN\"\" )\" )AUTUMN\"AUTUMN( */ /* \\\n";
}

std::string program_text(bool recursive) {
  const std::string s = all_bytes_string();
  // As a colour, a name crosses the module ABI as a C string: no NUL in it
  // (a colour name with a NUL byte is a known difference, docs/design.md).
  const std::string colour = "\"" + s.substr(2);
  std::string t = "(program\n" + all_bytes_comment() + "  (= GRID_SIZE 4)\n";
  t += "  (= s (initnext " + s + " s))\n";
  t += "  (= same (initnext false (== s " + s + ")))\n";
  t += "  (object Dot (: c String) (Cell 0 0 c))\n";
  t += "  (= d (initnext (Dot \"red\" (Position 1 1)) (Dot (if same then " + colour + " else \"blue\") (Position 2 2))))\n";
  if (recursive) t += "  (= f (fn (n) (if (== n 0) then 0 else (f (- n 1)))))\n  (= z (initnext (f 3) (f 2)))\n";
  t += all_bytes_comment() + ")\n";
  return t;
}

void compiles_and_agrees(bool recursive) {
  auto program = load_program(SourceFile{recursive ? "bytes_embedded.au" : "bytes_specialised.au",
                                         program_text(recursive)});
  EXPECT_EQ(lower_program(*program, "p").ok, !recursive) << "the program should lower as intended";
  std::string why;
  auto env = make_environment("compiled", program, &why);  // AUTUMN_STRICT_MODULES: no fallback
  ASSERT_TRUE(env) << why;
  DiffOptions o;
  o.seeds = 2;
  o.steps = 5;
  DiffResult r = diff_engines(program, o);
  EXPECT_EQ(r.divergence, "");
  EXPECT_EQ(r.errored, 0u);
}

TEST(EmitBytes, SpecialisedModuleCompiles) { compiles_and_agrees(false); }
TEST(EmitBytes, EmbeddedModuleCompiles) { compiles_and_agrees(true); }

// The embedded module carries the text itself: emit it for every single byte in
// a comment and in a string, and check the emitted literal decodes to the text.
TEST(EmitBytes, EmbeddedTextKeepsEveryByte) {
  ModuleSource src;
  src.name = "bytes";
  src.program_path = "bytes.au";
  src.force_embedded = true;
  src.program_text = program_text(false);
  const std::string module = emit_module(src);
  EXPECT_EQ(module.find(")AUTUMN\""), std::string::npos) << "the program text must not appear raw";
  for (unsigned char c : module)
    EXPECT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7f)) << "raw byte " << int(c) << " in the emitted source";
}

}  // namespace
}  // namespace autumn::emit_bytes_test
