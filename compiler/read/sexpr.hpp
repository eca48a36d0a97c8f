// sexpr — the s-expression reader (pass 1: read).
//
// Reproduces the reference's vendored "sexpresso" reader, which decides what the
// parser sees:
//  * whitespace (C isspace) separates items; '(' and ')' delimit lists;
//  * ';' starts a comment only at the start of an item (abc;def is one atom);
//  * "..." is a string atom; escapes \' \" \? \\ \a \b \f \n \r \t \v are decoded,
//    any other escape, a raw newline or a missing closing quote is an error; the
//    atom text keeps its surrounding quotes;
//  * anything else is a symbol atom up to whitespace or a parenthesis, and its text
//    is re-escaped (a backslash before ' " ? \ \a \b), so `alive?` reads as
//    `alive\?`. This matters for raw field names in (.. o f) and object names.
// Unlike the reference (which crashes on unbalanced input) every problem is a
// CompileError with the location of the offending character. Lists nest at most
// limits::kMaxSyntaxNesting deep (runtime/limits.hpp), so the parser, the
// analysis and the back ends, which recurse over the tree, never run out of stack.
#pragma once
#include <string>
#include <vector>

#include "compiler/read/source.hpp"

namespace autumn {

struct Sexp {
  bool is_list = false;
  bool is_string = false;  // a "..." atom
  std::string text;        // atom text (escaped symbol, or quoted string)
  std::vector<Sexp> items; // list children
  SourceLoc loc;           // of the atom, or of the '(' of a list
  SourceLoc end;           // for lists: the ')' (used to report missing parts)

  // The reference's view: an atom counts as having one child.
  size_t child_count() const { return is_list ? items.size() : 1; }
};

// Reads the whole text; returns the implicit top-level list of forms.
Sexp read_sexprs(const SourceFile& file);

// Text of a form for messages, shortened to `limit` characters.
std::string sexp_snippet(const Sexp& s, size_t limit = 60);

}  // namespace autumn
