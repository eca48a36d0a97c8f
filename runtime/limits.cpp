// limits — the message texts and the --limits parser of limits.hpp, out of
// line: both engines and every compiled module share this one copy (a module
// reaches them only on its error paths).
#include "runtime/limits.hpp"

namespace autumn::limits {

std::string raise_hint(std::string_view key) {
  return " (--limits " + std::string(key) + "=N raises it)";
}

std::string call_depth_error(int64_t limit, std::string_view callee) {
  return "call depth limit exceeded: more than " + std::to_string(limit) + " nested calls, calling " +
         (callee.empty() ? std::string("an unnamed function") : "'" + std::string(callee) + "'") +
         raise_hint("call-depth");
}

std::string list_length_error(int64_t length, int64_t limit) {
  return "list too long: " + std::to_string(length) + " elements, the limit is " + std::to_string(limit) +
         raise_hint("list-length");
}

std::string objects_error(int64_t limit, std::string_view global) {
  return "too many objects: the state holds more than " + std::to_string(limit) + " once '" + std::string(global) +
         "' is counted" + raise_hint("objects");
}

std::string state_cells_error(int64_t limit, std::string_view global) {
  return "state too large: more than " + std::to_string(limit) + " list elements and object fields once '" +
         std::string(global) + "' is counted" + raise_hint("cells");
}

std::string created_cells_error(int64_t limit) {
  return "memory budget exceeded: this step created more than " + std::to_string(limit) +
         " list elements and object fields" + raise_hint("cells");
}

std::string calls_error(int64_t limit) {
  return "time budget exceeded: this step made more than " + std::to_string(limit) + " function calls" +
         raise_hint("calls");
}

std::string loop_elements_error(int64_t limit) {
  return "time budget exceeded: this step's loops visited more than " + std::to_string(limit) +
         " list elements" + raise_hint("calls");
}

std::string syntax_nesting_error() {
  return "nested too deeply: more than " + std::to_string(kMaxSyntaxNesting) + " levels of parentheses";
}

std::string value_nesting_error() {
  return "value nested too deeply: more than " + std::to_string(kMaxValueNesting) +
         " levels of lists and objects inside each other";
}

std::string rotation_nesting_error() {
  return "rotate: a cell turned more than " + std::to_string(kMaxRotations) + " times";
}

std::string grid_size_error(int64_t size) {
  if (size >= kMinGridSize && size <= kMaxGridSize) return {};
  return "GRID_SIZE must be a number from " + std::to_string(kMinGridSize) + " to " + std::to_string(kMaxGridSize) +
         ", got " + std::to_string(size);
}

std::string grid_size_type_error(std::string_view type) {
  return "GRID_SIZE must be a number from " + std::to_string(kMinGridSize) + " to " + std::to_string(kMaxGridSize) +
         ", got a " + std::string(type);
}

Limits normalised(Limits l) {
  if (l.list_length < kMinListLength) l.list_length = kMinListLength;
  return l;
}

std::optional<Limits> parse(std::string_view spec, std::string* why, Limits base) {
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

}  // namespace autumn::limits
