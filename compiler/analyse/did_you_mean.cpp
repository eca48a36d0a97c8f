// did_you_mean — see did_you_mean.hpp.
#include "compiler/analyse/did_you_mean.hpp"

#include <algorithm>

namespace autumn {

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::optional<std::string_view> did_you_mean(std::string_view name, const std::vector<std::string_view>& candidates) {
  std::optional<std::string_view> best;
  size_t best_d = 3;  // at most two edits
  for (std::string_view c : candidates) {
    // The lengths alone bound the distance from below: a 5 MB name (Diagnostics
    // tests one) is never compared letter by letter with every name in scope.
    const size_t gap = name.size() > c.size() ? name.size() - c.size() : c.size() - name.size();
    if (c == name || gap >= best_d) continue;
    const size_t d = edit_distance(name, c);
    if (d < best_d && 2 * d <= name.size()) best_d = d, best = c;
  }
  return best;
}

}  // namespace autumn
