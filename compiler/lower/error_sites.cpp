// error_sites — see error_sites.hpp.
#include "compiler/lower/error_sites.hpp"

namespace autumn::lower {

void ErrorSites::reset(const Expr* outermost) {
  stack_.clear();
  if (outermost) stack_.push_back(outermost);
}

const Expr* ErrorSites::innermost_of_program() const {
  for (auto it = stack_.rbegin(); it != stack_.rend(); ++it)
    if ((*it)->loc.source == SourceId::Program) return *it;
  return nullptr;
}

bool ErrorSites::in_program() const { return innermost_of_program() != nullptr; }

int ErrorSites::here() {
  ErrorLoc l;
  if (!stack_.empty()) l.at = stack_.back()->loc;
  if (const Expr* e = innermost_of_program()) {
    l.in_program = true;
    l.program_at = e->loc;
  }
  l.prefix = prefix_;
  return intern(l);
}

int ErrorSites::intern(const ErrorLoc& l) {
  for (size_t i = 0; i < m_.locations.size(); ++i) {
    const ErrorLoc& o = m_.locations[i];
    if (o.at.line == l.at.line && o.at.col == l.at.col && o.at.source == l.at.source &&
        o.in_program == l.in_program && o.program_at.line == l.program_at.line &&
        o.program_at.col == l.program_at.col && o.prefix == l.prefix)
      return static_cast<int>(i);
  }
  m_.locations.push_back(l);
  return static_cast<int>(m_.locations.size() - 1);
}

void ErrorSites::unsupported(const std::string& why) const {
  SourceLoc at;
  if (!stack_.empty()) at = stack_.back()->loc;
  if (const Expr* e = innermost_of_program()) at = e->loc;
  throw Unsupported{why, at};
}

void ErrorSites::dynamic_site(const std::string& why) {
  SourceLoc at;
  if (const Expr* e = innermost_of_program()) at = e->loc;
  for (const DynamicSite& d : m_.dynamic_sites)
    if (d.loc.line == at.line && d.loc.col == at.col && d.why == why) return;
  m_.dynamic_sites.push_back(DynamicSite{at, why});
}

}  // namespace autumn::lower
