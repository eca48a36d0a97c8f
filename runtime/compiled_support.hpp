// compiled_support — what specialised modules (emitted by compiler/lower) link.
//
// Plain data only: positions, rendered elements, the occupancy table, the input
// latch, the wrapped RNG, 32-bit wrapping arithmetic, state hashing, and the
// Environment adapter that turns a generated `Program` type into a module.
//
// A generated Program type provides:
//   struct State { ... };               // copyable: a snapshot is a value copy
//   static const char* const kColours[];// per string id: its text without quotes, lower-cased; null-terminated
//   static void start(State&, uint64_t seed);
//   static void step(State&);           // inputs already latched in s.core
//   static void render(State&, Painter*, const std::vector<uint16_t>& palette_of_string);
//                                       // host render; null painter: only the side effects
//   static uint64_t hash(const State&);
//   static void save(const State&, SnapshotWriter&); static void load(State&, SnapshotReader&);
//   static constexpr int kOnClauses; static constexpr bool kUsesRandom;
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <unordered_set>
#include <utility>
#include <variant>
#include <vector>

#include "runtime/arith.hpp"
#include "runtime/diagnostic.hpp"
#include "runtime/environment.hpp"
#include "runtime/frame.hpp"
#include "runtime/hash_order.hpp"
#include "runtime/rng.hpp"
#include "runtime/snapshot_header.hpp"

namespace autumn::rt {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
[[noreturn]] inline void fail(const std::string& msg) { throw Error(msg); }

using autumn::arith::add;
using autumn::arith::mul;
using autumn::arith::neg;
using autumn::arith::sub;

// Where an emitted `fail_at` is: the innermost construct, and the innermost one
// of the user's program when that differs (an error inside the stdlib is
// reported at the program's call, "inside" the stdlib line). Mirrors the
// interpreter's RuntimeError locations (Interpreter::describe).
struct ErrorSite {
  int line, col;
  const char* source;  // null: the program file; else "<stdlib>", "<trigger>", "<internal>"
  bool in_program;
  int program_line, program_col;
  const char* prefix;  // "initialising 'x': " for start-up initialisers
};
struct LocatedError : std::runtime_error {
  LocatedError(int site, const std::string& msg) : std::runtime_error(msg), site(site) {}
  int site;
};
// Out of line and cold: a program has an error site at nearly every construct
// that can fail, and each inline throw was its own exception allocation and
// unwinding code for g++ to optimise (a tenth of an error-heavy module's
// compile). A message that is all text is printed as a C string (print_cpp).
[[noreturn, gnu::cold]] void fail_at(int site, const std::string& msg);
[[noreturn, gnu::cold]] void fail_at(int site, const char* msg);
// "path:line:col: runtime error: message[ (inside <stdlib>:l:c)]", as the interpreter says it.
std::string describe(const std::string& path, const ErrorSite& e, const std::string& msg,
                     const Relocation* moved = nullptr);

struct Unit {};  // the C++ value of a function or type: they exist only at compile time

// Holds working buffers inside a State without taking part in copies: a copy
// (clone) starts with empty buffers, and assigning a State keeps its own.
template <class T>
struct NoCopy {
  T v;
  NoCopy() = default;
  NoCopy(const NoCopy&) {}
  NoCopy& operator=(const NoCopy&) { return *this; }
};

struct Pos {
  int32_t x = 0, y = 0;
  bool operator==(const Pos&) const = default;
};
// A rendered element: a position and a colour (a string id).
struct Elem {
  Pos position;
  int32_t color = 0;
  bool operator==(const Elem&) const = default;
};

// A Position whose identity the program observes (removeObj by a Position):
// equal as a Position, whatever the uid.
struct PosU {
  int32_t x = 0, y = 0;
  uint32_t uid = 0;
  operator Pos() const { return Pos{x, y}; }
  bool operator==(const PosU& o) const { return x == o.x && y == o.y; }
};

// A Cell instance: per argument its value, and -1 (a number constant) or the
// index of the deferred argument the module evaluates (compiler/lower/spec_cells).
struct CellV {
  int32_t x = 0, y = 0, colour = 0;
  int16_t dx = -1, dy = -1, dc = -1;
  uint32_t uid = 0;
  bool operator==(const CellV&) const = default;
};

// Identity numbers (compiler/lower/spec_values): objects whose identity a
// program observes carry a uid, unique per object the reference makes; the
// number an object shows is its uid unless an assignment transferred another
// one onto it (the reference writes the old value's number into the shared
// object, so every holder sees it).
class IdTable {
 public:
  uint32_t fresh() { return next_++; }
  uint32_t id_of(uint32_t uid) const {
    auto it = std::lower_bound(remap_.begin(), remap_.end(), std::make_pair(uid, uint32_t{0}));
    return it != remap_.end() && it->first == uid ? it->second : uid;
  }
  void transfer(uint32_t uid, uint32_t id) {
    auto it = std::lower_bound(remap_.begin(), remap_.end(), std::make_pair(uid, uint32_t{0}));
    if (it != remap_.end() && it->first == uid) it->second = id;
    else remap_.insert(it, {uid, id});
  }
  uint32_t next() const { return next_; }
  const std::vector<std::pair<uint32_t, uint32_t>>& remap() const { return remap_; }
  void restore(uint32_t next, std::vector<std::pair<uint32_t, uint32_t>> remap) {
    next_ = next;
    remap_ = std::move(remap);
  }

 private:
  uint32_t next_ = 1;
  std::vector<std::pair<uint32_t, uint32_t>> remap_;  // sorted by uid
};

// `n` cells set to `value`, eight bytes a store: g++ -O2 wrote a frame's
// 2-byte cells one at a time (a seventh of a full grid's render).
template <class T>
[[gnu::always_inline]] inline void fill_all(T* cells, size_t n, T value) {
  static_assert(std::is_trivially_copyable_v<T> && 8 % sizeof(T) == 0);
  T word[8 / sizeof(T)];
  std::fill_n(word, 8 / sizeof(T), value);
  size_t i = 0;
  for (; i + 8 / sizeof(T) <= n; i += 8 / sizeof(T)) std::memcpy(cells + i, word, 8);
  for (; i < n; ++i) cells[i] = value;
}

// The grid cells a render set, so that the next render can unset just those:
// a fixed array of grid/4 + 1 entries (no growing list: a mark is made per
// element drawn, the hottest call of a many-object render) whose last entry is
// a sink. Once a mark reaches the sink, unsetting cell by cell would cost more
// than clearing the grid: the marks are dense, and undo() clears it all.
class Marks {
 public:
  Marks() = default;
  // Copies (clone, and every search successor's copy_from) take only the
  // entries in use, none once dense: the array is allocated, not filled.
  Marks(const Marks& o) { *this = o; }
  Marks& operator=(const Marks& o) {
    if (this == &o) return *this;
    if (size_ != o.size_) {
      at_.reset(o.size_ ? new uint32_t[o.size_] : nullptr);
      size_ = o.size_;
    }
    n_ = o.n_;
    if (!dense()) std::copy_n(o.at_.get(), n_, at_.get());
    return *this;
  }
  void reset(size_t cells) {
    size_ = cells / 4 + 1;
    at_.reset(new uint32_t[size_]);
    n_ = 0;
  }
  // Marks are added by a run: a plain value a render keeps in registers (a
  // Brush's), lent by lend() after reset() or undo() and given back with
  // take_back(). A run never taken back leaves the marks stale: the owner then
  // forgets its whole array (Occupancy::forget, Painter::forget).
  struct Run {
    uint32_t* next;
    uint32_t* sink;  // the array's last entry: marks from there on are not kept
    // A branch, not a store past the end: a render that outgrows the marks (a
    // grid covered by objects, gameOfLife) goes on without storing, and the
    // branch changes direction once per render. The branchless form (store,
    // then advance unless at the sink) cost a store and a reload of the sink
    // per element: 8% of gameOfLife's successor (docs/design.md, "The render's
    // marks").
    void add(uint32_t cell) {
      if (__builtin_expect(next != sink, 1)) *next++ = cell;
    }
  };
  Run lend() { return Run{at_.get() + n_, at_.get() + size_ - 1}; }
  void take_back(const Run& r) { n_ = static_cast<size_t>(r.next - at_.get()); }
  bool dense() const { return n_ == size_ - 1; }
  // Sets the marked cells of `cells` (the array the marks index) back to
  // `value`, or all of it once dense, and clears the marks.
  template <class T>
  void undo(std::vector<T>& cells, T value) {
    if (dense()) fill_all(cells.data(), cells.size(), value);
    else
      for (size_t k = 0; k < n_; ++k) cells[at_[k]] = value;
    n_ = 0;
  }

 private:
  // Invariant: after reset(), at_ holds size_ = cells/4 + 1 entries; n_ is at
  // most size_ - 1, and the first n_ entries are the cells marked since the
  // last undo() unless n_ is size_ - 1 (dense: a mark reached the sink, and
  // some were not kept); the others are unspecified. Before reset(), size_ and
  // n_ are 0 and nothing is marked.
  std::unique_ptr<uint32_t[]> at_;
  size_t size_ = 0;
  size_t n_ = 0;
};

// Positions covered at the last host render; out-of-grid positions count too.
class Occupancy {
 public:
  // Clears in time proportional to what the last render covered, not to the
  // grid (Marks).
  void clear(int size) {
    const size_t cells = static_cast<size_t>(size) * size;
    if (size != size_) {
      size_ = size;
      grid_.assign(cells, 0);
      marks_.reset(cells);
    } else {
      marks_.undo(grid_, uint8_t{0});
    }
    outside_.clear();
    sorted_ = true;
  }
  // A render's marking, lent after clear() to its Brush (Brush::mark) and
  // taken back at its end; a render cut short never gives it back, and the
  // host forgets the table (the next clear() makes it afresh).
  struct Run {
    uint8_t* grid;
    uint32_t size;
    Marks::Run marks;
    Occupancy* owner;
    // Always inline (Brush::mark).
    [[gnu::always_inline]] void add(Pos p) {
      if (static_cast<uint32_t>(p.x) < size && static_cast<uint32_t>(p.y) < size) {
        const uint32_t i = static_cast<uint32_t>(p.y) * size + static_cast<uint32_t>(p.x);
        if (!grid[i]) {
          grid[i] = 1;
          marks.add(i);
        }
      } else {
        owner->add_outside(p);
      }
    }
  };
  Run lend() { return Run{grid_.data(), static_cast<uint32_t>(size_), marks_.lend(), this}; }
  void take_back(const Run& r) { marks_.take_back(r.marks); }
  void forget() { size_ = 0; }
  // Off-grid positions are listed inline: some programs draw mostly there
  // (out of line, the call was half of gravity_2's step).
  [[gnu::always_inline]] void add_outside(Pos p) {
    outside_.push_back(key(p));
    sorted_ = false;
  }
  bool free(Pos p) const {
    if (p.x >= 0 && p.y >= 0 && p.x < size_ && p.y < size_) return !grid_[static_cast<size_t>(p.y) * size_ + p.x];
    if (outside_.empty()) return true;
    sort();
    return !std::binary_search(outside_.begin(), outside_.end(), key(p));
  }

 private:
  static uint64_t key(Pos p) { return (static_cast<uint64_t>(static_cast<uint32_t>(p.x)) << 32) | static_cast<uint32_t>(p.y); }
  void sort() const {
    if (!sorted_) sort_outside();
  }
  void sort_outside() const;  // compiled_support.cpp
  // Invariants: grid_ has size_ * size_ cells, 1 where covered, each marked
  // once in marks_ (reset for the grid), but while a Run is lent (its count is
  // the Run's). Before the first clear() and after forget(), size_ is 0 and
  // the rest is not looked at (the render clears first).
  int size_ = 0;
  std::vector<uint8_t> grid_;
  Marks marks_;
  mutable std::vector<uint64_t> outside_;  // positions off the grid, sorted on demand
  mutable bool sorted_ = true;
};

// A string id as a palette id: ids come from the program's literals, but a
// loaded snapshot may carry any number, so the lookup is checked.
[[noreturn, gnu::cold]] void fail_string_id(int32_t id);
inline uint16_t colour_of(const std::vector<uint16_t>& pal, int32_t id) {
  if (__builtin_expect(static_cast<uint32_t>(id) >= pal.size(), 0)) fail_string_id(id);
  return pal[static_cast<uint32_t>(id)];
}

// Paints frames incrementally: cells painted by the previous render are reset to
// the background, then the new cells are painted, so a render costs what it
// draws rather than the whole grid. The result is identical to a full repaint.
// While recording (the host's render_all() JSON), it also keeps every element
// drawn, out-of-grid ones included, with its colour's string id and the index
// of the global it came from.
//
// A render paints through a Brush (below): begin() resets the frame and lends
// the painter's working fields to it, the render paints and names its globals
// on the brush, and finish() takes the marks back. A render that throws never
// finishes: the host then calls forget(), and the next begin() repaints the
// whole frame.
struct Brush;
class Painter {
 public:
  struct Drawn {
    Pos position;
    int32_t colour = 0;  // string id
    int32_t global = 0;  // index into the program's kRenderNames
  };
  void bind(Frame* f) { frame_ = f; }
  void record(bool on) {
    record_ = on;
    recorded_ = false;
    drawn_.clear();
  }
  // drawn() holds the last render's elements: recording was on when it began.
  bool recorded() const { return recorded_; }
  const std::vector<Drawn>& drawn() const { return drawn_; }
  [[gnu::always_inline]] inline Brush begin(int size, uint16_t background, const std::vector<uint16_t>& pal);
  // The render's elements drawn (on the grid or not), for cacheRendered.
  inline int64_t finish(const Brush& b);
  // A render ended without finish(): which cells it set is not known.
  void forget() { background_ = kNoBackground; }

 private:
  friend struct Brush;
  static constexpr uint16_t kNoBackground = 0xffff;
  // begin() without marks to go by: the whole frame is set to the background.
  [[gnu::cold, gnu::noinline]] void repaint(int size, uint16_t background) {
    const size_t cells = static_cast<size_t>(size) * size;
    frame_->size = size;
    frame_->cells.assign(cells, background);
    background_ = background;
    marks_.reset(cells);
  }
  // A Brush's element that is recorded, or whose colour is not in the
  // palette (fails).
  [[gnu::cold, gnu::noinline]] uint16_t colour_slowly(Pos p, int32_t colour, int32_t global) {
    if (record_) drawn_.push_back(Drawn{p, colour, global});
    return colour_of(*pal_, colour);
  }
  // Invariants: between renders, frame_'s cells are the background but for the
  // cells in marks_ (reset for frame_'s grid), unless background_ is
  // kNoBackground (before the first render, after forget()): then begin()
  // fills the frame. A copy (the host's copy_host) copies the frame with it.
  Frame* frame_ = nullptr;
  const std::vector<uint16_t>* pal_ = nullptr;  // the palette of the render begun last
  uint16_t background_ = kNoBackground;
  Marks marks_;
  bool record_ = false, recorded_ = false;
  std::vector<Drawn> drawn_;
};

// One render's painting and occupancy marking: the painter's and the
// occupancy's working fields as a plain local value, so that the emitted
// render keeps them in registers (as members of the painter, each element's
// mark count went through memory: a load waiting on the last element's store,
// a third of gameOfLife's render). No constructor or destructor: an unwinding
// path would pin it to memory again. Without a painter (start-up's render) it
// only counts and marks.
struct Brush {
  // Always inline, as mark(): the hottest calls of a many-object render, and
  // one left out of line takes the brush's address, which puts it all in
  // memory (g++ did so with mark() in flood_defense's render).
  [[gnu::always_inline]] void paint(Pos p, int32_t colour) {
    ++drawn;
    uint16_t c;
    if (__builtin_expect(static_cast<uint32_t>(colour) < pal_size, 1)) c = pal[static_cast<uint32_t>(colour)];
    else if (painter) c = painter->colour_slowly(p, colour, from);
    else return;  // no painter: nothing to look up
    if (static_cast<uint32_t>(p.x) >= size || static_cast<uint32_t>(p.y) >= size) return;
    const uint32_t i = static_cast<uint32_t>(p.y) * size + static_cast<uint32_t>(p.x);
    cells[i] = c;
    painted.add(i);
  }
  // The occupancy's mark of an element drawn (the next step's isFreePos).
  [[gnu::always_inline]] void mark(Pos p) { covered.add(p); }
  // The global the next elements are drawn from (an index into kRenderNames).
  void global(int32_t index) { from = index; }

  Painter* painter;
  uint16_t* cells;
  uint32_t size;
  const uint16_t* pal;
  // 0 while recording: every element takes the painter's slow path. 32 bits,
  // as the colour is: compared as size_t, g++ computed the colour twice (once
  // sign-extended), a tenth of a many-object render.
  uint32_t pal_size;
  Marks::Run painted;
  int64_t drawn;
  int32_t from;  // the global being drawn (global())
  Occupancy::Run covered;
};

Brush Painter::begin(int size, uint16_t background, const std::vector<uint16_t>& pal) {
  Frame& f = *frame_;
  if (__builtin_expect(f.size != size || background != background_ || f.cells.size() != static_cast<size_t>(size) * size, 0))
    repaint(size, background);
  else
    marks_.undo(f.cells, background);
  drawn_.clear();
  recorded_ = record_;
  pal_ = &pal;
  const uint32_t pal_size = record_ ? 0 : static_cast<uint32_t>(pal.size());
  return Brush{this, f.cells.data(), static_cast<uint32_t>(size), pal.data(), pal_size, marks_.lend(), 0, 0, {}};
}

int64_t Painter::finish(const Brush& b) {
  marks_.take_back(b.painted);
  return b.drawn;
}

// The emitted render's first and last calls, after the occupancy's clear().
// Without a painter (start-up's render, which only counts cacheRendered's
// elements and marks the occupancy) the brush looks up no colour: the palette
// is empty then.
inline Brush begin_render(Painter* p, Occupancy& occupied, int size, int32_t background,
                          const std::vector<uint16_t>& pal) {
  Brush b = p ? p->begin(size, colour_of(pal, background), pal) : Brush{};
  b.covered = occupied.lend();
  return b;
}
// The elements drawn (on the grid or not): what cacheRendered holds.
inline int64_t end_render(Painter* p, Occupancy& occupied, const Brush& b) {
  occupied.take_back(b.covered);
  return p ? p->finish(b) : b.drawn;
}

// Cells rotate turned (compiler/lower: builtin_rotate): per group of objects made
// by one construction, the number of quarter turns its shared cells have had.
class RotationTable {
 public:
  void turn(uint32_t group) {
    auto it = std::lower_bound(turns_.begin(), turns_.end(), std::make_pair(group, uint32_t{0}));
    if (it != turns_.end() && it->first == group) ++it->second;
    else turns_.insert(it, {group, 1});
  }
  uint32_t of(uint32_t group) const {
    auto it = std::lower_bound(turns_.begin(), turns_.end(), std::make_pair(group, uint32_t{0}));
    return it != turns_.end() && it->first == group ? it->second : 0;
  }
  const std::vector<std::pair<uint32_t, uint32_t>>& turns() const { return turns_; }
  void restore(std::vector<std::pair<uint32_t, uint32_t>> t) { turns_ = std::move(t); }

 private:
  std::vector<std::pair<uint32_t, uint32_t>> turns_;  // sorted by group; absent: no turn
};

// A cell offset turned (x, y) -> (-y, x) `turns` times (wrapping negation).
inline Pos rotated(int32_t turns, int32_t x, int32_t y) {
  for (int32_t i = 0; i < (turns & 3); ++i) {
    const int32_t nx = neg(y);
    y = x;
    x = nx;
  }
  return Pos{x, y};
}

// Interpreter-independent state every specialised program has.
// limits.hpp's state rule, as the interpreter counts it (compiler/interpret/
// limits.cpp): after start-up and every step, each global holding a list or an
// instance is counted as a tree — a list its length, an instance its fields, an
// object one more object — depth first with children last to first, stopping
// once the global alone passes a limit; the totals over the globals in map order
// may not pass the limits, and an excess is reported at the definition of the
// global with the largest count so far.
struct Tally {
  int64_t objects = 0, cells = 0;
};
struct StateTally {
  Tally total;
  int64_t max_objects = -1, max_cells = -1;
  int site_objects = -1, site_cells = -1;  // where the largest globals are defined
  const char* name_objects = "";
  const char* name_cells = "";
};

struct Core {
  WrappedMinstd rng;
  // The generator's state as the last host render began (reset, step,
  // load_state set it): what a snapshot saves, so that load_state's render makes
  // the draws the original render made (a cell colour may draw at every render)
  // and leaves the generator where the original's left it.
  uint32_t rng_at_render = 0;
  bool click = false, left = false, right = false, up = false, down = false;
  int32_t click_x = -1, click_y = -1;
  bool have_prev = false;
  Occupancy occupied;
  std::vector<uint8_t> covered;
  bool triggered = false;
  IdTable ids;
  RotationTable rot;
  int64_t list_limit = Limits{}.list_length;  // the episode's list-length budget (runtime/limits.hpp)
  int64_t objects_limit = Limits{}.objects, cells_limit = Limits{}.cells;
  // The calls budget as loop elements (limits.hpp): `visited` counts what this
  // step's (or start-up's, or render's) loops were charged; reset before each.
  int64_t visited = 0, visit_limit = Limits{}.calls;
  // The cells budget's per-step part (limits.hpp): `built` counts the elements
  // this step's (or start-up's, or render's) program constructs put into new
  // lists (charge_built), against cells_limit; reset with `visited`.
  int64_t built = 0;
  int64_t rendered = 0;  // elements the last host render drew: what cacheRendered holds

  // Copied with every State (clone, copy_from, the planner's snapshots), the
  // same memberwise copy as the implicit one, but defined once in
  // compiled_support.cpp: inline, every module instantiated and optimised the
  // copies of these vectors again (0.3 s of a small module's compile).
  Core() = default;
  Core(const Core&);
  Core(Core&&) noexcept;
  Core& operator=(const Core&);
  Core& operator=(Core&&) noexcept;
  ~Core();

  void start(uint64_t seed, int on_clauses) {
    rng.reseed(seed);
    covered.assign(static_cast<size_t>(on_clauses), 0);
  }
  void clear_inputs() { click = left = right = up = down = false; }
  // A new entry (start-up, a step, a render) starts both per-step budgets afresh.
  void begin_entry() { visited = built = 0; }
};

// limits.hpp's list-length rule in emitted code: a list of `n` elements is about
// to be built at `site`.
[[noreturn, gnu::cold]] void fail_list_length(int site, int64_t n, int64_t limit);
inline void check_length(const Core& c, int site, int64_t n) {
  if (n > c.list_limit) fail_list_length(site, n, c.list_limit);
}
// A loop about to visit `n` elements (a list's, a range's) at `site`: charged
// once, before it runs, against the step's budget (limits.hpp, calls).
// The failure is out of line: charges sit in the hottest loops, and the message
// built inline at each one cost more than the charge itself.
// Both charges take the Core, or a loop's Budget (below): the counts and
// limits by the same names.
[[noreturn, gnu::cold]] void fail_loop_budget(int site, int64_t limit);
template <class Counts>
[[gnu::always_inline]] inline void charge_loop(Counts& c, int site, int64_t n) {
  c.visited += n > 0 ? n : 0;
  if (__builtin_expect(c.visited > c.visit_limit, 0)) fail_loop_budget(site, c.visit_limit);
}
// `n` elements about to be put into a list a program construct builds (a
// range, map, filter, concat, ...), charged at `site` against the step's cells
// budget (limits.hpp, cells): out of line for the same reason as the loops'.
[[noreturn, gnu::cold]] void fail_built_budget(int site, int64_t limit);
template <class Counts>
[[gnu::always_inline]] inline void charge_built(Counts& c, int site, int64_t n) {
  c.built += n > 0 ? n : 0;
  if (__builtin_expect(c.built > c.cells_limit, 0)) fail_built_budget(site, c.cells_limit);
}
// A loop's copy of the step's budget counts (compiler/lower/pass_budget_locals):
// a plain local, so that g++ keeps the counts of a loop charging as it runs in
// registers (through the core, each charge waited on the last one's store).
// Taken before the loop, given back after it; a failure inside throws out of
// the step, whose counts are then not read again (the next entry starts them
// afresh), so that path gives nothing back.
struct Budget {
  int64_t visited, built;
  int64_t visit_limit, cells_limit;
};
inline Budget budget_of(const Core& c) { return Budget{c.visited, c.built, c.visit_limit, c.cells_limit}; }
inline void give_back(Core& c, const Budget& b) {
  c.visited = b.visited;
  c.built = b.built;
}
// A list built element by element (allObjs) fails at the first element too many.
inline void check_appended_length(const Core& c, int site, int64_t n) {
  if (n > c.list_limit) fail_list_length(site, c.list_limit + 1, c.list_limit);
}
template <class L>
int64_t total_size(const L& lists) {
  int64_t t = 0;
  for (const auto& l : lists) t += static_cast<int64_t>(l.size());
  return t;
}

// Tallies of values (see StateTally). Each returns false for a value that is
// not a list or an instance (not counted). Leaves add cells only, so a run of
// them is added at once: where inside it the interpreter stops cannot change
// the object count or which global is the largest.
inline bool tally_over(const Tally& t, const Core& c) { return t.objects > c.objects_limit || t.cells > c.cells_limit; }
inline bool tally_value(Tally&, const Core&, int32_t) { return false; }
inline bool tally_value(Tally&, const Core&, uint32_t) { return false; }
inline bool tally_value(Tally&, const Core&, bool) { return false; }
inline bool tally_value(Tally&, const Core&, const Unit&) { return false; }
inline bool tally_value(Tally& t, const Core&, const Pos&) { return t.cells += 2, true; }
inline bool tally_value(Tally& t, const Core&, const PosU&) { return t.cells += 2, true; }
inline bool tally_value(Tally& t, const Core&, const CellV&) { return t.cells += 3, true; }
inline bool tally_value(Tally& t, const Core&, const Elem&) { return t.cells += 4, true; }  // + its Position
template <class T>
constexpr int64_t tally_leaf_cells() {
  if constexpr (std::is_same_v<T, Pos> || std::is_same_v<T, PosU>) return 2;
  else if constexpr (std::is_same_v<T, CellV>) return 3;
  else if constexpr (std::is_same_v<T, Elem>) return 4;
  else if constexpr (std::is_arithmetic_v<T>) return 0;
  else return -1;  // may hold objects: counted one by one
}
// Objects of a class with a constant count (T::kTally cells each) are counted
// at once too: the interpreter stops before the first object that finds the
// count past a limit, and that object is found by arithmetic. (It may stop
// inside an object, past a limit already: that changes neither the object count
// nor which global is the largest for the limit that is passed.)
template <class T>
int64_t tally_constant_cells() {
  if constexpr (requires { T::kTally; }) return T::kTally;
  else return -1;
}
template <class T>
bool tally_value(Tally& t, const Core& c, const std::vector<T>& v) {
  const int64_t n = static_cast<int64_t>(v.size());
  t.cells += n;
  if constexpr (tally_leaf_cells<T>() >= 0) {
    if (!tally_over(t, c)) t.cells += tally_leaf_cells<T>() * n;
  } else if (const int64_t k = tally_constant_cells<T>(); k > 0) {
    // Every object counted when none can pass a limit (the usual case: no
    // division); otherwise the objects before the one that passes it.
    if (t.objects + n <= c.objects_limit && t.cells + n * k <= c.cells_limit) {
      t.objects += n;
      t.cells += n * k;
      return true;
    }
    int64_t j = n;                                                           // objects visited
    j = std::min(j, std::max<int64_t>(0, c.objects_limit - t.objects + 1));  // before objects pass
    j = std::min(j, std::max<int64_t>(0, (c.cells_limit - t.cells) / k + 1));  // before cells pass
    if (t.cells > c.cells_limit) j = 0;
    t.objects += j;
    t.cells += j * k;
  } else {
    for (auto it = v.rbegin(); it != v.rend() && !tally_over(t, c); ++it) tally_value(t, c, *it);
  }
  return true;
}
template <class... T>
bool tally_value(Tally& t, const Core& c, const std::variant<T...>& v) {
  return std::visit([&](const auto& x) { return tally_value(t, c, x); }, v);
}
// A total past a limit: the error at the largest global's definition (cold).
[[noreturn, gnu::cold]] void fail_state_limit(const Core& c, const StateTally& s, bool objects);
// Adds one global's count to the check's totals, `s`: a local of the emitted
// function (TallyBegin), so that g++ keeps it in registers. Inline, in the
// module's own code: out of line (in the runtime archive, compiled by another
// compiler than the module's) its 16-byte load of the totals waited on the
// caller's narrower stores of them, half of a clang-built module's step on
// ajl_nim (docs/design.md, "The module's compiler").
[[gnu::always_inline]] inline void tally_add(const Core& c, StateTally& s, int site, const char* name, const Tally& one) {
  if (one.objects > s.max_objects) s.max_objects = one.objects, s.site_objects = site, s.name_objects = name;
  if (one.cells > s.max_cells) s.max_cells = one.cells, s.site_cells = site, s.name_cells = name;
  s.total.objects += one.objects;
  s.total.cells += one.cells;
  if (__builtin_expect(s.total.objects > c.objects_limit, 0)) fail_state_limit(c, s, true);
  if (__builtin_expect(s.total.cells > c.cells_limit, 0)) fail_state_limit(c, s, false);
}
// One global of the state check, defined at `site`.
template <class T>
[[gnu::always_inline]] inline void tally_global(const Core& c, StateTally& s, int site, const char* name, const T& v) {
  Tally one;
  if (tally_value(one, c, v)) tally_add(c, s, site, name, one);
}
// cacheRendered: the list of the last render's elements (RenderedElem: 2 fields and a Position).
inline void tally_rendered(const Core& c, StateTally& s, int site, const char* name) {
  tally_add(c, s, site, name, Tally{0, 5 * c.rendered});
}

struct Hash {
  uint64_t h = 0x9e3779b97f4a7c15ULL;
  void mix(uint64_t v) {
    h = (h ^ v) * 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
  }
  // Two words in one step: the 128-bit product of (h ^ a) and (b ^ a constant),
  // its halves folded (wyhash's "mum"). One multiply where mix takes two, and a
  // shorter chain: an object's fields are absorbed two at a time (hash_fields).
  void mix2(uint64_t a, uint64_t b) {
    const unsigned __int128 p = static_cast<unsigned __int128>(h ^ a) * (b ^ 0xe7037ed1a0b428dbULL);
    h = static_cast<uint64_t>(p) ^ static_cast<uint64_t>(p >> 64);
  }
};
// The one word a scalar hashes as (hash_fields pairs them).
inline uint64_t hash_word(int32_t v) { return static_cast<uint32_t>(v); }
inline uint64_t hash_word(uint32_t v) { return v; }
inline uint64_t hash_word(bool v) { return v ? 0xB1 : 0xB0; }
// x in the low half, y in the high: a Pos's own byte order, so that g++ reads
// the word with one load (y in the low half took two loads, a shift and an or:
// gameOfLife's 258-object state hashed in 340 cycles instead of 270).
inline uint64_t hash_word(const Pos& p) {
  return static_cast<uint64_t>(static_cast<uint32_t>(p.y)) << 32 | static_cast<uint32_t>(p.x);
}
inline uint64_t hash_word(const Unit&) { return 0x55; }
template <class T>
concept HashWord = requires(const T& v) { hash_word(v); };
inline void hash_value(Hash& h, int32_t v) { h.mix(hash_word(v)); }
inline void hash_value(Hash& h, bool v) { h.mix(hash_word(v)); }
// One mix for both coordinates: each mix waits on the previous one, and
// positions are most of what a state holds.
inline void hash_value(Hash& h, const Pos& p) { h.mix(hash_word(p)); }
inline void hash_value(Hash& h, const Unit& u) { h.mix(hash_word(u)); }
inline void hash_value(Hash& h, const PosU& p) { h.mix2(hash_word(Pos{p.x, p.y}), p.uid); }
// Identities hash by their pattern, not their numbers (states reached by
// different histories hash alike): the table holds no numbers of its own here.
inline void hash_value(Hash& h, uint32_t uid) { h.mix(hash_word(uid)); }
inline void hash_value(Hash& h, const CellV& c) {
  h.mix2(hash_word(Pos{c.x, c.y}), static_cast<uint32_t>(c.colour) | static_cast<uint64_t>(static_cast<uint16_t>(c.dx)) << 32 |
                                       static_cast<uint64_t>(static_cast<uint16_t>(c.dy)) << 48);
  h.mix2(static_cast<uint16_t>(c.dc), c.uid);
}
// An object's fields in order: neighbouring one-word fields two at a time
// (Hash::mix2), any other field by its own hash_value.
inline void hash_fields(Hash&) {}
template <class A, class... R>
void hash_fields(Hash& h, const A& a, const R&... r);
template <HashWord A, HashWord B, class... R>
void hash_fields(Hash& h, const A& a, const B& b, const R&... r) {
  h.mix2(hash_word(a), hash_word(b));
  hash_fields(h, r...);
}
template <class A, class... R>
void hash_fields(Hash& h, const A& a, const R&... r) {
  hash_value(h, a);
  hash_fields(h, r...);
}
inline void hash_value(Hash& h, const Elem& e) { hash_fields(h, e.position, e.color); }
template <class... T>
void hash_value(Hash& h, const std::variant<T...>& v) {
  h.mix(v.index());
  std::visit([&](const auto& x) { hash_value(h, x); }, v);
}
// A long list is hashed in four interleaved lanes, folded at the end: each mix
// waits on the one before it, so one chain over a list of objects kept the
// CPU waiting (a 256-object state was a quarter of a BFS successor's time).
template <class T>
void hash_value(Hash& h, const std::vector<T>& v) {
  h.mix(v.size());
  const size_t n = v.size();
  if (n < 8) {
    for (const T& x : v) hash_value(h, x);
    return;
  }
  // Four named lanes, not an array: g++ kept an array's lanes in memory, each
  // mix then waiting on a store and a load.
  Hash a = h, b{h.h ^ 0x1}, c{h.h ^ 0x2}, d{h.h ^ 0x3};
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    hash_value(a, v[i]);
    hash_value(b, v[i + 1]);
    hash_value(c, v[i + 2]);
    hash_value(d, v[i + 3]);
  }
  for (; i < n; ++i) hash_value(a, v[i]);
  h = a;
  h.mix(b.h);
  h.mix(c.h);
  h.mix(d.h);
}
// The occupancy table is not hashed: after a host render it is a function of the
// globals, which are (and states are hashed between host steps).
inline void hash_core(Hash& h, const Core& c, bool uses_random) {
  if (uses_random) h.mix(c.rng.state());
  for (const auto& [uid, id] : c.ids.remap()) {
    h.mix(uid);
    h.mix(id);
  }
  for (const auto& [group, turns] : c.rot.turns()) {
    h.mix(group);
    h.mix(turns);
  }
}

// Snapshots (Environment::save_state/load_state): the state that carries from
// one step to the next as flat bytes. Left out: the working buffers, the prev_/u_
// copies (rewritten at the start of every step) and what a render rebuilds (the
// occupancy table, the frame); load_state renders after reading.
// Every snapshot opens with the header of snapshot_header.hpp; load_state
// refuses bytes of another format or layout with that reason, before reading a
// field: a state of another program, or of another build of the same program,
// would otherwise be read into the wrong slots and could pass every check of
// the values.
class SnapshotWriter {
 public:
  explicit SnapshotWriter(std::vector<uint8_t>& out) : out_(out), n_(out.size()) {}
  ~SnapshotWriter() { out_.resize(n_); }  // shrinking: no allocation, no fill
  // Only types whose every byte is a value's: a padding byte would carry
  // whatever the memory held into the snapshot (equal states, unequal bytes;
  // another compiler, other bytes), as CellV's two did until snapshot format 2.
  template <class T>
  void raw(const T& v) {
    static_assert(std::has_unique_object_representations_v<T>, "a snapshot writes no padding: write the fields");
    if (n_ + sizeof v > out_.size()) out_.resize(std::max<size_t>(2 * out_.size(), n_ + sizeof v + 256));
    std::memcpy(out_.data() + n_, &v, sizeof v);
    n_ += sizeof v;
  }

 private:
  std::vector<uint8_t>& out_;
  size_t n_;  // bytes written; out_ is grown ahead in steps, trimmed to n_ at the end
};
[[noreturn, gnu::cold]] void truncated_snapshot();
struct SnapshotReader {
  const uint8_t* p;
  const uint8_t* end;
  template <class T>
  void raw(T& v) {
    if (static_cast<size_t>(end - p) < sizeof v) truncated_snapshot();
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
  }
};
inline void save_value(SnapshotWriter& w, int32_t v) { w.raw(v); }
inline void save_value(SnapshotWriter& w, uint8_t v) { w.raw(v); }
inline void save_value(SnapshotWriter& w, bool v) { w.raw(static_cast<uint8_t>(v)); }
inline void save_value(SnapshotWriter& w, const Pos& p) {
  w.raw(p.x);
  w.raw(p.y);
}
inline void save_value(SnapshotWriter& w, const Elem& e) {
  save_value(w, e.position);
  w.raw(e.color);
}
inline void save_value(SnapshotWriter&, const Unit&) {}
inline void save_value(SnapshotWriter& w, uint32_t v) { w.raw(v); }
// A CellV field by field (it has two bytes of padding), in one order for the
// writer and the reader (Io: SnapshotWriter with a const CellV, or SnapshotReader).
template <class Io, class C>
void cell_fields(Io& io, C& c) {
  io.raw(c.x);
  io.raw(c.y);
  io.raw(c.colour);
  io.raw(c.dx);
  io.raw(c.dy);
  io.raw(c.dc);
  io.raw(c.uid);
}
inline void save_value(SnapshotWriter& w, const CellV& c) { cell_fields(w, c); }
inline void save_value(SnapshotWriter& w, const PosU& p) { w.raw(p); }
template <class... T>
void save_value(SnapshotWriter& w, const std::variant<T...>& v) {
  w.raw(static_cast<uint8_t>(v.index()));
  std::visit([&](const auto& x) { save_value(w, x); }, v);
}
template <class T>
void save_value(SnapshotWriter& w, const std::vector<T>& v) {
  w.raw(static_cast<uint32_t>(v.size()));
  for (const T& x : v) save_value(w, x);
}
inline void load_value(SnapshotReader& r, int32_t& v) { r.raw(v); }
inline void load_value(SnapshotReader& r, uint8_t& v) { r.raw(v); }
[[noreturn, gnu::cold]] void corrupt_snapshot(const char* what);
inline void load_value(SnapshotReader& r, bool& v) {
  uint8_t b = 0;
  r.raw(b);
  if (b > 1) corrupt_snapshot("a truth value is neither 0 nor 1");
  v = b != 0;
}
inline void load_value(SnapshotReader& r, Pos& p) {
  r.raw(p.x);
  r.raw(p.y);
}
inline void load_value(SnapshotReader& r, Elem& e) {
  load_value(r, e.position);
  r.raw(e.color);
}
inline void load_value(SnapshotReader&, Unit&) {}
inline void load_value(SnapshotReader& r, uint32_t& v) { r.raw(v); }
inline void load_value(SnapshotReader& r, CellV& c) { cell_fields(r, c); }
inline void load_value(SnapshotReader& r, PosU& p) { r.raw(p); }
template <class V, size_t I = 0>
void load_alternative(SnapshotReader& r, V& v, size_t index) {
  if constexpr (I < std::variant_size_v<V>) {
    if (index == I) {
      load_value(r, v.template emplace<I>());
      return;
    }
    load_alternative<V, I + 1>(r, v, index);
  } else {
    corrupt_snapshot("a variant tag out of range");
  }
}
template <class... T>
void load_value(SnapshotReader& r, std::variant<T...>& v) {
  uint8_t index = 0;
  r.raw(index);
  load_alternative(r, v, index);
}
template <class T>
void load_value(SnapshotReader& r, std::vector<T>& v) {
  uint32_t n = 0;
  r.raw(n);
  if (n > static_cast<size_t>(r.end - r.p)) corrupt_snapshot("a list longer than the snapshot");
  v.resize(n);
  if constexpr (std::is_same_v<T, bool>) {  // std::vector<bool> has no bool& elements
    for (uint32_t i = 0; i < n; ++i) {
      bool b = false;
      load_value(r, b);
      v[i] = b;
    }
  } else {
    for (T& x : v) load_value(r, x);
  }
}
// Reads the header save_state wrote; throws the reason a snapshot of another
// format or layout (`layout`: the loading module's) is refused.
void check_snapshot_header(SnapshotReader& r, uint64_t layout);
void save_core(SnapshotWriter& w, const Core& c);
// A table of (key, value) pairs, strictly increasing by key (lookups bisect it).
std::vector<std::pair<uint32_t, uint32_t>> load_sorted_pairs(SnapshotReader& r, const char* what);
// Validates as it reads; `on_clauses` is the program's count (the covered flags).
void load_core(SnapshotReader& r, Core& c, int on_clauses);

// The global map's key order, kept at run time by a program that defines globals
// during steps (or erases them) and also observes the order (allObjs, removeObj
// of one object): the same insert/erase history as the interpreter's map, so the
// same iteration order. Keys are the program's symbol numbers. Only modules with
// Module::runtime_order have one (State::order).
class GlobalOrder {
 public:
  void define(int sym, uint64_t hash) {
    if (map_.contains(sym)) return;
    map_.insert(sym, hash);
    list();
  }
  void erase(int sym) {
    if (!map_.contains(sym)) return;
    map_.erase(sym);
    list();
  }
  // The keys in the map's order, listed at each change of the map: walking
  // its node list (each load waiting on the one before) at every read was a
  // quarter of egg's step. Listed eagerly, so reads write nothing (a shared
  // prototype may be read by several threads).
  const std::vector<int32_t>& keys() const { return keys_; }
  // Into a list the step keeps (no allocation once it has grown).
  void keys_into(std::vector<int32_t>& out) const { out.assign(keys_.begin(), keys_.end()); }
  const HashOrder& map() const { return map_; }
  // A snapshot's order (load_value); throws as HashOrder::restore.
  void restore(size_t bucket_count, size_t next_resize, const std::vector<std::pair<int, uint64_t>>& keys) {
    map_.restore(bucket_count, next_resize, keys);
    list();
  }

 private:
  void list() {
    keys_.clear();
    map_.for_each([&](int k) { keys_.push_back(k); });
  }
  HashOrder map_;
  std::vector<int32_t> keys_;  // invariant: map_'s keys in its iteration order
};
// The order is part of the state: two states whose maps iterate differently may
// diverge later, so they hash and save differently.
inline void hash_value(Hash& h, const GlobalOrder& o) {
  h.mix(o.map().bucket_count());
  for (int32_t k : o.keys()) h.mix(static_cast<uint32_t>(k));
}
void save_value(SnapshotWriter& w, const GlobalOrder& o);
// Symbol numbers index the order's tables: a loaded one is bounded first.
constexpr int32_t kMaxOrderKey = 1 << 20;
void load_value(SnapshotReader& r, GlobalOrder& o);

// The globals steps defined for the first time, in that order: the host render
// draws them after start-up's, in this order (compiler/analyse/render_order.hpp).
// Kept by programs where two or more such globals draw.
class DrawOrder {
 public:
  void note(int32_t sym) {
    if (std::find(syms_.begin(), syms_.end(), sym) == syms_.end()) syms_.push_back(sym);
  }
  const std::vector<int32_t>& syms() const { return syms_; }
  // Into a list the render keeps (no allocation once it has grown).
  void syms_into(std::vector<int32_t>& out) const { out.assign(syms_.begin(), syms_.end()); }
  // A snapshot's list: refused (corrupt_snapshot) with a symbol twice or out of bounds.
  void restore(std::vector<int32_t> syms) {
    std::vector<int32_t> sorted = syms;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) corrupt_snapshot("a global drawn twice");
    if (!sorted.empty() && (sorted.front() < 0 || sorted.back() >= kMaxOrderKey)) corrupt_snapshot("a global out of bounds");
    syms_ = std::move(syms);
  }

 private:
  std::vector<int32_t> syms_;  // invariant: distinct, each in [0, kMaxOrderKey)
};
inline void hash_value(Hash& h, const DrawOrder& o) {
  h.mix(o.syms().size());
  for (int32_t s : o.syms()) h.mix(static_cast<uint32_t>(s));
}
inline void save_value(SnapshotWriter& w, const DrawOrder& o) { save_value(w, o.syms()); }
inline void load_value(SnapshotReader& r, DrawOrder& o) {
  std::vector<int32_t> syms;
  load_value(r, syms);
  o.restore(std::move(syms));
}

// What the Environment adapter keeps besides the program's state: the frame and
// its painter, the episode's error, the host's name for the program and the
// limits. The same for every program, so its code is compiled once
// (compiled_support.cpp), not in every module.
class CompiledHost : public Environment {
 public:
  ~CompiledHost() override;
  const Frame& frame() const override { return frame_; }
  bool failed() const override { return failed_; }
  const std::string& error() const override { return error_; }
  void set_source_name(const std::string& path) override;
  void set_relocation(std::shared_ptr<const Relocation> r) override { relocation_ = std::move(r); }
  // Specialised code enforces the list-length, objects and state-cells budgets,
  // the calls budget as loop elements (charge_loop), and the fixed limits; the
  // per-step created-cells budget is the interpreter's alone (docs/design.md, "Limits").
  void set_limits(const Limits& l) override;

 protected:
  explicit CompiledHost(const char* program_name) : source_name_(program_name) {}
  CompiledHost(const CompiledHost&);
  void copy_host(const CompiledHost& o);  // everything here but the state
  void succeeded() {
    failed_ = false;
    error_.clear();
  }
  // Inside a catch block: ends the episode with the exception being handled,
  // a LocatedError described at its site in `sites` (the program's kErrors).
  void fail_with_current(const ErrorSite* sites);

  Frame frame_;
  Painter painter_;
  bool failed_ = true;
  std::string error_ = "not started";
  std::string source_name_;  // the program's path, once the host names it
  std::shared_ptr<const Relocation> relocation_;  // where the program's locations moved (null: nowhere)
  Limits limits_;            // applied at each reset (Core's limits)
};

// The program's entry points other than step, as plain functions over its
// State (passed as void*): what CompiledProgramHost calls. One table per
// program (CompiledEnvironment<P>::ops); each entry is a one-line forward.
// The palette is fixed by the program's string literals: one copy per process
// and program, so that clone() copies only the state and the frame.
struct PaletteTables {
  Palette palette;
  std::vector<uint16_t> pal;  // string id -> palette id
};

struct ProgramOps {
  const char* name;            // P::kProgramName
  const char* const* colours;  // P::kColours
  const char* const* string_text;   // P::kStringText: the string literals as written
  const char* const* render_names;  // P::kRenderNames: the globals the render draws
  const ErrorSite* errors;     // P::kErrors
  int on_clauses;
  bool uses_random;
  uint64_t snapshot_layout;  // P::kSnapshotLayout: what its snapshots hold (print_cpp's snapshot_layout)
  void (*clear)(void* state);                     // *state = State{}
  void (*assign)(void* state, const void* from);  // *state = *from
  void (*start)(void* state, uint64_t seed);
  void (*render)(void* state, Painter*, const std::vector<uint16_t>& palette_of_string);
  uint64_t (*hash)(const void* state);
  void (*save)(const void* state, SnapshotWriter&);
  void (*load)(void* state, SnapshotReader&);
  // The program's tables, made by its first environment (under a lock) and
  // kept by the module, whose unloading ends them.
  std::shared_ptr<const PaletteTables>* tables;
};

// Everything of the Environment adapter but the step: reset, clone support,
// snapshots, hashing, the palette. The same code for every program, over its
// ProgramOps, so it is compiled once (compiled_support.cpp) and not in every
// module (docs/design.md, "Tests": the fixed part of a module's compile).
class CompiledProgramHost : public CompiledHost {
 public:
  bool reset(uint64_t seed) override;
  const Palette& palette() const override { return tables_->palette; }
  bool triggered() const override { return core_->triggered; }
  int on_clause_count() const override { return ops_->on_clauses; }
  int covered_on_clause_count() const override;
  bool copy_from(const Environment& other) override;
  uint64_t state_hash() const override;
  bool save_state(std::vector<uint8_t>& out) const override;
  bool load_state(const uint8_t* data, size_t size) override;
  bool deterministic() const override { return !ops_->uses_random; }
  int64_t random_draws() const override;
  bool reseed_random(uint64_t seed) override;
  bool set_draw_script(autumn_draw_script* script) override;
  bool record_render(bool on) override {
    painter_.record(on);
    return true;
  }
  bool render_json(std::string* out) const override;

 protected:
  // `state` is the derived class's own State member and `core` its `core`;
  // they stay valid as long as this object (a copy binds its own, bind()).
  CompiledProgramHost(const ProgramOps& ops, void* state, Core* core);
  CompiledProgramHost(const CompiledProgramHost&);  // binds the other's state: the copy binds its own
  ~CompiledProgramHost() override;
  void bind(void* state, Core* core) {
    state_ = state;
    core_ = core;
  }
  void latch(const Action& a);
  // Runs f; a throw ends the episode with its error (fail_with_current).
  template <class F>
  bool guarded(F&& f) {
    try {
      f();
      succeeded();
      return true;
    } catch (...) {
      fail_with_current(ops_->errors);
      // A render may have been cut short: its brush never gave back the marks.
      painter_.forget();
      core_->occupied.forget();
      return false;
    }
  }

  const ProgramOps* ops_;
  std::shared_ptr<const PaletteTables> tables_;

 private:
  void* state_;  // the derived class's P::State
  Core* core_;   // its `core`
};

// The Environment adapter for a generated Program: its State, and the step,
// whose call of P::step and P::render is direct (the one hot path).
template <class P>
class CompiledEnvironment final : public CompiledProgramHost {
 public:
  // state_ is constructed after the base: bound here, not in the base's initialiser.
  CompiledEnvironment() : CompiledProgramHost(ops(), nullptr, nullptr) { bind(&state_, &state_.core); }
  CompiledEnvironment(const CompiledEnvironment& o) : CompiledProgramHost(o), state_(o.state_) { bind(&state_, &state_.core); }
  CompiledEnvironment& operator=(const CompiledEnvironment&) = delete;
  bool step(const Action& a) override { return run_step(a, true); }
  bool advance(const Action& a) override { return run_step(a, false); }
  std::unique_ptr<Environment> clone() const override { return std::make_unique<CompiledEnvironment>(*this); }

 private:
  using State = typename P::State;
  static const ProgramOps& ops() {
    static std::shared_ptr<const PaletteTables> tables;
    static const ProgramOps table{
        P::kProgramName,
        P::kColours,
        P::kStringText,
        P::kRenderNames,
        P::kErrors,
        P::kOnClauses,
        P::kUsesRandom,
        P::kSnapshotLayout,
        [](void* s) { *static_cast<State*>(s) = State{}; },
        [](void* s, const void* from) { *static_cast<State*>(s) = *static_cast<const State*>(from); },
        [](void* s, uint64_t seed) { P::start(*static_cast<State*>(s), seed); },
        [](void* s, Painter* p, const std::vector<uint16_t>& pal) { P::render(*static_cast<State*>(s), p, pal); },
        [](const void* s) { return P::hash(*static_cast<const State*>(s)); },
        [](const void* s, SnapshotWriter& w) { P::save(*static_cast<const State*>(s), w); },
        [](void* s, SnapshotReader& r) { P::load(*static_cast<State*>(s), r); },
        &tables,
    };
    return table;
  }
  bool run_step(const Action& a, bool render) {
    if (failed_) return false;
    return guarded([&] {
      latch(a);
      state_.core.begin_entry();
      P::step(state_);
      if (!render) return;
      painter_.bind(&frame_);  // a clone copies the painter: point it at our own frame
      state_.core.begin_entry();
      state_.core.rng_at_render = state_.core.rng.state();
      P::render(state_, &painter_, tables_->pal);
    });
  }

  State state_;
};

}  // namespace autumn::rt
