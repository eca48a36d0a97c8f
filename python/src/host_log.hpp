// host_log — the reference host's calls on one episode, as a replayable log.
//
// The reference's Python Interpreter is driven call by call: inputs are set
// (several may be pending), step() runs one time step, render_all() renders (and
// refreshes the occupancy isFreePos reads, and may draw random numbers in cell
// colours), set_random_seed() reseeds, evaluate_to_string / tmp_execute_stmt run
// code against the state. An episode is therefore exactly (program, seed, log of
// these calls): replaying the log on a fresh interpreter reproduces the state bit
// for bit. The Session keeps its engines behind that log (session.hpp), and
// get_state() serialises it.
//
// Expressions and statements of Eval/Exec entries live in a Snippets store shared
// by the clones of a session (append-only; indices stay valid).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "compiler/parse/ast.hpp"
#include "runtime/action.hpp"

namespace autumn::py {

struct HostOp {
  enum Kind : uint8_t { Press, Step, Render, Reseed, Eval, Exec };
  Kind kind = Step;
  bool effect = true;  // Eval: false when the evaluation left the state as it was
  Action input;        // Press
  uint64_t arg = 0;    // Reseed: the seed; Eval/Exec: index into Snippets
};

// Parsed text of an Eval (expression) or Exec (statement) entry.
struct Snippet {
  std::string text;
  ExprPtr expr;                // Eval
  std::shared_ptr<Stmt> stmt;  // Exec (the interpreter keeps pointers to on-clauses)
};

struct Snippets {
  std::vector<std::shared_ptr<const Snippet>> items;
  uint64_t add(std::shared_ptr<const Snippet> s) {
    items.push_back(std::move(s));
    return items.size() - 1;
  }
};

using HostLog = std::vector<HostOp>;

}  // namespace autumn::py
