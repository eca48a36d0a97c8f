// module — what the lowering produces: the IR functions of one program with the
// tables the printer needs (classes, state slots, strings, error locations) and
// the specialisation report.
//
// Produced by the specialiser (specialise.hpp), rewritten by the IR passes,
// printed by print_cpp.hpp.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "compiler/lower/ir.hpp"
#include "compiler/lower/types.hpp"

namespace autumn::lower {

// How the objects of a class know their cells (docs/design.md, "Cells").
enum class CellMode : uint8_t {
  Static,   // every object has the same cells: rendering is specialised per class
  Stored,   // each object carries its cell list (shape decided at construction)
};

// One cell of a Static class: constant offsets; the colour either a constant
// string or a deferred expression evaluated at every render by `colour_fn`.
struct StaticCell {
  int32_t x = 0, y = 0;
  int colour = -1;     // string id, or -1: call colour_fn
  int colour_fn = -1;  // module function (State&, const C&) -> string id
};

struct ClassInfo {
  std::string name;       // as written (may hold characters C++ names cannot)
  std::string cpp;        // C++ struct name
  Sym sym = -1;
  const struct Stmt* stmt = nullptr;
  std::vector<Sym> fields;
  std::vector<std::string> field_names;  // as written
  std::vector<TypeP> field_types;        // static types of the values the fields hold
  std::string type_string;               // the reference's "class A {f: T, ..., }"
  std::string unknown_field;             // a field of unknown type: stringifying the class is an error
  CellMode mode = CellMode::Static;
  std::vector<StaticCell> cells;         // Static
  std::string cells_print;               // Static: printed form of the cell list
  bool tracked = false;                  // objects carry identity (uid)
  bool rotatable = false;                // objects carry the group of cells rotate turns (group)
  ir::Node* static_shape = nullptr;       // Static: the cell list every object has (MakeList of MakeCell)
  bool shape_table = false;              // Static: some render loops over static_shape, printed once as a
                                         // table (Op::Shape); its cells are then all literal (x, y, colour)
  int render_fn = -1;                    // Stored: the module function rendering one object
};

// Whether every cell of a shape (a MakeList of MakeCell) has a literal Int x and y
// and a literal String colour: the cells an Op::Shape table is printed from.
// Shared by the specialiser (which then uses the table) and ir_verify.
inline bool literal_cells(const ir::Node& shape) {
  for (const ir::Node* c : shape.a) {
    if (c->op != ir::Op::MakeCell || c->a.size() < 3) return false;
    for (int which = 0; which < 3; ++which) {
      const ir::Node* v = c->a[which];
      if (v->op != ir::Op::Lit || !v->type || v->type->k != (which == 2 ? TK::Str : TK::Int)) return false;
    }
  }
  return true;
}

// An argument of a (Cell x y colour) that did not evaluate to a number when the
// cell was made: the reference keeps the expression and evaluates it at every
// render, with the names the cell captured first (compiler/interpret/eval.cpp,
// construct_cell). `fixed` ones evaluate to the same value every time (no
// effects, nothing read but captured names), so the value is kept in the cell.
struct DeferredArg {
  const Expr* expr = nullptr;
  int arg = 0;                                   // 0 x, 1 y, 2 colour
  std::vector<int> classes;                      // the classes being constructed when the cell was made
  std::vector<std::pair<Sym, ir::Node*>> captured;  // name -> constant value (Lit/MakePos/MakeList)
  std::vector<std::pair<Sym, TypeP>> captured_types;
  bool fixed = false;
  int print = 0;                                 // equal printed forms, equal ids
};

// Where a runtime error is reported: the innermost construct, and the innermost
// construct of the user's program when that is a different one (an error inside
// the stdlib is reported at the program's call, "inside" the stdlib line).
struct ErrorLoc {
  SourceLoc at;
  bool in_program = false;
  SourceLoc program_at;
  std::string prefix;  // "initialising 'x': " for start-up initialisers
};

// A place where the specialisation is not fully static, with why.
struct DynamicSite {
  SourceLoc loc;
  std::string why;
};

struct Module {
  std::string name;
  Types types;
  std::vector<ClassInfo> classes;
  std::vector<ir::Slot> slots;
  std::vector<std::unique_ptr<ir::Function>> functions;
  ir::Arena arena;
  ir::Arena lasting;  // nodes that outlive a walk (learnt shapes, cell captures): never cleared
  std::vector<std::string> strings;  // string literals by id, quotes included
  std::vector<std::string> render_names;  // the globals the render draws, by PaintGlobal index
  std::vector<ErrorLoc> locations;
  std::vector<TypeP> sums;           // the Sum types the code uses (variants to define)
  std::vector<DynamicSite> dynamic_sites;
  std::vector<DeferredArg> deferred;
  // Cell arguments that are number constants where a colour is due (the cell
  // fails when rendered): the argument and the classes being constructed. A
  // MakeCell with such a colour has `index` = 1 + its entry here.
  struct NumberColour {
    const Expr* expr = nullptr;
    std::vector<int> classes;
  };
  std::vector<NumberColour> number_colours;
  std::vector<std::string> deferred_prints;  // printed forms of deferred arguments, by print id
  int grid = 16;
  int on_clauses = 0;
  bool uses_random = false;
  bool uses_ids = false;             // identity numbers are observed
  bool pos_tracked = false;          // Positions carry identities (PosU)
  bool runtime_order = false;        // the global map order is kept at run time (State::order)
  bool draw_order = false;           // globals steps first define draw in that order (State::drawn)
  std::map<int, uint64_t> order_hashes;  // symbol -> its name's std::hash, for DefineGlobal
  int start_fn = -1, step_fn = -1, render_fn = -1;
  std::string program_path;          // for comments

  // Everything but the types (which hints point into) starts over for a new walk.
  void clear_for_walk() {
    classes.clear();
    slots.clear();
    functions.clear();
    arena = ir::Arena{};
    // `strings` stays too: string ids appear in the shapes and constants hints keep.
    locations.clear();
    render_names.clear();
    sums.clear();
    dynamic_sites.clear();
    // `deferred` stays: cells made in one walk name their arguments by index,
    // and shapes learnt in one walk are compared in the next.
    uses_ids = runtime_order = draw_order = pos_tracked = false;
    start_fn = step_fn = render_fn = -1;
  }
};

}  // namespace autumn::lower
