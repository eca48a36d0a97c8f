// ir — the typed lowering IR: structured, C-like code over static types.
//
// The specialiser (specialise.hpp) produces it, the passes (pass_*.cpp) rewrite
// it, and one printer (print_cpp.cpp) turns it into C++. Nothing downstream ever
// reads C++ text: every decision is taken on this IR.
//
// A Function is a tree of statements. Values are Nodes: leaves (literals,
// variables, state slots) and operations (Op) on typed operands. A Var is one
// C++ local; every Var is introduced by exactly one statement (Let, Decl, Bind,
// a loop), which also fixes its scope: the rest of the enclosing block.
//
//   Let     const T v = a;            an immutable temporary
//   Decl    T v = a;  / T v;          a mutable variable (a may be null)
//   Bind    const T& v = a;           a name for a place (a global, a variable):
//                                      pass_refs keeps it a reference when no store
//                                      to the place can intervene, else a copy
//   Set     a = b;                    a is a place
//   Push    a.push_back(b);
//   Eval    a;                        a helper call for its effect
//   Swap    std::swap(a, b);          two places exchange values (storage is recycled)
//   If / ForEach / ForRange / Switch / Block / Break / Return / Fail / Comment
//
// Invariant: a place (Local, Global, Slot, Field of a place) read by an
// operation is read when the statement runs; anything that must keep a value
// across later statements is first put in a Let, Decl or Bind.
#pragma once
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "compiler/lower/types.hpp"

namespace autumn::lower::ir {

struct Var {
  int id = 0;
  TypeP type = nullptr;
  std::string hint;        // a readable stem for the printed name ("a_obj", "t")
  bool mut = false;        // Decl: assigned after its declaration
  bool is_ref = true;      // Bind: settled by pass_refs (false: a copy)
  bool scratch = false;    // a list rebuilt each time: storage reused (pass_scratch)
  bool moved = false;      // its last use may move from it (pass_moves)
};

// Members of values, by the base value's type.
enum class Member : uint8_t {
  X, Y,                 // Pos
  Position, Color,      // Elem
  Origin, Field, Uid,   // Obj (Field: user field `index`), Uid on any tracked object
  Group,                // Obj: the cells it shares with every object of its construction (rotate)
  CellX, CellY, CellColour,  // Cell: the values (constants, fixed deferred values)
  CellDx, CellDy, CellDc,    // Cell: -1 or the DeferredArg of each argument
  Cells,                     // Obj: the object's own cell list (CellMode::Stored)
};

// Runtime helpers (runtime/compiled_support.hpp); their C++ names live in the printer.
enum class Helper : uint8_t {
  RngNext,        // (bound) -> int32: one draw
  OccupancyFree,  // (pos) -> bool
  IdOf,           // (uid) -> uint32: the identity number an object shows
  IdTransfer,     // (uid of the new value, id of the old one): assignment's rule
  NewUid,         // () -> uint32
  Sqrt,           // (n) -> floor(sqrt(n)), n >= 0
  DefineGlobal,   // (symbol): the run-time map order learns a key (no-op if present)
  EraseGlobal,    // (symbol): the run-time map order forgets a key
  OrderKeys,      // (list): the list := the global symbols in the run-time map order
  ClickPos,       // () -> Pos of the pending click
  ClickDefine,    // (): the global `click` := the pending click
  Reserve,        // (list, n)
  Append,         // (list, other list): append all elements
  Clear,          // (list)
  StrOfInt,       // (n) -> std::string (for error texts)
  StrOfStr,       // (string id) -> its text with quotes (for error texts)
  OccupancyClear, // (): the host render starts
  OccupancyAdd,   // (pos)
  PaintBegin,     // (background): the frame is reset to it; the render's Brush is made
  Paint,          // (elem)
  PaintGlobal,    // (index into Module::render_names): the global the next elements are drawn from
  PaintEnd,       // (): the render ends (the painter takes its marks back; cacheRendered's count)
  SetTriggered,   // (bool): what the host reads as the trigger state
  Covered,        // (clause index): the on-clause fired
  HavePrev,       // () -> bool: a step has begun (prev is usable)
  InputFlag,      // (kind: 0 click, 1 left, 2 right, 3 up, 4 down) -> bool
  RotTurn,        // (group): rotate turned the group's cells a quarter
  RotOf,          // (group) -> how many quarter turns the group's cells have had
  Rotated,        // (turns, x, y) -> Pos: a cell offset turned (x, y) -> (-y, x) that many times
  TallyBegin,     // (): the state check starts: its StateTally, a local of the function
                  // (runtime/compiled_support.hpp), read by the Tally helpers after it
  TallyGlobal,    // (value): one global of the state check; imm: its definition's error site; text: its name
  TallyRendered,  // (): cacheRendered in the state check; imm, text: as TallyGlobal
  CheckLength,    // (...): the list-length budget; imm: error site; index: a LengthOf saying how
                  // the length is formed from the arguments
  ChargeBuilt,    // (...): the step's cells budget charged with the elements a list is about to be
                  // given; imm, index: as CheckLength, any LengthOf but kLengthAppended and
                  // kLengthCounted (a list built one element at a time charges kLengthIs 1 per
                  // element; charge_built)
  NoteDrawn,      // (symbol): a step defined a global for the first time (State::drawn)
  DrawnKeys,      // (list): the list := the globals steps first defined, in that order
};

// How Helper::CheckLength (and ChargeBuilt) forms the length of the list about to be built.
enum LengthOf : int { kLengthIs = 0, kLengthSpan, kLengthArea, kLengthSizes, kLengthSizePlus, kLengthAppended,
                      kLengthTotal, kLengthCounted };
//   kLengthIs        a0                     (a count)
//   kLengthSpan      a1 - a0                (range)
//   kLengthArea      a0 * a1                (allPositions)
//   kLengthSizes     size(a0) + size(a1)... (concat of known parts)
//   kLengthSizePlus  size(a0) + a1          (addObj)
//   kLengthAppended  size(a0), built one element at a time (allObjs)
//   kLengthTotal     sum of the sizes of a0's elements (concat of a list of lists)
//   kLengthCounted   a0, a count of elements met one at a time, as kLengthAppended's list would
//                    hold them (allObjs walked by a filter without building it; CheckLength only)

enum class Op : uint8_t {
  Lit,        // imm (Int; Bool 0/1; Str: string id)
  Text,       // text: a C++ string literal (error messages)
  Local,      // var
  Global,     // slot: a state member holding a global's value
  Slot,       // slot: any other state member (flags, prev copies, counters)
  Member,     // a[0].member (index for Member::Field)
  Add, Sub, Mul, Neg, Div, Mod,   // wrapping, as runtime/arith.hpp (Div/Mod: checked before)
  Lt, Le, Gt, Ge, Eq, Ne,         // on Int/Bool/Str/Pos/Elem operands of one type
  Not, And, Or,                   // on Bool, no side effects
  MakePos, MakeElem, MakeObj, MakeCell,  // struct values from their members (MakeObj: index = class)
  MakeList,   // a list literal of the operands
  MakeSum,    // a[0] as alternative `index` of the Sum type
  SumIs,      // a[0] holds alternative `index`
  SumGet,     // a[0]'s alternative `index` (SumIs checked before)
  Size, Empty, Index, Front, Back,  // lists (Index unchecked)
  Call,       // helper(a...)
  FnCall,     // call of module function `index` (recursive functions, render, colour)
  Concat,     // strings: a[0] + a[1] + ... (error texts)
  Select,     // a[0] ? a[1] : a[2] (places of one type: the result names one of them)
  Shape,      // the constant cells of class `index` (ClassInfo::static_shape) as a table the printer
              // writes once (List<Cell>; ClassInfo::shape_table); only a ForEach reads it
};

struct Node {
  Op op;
  TypeP type = nullptr;  // null for Text and effect-only calls
  int64_t imm = 0;
  int index = 0;         // Member::Field index, MakeObj class, Sum alternative, function
  Member member = Member::X;
  Helper helper = Helper::RngNext;
  Var* var = nullptr;
  int slot = -1;
  std::string text;
  std::vector<Node*> a;
};

enum class SK : uint8_t { Let, Decl, Bind, Set, Push, Eval, If, ForEach, ForRange, Switch, Block, Break,
                          Return, Fail, Comment, Swap };

struct Stmt;
using Block = std::vector<Stmt*>;

struct Stmt {
  SK k;
  Var* var = nullptr;   // Let, Decl, Bind, ForEach (element), ForRange (counter)
  Node* a = nullptr;    // init / place / condition / list / low bound / switch subject / message
  Node* b = nullptr;    // value / high bound
  Block body, other;    // If: then, else; loops, Block: body; Switch: unused
  std::vector<std::pair<int, Block>> cases;  // Switch: alternative index -> block
  int loc = -1;         // Fail, ForEach, ForRange (the loop budget's site): index into Module::locations
  bool move_value = false;  // Set, Push: b is a variable's last use, moved from; ForEach: the list
                            // is, whole, into the list its one push fills (pass_moves)
  bool charged = true;      // ForEach, ForRange: charges the loop budget; false when short (pass_loop_budget)
  bool charge_each = false; // ForEach, ForRange that may stop early: charged one per element visited (pass_loop_budget)
  bool local_budget = false;  // ForEach, ForRange: the budget counts are a local while it runs
                              // (pass_budget_locals); never nested, no return inside
  uint32_t move_operands = 0;  // Let, Decl, Set, Push: the value's operands (bits) moved from
  std::string text;     // Comment
};

// A state member: a global's value, or a flag/copy the lowering keeps.
struct Slot {
  std::string name;     // C++ member name
  TypeP type = nullptr; // null: bool
  enum Kind : uint8_t { Value, Defined, Updated, Saved, Prev, PrevDefined, Bound, Other } kind = Value;
  Sym sym = -1;
  bool in_snapshot = true;  // part of hash/save/load (values and definedness)
};

// One C++ function of the module. Every function takes the state (`s`) first.
struct Function {
  std::string name;
  enum Kind : uint8_t { Start, Step, Render, Colour, Helper } kind = Helper;
  std::vector<Var*> params;
  TypeP ret = nullptr;  // null: void
  Block body;
};

// Owns every node, statement and variable of a module's functions.
struct Arena {
  std::deque<Node> nodes;
  std::deque<Stmt> stmts;
  std::deque<Var> vars;
};

}  // namespace autumn::lower::ir
