// did_you_mean — the one rule for suggesting a name in place of a misspelt one.
//
// A candidate is suggested when it is within two edits (insertions, deletions,
// substitutions) of the name and at most half the name's length away, so "x" is
// never "corrected" to "y"; of several, the nearest, and of equally near ones
// the first given. Colour names (colour_names.hpp) and names no construct binds
// (analyse/program.cpp) both ask it. Test: tests/lint_test.cpp (DidYouMean).
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace autumn {

size_t edit_distance(std::string_view a, std::string_view b);

// The suggestion is one of `candidates` (a view of the caller's storage).
std::optional<std::string_view> did_you_mean(std::string_view name, const std::vector<std::string_view>& candidates);

}  // namespace autumn
