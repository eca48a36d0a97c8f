#include "harness/module_key.hpp"

#include <string_view>
#include <vector>

#include "compiler/read/sexpr.hpp"

namespace autumn {
namespace {

struct Fnv {
  uint64_t h = 0xcbf29ce484222325ULL;
  void byte(unsigned char c) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  void text(std::string_view s) {
    for (char c : std::to_string(s.size())) byte(static_cast<unsigned char>(c));
    byte(':');
    for (char c : s) byte(static_cast<unsigned char>(c));
  }
};

void feed(Fnv& f, const Sexp& s) {
  if (!s.is_list) {
    f.byte(s.is_string ? 's' : 'a');
    f.text(s.text);
    return;
  }
  f.byte('(');
  for (const Sexp& k : s.items) feed(f, k);
  f.byte(')');
}

std::optional<Sexp> read(const std::string& text) {
  try {
    return read_sexprs(SourceFile{"<key>", text, SourceId::Program});
  } catch (const CompileError&) {
    return std::nullopt;
  }
}

void locations(const Sexp& s, std::vector<std::pair<int, int>>& out) {
  out.emplace_back(s.loc.line, s.loc.col);
  for (const Sexp& k : s.items) locations(k, out);
}

}  // namespace

std::optional<uint64_t> canonical_program_hash(const std::string& program_text,
                                               const std::optional<std::string>& trigger) {
  auto tree = read(program_text);
  if (!tree) return std::nullopt;
  Fnv f;
  f.text("autumn canonical v1");
  feed(f, *tree);
  f.byte(trigger ? 1 : 0);
  if (trigger) f.text(*trigger);  // exact: trigger errors are located in its own text
  return f.h;
}

LocationMap::LocationMap(const std::string& from, const std::string& to) {
  if (from == to) return;
  identity_ = false;
  auto a = read(from), b = read(to);
  if (!a || !b) return;
  std::vector<std::pair<int, int>> la, lb;
  locations(*a, la);
  locations(*b, lb);
  if (la.size() != lb.size()) return;
  for (size_t i = 0; i < la.size(); ++i) map_.emplace(la[i], lb[i]);
}

std::string LocationMap::rewrite(const std::string& error, const std::string& path) const {
  if (identity_ || error.compare(0, path.size() + 1, path + ":") != 0) return error;
  int line = 0, col = 0, used = 0;
  if (std::sscanf(error.c_str() + path.size() + 1, "%d:%d:%n", &line, &col, &used) != 2 || used == 0) return error;
  auto it = map_.find({line, col});
  if (it == map_.end()) return error;
  return path + ":" + std::to_string(it->second.first) + ":" + std::to_string(it->second.second) + ":" +
         error.substr(path.size() + 1 + used);
}

}  // namespace autumn
