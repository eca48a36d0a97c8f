// fuzz_frontend — libFuzzer target: the reader, parser and analysis.
//
// The input is a program text; it is loaded as a program, and (as a second
// case) as the trigger condition of a small fixed program. Bad input must be a
// CompileError with a location inside the text; anything else escaping, a
// crash or a sanitizer report is a bug. The standard library is a one-line
// stand-in: reading and analysing the real one again for every input would be
// most of the work, and it is the same text every time (the interp target runs
// with the real one).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "compiler/analyse/program.hpp"
#include "compiler/parse/ast_print.hpp"

namespace {

const std::string kStdlib = "(module (= background \"black\") (= moveLeft (--> obj obj)))";

// A located, one-line message: 1-based, within the text's lines.
void check_error(const autumn::CompileError& e, const std::string& text) {
  const auto loc = e.loc();
  const long lines = 1 + static_cast<long>(std::count(text.begin(), text.end(), '\n'));
  if (loc.line < 1 || loc.col < 1 || loc.line > lines) std::abort();
  const std::string msg = e.what();
  if (msg.find('\n') != std::string::npos || msg.find('\r') != std::string::npos) std::abort();
}

void load_as_program(const std::string& text) {
  try {
    auto p = autumn::load_program(autumn::SourceFile{"fuzz.au", text}, std::nullopt, kStdlib);
    for (const auto& st : p->stmts)
      if (st.kind == autumn::StmtKind::Expr) (void)autumn::ast_to_string(p->symbols, *st.expr);
  } catch (const autumn::CompileError& e) {
    check_error(e, text);
  }
}

void load_as_trigger(const std::string& text) {
  try {
    autumn::load_program(autumn::SourceFile{"t.au", "(program (= GRID_SIZE 4) (= x (initnext 0 (+ x 1))))"}, text,
                         kStdlib);
  } catch (const autumn::CompileError& e) {
    check_error(e, text);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  load_as_program(text);
  if (size < 512) load_as_trigger(text);
  return 0;
}
