// The compiled engine's incremental render (runtime/compiled_support.hpp):
// Painter and Occupancy undo only the cells the last render set, remembered
// in Marks (a fixed array, dense past a quarter of the grid), and copies take
// only the marks in use. Checked against a repaint from scratch over random
// renders of every density, with copies between hosts in between, as a
// search's copy_from makes them.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <utility>
#include <vector>

#include "runtime/compiled_support.hpp"

namespace autumn::paint_marks_test {
namespace {

using rt::Pos;

constexpr int kGrid = 16;
constexpr uint16_t kBackground = 7;

struct Host {  // a compiled host's frame and painter, copied as copy_host does
  Frame frame;
  rt::Painter painter;
  rt::Occupancy occupied;
  void copy_from(const Host& o) {
    frame = o.frame;
    painter = o.painter;
    occupied = o.occupied;
  }
};

// A render of `n` elements, some off the grid, with colours from the palette.
std::vector<std::pair<Pos, int32_t>> random_render(std::mt19937& rng, int n) {
  std::uniform_int_distribution<int> coord(-2, kGrid + 1), colour(0, 5);
  std::vector<std::pair<Pos, int32_t>> r;
  for (int i = 0; i < n; ++i) r.push_back({Pos{coord(rng), coord(rng)}, colour(rng)});
  return r;
}

void draw(Host& h, const std::vector<std::pair<Pos, int32_t>>& render, const std::vector<uint16_t>& pal) {
  h.painter.bind(&h.frame);
  h.occupied.clear(kGrid);
  h.painter.begin(kGrid, kBackground);
  for (const auto& [p, c] : render) {
    h.occupied.add(p);
    h.painter.paint(p, c, pal);
  }
}

std::vector<uint16_t> repainted(const std::vector<std::pair<Pos, int32_t>>& render, const std::vector<uint16_t>& pal) {
  std::vector<uint16_t> cells(kGrid * kGrid, kBackground);
  for (const auto& [p, c] : render)
    if (p.x >= 0 && p.y >= 0 && p.x < kGrid && p.y < kGrid) cells[p.y * kGrid + p.x] = pal[c];
  return cells;
}

TEST(PaintMarks, IncrementalRendersEqualARepaintAcrossDensitiesAndCopies) {
  const std::vector<uint16_t> pal = {1, 2, 3, 4, 5, 6};
  std::mt19937 rng(12345);
  // Sizes around the dense threshold (a quarter of 256 cells) and far from it.
  const int sizes[] = {0, 1, 3, 20, 63, 64, 65, 66, 100, 256, 400};
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(sizes)) - 1), coin(0, 3);
  Host hosts[3];
  int at = 0;
  for (int round = 0; round < 2000; ++round) {
    if (coin(rng) == 0) {  // the next render happens on another host, copied from this one
      const int to = (at + 1 + coin(rng) % 2) % 3;
      hosts[to].copy_from(hosts[at]);
      at = to;
    }
    const auto render = random_render(rng, sizes[pick(rng)]);
    draw(hosts[at], render, pal);
    ASSERT_EQ(hosts[at].frame.size, kGrid);
    ASSERT_EQ(hosts[at].frame.cells, repainted(render, pal)) << "round " << round;
    std::set<std::pair<int, int>> covered;
    for (const auto& [p, c] : render) covered.insert({p.x, p.y});
    for (int x = -2; x < kGrid + 2; ++x)
      for (int y = -2; y < kGrid + 2; ++y)
        ASSERT_EQ(hosts[at].occupied.free(Pos{x, y}), !covered.count({x, y})) << "round " << round << " at " << x << "," << y;
  }
}

}  // namespace
}  // namespace autumn::paint_marks_test
