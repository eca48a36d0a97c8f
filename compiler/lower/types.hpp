// types — the static types of the lowering IR.
//
// Every value the specialiser handles has one of these types, fixed at compile
// time: Int, Bool, Str (an id into the module's string table), Pos (a Position
// instance), Elem (a RenderedElem), Cell (a Cell instance: three possibly
// deferred fields), Obj (an instance of one user class), List of one element
// type, Func (one function value known statically: a lambda, a builtin, or the
// render method of a class), Class (a class used as a callee) and Sum (one of
// several of the above, decided at run time: a tagged variant).
//
// Types are interned by a Types table, so equal types are the same pointer.
// A List whose element type is null is a list the specialiser knows to be
// empty (`(list)`, a map over an empty list); it fits any list type.
//
// A Sum is the compact dynamic value of the issue: it appears only where values
// of different types meet (an `if` whose branches differ, a variable assigned
// values of different classes, allObjs). A Sum of objects is a typed variant
// over classes; any other Sum is a "dynamic site" in the specialisation report.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "compiler/analyse/builtins.hpp"
#include "compiler/parse/ast.hpp"

namespace autumn::lower {

// Never: the type of code after an error that certainly happens (it fits every type).
// Deferred: a field of a Cell read with (.. c x): calling it evaluates that
// argument of the cell (cls: 0 x, 1 y, 2 colour); its value is the cell.
enum class TK : uint8_t { Int, Bool, Str, Pos, Elem, Cell, Obj, List, Func, Class, Sum, Deferred, Never };

// A function value known at compile time. Functions are dynamically scoped and
// capture nothing, so the function is all there is to its value.
struct FuncRef {
  enum Kind : uint8_t { Lambda, Native, Method } kind = Lambda;
  const Expr* lambda = nullptr;  // Lambda
  Builtin builtin = Builtin::Map; // Native
  int cls = -1;                  // Method: the class whose render method this is
  bool operator==(const FuncRef& o) const {
    return kind == o.kind && lambda == o.lambda && builtin == o.builtin && cls == o.cls;
  }
};

// Classes used as callees besides user classes (which are >= 0).
inline constexpr int kPositionClass = -1, kCellClass = -2, kElemClass = -3;
// Primitive type names used as values (calling one is an error).
inline constexpr int kBoolType = -4, kStringType = -5, kNumberType = -6;

struct Type {
  TK k;
  int id = 0;                         // interning index: a stable order for Sum alternatives
  int cls = 0;                        // Obj, Class
  const Type* elem = nullptr;         // List (null: known to be empty)
  std::vector<const Type*> alts;      // Sum: two or more, sorted by id, none a Sum
  FuncRef fn;                         // Func
};
using TypeP = const Type*;

class Types {
 public:
  Types();
  Types(const Types&) = delete;
  Types& operator=(const Types&) = delete;
  TypeP int_() const { return int_t_; }
  TypeP bool_() const { return bool_t_; }
  TypeP str() const { return str_t_; }
  TypeP pos() const { return pos_t_; }
  TypeP elem() const { return elem_t_; }
  TypeP cell() const { return cell_t_; }
  TypeP empty_list() const { return empty_list_; }
  TypeP never() const { return never_t_; }
  TypeP obj(int cls);
  TypeP list(TypeP elem);
  TypeP func(const FuncRef& f);
  TypeP cls(int cls);
  TypeP deferred(int arg);
  TypeP sum(std::vector<TypeP> alts);  // flattens, dedups; one alternative is that type

  // The least type holding values of both (empty lists fit any list; lists of
  // different element types become lists of the join; anything else a Sum).
  TypeP join(TypeP a, TypeP b);
  // Whether a value of type `v` can be stored where `slot` is expected without
  // widening the slot (v == slot, an empty list into a list, an alternative into a Sum,
  // lists whose elements fit).
  bool fits(TypeP v, TypeP slot) const;

 private:
  TypeP intern(Type t);
  std::vector<std::unique_ptr<Type>> all_;
  std::map<std::string, TypeP> by_key_;  // structural key -> the interned type
  TypeP int_t_, bool_t_, str_t_, pos_t_, elem_t_, cell_t_, empty_list_, never_t_;
};

// Predicates used everywhere.
inline bool is_list(TypeP t) { return t->k == TK::List; }
inline bool is_sum(TypeP t) { return t->k == TK::Sum; }
// A function, or one of several (an `if` choosing between two lambdas): what
// builtins that call an argument accept.
inline bool is_function(TypeP t) {
  if (t->k == TK::Func) return true;
  if (t->k != TK::Sum) return false;
  for (TypeP a : t->alts)
    if (a->k != TK::Func) return false;
  return true;
}
// A function, or a Sum with a function among its alternatives (a value that is
// called where the interpreter calls function values: conditions, & and |).
inline bool may_be_function(TypeP t) {
  if (t->k == TK::Func) return true;
  if (t->k != TK::Sum) return false;
  for (TypeP a : t->alts)
    if (a->k == TK::Func) return true;
  return false;
}
// Values that are heap objects in the reference (they carry identity numbers).
inline bool is_heap(TypeP t) {
  return t->k == TK::Pos || t->k == TK::Elem || t->k == TK::Cell || t->k == TK::Obj || t->k == TK::List ||
         t->k == TK::Func;
}
// Instances of a class, the reference's InstanceObj: a user class's objects, and
// Positions, Cells and RenderedElems (appends to a list never compare their types).
inline bool is_instance(TypeP t) {
  return t->k == TK::Pos || t->k == TK::Elem || t->k == TK::Cell || t->k == TK::Obj;
}
// Whether every alternative of a Sum (or the type itself) is an instance of a user class.
bool is_object_like(TypeP t);
// A Sum that is a typed variant rather than a dynamic value: all alternatives
// objects of user classes, or all functions (which carry nothing at run time).
bool is_typed_variant(TypeP t);
// The user classes a value of type t holds: `by_value`, those its C++ type
// contains (an object, a sum's alternatives), which must be complete before it;
// else also those inside lists, which need only be declared.
void classes_held(TypeP t, bool by_value, std::vector<int>& out);

}  // namespace autumn::lower
