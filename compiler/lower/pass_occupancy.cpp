// pass_occupancy — a program that never asks isFreePos builds no occupancy.
//
// The host render marks every element it draws in the occupancy grid
// (runtime/compiled_support.hpp, Occupancy), which exists only to answer the
// next step's isFreePos (Helper::OccupancyFree). Where no function of the
// module reads it, the marks are dropped; the clear at the render's start
// stays (on an empty grid it costs a compare):
//
//   s.core.occupied.clear(kGrid);                              (kept)
//   const Elem e4 = Elem{...};                                 const Elem e4 = Elem{...};
//   s.core.occupied.add(e4.position);                =>      (removed)
//   brush.paint(e4.position, e4.color);                       brush.paint(e4.position, e4.color);
//
// gameOfLife's 258 marks a successor were 9% of its BFS (perf). Tests: the
// filetests tests/ir/mark_occupancy_if_read.ir (no isFreePos: marks dropped)
// and tests/ir/mark_occupancy_if_read_kept.ir (isFreePos: marks kept).
#include "compiler/lower/passes.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

bool is_helper(const Node* n, Helper h) { return n && n->op == Op::Call && n->helper == h; }

bool reads(const Node* n) {
  if (!n) return false;
  if (is_helper(n, Helper::OccupancyFree)) return true;
  for (const Node* k : n->a)
    if (reads(k)) return true;
  return false;
}

bool reads(const Block& b) {
  for (const Stmt* s : b) {
    if (reads(s->a) || reads(s->b) || reads(s->body) || reads(s->other)) return true;
    for (const auto& [k, c] : s->cases)
      if (reads(c)) return true;
  }
  return false;
}

void drop_marks(Block& b) {
  std::erase_if(b, [](const Stmt* s) { return s->k == SK::Eval && is_helper(s->a, Helper::OccupancyAdd); });
  for (Stmt* s : b) {
    drop_marks(s->body);
    drop_marks(s->other);
    for (auto& [k, c] : s->cases) drop_marks(c);
  }
}

}  // namespace

void mark_occupancy_if_read(Module& m) {
  for (const auto& f : m.functions)
    if (reads(f->body)) return;
  for (const auto& f : m.functions) drop_marks(f->body);
}

}  // namespace autumn::lower
