// diagnostic — how every message names its place, decided once.
//
// The frontend's errors (format_diagnostic), the interpreter's runtime errors
// and the compiled module's runtime errors all begin with this prefix (and end
// with the same "inside" suffix), so the two engines say the same text for the
// same failure:
//
//   prog.au:12:5: runtime error: ...   a place in the file
//   prog.au: runtime error: ...        line 0: no place (the file could not be
//                                      read, or the value no statement defines,
//                                      such as cacheRendered, broke a limit)
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace autumn {

// Where a program's locations move when a module built from one layout of a
// program serves another with the same tree (harness/module_key: relocation_between):
// the engines report errors at the moved locations, relocated as data when the
// message is made, never by rewriting its text.
struct Relocation {
  struct Move {
    int32_t from_line, from_col, to_line, to_col;
  };
  std::vector<Move> moves;  // sorted by (from_line, from_col)
  // (line, col) moved, or unchanged when the map does not have it.
  std::pair<int, int> at(int line, int col) const;
};

// The place alone: "prog.au:12:5", or "prog.au" for line 0.
std::string diagnostic_place(const std::string& file, int line, int col);

std::string diagnostic_prefix(const std::string& file, int line, int col, const std::string& severity);

// The library place an error located in the program came from:
// " (inside <stdlib>:40:3)".
std::string diagnostic_inside(const std::string& source, int line, int col);

// A message as it is safe to print: control bytes (newline and tab aside) and a
// UTF-8 byte-order mark shown escaped ("\x00", "\ufeff"), so a NUL cannot cut it
// short and nothing invisible hides in it; a run of more than 256 bytes without
// a space (a huge identifier or literal) shown as its start, "...(N bytes)..."
// and its end. Every diagnostic's message passes through it, in both engines.
std::string shown(std::string_view message);

// A type as the author writes it, from the reference's type string (the text
// the engines compare types by, which spells out every field): "class Ball
// {speed: Number, origin: ...}" is shown Ball, "List<class Ball {...}>" (List
// Ball), "List<Unknown>" (an empty list's) List, "AutumnFunc" Function; Number,
// Bool, String and Unknown as they are. Every message that names a type, in
// both engines and the linter, names it through this.
std::string shown_type(std::string_view reference_type);

}  // namespace autumn
