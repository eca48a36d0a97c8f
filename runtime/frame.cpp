#include "runtime/frame.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdio>

namespace autumn {

uint64_t Palette::fresh_version() {
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

uint16_t Palette::id(std::string_view colour) {
  auto it = ids_.find(std::string(colour));
  if (it != ids_.end()) return it->second;
  uint16_t id = static_cast<uint16_t>(names_.size());
  names_.emplace_back(colour);
  ids_.emplace(std::string(colour), id);
  version_ = fresh_version();
  return id;
}

std::vector<std::string> frame_rows(const Frame& f, const Palette& p) {
  std::vector<std::string> rows;
  rows.reserve(f.size);
  for (int y = 0; y < f.size; ++y) {
    std::string row;
    for (int x = 0; x < f.size; ++x) {
      if (x) row += ' ';
      row += p.name(f.at(x, y));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string lower_ascii(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

namespace {

// What %.*s prints of a view: up to its first NUL.
std::string_view c_text(std::string_view s) { return s.substr(0, s.find('\0')); }

void append_int(std::string& out, int32_t v) {
  char buf[16];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// Appends `piece` as a 256-byte snprintf buffer would hold it: its first 255 bytes.
void append_cut(std::string& out, const std::string& piece) { out.append(piece, 0, std::min<size_t>(piece.size(), 255)); }

}  // namespace

std::string render_all_json(const std::vector<NamedCell>& cells, int grid_size) {
  // Each piece is cut as the reference's 256-byte snprintf buffer cuts it (a
  // longer name or colour loses its end there).
  std::string out = "{", piece;
  for (size_t i = 0; i < cells.size();) {
    const std::string_view name = cells[i].global;
    piece.assign("\"").append(c_text(name)).append("\": [");
    append_cut(out, piece);
    size_t j = i;
    for (; j < cells.size() && cells[j].global == name; ++j) {
      piece.assign("{\"position\": {\"x\": ");
      append_int(piece, cells[j].x);
      piece.append(", \"y\": ");
      append_int(piece, cells[j].y);
      piece.append("}, \"color\": ").append(c_text(cells[j].colour)).append("}, ");
      append_cut(out, piece);
    }
    out.resize(out.size() - 2);
    out += "], ";
    i = j;
  }
  out += "\"GRID_SIZE\": ";
  append_int(out, grid_size);
  return out + "}";
}

}  // namespace autumn
