// module_key — what a cached module is looked up by, so that a comment-only or
// layout-only edit of a program does not recompile it.
//
// The key is the SHA-256 of the program's s-expressions as the reader sees them
// (compiler/read/sexpr): comments, whitespace and line breaks are not part of it;
// atoms are digested with their kind and length, so no two different trees share
// a key. Two texts with the same key are the same program to every later pass; only
// their source locations differ. A module built from one of them serves the other
// with its locations moved (relocation_between): the nodes of the two texts are
// paired in reading order, and the engine reports the moved location when it
// makes a message (runtime/diagnostic.hpp, Relocation), never by rewriting text.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "runtime/diagnostic.hpp"

namespace autumn {

// The canonical digest (64 hex digits); null when the text does not read
// (callers then key on program_digest).
std::optional<std::string> canonical_program_hash(const std::string& program_text,
                                                  const std::optional<std::string>& trigger);

// The SHA-256 of the exact text and trigger: what a cached module records as the
// program it was built from.
std::string program_digest(const std::string& program_text, const std::optional<std::string>& trigger);

// Where the nodes of `from` (the text a module was built from) stand in `to`
// (the text being run), paired in reading order: what the engines move their
// program locations by (Environment::set_relocation). Null when the texts are
// the same, or do not read as one tree.
std::shared_ptr<const Relocation> relocation_between(const std::string& from, const std::string& to);

}  // namespace autumn
