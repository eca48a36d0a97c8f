#include "harness/difftest.hpp"

#include "harness/engine.hpp"
#include "harness/policy.hpp"

namespace autumn {

DiffResult diff_engines(const std::shared_ptr<const Program>& program, const DiffOptions& o) {
  DiffResult r;
  std::string why;
  auto a = make_environment(o.engine_a, program, &why);
  auto b = a ? make_environment(o.engine_b, program, &why) : nullptr;
  if (!a || !b) {
    r.setup_failed = true;
    r.divergence = why;
    return r;
  }
  a->set_limits(o.limits);
  b->set_limits(o.limits);
  for (int k = 0; k < o.seeds && r.divergence.empty(); ++k) {
    const uint64_t seed = o.first_seed + static_cast<uint64_t>(k);
    ++r.episodes;
    bool oka = a->reset(seed), okb = b->reset(seed);
    std::string at = "seed " + std::to_string(seed);
    auto compare = [&](const std::string& where) {
      if (oka != okb) {
        r.divergence = where + ": " + o.engine_a + (oka ? " ran on" : " failed (" + a->error() + ")") + " but " +
                       o.engine_b + (okb ? " ran on" : " failed (" + b->error() + ")");
        return false;
      }
      if (!oka) {  // both failed at the same step: they must say the same, and the episode is over
        ++r.errored;
        if (r.first_error.empty()) r.first_error = where + ": " + a->error();
        if (a->error() != b->error())
          r.divergence = where + ": both failed, with different errors:\n  " + o.engine_a + ": " + a->error() +
                         "\n  " + o.engine_b + ": " + b->error();
        return false;
      }
      if (frame_rows(a->frame(), a->palette()) != frame_rows(b->frame(), b->palette())) {
        r.divergence = where + ": frames differ";
        return false;
      }
      if (a->triggered() != b->triggered()) {
        r.divergence = where + ": trigger values differ";
        return false;
      }
      if (a->covered_on_clause_count() != b->covered_on_clause_count()) {
        r.divergence = where + ": on-clause coverage differs";
        return false;
      }
      return true;
    };
    if (!compare(at + ", after reset")) continue;
    RandomPolicy policy(seed * 7919 + 17);
    std::string prefix;
    for (int i = 0; i < o.steps; ++i) {
      Action act = policy.next(a->frame());
      prefix += (prefix.empty() ? "" : ",") + format_action(act);
      oka = a->step(act);
      okb = b->step(act);
      ++r.steps;
      if (!compare(at + ", step " + std::to_string(i + 1) + " (actions: " + prefix + ")")) break;
    }
  }
  return r;
}

}  // namespace autumn
