// lower — the lowering as a sequence of passes (see lower.hpp).
#include "compiler/lower/lower.hpp"

#include "compiler/lower/passes.hpp"
#include "compiler/lower/print_cpp.hpp"
#include "compiler/lower/specialise.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn {

// A reason the lowering gives (no severity: autumnc lists them under its own
// heading), at its place when it has one.
static std::string located(const Program& p, SourceLoc loc, const std::string& why) {
  if (!loc.line) return why;
  return diagnostic_place(p.file_name(loc.source), loc.line, loc.col) + ": " + why;
}

Lowered lower_program(const Program& program, const std::string& program_name) {
  Lowered out;
  lower::Module m;
  m.name = program_name;
  m.program_path = program.file.name;
  try {
    lower::specialise_program(program, m);
    lower::settle_references(m);
    lower::resolve_aliases(m);
    lower::remove_dead_names(m);
    lower::move_last_uses(m);
    lower::reuse_buffers(m);
    lower::spare_short_loops(m);
    out.code = lower::print_cpp(m);
    out.ok = true;
    for (const lower::DynamicSite& d : m.dynamic_sites) out.dynamic_sites.push_back(located(program, d.loc, d.why));
  } catch (const lower::Unsupported& u) {
    out.reason = located(program, u.loc, u.why);
  }
  return out;
}

}  // namespace autumn
