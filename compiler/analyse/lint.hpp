// lint — located warnings for mistakes the reference accepts without a word.
//
// The reference reads many wrong programs happily and then does something the
// author did not mean. analyse (program.cpp) runs these checks over the user's
// program (never the stdlib) and adds one "file:line:col: warning: ..." per
// finding to Program::warnings; `--Werror` turns them into errors. Each check
// says what the reference will actually do:
//  * atoms the reader truncates: `1.7` is 1, `3px` is 3, `move-left` is `move`;
//  * colour strings (the colour of a Cell, `background`) that are not colour
//    names the benchmark draws ("brwn": drawn black), with a suggestion;
//  * an object class defined twice (the later definition replaces the earlier);
//  * calls with more arguments than the function, object class or builtin takes
//    (extras are ignored or an error) or fewer (an error at run time);
//  * `(f)` where f is a function, outside the places that call function values
//    (on-clause conditions, and/or operands): it is the function, not a call;
//  * type declarations naming no type, and declared types contradicted by a
//    literal value.
// A GRID_SIZE that cannot be painted is not a warning but an error of analysis
// (compiler/analyse/program.cpp, the range in runtime/limits.hpp).
#pragma once
#include <string>
#include <vector>

namespace autumn {

struct Program;

// Appends the warnings about p's program file.
void lint_program(const Program& p, std::vector<std::string>& warnings);

// The error that ends a run under --Werror when the program has warnings
// ("prog.au: error: 2 warnings treated as errors (--Werror)"); autumn and autumnc say it alike.
std::string warnings_as_errors(const std::string& path, size_t count);

}  // namespace autumn
