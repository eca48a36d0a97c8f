// diagnostic — the place prefixes of diagnostic.hpp. Out of line: every
// compiled module calls them only on its error paths.
#include "runtime/diagnostic.hpp"

namespace autumn {

std::string diagnostic_place(const std::string& file, int line, int col) {
  if (line == 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(col);
}

std::string diagnostic_prefix(const std::string& file, int line, int col, const std::string& severity) {
  return diagnostic_place(file, line, col) + ": " + severity + ": ";
}

std::string diagnostic_inside(const std::string& source, int line, int col) {
  return " (inside " + diagnostic_place(source, line, col) + ")";
}

}  // namespace autumn
