// make_cd — generate a change-detection task for any program (`autumn make-task cd`).
//
// The changed ("wrong") program is the original's source text with two edits made
// by byte range (positions from the reader's source locations, never a regex):
// a clock global inserted first in the program, `(= cdClock (initnext 0 (+ (prev
// cdClock) 1)))` (the name made unique), so the state after step n has cdClock = n;
// and ONE guarded rewrite that acts from clock value K on:
//   colour    — a colour string literal becomes (if GUARD then "NEW" else "OLD");
//   direction — a literal direction in an on-clause body, (Position dx dy) or a
//               moveLeft/moveRight/... function, is reversed under the guard;
//   spawn     — a new last on-clause adds an object of an existing type to a list
//               global when the clock reaches the guard's value.
// The trigger condition is `>= cdClock K`, so t* (change_detection.hpp) is K. The
// guard reads the clock either as the state being drawn (colours in object cells)
// or one step behind (on-clauses run before the clock's own update), so each
// rewrite is tried with the guard's number at K and at K-1, and the number is not
// trusted: a candidate is kept only when, in four seeded random episodes with the
// task's environment seed (the same actions for both programs), the changed
// program's frames equal the original's before t*, differ at t*, and t* is the
// first state on which triggered() holds. Candidates are tried in a seeded order
// (interpreter; the winner is checked again with the requested engine); the first
// that passes wins. AUTUMN_CD_DEBUG=1 prints rejected candidates to stderr.
//
// Files (--out must be DIR/prompts/NAME.json): the prompt, the original program as
// programs/STEM.<ext>, the changed one as programs/STEM_wrong.<ext>, and
// answers/STEM_change_detection.json with the condition, seed, t_star, a one-line
// description of the change and the generator's settings. A differing existing
// file is never overwritten.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/agent/make_task.hpp"

namespace autumn::agent {

struct MadeCd {
  nlohmann::json prompt;    // {"type": "change_detection", "program", "wrong_program"}
  nlohmann::ordered_json answers;
  std::string original_text, changed_text;
  int steps = 0;            // K
  int t_star = 0;
  std::string change;       // one-line description of the rewrite
};

MadeCd make_cd(const MakeTaskOptions& opts);
// Writes the prompt, both programs and the answers file; returns notes.
std::vector<std::string> write_cd(const MadeCd& made, const MakeTaskOptions& opts);

}  // namespace autumn::agent
