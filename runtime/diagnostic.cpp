// diagnostic — the place prefixes of diagnostic.hpp. Out of line: every
// compiled module calls them only on its error paths.
#include "runtime/diagnostic.hpp"

#include <algorithm>

namespace autumn {

std::string diagnostic_place(const std::string& file, int line, int col) {
  if (line == 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(col);
}

std::string diagnostic_prefix(const std::string& file, int line, int col, const std::string& severity) {
  return diagnostic_place(file, line, col) + ": " + severity + ": ";
}

std::string diagnostic_inside(const std::string& source, int line, int col) {
  return " (inside " + diagnostic_place(source, line, col) + ")";
}

namespace {

constexpr size_t kLongRun = 256, kHead = 96, kTail = 24;

void append_escaped(std::string& out, std::string_view s) {
  static const char* const kHex = "0123456789abcdef";
  for (size_t i = 0; i < s.size(); ++i) {
    const auto u = static_cast<unsigned char>(s[i]);
    if (u == 0xEF && s.substr(i, 3) == "\xEF\xBB\xBF") {
      out += "\\ufeff";
      i += 2;
    } else if ((u < 0x20 && u != '\n' && u != '\t') || u == 0x7f) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += s[i];
    }
  }
}

// `at` moved back to the start of a UTF-8 character.
size_t char_start(std::string_view s, size_t at) {
  while (at > 0 && at < s.size() && (static_cast<unsigned char>(s[at]) & 0xC0) == 0x80) --at;
  return at;
}

}  // namespace

std::string shown(std::string_view message) {
  std::string out;
  out.reserve(message.size() < 4096 ? message.size() + 16 : 4096);
  size_t i = 0;
  while (i <= message.size()) {
    size_t j = message.find(' ', i);
    if (j == std::string_view::npos) j = message.size();
    const std::string_view run = message.substr(i, j - i);
    if (run.size() > kLongRun) {
      const size_t head = char_start(run, kHead), tail = char_start(run, run.size() - kTail);
      append_escaped(out, run.substr(0, head));
      out += "...(" + std::to_string(run.size()) + " bytes)...";
      append_escaped(out, run.substr(tail));
    } else {
      append_escaped(out, run);
    }
    if (j == message.size()) break;
    out += ' ';
    i = j + 1;
  }
  return out;
}

std::string shown_type(std::string_view t) {
  constexpr std::string_view kList = "List<", kClass = "class ";
  if (t.substr(0, kList.size()) == kList && t.size() > kList.size() && t.back() == '>') {
    const std::string_view elem = t.substr(kList.size(), t.size() - kList.size() - 1);
    return elem == "Unknown" ? "List" : "(List " + shown_type(elem) + ")";
  }
  if (t.substr(0, kClass.size()) == kClass) {
    const std::string_view rest = t.substr(kClass.size());
    return std::string(rest.substr(0, rest.find(' ')));
  }
  if (t == "AutumnFunc") return "Function";
  return std::string(t);
}

std::pair<int, int> Relocation::at(int line, int col) const {
  auto it = std::lower_bound(moves.begin(), moves.end(), std::make_pair(line, col), [](const Move& m, std::pair<int, int> k) {
    return std::make_pair(m.from_line, m.from_col) < k;
  });
  if (it == moves.end() || it->from_line != line || it->from_col != col) return {line, col};
  return {it->to_line, it->to_col};
}

}  // namespace autumn
