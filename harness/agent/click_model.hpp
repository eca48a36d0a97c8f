// click_model — which inputs a program can tell apart, from its syntax, and the
// search model that lets a planner merge clicks with equal effects.
//
// Search over "a click on every cell" multiplies the branching factor by
// GRID_SIZE^2. This conservative static analysis finds what does not matter:
//   ClickUse::None         — nothing the program or trigger can evaluate reads an
//                            input click (`clicked` is never mentioned): a click
//                            is a noop.
//   ClickUse::PositionFree — `clicked` is only used bare (on-clause conditions,
//                            logical operands, if conditions) and nothing reads
//                            `click`: every click has the same future.
//   ClickUse::Position     — anything else (click read, `(clicked obj)`,
//                            `clicked` passed as a value, the names rebound,
//                            "click" spelled in a string).
// Arrows are read or not: an arrow no reachable code mentions is a noop.
// The walk starts from the program's statements and the trigger and follows
// every name into the standard library's definitions (objClicked calls
// (clicked obj)).
//
// Step-local clicks. `clicked` stores the pending click in the global `click`,
// which persists: two states that differ only in the cell of the last click hash
// differently, so a breadth-first search cannot merge a click that changed
// nothing with a noop (every click is a new state). When every read of `click`
// happens in a step whose click is pending — on-clause conditions after a
// `clicked` test that must have held ((& clicked (isFreePos click))), bodies of
// clauses whose condition implies one — and nothing observes the global map's
// order (allObjs, defined, one-argument removeObj) or the value's identity
// (prev of click), then the value `click` carries into the next step is dead.
// The search model (click_reset_program) is then the program with a last
// on-clause `(on true (= click (Position 0 0)))`: it behaves exactly like the
// program, frame for frame, and states that differ only in a dead click are
// one state.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "runtime/action.hpp"

namespace autumn::agent {

enum class ClickUse { None, PositionFree, Position };
const char* click_use_name(ClickUse u);

ClickUse analyse_click_use(const Program& program);

struct InputUse {
  ClickUse clicks = ClickUse::None;
  bool arrows[4] = {false, false, false, false};  // left, right, up, down read anywhere
  bool click_step_local = false;                  // see above
  std::string click_note;                         // why not step-local ("" when it is)
};
InputUse analyse_inputs(const Program& program);

// The planner's action set: noop, left, right, up, down, then clicks — none for
// ClickUse::None, one representative (click 0 0) for PositionFree, every cell in
// row-major order for Position.
std::vector<Action> search_actions(ClickUse use, int grid_size);
// The same without the arrows the program never reads.
std::vector<Action> search_actions(const InputUse& use, int grid_size);

// `text` (a whole program) with the click-resetting on-clause appended inside its
// (program ...) form; nullopt when the text has no such form.
std::optional<std::string> click_reset_program(const std::string& text);

// The planner's one rule for using that model: the text of `program`'s
// click-reset model when its clicks are read and step-local (and the text has
// its (program ...) form); else nullopt and, in *why, the reason ("" when the
// program reads no clicks). The planner still checks that the model agrees
// with the program before it searches it (PlanProblem::choose_model); solve
// builds its module before the clock starts (prepare_modules).
std::optional<std::string> click_reset_model_text(const Program& program, const InputUse& inputs, std::string* why);

}  // namespace autumn::agent
