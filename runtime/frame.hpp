// frame — what an environment shows after a host render.
//
// The benchmark harness paints a GRID_SIZE x GRID_SIZE grid with the background
// colour, then every rendered cell in render order (later cells overwrite earlier
// ones); cells outside the grid are dropped and colour names are lower-cased.
// A Frame stores colour ids into a per-environment Palette so that frames compare
// and hash cheaply; rows() gives the text form used by the golden traces.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace autumn {

class Palette {
 public:
  uint16_t id(std::string_view colour);  // interns a lower-case colour name
  const std::string& name(uint16_t id) const { return names_.at(id); }
  size_t size() const { return names_.size(); }
  // Equal versions mean equal contents: copies keep the version, every new name
  // takes a fresh one (unique in the process). Caches of palette-id maps key on
  // it; the address and size are not enough, as two environments with different
  // histories can name the same colours in different orders.
  uint64_t version() const { return version_; }

 private:
  static uint64_t fresh_version();
  std::vector<std::string> names_;
  std::unordered_map<std::string, uint16_t> ids_;
  uint64_t version_ = fresh_version();
};

struct Frame {
  int size = 0;                 // GRID_SIZE at the render
  std::vector<uint16_t> cells;  // row-major: cells[y * size + x], palette ids
  uint16_t at(int x, int y) const { return cells[static_cast<size_t>(y) * size + x]; }
  bool operator==(const Frame&) const = default;
};

// One string per row, colour names joined by single spaces (the trace format).
std::vector<std::string> frame_rows(const Frame& f, const Palette& p);

// Lower-cases ASCII, as Python's str.lower() does for colour names.
std::string lower_ascii(std::string_view s);

// One element of a host render as the reference's render_all() lists it: the
// global it was drawn from, its position (outside the grid too) and its colour
// as the program wrote it (quotes included).
struct NamedCell {
  std::string_view global;
  int32_t x = 0, y = 0;
  std::string_view colour;
};
// The reference's render_all() JSON of one host render's elements, in render
// order: {"NAME": [{"position": {"x": X, "y": Y}, "color": COLOUR}, ...], ...,
// "GRID_SIZE": N}, a run of elements of one global under one key. Both engines'
// render_all() is this text (python/src/session.cpp).
std::string render_all_json(const std::vector<NamedCell>& cells, int grid_size);

}  // namespace autumn
