// facts — what the lowering knows about a program before specialising it (pass 1).
//
// Computed once from the analysed Program, read by every walk of the
// specialiser: the object classes (names, fields, C++ names), the names some
// assignment targets, the on-clauses in source order, the initnext variables
// in the INIT/NEXT hash order (the libstdc++ order the reference iterates its
// registrations in), and the stdlib's renderValue. Test: tests/lowering_test.cpp.
#pragma once
#include <set>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/module.hpp"

namespace autumn::lower {

struct Facts {
  std::vector<ClassInfo> classes;   // the skeletons: names, fields; types come from the walks
  std::vector<int> class_of_sym;    // class index by symbol (the last definition of a name), -1
  std::set<Sym> assigned;           // every name some assignment targets
  std::vector<const Stmt*> on_clauses;
  std::vector<Sym> initnext_order;  // initnext names, INIT/NEXT hash order
  const Expr* stdlib_render_value = nullptr;  // the stdlib's renderValue lambda
};

Facts program_facts(const Program& p);

}  // namespace autumn::lower
