// module_key — the canonical SHA-256 of a program (its s-expressions, as read) and
// the exact program digest, plus the relocation between two layouts of one
// program (module_key.hpp).
#include "harness/module_key.hpp"

#include <algorithm>
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

std::shared_ptr<const Relocation> relocation_between(const std::string& from, const std::string& to) {
  if (from == to) return nullptr;
  auto a = read(from), b = read(to);
  if (!a || !b) return nullptr;
  std::vector<std::pair<int, int>> la, lb;
  locations(*a, la);
  locations(*b, lb);
  if (la.size() != lb.size()) return nullptr;
  auto r = std::make_shared<Relocation>();
  for (size_t i = 0; i < la.size(); ++i) r->moves.push_back({la[i].first, la[i].second, lb[i].first, lb[i].second});
  std::stable_sort(r->moves.begin(), r->moves.end(), [](const Relocation::Move& x, const Relocation::Move& y) {
    return std::make_pair(x.from_line, x.from_col) < std::make_pair(y.from_line, y.from_col);
  });
  // A location two nodes share (a list and its first atom) moves once: the first pairing, as the map kept it.
  r->moves.erase(std::unique(r->moves.begin(), r->moves.end(),
                             [](const Relocation::Move& x, const Relocation::Move& y) {
                               return x.from_line == y.from_line && x.from_col == y.from_col;
                             }),
                 r->moves.end());
  return r;
}

}  // namespace autumn
