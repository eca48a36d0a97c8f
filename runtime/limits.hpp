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
//                single step can exhaust memory)
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
constexpr int kMaxValueNesting = 1000;   // lists/objects inside each other; rotations of one cell
// The smallest list-length budget: every list a program's text spells out (a
// literal, a range of constants) up to this length needs no check at run time.
constexpr int64_t kMinListLength = 1000;
constexpr int32_t kMinGridSize = 1;
constexpr int32_t kMaxGridSize = 4096;

inline std::string raise_hint(std::string_view key) {
  return " (--limits " + std::string(key) + "=N raises it)";
}

// `callee`: the called name as written, or empty for a function without one.
inline std::string call_depth_error(int64_t limit, std::string_view callee) {
  return "call depth limit exceeded: more than " + std::to_string(limit) + " nested calls, calling " +
         (callee.empty() ? std::string("an unnamed function") : "'" + std::string(callee) + "'") +
         raise_hint("call-depth");
}
inline std::string list_length_error(int64_t length, int64_t limit) {
  return "list too long: " + std::to_string(length) + " elements, the limit is " + std::to_string(limit) +
         raise_hint("list-length");
}
inline std::string objects_error(int64_t limit, std::string_view global) {
  return "too many objects: the state holds more than " + std::to_string(limit) + " once '" + std::string(global) +
         "' is counted" + raise_hint("objects");
}
inline std::string state_cells_error(int64_t limit, std::string_view global) {
  return "state too large: more than " + std::to_string(limit) + " list elements and object fields once '" +
         std::string(global) + "' is counted" + raise_hint("cells");
}
inline std::string created_cells_error(int64_t limit) {
  return "memory budget exceeded: this step created more than " + std::to_string(limit) +
         " list elements and object fields" + raise_hint("cells");
}
inline std::string calls_error(int64_t limit) {
  return "time budget exceeded: this step made more than " + std::to_string(limit) + " function calls" +
         raise_hint("calls");
}
inline std::string loop_elements_error(int64_t limit) {
  return "time budget exceeded: this step's loops visited more than " + std::to_string(limit) +
         " list elements" + raise_hint("calls");
}
inline std::string syntax_nesting_error() {
  return "nested too deeply: more than " + std::to_string(kMaxSyntaxNesting) + " levels of parentheses";
}
inline std::string value_nesting_error() {
  return "value nested too deeply: more than " + std::to_string(kMaxValueNesting) +
         " levels of lists and objects inside each other";
}
inline std::string rotation_nesting_error() {
  return "rotate: a cell turned more than " + std::to_string(kMaxValueNesting) + " times";
}
// Empty when `size` is a paintable GRID_SIZE.
inline std::string grid_size_error(int64_t size) {
  if (size >= kMinGridSize && size <= kMaxGridSize) return {};
  return "GRID_SIZE must be a number from " + std::to_string(kMinGridSize) + " to " + std::to_string(kMaxGridSize) +
         ", got " + std::to_string(size);
}
inline std::string grid_size_type_error(std::string_view type) {
  return "GRID_SIZE must be a number from " + std::to_string(kMinGridSize) + " to " + std::to_string(kMaxGridSize) +
         ", got a " + std::string(type);
}

// "--limits" syntax: comma-separated KEY=N (keys as in the table above), each
// N a positive integer. Unnamed keys keep `base`'s values. nullopt (and *why)
// for anything else.
// The limits an engine applies: as given, with list-length at least kMinListLength.
inline Limits normalised(Limits l) {
  if (l.list_length < kMinListLength) l.list_length = kMinListLength;
  return l;
}

inline std::optional<Limits> parse(std::string_view spec, std::string* why, Limits base = {}) {
  auto bad = [&](const std::string& msg) -> std::optional<Limits> {
    if (why) *why = msg;
    return std::nullopt;
  };
  while (!spec.empty()) {
    const size_t comma = spec.find(',');
    const std::string_view item = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view() : spec.substr(comma + 1);
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos) return bad("expected KEY=N, got '" + std::string(item) + "'");
    const std::string_view key = item.substr(0, eq), digits = item.substr(eq + 1);
    int64_t n = 0;
    if (digits.empty() || digits.size() > 18) return bad("'" + std::string(item) + "': N must be a positive integer");
    for (char c : digits) {
      if (c < '0' || c > '9') return bad("'" + std::string(item) + "': N must be a positive integer");
      n = n * 10 + (c - '0');
    }
    if (n <= 0) return bad("'" + std::string(item) + "': N must be a positive integer");
    if (key == "list-length" && n < kMinListLength)
      return bad("'" + std::string(item) + "': list-length must be at least " + std::to_string(kMinListLength));
    if (key == "call-depth") base.call_depth = n;
    else if (key == "list-length") base.list_length = n;
    else if (key == "objects") base.objects = n;
    else if (key == "cells") base.cells = n;
    else if (key == "calls") base.calls = n;
    else return bad("unknown limit '" + std::string(key) + "' (call-depth, list-length, objects, cells, calls)");
  }
  return base;
}

}  // namespace limits
}  // namespace autumn
