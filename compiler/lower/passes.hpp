// passes — the IR passes that run between specialisation and printing, each in
// a file of its own (pass_*.cpp) with an example and a pointer to its test.
//
//   define_click_once   pass_click_once.cpp  a loop's repeated definition of click is done once, before it
//   settle_references   pass_refs.cpp     Bind: reference or copy
//   resolve_aliases     pass_aliases.cpp  a reference to a local is the local
//   mark_occupancy_if_read  pass_occupancy.cpp  no isFreePos: the render marks no occupancy
//   remove_dead_names   pass_dead.cpp     unused pure names are not computed
//   reuse_buffers       pass_scratch.cpp  short-lived lists keep their storage
//   move_last_uses      pass_moves.cpp    a value's last use moves it
//   spare_short_loops   pass_loop_budget.cpp  loops of at most 16 known elements charge nothing
//   keep_budgets_local  pass_budget_locals.cpp  a loop charging as it runs counts in a local
#pragma once
#include "compiler/lower/module.hpp"

namespace autumn::lower {

void define_click_once(Module& m);
void settle_references(Module& m);
void resolve_aliases(Module& m);
void mark_occupancy_if_read(Module& m);
void remove_dead_names(Module& m);
void reuse_buffers(Module& m);
void move_last_uses(Module& m);
void spare_short_loops(Module& m);
void keep_budgets_local(Module& m);

}  // namespace autumn::lower
