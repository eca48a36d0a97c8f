#include "runtime/frame.hpp"

#include <atomic>

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

}  // namespace autumn
