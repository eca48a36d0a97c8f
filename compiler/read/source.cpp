#include "compiler/read/source.hpp"

namespace autumn {

std::string format_diagnostic(const std::string& file, SourceLoc loc, const std::string& severity,
                              const std::string& message) {
  // Line 0 is no place in the file (it could not be opened): "file: error: ...".
  if (loc.line == 0) return file + ": " + severity + ": " + message;
  return file + ":" + std::to_string(loc.line) + ":" + std::to_string(loc.col) + ": " + severity +
         ": " + message;
}

std::string CompileError::formatted() const { return format_diagnostic(file_, loc_, "error", what()); }

}  // namespace autumn
