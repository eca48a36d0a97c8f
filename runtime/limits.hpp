// limits — the resource limits every engine enforces, decided once.
//
// A program must never crash or hang its host, so each episode runs under a
// budget. The numbers, their defaults, the `--limits` flag's syntax and the exact
// error texts live here, in one header both engines include, so that both say
// the same thing at the same construct (the difftest compares their messages).
//
//   call-depth   nested function calls (lambdas, constructors, render methods)
//   list-length  elements of any one list the program builds
//   objects      object instances (of the program's classes) in the state
//   cells        list elements and object fields: in the state after start-up and
//                after every step, and created by the program in one step (so no
//                single step can exhaust memory); specialised compiled code counts
//                the per-step part as the elements its program constructs put into
//                new lists (ranges, maps, filters, concat, addObj, ...), a part of
//                what the interpreter counts (it adds object fields, Positions and
//                list literals), so a step the interpreter finishes within the
//                budget the compiled engine finishes too, and one over it can fail
//                later or at another construct (with the same text, which holds for
//                both: the interpreter's count is at least the compiled engine's)
//   calls        function calls the program makes in one step (so no step hangs);
//                specialised compiled code inlines its functions, so there the
//                same number bounds the list elements and range steps its loops
//                visit in one step (charged once per loop, before it runs): a
//                step either engine finishes within the budget is the same step,
//                but a step over it can fail at another construct, with the
//                loops' text below.
//
// "One step" is also the start-up and each host render, counted separately; only
// the program's own constructs count (its expressions and the stdlib's, cell
// expressions included), not the engines' rendering machinery.
//
// The state is counted as values (a list held twice counts twice, as the
// compiled engine's copies do), from the globals, at the end of start-up and of
// every step; an excess is reported at the definition of the global whose count
// crossed the limit. The other limits are reported at the construct that
// crossed them. Fixed limits, not configurable: syntax nesting (the reader and
// parser refuse deeper text, so no pass recurses without bound), value nesting
// (lists and objects inside each other, and cells turned by rotate), and the
// GRID_SIZE range, which is checked when the program is loaded (a literal
// definition; autumnc refuses it) and at every render.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace autumn {

struct Limits {
  int64_t call_depth = 10'000;
  int64_t list_length = 1'000'000;
  int64_t objects = 1'000'000;
  int64_t cells = 10'000'000;
  int64_t calls = 10'000'000;
  bool operator==(const Limits&) const = default;
};

namespace limits {

constexpr int kMaxSyntaxNesting = 1000;  // nested parentheses in a program or trigger
constexpr int kMaxValueNesting = 1000;   // lists/objects inside each other; a cell's coordinate expressions
// Turns of one cell: a turn (x, y) -> (-y, x) nests one of its two coordinates
// once more, so this many turns nest each kMaxValueNesting deep. Both engines
// compare the turns so far with it (the interpreter as the sum of its two
// coordinates' nesting, the compiled engine as its per-group count).
constexpr int kMaxRotations = 2 * kMaxValueNesting;
// The smallest list-length budget: every list a program's text spells out (a
// literal, a range of constants) up to this length needs no check at run time.
constexpr int64_t kMinListLength = 1000;
constexpr int32_t kMinGridSize = 1;
constexpr int32_t kMaxGridSize = 4096;

std::string raise_hint(std::string_view key);

// `callee`: the called name as written, or empty for a function without one.
std::string call_depth_error(int64_t limit, std::string_view callee);
std::string list_length_error(int64_t length, int64_t limit);
std::string objects_error(int64_t limit, std::string_view global);
std::string state_cells_error(int64_t limit, std::string_view global);
std::string created_cells_error(int64_t limit);
std::string calls_error(int64_t limit);
std::string loop_elements_error(int64_t limit);
std::string syntax_nesting_error();
std::string value_nesting_error();
std::string rotation_nesting_error();
// Empty when `size` is a paintable GRID_SIZE.
std::string grid_size_error(int64_t size);
std::string grid_size_type_error(std::string_view type);

// The limits an engine applies: as given, with list-length at least kMinListLength.
Limits normalised(Limits l);

// "--limits" syntax: comma-separated KEY=N (keys as in the table above), each
// N a positive integer. Unnamed keys keep `base`'s values. nullopt (and *why)
// for anything else.
std::optional<Limits> parse(std::string_view spec, std::string* why, Limits base = {});

}  // namespace limits
}  // namespace autumn
