// program — a loaded, analysed Autumn program (pass 3: analyse).
//
// load_program reads and parses the bundled standard library and the user's
// program into one symbol table, parses the trigger condition if any, and adds
// what both back ends need and the reference computes implicitly:
//  * for every object class, its initializer as an ordinary lambda
//    ((fields... origin) -> [fields..., origin, cells]) so that construction goes
//    through the normal call/assignment machinery (including the `allCells`
//    temporary that clobbers a global of that name);
//  * the render method's body, shared by all classes;
//  * located warnings for names that are bound nowhere (evaluating them is an
//    "undefined variable" error at run time, as in the reference).
// A Program is immutable once loaded and can be shared by many interpreters
// (threads included).
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "compiler/analyse/builtins.hpp"
#include "compiler/parse/ast.hpp"
#include "compiler/read/source.hpp"

namespace autumn {

struct WellKnownNames {
  Sym GRID_SIZE, FRAME_RATE, background, SpecialConditionTriggered, cacheRendered, click,
      allCells, isList, origin, elems, x, y, color, position, render, e;
  Sym Bool, String, Number, Int, Position, Cell, RenderedElem;
};

struct Program {
  SourceFile file;
  SourceFile stdlib;
  SymbolTable symbols;
  std::vector<Stmt> stdlib_stmts;
  std::vector<Stmt> stmts;
  ExprPtr trigger;           // null when no trigger condition was given
  std::string trigger_text;
  ExprPtr render_lambda;     // (--> () (map (--> e (RenderedElem ...)) elems))
  std::vector<std::string> warnings;
  WellKnownNames names;
  // False when neither the program nor the trigger mentions uniformChoice or
  // randomPositions: the RNG can then never be drawn from.
  bool uses_random = true;
  // The host render's order of the globals start-up defines (render_order.hpp):
  // initnext declarations, then first definitions, cacheRendered last. Globals
  // first defined later are drawn after these, in first-definition order.
  std::vector<Sym> render_order;
  // Per symbol, where the program defines it, for errors about a global's value
  // (GRID_SIZE's range, the state budget): its first top-level assignment, else
  // its first assignment anywhere, in the program and then the stdlib; line 0
  // when nothing assigns it.
  std::vector<SourceLoc> definitions;
  // True when a top-level statement defines a global only on some paths (inside an
  // `if` or the right operand of and/or), so its place in render_order depends on
  // the run; such globals are not in render_order.
  bool start_defines_conditionally = false;
  // The symbol of each builtin, indexed by Builtin.
  std::array<Sym, kBuiltinCount> builtin_syms{};

  // The builtin named `s`, if any (the names are interned consecutively, in table order).
  std::optional<Builtin> builtin_of(Sym s) const {
    if (s < builtin_syms.front() || s > builtin_syms.back()) return std::nullopt;
    return static_cast<Builtin>(s - builtin_syms.front());
  }

  const std::string& name(Sym s) const { return symbols.name(s); }
  const std::string& file_name(SourceId id) const;
};

// Throws CompileError for unreadable or unparsable input.
// `stdlib`: another standard library text in place of the bundled one (the
// Python binding's run_script takes it as an argument).
std::shared_ptr<const Program> load_program(SourceFile file,
                                            const std::optional<std::string>& trigger = std::nullopt,
                                            const std::optional<std::string>& stdlib = std::nullopt);
// A program file's text; a file that cannot be read (missing, a folder) is a
// CompileError at line 0, "path: error: ...". autumnc reads its input with it too.
std::string read_program_text(const std::string& path);
// read_program_text, then load_program.
std::shared_ptr<const Program> load_program_file(const std::string& path,
                                                 const std::optional<std::string>& trigger = std::nullopt);

// The bundled standard library text (compiler/stdlib/stdlib.au).
const std::string& stdlib_text();

}  // namespace autumn
