// lower — the lowering as a sequence of passes (see lower.hpp).
#include "compiler/lower/lower.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "compiler/lower/ir_print.hpp"
#include "compiler/lower/ir_verify.hpp"
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

namespace {

// The passes after specialisation, in order (passes.hpp says what each does).
struct Pass {
  const char* name;
  void (*run)(lower::Module&);
};
constexpr Pass kPasses[] = {
    {"mark_occupancy_if_read", lower::mark_occupancy_if_read},
    {"define_click_once", lower::define_click_once},
    {"settle_references", lower::settle_references},
    {"resolve_aliases", lower::resolve_aliases},
    {"remove_dead_names", lower::remove_dead_names},
    {"move_last_uses", lower::move_last_uses},
    {"reuse_buffers", lower::reuse_buffers},
    {"spare_short_loops", lower::spare_short_loops},
    {"keep_budgets_local", lower::keep_budgets_local},
};

// After each stage: the IR still holds its invariants (when AUTUMN_VERIFY_IR is
// set: ctest and the fuzz smokes), and its text when this is the stage asked for.
void after(const char* stage, const lower::Module& m, const LowerOptions& o, Lowered& out) {
  const char* verify = std::getenv("AUTUMN_VERIFY_IR");
  if (verify && *verify && std::string_view(verify) != "0") {
    const std::vector<std::string> problems = lower::verify_ir(m);
    if (!problems.empty())
      throw std::logic_error("internal error: the lowering IR is broken after " + std::string(stage) + ": " +
                             problems[0] +
                             (problems.size() > 1 ? " (and " + std::to_string(problems.size() - 1) + " more)" : ""));
  }
  if (o.dump_ir_after == stage) out.ir = lower::print_ir(m);
}

}  // namespace

const std::vector<std::string>& lowering_stages() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"specialise"};
    for (const Pass& p : kPasses) n.push_back(p.name);
    return n;
  }();
  return names;
}

Lowered lower_program(const Program& program, const std::string& program_name, const LowerOptions& options) {
  Lowered out;
  lower::Module m;
  m.name = program_name;
  m.program_path = program.file.name;
  try {
    lower::specialise_program(program, m);
    after("specialise", m, options, out);
    for (const Pass& p : kPasses) {
      p.run(m);
      after(p.name, m, options, out);
    }
    out.code = lower::print_cpp(m);
    out.snapshot_layout = lower::snapshot_layout(m);
    out.ok = true;
    for (const lower::DynamicSite& d : m.dynamic_sites) out.dynamic_sites.push_back(located(program, d.loc, d.why));
  } catch (const lower::Unsupported& u) {
    out.reason = located(program, u.loc, u.why);
  }
  return out;
}

}  // namespace autumn
