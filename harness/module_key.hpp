// module_key — what a cached module is looked up by, so that a comment-only or
// layout-only edit of a program does not recompile it.
//
// The key is the SHA-256 of the program's s-expressions as the reader sees them
// (compiler/read/sexpr): comments, whitespace and line breaks are not part of it;
// atoms are digested with their kind and length, so no two different trees share
// a key. Two texts with the same key are the same program to every later pass; only
// their source locations differ. A module built from one of them reports runtime
// errors at that text's locations, so LocationMap translates them: it pairs the
// nodes of the two texts in reading order and rewrites the leading
// "path:line:col:" of an error message.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace autumn {

// The canonical digest (64 hex digits); null when the text does not read
// (callers then key on program_digest).
std::optional<std::string> canonical_program_hash(const std::string& program_text,
                                                  const std::optional<std::string>& trigger);

// The SHA-256 of the exact text and trigger: what a cached module records as the
// program it was built from.
std::string program_digest(const std::string& program_text, const std::optional<std::string>& trigger);

class LocationMap {
 public:
  // `from`: the text a module was built from; `to`: the text being run. Both
  // must read and have the same canonical hash; otherwise the map is empty.
  LocationMap(const std::string& from, const std::string& to);
  bool identity() const { return identity_; }
  // "path:L:C: rest" with (L, C) a node of `from` becomes "path:L':C': rest";
  // anything else is returned unchanged.
  std::string rewrite(const std::string& error, const std::string& path) const;

 private:
  bool identity_ = true;
  std::map<std::pair<int, int>, std::pair<int, int>> map_;
};

}  // namespace autumn
