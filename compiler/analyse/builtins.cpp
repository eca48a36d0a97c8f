// builtins — see builtins.hpp. The arities are the reference's argument checks;
// the effects are what the lowering must preserve or may exploit.
#include "compiler/analyse/builtins.hpp"

namespace autumn {
namespace {

constexpr uint16_t kList = kCallsFunctions;
constexpr BuiltinInfo kTable[kBuiltinCount] = {
    {Builtin::Map, "map", 2, 2, kList},
    {Builtin::Concat, "concat", 1, 1, kPure},
    {Builtin::Filter, "filter", 2, 2, kList},
    {Builtin::Foldl, "foldl", 3, 3, kList},
    {Builtin::Length, "length", 1, 1, kPure, "Number"},
    {Builtin::Head, "head", 1, 1, kPure},
    {Builtin::At, "at", 2, 2, kPure},
    {Builtin::Tail, "tail", 1, 1, kPure},
    {Builtin::RenderAll, "renderAll", 0, kAnyArity, kRenders | kWritesGlobals},
    {Builtin::Defined, "defined", 1, 1, kReadsGlobalOrder, "Bool"},
    {Builtin::ArrayEqual, "arrayEqual", 2, 2, kPure},
    {Builtin::Sqrt, "sqrt", 1, 1, kPure, "Number"},
    {Builtin::Prev, "prev", 1, 1, kReadsIdentity | kReadsGlobalOrder},
    {Builtin::Any, "any", 1, 2, kList, "Bool"},
    {Builtin::IsList, "isList", 1, 1, kPure, "Bool"},
    {Builtin::UniformChoice, "uniformChoice", 1, kAnyArity, kDrawsRandom},
    {Builtin::AdjPositions, "adjPositions", 1, 1, kReadsGridSize},
    {Builtin::AddObj, "addObj", 2, 2, kCopies},
    {Builtin::IsFreePos, "isFreePos", 1, 1, kReadsOccupancy, "Bool"},
    {Builtin::Range, "range", 2, 2, kPure},
    {Builtin::Print, "print", 1, 1, kPure},
    {Builtin::RemoveObj, "removeObj", 1, 2, kList | kReadsIdentity | kReadsGlobalOrder | kWritesGlobals},
    {Builtin::UpdateObj, "updateObj", 2, 3, kList | kCopies},
    {Builtin::RandomPositions, "randomPositions", 2, 2, kDrawsRandom},
    {Builtin::AllPositions, "allPositions", 1, 2, kPure},
    {Builtin::Clicked, "clicked", 0, 1, kReadsInputs | kRenders | kWritesGlobals, "Bool"},
    {Builtin::Left, "left", 0, kAnyArity, kReadsInputs, "Bool"},
    {Builtin::Right, "right", 0, kAnyArity, kReadsInputs, "Bool"},
    {Builtin::Up, "up", 0, kAnyArity, kReadsInputs, "Bool"},
    {Builtin::Down, "down", 0, kAnyArity, kReadsInputs, "Bool"},
    {Builtin::IsWithinBounds, "isWithinBounds", 1, 1, kRenders | kReadsGridSize, "Bool"},
    {Builtin::AllObjs, "allObjs", 0, kAnyArity, kReadsGlobalOrder},
    {Builtin::Rotate, "rotate", 1, 1, kMutatesShared | kCopies},
};

}  // namespace

const BuiltinInfo* builtin_table() { return kTable; }

const BuiltinInfo& builtin_info(Builtin b) { return kTable[static_cast<int>(b)]; }

std::string builtin_arity_error(Builtin b, size_t given) {
  const BuiltinInfo& info = builtin_info(b);
  if (info.min_args != info.max_args || given == info.min_args) return "";
  return std::string(info.name) + " takes " + std::to_string(info.min_args) + " argument(s), got " +
         std::to_string(given);
}

std::optional<Builtin> builtin_by_name(std::string_view name) {
  for (const BuiltinInfo& b : kTable)
    if (name == b.name) return b.id;
  return std::nullopt;
}

}  // namespace autumn
