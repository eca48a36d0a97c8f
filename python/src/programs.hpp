// programs — loading programs for the Python package, once.
//
// load() parses a program (text, name for messages, trigger, standard library)
// and keeps the result in a small cache keyed by the texts, so that a caller
// that makes a fresh Interpreter and run_script()s the same program on every
// reset, as MARAProtocol does, parses it once. The standard library argument
// follows the reference's run_script: empty means the file
// autumnstdlib/stdlib.sexp under the working directory (without the file the
// bundled library is used rather than none); a text that parses to the bundled
// library's statements (the reference's own file does: same definitions, other
// layout and comments) is the bundled library, and only then can the compiled
// engine serve the program (modules are built with the bundled library).
#pragma once
#include <memory>
#include <optional>
#include <string>

#include "compiler/analyse/program.hpp"

namespace autumn::py {

struct LoadedProgram {
  std::shared_ptr<const Program> program;
  bool compilable = true;  // the bundled standard library
};

// Throws CompileError for text that does not read or parse.
LoadedProgram load(const std::string& text, const std::string& name, const std::string& trigger,
                   const std::optional<std::string>& stdlib);

}  // namespace autumn::py
