// error_sites — where the specialiser is in the program, for the errors it
// compiles in and the constructs it gives up on.
//
// A run-time error of specialised code must name the place the interpreter's
// would: the construct being evaluated (`at`) and the innermost construct of
// the program itself (`program_at`; stdlib code is reported at the program's
// call into it), with the start-up prefix ("initialising 'x': "). The walk
// enters a construct before lowering it and leaves it after; here() interns the
// current place into Module::locations and returns its index, which compiled
// code passes to its error helpers. The same stack places an unsupported
// construct (Unsupported, thrown) and a dynamic site (reported).
#pragma once
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/module.hpp"

namespace autumn::lower {

// The lowering gives up on a program only for constructs it cannot express
// faithfully at all; the emitter then embeds the interpreter (module.hpp).
struct Unsupported {
  std::string why;
  SourceLoc loc;
};

class ErrorSites {
 public:
  explicit ErrorSites(Module& m) : m_(m) {}

  // The constructs being lowered, innermost last. Enter and leave pair.
  void enter(const Expr* e) { stack_.push_back(e); }
  void leave() { stack_.pop_back(); }
  // Starts again from `outermost` alone (null: from nothing), at a function's start.
  void reset(const Expr* outermost);
  const Expr& innermost() const { return *stack_.back(); }
  // Whether some construct being lowered is the program's own (not the stdlib's).
  bool in_program() const;
  // Errors of start-up initialisers carry the initialised name ("" ends it).
  void set_prefix(std::string prefix) { prefix_ = std::move(prefix); }

  // The index of the current place among the module's error sites (added if new).
  int here();
  // The index of `l` among the module's error sites (added if new).
  int intern(const ErrorLoc& l);
  // Gives up on the program at the innermost construct of the program.
  [[noreturn]] void unsupported(const std::string& why) const;
  // Reports a dynamic site (once per place and reason).
  void dynamic_site(const std::string& why);

 private:
  const Expr* innermost_of_program() const;  // null: none
  Module& m_;
  std::vector<const Expr*> stack_;
  std::string prefix_;
};

}  // namespace autumn::lower
