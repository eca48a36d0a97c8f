#include "compiler/read/sexpr.hpp"

#include <cctype>

#include "runtime/limits.hpp"

namespace autumn {
namespace {

// The character after a backslash as an error message shows it: itself if
// printable ASCII, else xNN (so '\x0a' for a newline), so that a message stays on
// one line whatever the input holds.
std::string shown_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7f) return std::string(1, c);
  static const char* const kHex = "0123456789abcdef";
  return std::string("x") + kHex[u >> 4] + kHex[u & 15];
}

}  // namespace

namespace {

constexpr char kEscapeNames[] = {'\'', '"', '?', '\\', 'a', 'b', 'f', 'n', 'r', 't', 'v'};
constexpr char kEscapeValues[] = {'\'', '"', '?', '\\', '\a', '\b', '\f', '\n', '\r', '\t', '\v'};

std::string escape_symbol(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    int i = 0;
    for (; i < 11; ++i)
      if (kEscapeValues[i] == c) break;
    if (i < 11) {
      out += '\\';
      out += kEscapeNames[i];
    } else {
      out += c;
    }
  }
  return out;
}

class Reader {
 public:
  explicit Reader(const SourceFile& f) : file_(f), text_(f.text) {}

  Sexp read_all() {
    std::vector<Sexp> stack;
    stack.push_back(Sexp{true, false, "", {}, {1, 1, f_id()}, {}});
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (std::isspace(static_cast<unsigned char>(c))) {
        advance();
        continue;
      }
      SourceLoc here = loc();
      if (c == '(') {
        // Every later pass recurses over this tree: its depth is bounded here.
        if (stack.size() > static_cast<size_t>(limits::kMaxSyntaxNesting))
          throw CompileError(file_.name, here, limits::syntax_nesting_error());
        advance();
        stack.push_back(Sexp{true, false, "", {}, here, {}});
      } else if (c == ')') {
        if (stack.size() == 1)
          throw CompileError(file_.name, here, "unbalanced ')': no list is open here");
        advance();
        Sexp done = std::move(stack.back());
        done.end = here;
        stack.pop_back();
        stack.back().items.push_back(std::move(done));
      } else if (c == '"') {
        stack.back().items.push_back(read_string(here));
      } else if (c == ';') {
        while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') advance();
      } else {
        size_t start = pos_;
        while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_])) &&
               text_[pos_] != '(' && text_[pos_] != ')')
          advance();
        Sexp atom;
        atom.text = escape_symbol(text_.substr(start, pos_ - start));
        atom.loc = here;
        stack.back().items.push_back(std::move(atom));
      }
    }
    if (stack.size() != 1)
      throw CompileError(file_.name, stack.back().loc,
                         "unclosed '(': the file ends before this list is closed");
    stack[0].end = loc();
    return std::move(stack[0]);
  }

 private:
  SourceLoc loc() const { return {line_, col_, file_.id}; }
  void advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      col_ = 1;
    } else {
      ++col_;
    }
    ++pos_;
  }

  Sexp read_string(SourceLoc start) {
    advance();  // opening quote
    std::string out = "\"";
    while (true) {
      if (pos_ >= text_.size())
        throw CompileError(file_.name, start, "unterminated string literal");
      char c = text_[pos_];
      if (c == '"') {
        advance();
        break;
      }
      if (c == '\n') throw CompileError(file_.name, loc(), "newline inside a string literal");
      if (c == '\\') {
        SourceLoc at = loc();
        advance();
        if (pos_ >= text_.size())
          throw CompileError(file_.name, start, "unterminated string literal");
        char e = text_[pos_];
        int i = 0;
        for (; i < 11; ++i)
          if (kEscapeNames[i] == e) break;
        if (i == 11)
          throw CompileError(file_.name, at, "invalid escape '\\" + shown_char(e) + "' in string");
        out += kEscapeValues[i];
        advance();
        continue;
      }
      out += c;
      advance();
    }
    out += '"';
    Sexp atom;
    atom.is_string = true;
    atom.text = std::move(out);
    atom.loc = start;
    return atom;
  }

  SourceId f_id() const { return file_.id; }
  const SourceFile& file_;
  const std::string& text_;
  size_t pos_ = 0;
  int line_ = 1, col_ = 1;
};

void snippet_into(const Sexp& s, std::string& out, size_t limit) {
  if (out.size() > limit) return;
  if (!s.is_list) {
    // Control bytes (a raw CR inside a string literal) shown as \xNN: one line.
    for (char c : s.text) {
      const auto u = static_cast<unsigned char>(c);
      if (u < 0x20 || u == 0x7f) out += "\\" + shown_char(c);
      else out += c;
    }
    return;
  }
  out += '(';
  for (size_t i = 0; i < s.items.size(); ++i) {
    if (i) out += ' ';
    snippet_into(s.items[i], out, limit);
    if (out.size() > limit) return;
  }
  out += ')';
}

}  // namespace

Sexp read_sexprs(const SourceFile& file) { return Reader(file).read_all(); }

std::string sexp_snippet(const Sexp& s, size_t limit) {
  std::string out;
  snippet_into(s, out, limit);
  if (out.size() > limit) out = out.substr(0, limit) + "...";
  return out;
}

}  // namespace autumn
