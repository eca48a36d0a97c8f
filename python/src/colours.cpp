#include "python/src/colours.hpp"

#include <mutex>
#include <stdexcept>
#include <unordered_map>

#include "harness/agent/task_file.hpp"

namespace autumn::py {
namespace {

struct Vocabulary {
  std::mutex mu;
  std::vector<std::string> names;
  std::unordered_map<std::string, uint8_t> ids;
  Vocabulary() {
    agent::ColourTable table;
    for (int i = 0; i < table.table_size(); ++i) {
      names.push_back(table.name(i));
      ids.emplace(names.back(), static_cast<uint8_t>(i));
    }
  }
};

Vocabulary& vocabulary() {
  static auto* v = new Vocabulary();  // used by worker threads until exit
  return *v;
}

}  // namespace

uint8_t colour_id(const std::string& name) {
  Vocabulary& v = vocabulary();
  std::lock_guard<std::mutex> lock(v.mu);
  if (auto it = v.ids.find(name); it != v.ids.end()) return it->second;
  if (v.names.size() >= 256)
    throw std::length_error("more than 256 distinct colours in this process; cannot give '" + name + "' a uint8 id");
  v.names.push_back(name);
  return v.ids[name] = static_cast<uint8_t>(v.names.size() - 1);
}

std::vector<std::string> colour_names() {
  Vocabulary& v = vocabulary();
  std::lock_guard<std::mutex> lock(v.mu);
  return v.names;
}

const std::vector<uint8_t>& PaletteMap::of(const Palette& p) {
  if (p.version() != version_ || p.size() != size_) {
    ids_.resize(p.size());
    for (size_t i = 0; i < p.size(); ++i) ids_[i] = colour_id(p.name(static_cast<uint16_t>(i)));
    version_ = p.version();
    size_ = p.size();
  }
  return ids_;
}

void PaletteMap::paint(const Frame& f, const Palette& p, uint8_t* out) {
  const std::vector<uint8_t>& ids = of(p);
  const size_t n = f.cells.size();
  for (size_t i = 0; i < n; ++i) out[i] = ids[f.cells[i]];
}

}  // namespace autumn::py
