// module_key — the canonical SHA-256 of a program (its s-expressions, as read) and
// the exact program digest, plus the location map between two layouts of one
// program (module_key.hpp).
#include "harness/module_key.hpp"

#include <string_view>
#include <vector>

#include "compiler/read/sexpr.hpp"
#include "harness/digest.hpp"

namespace autumn {
namespace {

// The canonical form, fed as it is walked: atoms by kind and length-prefixed
// text, lists by brackets.
void feed(Sha256& d, const Sexp& s) {
  if (!s.is_list) {
    d.update(s.is_string ? "s" : "a");
    d.piece(s.text);
    return;
  }
  d.update("(");
  for (const Sexp& k : s.items) feed(d, k);
  d.update(")");
}

void feed_trigger(Sha256& d, const std::optional<std::string>& trigger) {
  d.update(trigger ? "T" : "N");
  if (trigger) d.piece(*trigger);
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

std::optional<std::string> canonical_program_hash(const std::string& program_text,
                                                  const std::optional<std::string>& trigger) {
  auto tree = read(program_text);
  if (!tree) return std::nullopt;
  Sha256 d;
  d.piece("autumn canonical v2");
  feed(d, *tree);
  feed_trigger(d, trigger);  // exact: trigger errors are located in its own text
  return d.hex();
}

std::string program_digest(const std::string& program_text, const std::optional<std::string>& trigger) {
  Sha256 d;
  d.piece("autumn program v1");
  d.piece(program_text);
  feed_trigger(d, trigger);
  return d.hex();
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
