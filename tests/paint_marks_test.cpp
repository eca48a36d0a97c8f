// The compiled engine's incremental render (runtime/compiled_support.hpp):
// Painter and Occupancy undo only the cells the last render set, remembered
// in Marks (a fixed array, dense past a quarter of the grid), and copies take
// only the marks in use. Checked against a repaint from scratch over random
// renders of every density, with copies between hosts in between, as a
// search's copy_from makes them, and renders cut short by an error (the host
// forgets them) before some. Also the state hash of lists, and the state
// check's count of a list of objects of a constant size (counted at once)
// against the count object by object.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "runtime/compiled_support.hpp"

namespace autumn::paint_marks_test {
namespace {

using rt::Pos;

constexpr int kGrid = 16;
constexpr int32_t kBackgroundId = 6;  // the background's string id: pal[6] below
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

// A render as emitted code paints: the occupancy cleared, begin_render, each
// element marked and painted on the brush, end_render (a render that throws
// stops after `cut` elements, without ending, and the host forgets both
// tables; its frame is not looked at, as the episode has failed). Without
// `painting`, as start-up renders: no painter, the occupancy only.
void draw(Host& h, const std::vector<std::pair<Pos, int32_t>>& render, const std::vector<uint16_t>& pal,
          size_t cut = SIZE_MAX, bool painting = true) {
  h.painter.bind(&h.frame);
  h.occupied.clear(kGrid);
  rt::Painter* painter = painting ? &h.painter : nullptr;
  static const std::vector<uint16_t> none;  // start-up's palette
  rt::Brush brush = rt::begin_render(painter, h.occupied, kGrid, kBackgroundId, painting ? pal : none);
  for (size_t i = 0; i < render.size(); ++i) {
    if (i == cut) {
      h.painter.forget();
      h.occupied.forget();
      return;
    }
    brush.mark(render[i].first);
    brush.paint(render[i].first, render[i].second);
  }
  ASSERT_EQ(rt::end_render(painter, h.occupied, brush), static_cast<int64_t>(render.size()));
}

// The occupancy after `render`: covered exactly where it drew, off the grid too.
void expect_covered(const Host& h, const std::vector<std::pair<Pos, int32_t>>& render, int round) {
  std::set<std::pair<int, int>> covered;
  for (const auto& [p, c] : render) covered.insert({p.x, p.y});
  for (int x = -2; x < kGrid + 2; ++x)
    for (int y = -2; y < kGrid + 2; ++y)
      ASSERT_EQ(h.occupied.free(Pos{x, y}), !covered.count({x, y})) << "round " << round << " at " << x << "," << y;
}

std::vector<uint16_t> repainted(const std::vector<std::pair<Pos, int32_t>>& render, const std::vector<uint16_t>& pal) {
  std::vector<uint16_t> cells(kGrid * kGrid, kBackground);
  for (const auto& [p, c] : render)
    if (p.x >= 0 && p.y >= 0 && p.x < kGrid && p.y < kGrid) cells[p.y * kGrid + p.x] = pal[c];
  return cells;
}

TEST(PaintMarks, IncrementalRendersEqualARepaintAcrossDensitiesAndCopies) {
  const std::vector<uint16_t> pal = {1, 2, 3, 4, 5, 6, kBackground};
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
    if (coin(rng) == 0) {  // a render cut short: the host forgets what it painted
      const auto cut = random_render(rng, sizes[pick(rng)] + 1);
      draw(hosts[at], cut, pal, std::uniform_int_distribution<size_t>(0, cut.size() - 1)(rng));
    }
    if (coin(rng) == 0) {  // start-up's render: no painter (the frame is left as it was)
      const auto counted = random_render(rng, sizes[pick(rng)]);
      draw(hosts[at], counted, pal, SIZE_MAX, false);
      expect_covered(hosts[at], counted, round);
    }
    const auto render = random_render(rng, sizes[pick(rng)]);
    draw(hosts[at], render, pal);
    ASSERT_EQ(hosts[at].frame.size, kGrid);
    ASSERT_EQ(hosts[at].frame.cells, repainted(render, pal)) << "round " << round;
    expect_covered(hosts[at], render, round);
  }
}

// The state hash (rt::Hash, hash_value) on the structured values states are
// made of: small coordinates, a flag, lists whose order matters. A search
// takes equal hashes for equal states, so these must all hash apart.
uint64_t hash_of(const std::vector<rt::Elem>& v) {
  rt::Hash h;
  rt::hash_value(h, v);
  return h.h;
}

TEST(StateHash, SmallListsOfElementsHashApart) {
  std::vector<rt::Elem> cells;
  for (int x = 0; x < kGrid; ++x)
    for (int y = 0; y < kGrid; ++y)
      for (int32_t c : {0, 1}) cells.push_back(rt::Elem{Pos{x, y}, c});
  std::set<uint64_t> seen;
  size_t made = 1;
  seen.insert(hash_of({}));
  for (const rt::Elem& a : cells) {
    seen.insert(hash_of({a}));
    ++made;
    for (const rt::Elem& b : cells) {
      seen.insert(hash_of({a, b}));
      ++made;
    }
  }
  EXPECT_EQ(seen.size(), made);  // 1 + 512 + 512 * 512 distinct lists
}

TEST(StateHash, LongListsHashByOrder) {
  // Lists of 8 and more are hashed in lanes (compiled_support.hpp): every
  // order of 8 distinct elements, and every one-element change, hashes apart.
  std::vector<rt::Elem> v;
  for (int i = 0; i < 8; ++i) v.push_back(rt::Elem{Pos{i, 2 * i}, i % 2});
  std::set<uint64_t> seen;
  size_t made = 0;
  std::sort(v.begin(), v.end(), [](const rt::Elem& a, const rt::Elem& b) { return a.position.x < b.position.x; });
  do {
    seen.insert(hash_of(v));
    ++made;
  } while (std::next_permutation(v.begin(), v.end(), [](const rt::Elem& a, const rt::Elem& b) { return a.position.x < b.position.x; }));
  for (size_t i = 0; i < v.size(); ++i)
    for (int x = -3; x < kGrid + 3; ++x) {
      std::vector<rt::Elem> w = v;
      w[i].position.x = x + 100;
      seen.insert(hash_of(w));
      ++made;
    }
  EXPECT_EQ(made, 40320u + 8u * (kGrid + 6));
  EXPECT_EQ(seen.size(), made);
}

// An object as print_cpp emits it: its fields in one hash_fields call, which
// pairs neighbouring one-word fields (Hash::mix2) and hashes any other (here a
// list) on its own. Every object of a 16x16 grid with two flags, a short list
// and an identity hashes apart, and 256 of them in a list hash by their order.
struct Blob {
  bool f0 = false;
  std::vector<int32_t> f1;
  rt::Pos origin;
  uint32_t uid = 0;
  friend void hash_value(rt::Hash& h, const Blob& v) { rt::hash_fields(h, v.f0, v.f1, v.origin, v.uid); }
};
uint64_t hash_of(const std::vector<Blob>& v) {
  rt::Hash h;
  rt::hash_value(h, v);
  return h.h;
}

TEST(StateHash, ObjectsHashFieldByField) {
  std::set<uint64_t> seen;
  size_t made = 0;
  for (int x = 0; x < kGrid; ++x)
    for (int y = 0; y < kGrid; ++y)
      for (bool f0 : {false, true})
        for (const std::vector<int32_t>& f1 : std::vector<std::vector<int32_t>>{{}, {0}, {1}, {0, 0}, {x + 2}})
          for (uint32_t uid : {0u, 1u, 7u}) {
            seen.insert(hash_of({Blob{f0, f1, Pos{x, y}, uid}}));
            ++made;
          }
  EXPECT_EQ(seen.size(), made);
  std::vector<Blob> grid;
  for (int i = 0; i < kGrid * kGrid; ++i) grid.push_back(Blob{i % 3 == 0, {}, Pos{i % kGrid, i / kGrid}, 0});
  const uint64_t base = hash_of(grid);
  for (size_t i = 0; i + 1 < grid.size(); ++i) {
    std::vector<Blob> swapped = grid;
    std::swap(swapped[i], swapped[i + 1]);
    ASSERT_NE(hash_of(swapped), base) << "objects " << i << " and " << i + 1 << " swapped";
    std::vector<Blob> flipped = grid;
    flipped[i].f0 = !flipped[i].f0;
    ASSERT_NE(hash_of(flipped), base) << "object " << i << "'s flag";
  }
}

// An object of a constant count (kTally cells), as emitted for a class with no
// list fields: one more object, then its cells in steps, stopping once over.
struct Dot {
  static constexpr int64_t kTally = 9;
  friend bool tally_value(rt::Tally& t, const rt::Core& c, const Dot&) {
    ++t.objects;
    t.cells += 3;
    if (rt::tally_over(t, c)) return true;
    t.cells += 4;
    if (rt::tally_over(t, c)) return true;
    t.cells += 2;
    return true;
  }
};

TEST(StateTally, ListsOfConstantCountObjectsCountAsObjectByObject) {
  // The interpreter's rule, one object at a time: the list's length, then its
  // objects (last first) until the count passes a limit.
  auto by_object = [](rt::Tally t, const rt::Core& c, const std::vector<Dot>& v) {
    t.cells += static_cast<int64_t>(v.size());
    for (auto it = v.rbegin(); it != v.rend() && !rt::tally_over(t, c); ++it) tally_value(t, c, *it);
    return t;
  };
  int checked = 0, passed = 0;
  for (int64_t objects_limit : {0, 1, 5, 6, 7, 40})
    for (int64_t cells_limit : {0, 9, 50, 59, 60, 61, 70, 400})
      for (int64_t before_objects : {0, 2})
        for (int64_t before_cells : {0, 5, 55})
          for (size_t n : {0, 1, 5, 6, 30}) {
            rt::Core c;
            c.objects_limit = objects_limit;
            c.cells_limit = cells_limit;
            const std::vector<Dot> v(n);
            const rt::Tally start{before_objects, before_cells};
            rt::Tally at_once = start;
            ASSERT_TRUE(rt::tally_value(at_once, c, v));
            const rt::Tally one_by_one = by_object(start, c, v);
            SCOPED_TRACE(testing::Message() << "limits " << objects_limit << "/" << cells_limit << ", from "
                                            << before_objects << "/" << before_cells << ", " << n << " objects");
            // The same objects and the same error (the objects limit is
            // looked at first, tally_add); the cells agree whenever no limit
            // is passed (past one, the count may stop inside an object).
            auto error = [&](const rt::Tally& t) {
              return t.objects > objects_limit ? "objects" : t.cells > cells_limit ? "cells" : "none";
            };
            EXPECT_EQ(at_once.objects, one_by_one.objects);
            EXPECT_STREQ(error(at_once), error(one_by_one));
            if (!rt::tally_over(one_by_one, c)) {
              EXPECT_EQ(at_once.cells, one_by_one.cells);
            }
            passed += rt::tally_over(one_by_one, c);
            ++checked;
          }
  EXPECT_GT(passed, 0);
  EXPECT_LT(passed, checked);  // both sides of the limits were checked
}

}  // namespace
}  // namespace autumn::paint_marks_test
