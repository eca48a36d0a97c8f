#include "compiler/read/source.hpp"

#include "runtime/diagnostic.hpp"

namespace autumn {

std::string format_diagnostic(const std::string& file, SourceLoc loc, const std::string& severity,
                              const std::string& message) {
  return diagnostic_prefix(file, loc.line, loc.col, severity) + shown(message);
}

std::string CompileError::formatted() const { return format_diagnostic(file_, loc_, "error", what()); }

}  // namespace autumn
