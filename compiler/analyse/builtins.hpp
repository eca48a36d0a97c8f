// builtins — the one table of the language's native functions.
//
// Every native builtin the reference defines at start-up is listed here once, in
// the reference's definition order (which is also the order their names enter
// the global hash map, so it is observable through allObjs and removeObj). Each
// entry says how many arguments the builtin accepts and what it touches. The
// analysis (interning, unbound-name warnings, "can this program draw?"), the
// interpreter (start-up and dispatch) and the lowering (dispatch, effect and
// feature screens) all read this table; nobody else spells a builtin's name.
//
// Arity: min..max arguments the builtin accepts without an argument-count
// error; max = kAnyArity when it ignores extras (left, right, ...).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace autumn {

enum class Builtin : uint8_t {
  Map, Concat, Filter, Foldl, Length, Head, At, Tail, RenderAll, Defined, ArrayEqual, Sqrt,
  Prev, Any, IsList, UniformChoice, AdjPositions, AddObj, IsFreePos, Range, Print, RemoveObj,
  UpdateObj, RandomPositions, AllPositions, Clicked, Left, Right, Up, Down, IsWithinBounds,
  AllObjs, Rotate
};
inline constexpr int kBuiltinCount = static_cast<int>(Builtin::Rotate) + 1;
inline constexpr int kAnyArity = 255;

// What a builtin may touch beyond its arguments. Pure builtins read nothing else.
enum BuiltinEffect : uint16_t {
  kPure = 0,
  kDrawsRandom = 1 << 0,      // reads and advances the random generator
  kReadsOccupancy = 1 << 1,   // isFreePos: the occupancy of the last host render
  kReadsIdentity = 1 << 2,    // compares identity numbers (removeObj, prev by value)
  kReadsGlobalOrder = 1 << 3, // iterates the global hash map (allObjs, removeObj 1-arg)
  kWritesGlobals = 1 << 4,    // defines or erases globals (clicked: click; removeObj; renderAll)
  kCallsFunctions = 1 << 5,   // calls a function argument (map, filter, ...)
  kRenders = 1 << 6,          // renders an object argument (render methods, deferred cells)
  kReadsInputs = 1 << 7,      // the input latch (clicked, left, ...)
  kMutatesShared = 1 << 8,    // mutates objects shared by other holders (rotate)
  kReadsGridSize = 1 << 9,    // looks GRID_SIZE up dynamically
  kCopies = 1 << 10,          // makes fresh copies of objects (new identity numbers)
};
// Builtins that may answer otherwise when called again with the same arguments:
// what they read beyond them (the global map, the prev snapshot, the occupancy,
// the inputs, the random generator, an object's render, GRID_SIZE) changes as
// the episode runs. A cell argument that calls one is evaluated at every render
// (compiler/lower/spec_cells.cpp), as the reference does every deferred one.
inline constexpr uint16_t kReadsChangingState =
    kDrawsRandom | kReadsOccupancy | kReadsIdentity | kReadsGlobalOrder | kReadsInputs | kRenders | kReadsGridSize;

struct BuiltinInfo {
  Builtin id;
  const char* name;
  uint8_t min_args, max_args;
  uint16_t effects;
  // The type of every value it returns, as the author writes it, where that is
  // fixed (the linter's static types); nullptr where it depends on the arguments.
  const char* result = nullptr;
};

// All builtins, in the reference's definition order (GRID_SIZE, which the
// reference defines first, is an ordinary number and not listed).
const BuiltinInfo* builtin_table();
const BuiltinInfo& builtin_info(Builtin b);
inline const char* builtin_name(Builtin b) { return builtin_info(b).name; }
std::optional<Builtin> builtin_by_name(std::string_view name);
// The argument-count error both engines raise when a builtin that takes exactly
// its table's count is given `given` arguments ("length takes 1 argument(s), got
// 2"), or "" when the count is right. A builtin that takes a range checks its
// own count (each says it in its own words, as the reference does).
std::string builtin_arity_error(Builtin b, size_t given);

// The built-in type names the reference defines at start-up, in its order.
inline constexpr const char* kBuiltinTypeNames[] = {"Bool", "String", "Number", "Int",
                                                    "Position", "Cell", "RenderedElem"};
// The builtin after which the reference defines the built-in type names.
inline constexpr Builtin kTypesDefinedAfter = Builtin::Sqrt;

}  // namespace autumn
