// print_cpp — the one place that prints C++: a Module to the `struct Prog`
// definition that runtime/compiled_support.hpp's CompiledEnvironment runs.
//
// Indentation follows the statement tree; variables are named by their hint
// and numbered per function in order of appearance. Nothing here decides
// semantics: every operation is printed as the IR says, with the runtime's
// helpers (compiled_support.hpp) for arithmetic, draws, occupancy and identity.
// Test: the generated/ regeneration test and every compiled-engine test.
#include "compiler/lower/print_cpp.hpp"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "runtime/fnv1a.hpp"
#include "runtime/frame.hpp"

namespace autumn::lower {
namespace {

using namespace ir;

}  // namespace

std::string cpp_string_literal(const std::string& s) {
  // Every byte outside printable ASCII (and the quote and backslash) as an octal
  // escape: three digits, so no following character can extend it.
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c >= 0x7f || c == '?') {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

namespace {

std::string quoted(const std::string& s) { return cpp_string_literal(s); }

// A Position's C++ type: with identities tracked (Module::pos_tracked) every one
// carries its uid.
std::string pos_type_of(const Module& m) { return m.pos_tracked ? "PosU" : "Pos"; }

std::string hex64(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The prev snapshot lives only within a step (the step's first store to a
// global moves its value there), so copies of the state leave it behind.
bool in_scratch(const Slot& s) {
  return s.kind == Slot::Prev || s.kind == Slot::Saved || s.kind == Slot::PrevDefined;
}

class Printer {
 public:
  explicit Printer(const Module& m) : m_(m) {}
  std::string run();

 private:
  // --- types
  std::string pos_type() const { return pos_type_of(m_); }
  std::string type(TypeP t) const {
    switch (t->k) {
      case TK::Int:
      case TK::Str: return "int32_t";
      case TK::Bool: return "bool";
      case TK::Pos: return pos_type();
      case TK::Elem: return "Elem";
      case TK::Cell:
      case TK::Deferred: return "CellV";
      case TK::Obj: return m_.classes[t->cls].cpp;
      case TK::List: return "std::vector<" + (t->elem ? type(t->elem) : std::string("int32_t")) + ">";
      case TK::Sum: return "S" + std::to_string(t->id);
      default: return "Unit";
    }
  }
  // --- expressions
  std::string name(const Var* v) {
    auto it = names_.find(v);
    if (it != names_.end()) return it->second;
    std::string stem;
    for (char c : v->hint) stem += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    if (stem.empty()) stem = "t";
    std::string n = stem + std::to_string(++counter_);
    names_[v] = n;
    return n;
  }
  std::string expr(const Node* n);
  std::string message(const Node* n);
  std::string member(const Node* n);
  std::string helper(const Node* n);
  std::string check_length(const Node* n);  // Helper::CheckLength and ChargeBuilt
  void tally_function(const ClassInfo& c);
  // --- statements
  void line(const std::string& s) { out_ << std::string(2 * depth_, ' ') << s << "\n"; }
  void block(const Block& b) {
    ++depth_;
    for (const Stmt* s : b) stmt(*s);
    --depth_;
  }
  void stmt(const Stmt& s);
  void decl_stmt(const Stmt& s);
  void loop_stmt(const Stmt& s);
  void for_each_stmt(const Stmt& s);
  void for_range_stmt(const Stmt& s);
  void switch_stmt(const Stmt& s);
  void function(const Function& f, int index);
  // --- module parts
  void declarations();
  void class_struct(const ClassInfo& c);
  void sum_alias(TypeP t);
  void state();
  void snapshot_functions();
  void tables();
  void shape_table(const ClassInfo& c);

  const Module& m_;
  std::ostringstream out_;
  int depth_ = 1;
  std::map<const Var*, std::string> names_;
  int counter_ = 0;
  std::vector<std::string> scratch_;  // members of Scratch
  std::vector<TypeP> sums_;
  const Node* moving_node_ = nullptr;  // the statement's value whose operands (mask) are moved from
  uint32_t moving_mask_ = 0;
  // Where the budget's charges go: the core, or inside a loop that keeps the
  // counts in a local (Stmt::local_budget) that local.
  std::string counts_ = "s.core";
};

std::string Printer::member(const Node* n) {
  const std::string base = expr(n->a[0]);
  switch (n->member) {
    case Member::X: return base + ".x";
    case Member::Y: return base + ".y";
    case Member::Position: return base + ".position";
    case Member::Color: return base + ".color";
    case Member::Origin: return base + ".origin";
    case Member::Field: return base + ".f" + std::to_string(n->index);
    case Member::Uid: return base + ".uid";
    case Member::Group: return base + ".group";
    case Member::CellX: return base + ".x";
    case Member::CellY: return base + ".y";
    case Member::CellColour: return base + ".colour";
    case Member::CellDx: return "int32_t(" + base + ".dx)";
    case Member::CellDy: return "int32_t(" + base + ".dy)";
    case Member::CellDc: return "int32_t(" + base + ".dc)";
    case Member::Cells: return base + ".cells";
  }
  return base;
}

std::string Printer::check_length(const Node* n) {
  auto i64 = [&](size_t i) { return "int64_t(" + expr(n->a[i]) + ")"; };
  auto size = [&](size_t i) { return "int64_t(" + expr(n->a[i]) + ".size())"; };
  const std::string site = std::to_string(n->imm);
  std::string len;
  switch (n->index) {
    case kLengthIs: len = i64(0); break;
    case kLengthSpan: len = i64(1) + " - " + i64(0); break;
    case kLengthArea: len = i64(0) + " * " + i64(1); break;
    case kLengthSizes:
      for (size_t i = 0; i < n->a.size(); ++i) len += (i ? " + " : "") + size(i);
      break;
    case kLengthSizePlus: len = size(0) + " + " + i64(1); break;
    case kLengthAppended: return "check_appended_length(s.core, " + site + ", " + size(0) + ")";
    case kLengthTotal: len = "total_size(" + expr(n->a[0]) + ")"; break;
    case kLengthCounted: return "check_appended_length(s.core, " + site + ", " + i64(0) + ")";
  }
  return (n->helper == Helper::ChargeBuilt ? "charge_built(" + counts_ + ", " : "check_length(s.core, ") + site + ", " + len +
         ")";
}

std::string Printer::helper(const Node* n) {
  auto arg = [&](size_t i) { return expr(n->a[i]); };
  switch (n->helper) {
    case Helper::RngNext: return "int32_t(s.core.rng.next(uint64_t(uint32_t(" + arg(0) + "))))";
    case Helper::OccupancyFree: return "s.core.occupied.free(" + arg(0) + ")";
    case Helper::IdOf: return "int32_t(s.core.ids.id_of(uint32_t(" + arg(0) + ")))";
    case Helper::IdTransfer: return "s.core.ids.transfer(uint32_t(" + arg(0) + "), uint32_t(" + arg(1) + "))";
    case Helper::NewUid: return "s.core.ids.fresh()";  // uint32_t, as the uid members
    case Helper::Sqrt: return "int32_t(std::sqrt(double(" + arg(0) + ")))";
    case Helper::DefineGlobal:
      return "s.order.define(" + arg(0) + ", " + std::to_string(m_.order_hashes.at(static_cast<int>(n->a[0]->imm))) + "ULL)";
    case Helper::EraseGlobal: return "s.order.erase(" + arg(0) + ")";
    case Helper::OrderKeys: return "s.order.keys_into(" + arg(0) + ")";
    case Helper::NoteDrawn: return "s.drawn.note(" + arg(0) + ")";
    case Helper::DrawnKeys: return "s.drawn.syms_into(" + arg(0) + ")";
    case Helper::ClickPos: return "Pos{s.core.click_x, s.core.click_y}";
    case Helper::ClickDefine: return "(void)0";
    case Helper::Reserve: return arg(0) + ".reserve(size_t(" + arg(1) + "))";
    case Helper::Append: return arg(0) + ".insert(" + arg(0) + ".end(), " + arg(1) + ".begin(), " + arg(1) + ".end())";
    case Helper::Clear: return arg(0) + ".clear()";
    case Helper::StrOfInt: return "std::to_string(" + arg(0) + ")";
    case Helper::StrOfStr: return "std::string(kStrings[" + arg(0) + "])";
    case Helper::OccupancyClear: return "s.core.occupied.clear(kGrid)";
    case Helper::OccupancyAdd: return "brush.mark(" + arg(0) + ")";
    case Helper::PaintBegin: return "Brush brush = begin_render(paint, s.core.occupied, kGrid, " + arg(0) + ", pal)";
    case Helper::Paint: return "brush.paint(" + arg(0) + ".position, " + arg(0) + ".color)";
    case Helper::PaintGlobal: return "brush.global(" + arg(0) + ")";
    case Helper::PaintEnd: return "s.core.rendered = end_render(paint, s.core.occupied, brush)";  // cacheRendered (the state check)
    case Helper::SetTriggered: return "s.core.triggered = " + arg(0);
    case Helper::Covered: return "s.core.covered[" + arg(0) + "] = 1";
    case Helper::HavePrev: return "s.core.have_prev";
    case Helper::RotTurn: return "s.core.rot.turn(uint32_t(" + arg(0) + "))";
    case Helper::RotOf: return "int32_t(s.core.rot.of(uint32_t(" + arg(0) + ")))";
    case Helper::Rotated: return "rotated(" + arg(0) + ", " + arg(1) + ", " + arg(2) + ")";
    case Helper::CheckLength:
    case Helper::ChargeBuilt: return check_length(n);
    case Helper::TallyBegin: return "StateTally tally{}";
    case Helper::TallyGlobal:
      return "tally_global(s.core, tally, " + std::to_string(n->imm) + ", " + quoted(n->text) + ", " + arg(0) + ")";
    case Helper::TallyRendered:
      return "tally_rendered(s.core, tally, " + std::to_string(n->imm) + ", " + quoted(n->text) + ")";
    case Helper::InputFlag: {
      static const char* const flags[] = {"click", "left", "right", "up", "down"};
      return "s.core." + std::string(flags[n->a[0]->imm]);
    }
  }
  return "(void)0";
}

std::string Printer::expr(const Node* n) {
  uint32_t moving = 0;
  if (n == moving_node_) {
    moving = moving_mask_;
    moving_node_ = nullptr;
  }
  // The move mask covers the first 32 operands (pass_moves sets no others).
  auto a = [&](size_t i) { return i < 32 && (moving >> i) & 1 ? "std::move(" + expr(n->a[i]) + ")" : expr(n->a[i]); };
  auto list = [&](size_t from) {
    std::string s;
    for (size_t i = from; i < n->a.size(); ++i) s += (i > from ? ", " : "") + a(i);
    return s;
  };
  switch (n->op) {
    case Op::Lit:
      if (n->type && n->type->k == TK::Bool) return n->imm ? "true" : "false";
      if (n->type && (n->type->k == TK::Func || n->type->k == TK::Class)) return "Unit{}";
      return "int32_t(" + std::to_string(n->imm) + (n->imm < -2147483647 ? "LL" : "") + ")";
    case Op::Text: return "std::string(" + quoted(n->text) + ")";
    case Op::Local: return name(n->var);
    case Op::Global:
    case Op::Slot: return (in_scratch(m_.slots[n->slot]) ? "s.scratch.v." : "s.") + m_.slots[n->slot].name;
    case Op::Member: return member(n);
    case Op::Add: return "add(" + a(0) + ", " + a(1) + ")";
    case Op::Sub: return "sub(" + a(0) + ", " + a(1) + ")";
    case Op::Mul: return "mul(" + a(0) + ", " + a(1) + ")";
    case Op::Neg: return "neg(" + a(0) + ")";
    case Op::Div: return "autumn::arith::div_unchecked(" + a(0) + ", " + a(1) + ")";
    case Op::Mod: return "autumn::arith::mod_unchecked(" + a(0) + ", " + a(1) + ")";
    case Op::Lt: return "(" + a(0) + " < " + a(1) + ")";
    case Op::Le: return "(" + a(0) + " <= " + a(1) + ")";
    case Op::Gt: return "(" + a(0) + " > " + a(1) + ")";
    case Op::Ge: return "(" + a(0) + " >= " + a(1) + ")";
    case Op::Eq: return "(" + a(0) + " == " + a(1) + ")";
    case Op::Ne: return "(" + a(0) + " != " + a(1) + ")";
    case Op::Not: return "!" + a(0);
    case Op::And: return "(" + a(0) + " && " + a(1) + ")";
    case Op::Or: return "(" + a(0) + " || " + a(1) + ")";
    case Op::MakePos:
      if (n->a.size() > 2) return "PosU{" + a(0) + ", " + a(1) + ", uint32_t(" + a(2) + ")}";
      return "Pos{" + a(0) + ", " + a(1) + "}";
    case Op::MakeElem: return "Elem{" + a(0) + ", " + a(1) + "}";
    case Op::MakeObj: return m_.classes[n->index].cpp + "{" + list(0) + "}";
    case Op::MakeCell: {
      std::string s = "CellV{" + a(0) + ", " + a(1) + ", " + a(2) + ", int16_t(" + a(3) + "), int16_t(" + a(4) +
                      "), int16_t(" + a(5) + ")";
      if (n->a.size() > 6) s += ", uint32_t(" + a(6) + ")";
      return s + "}";
    }
    case Op::MakeList: return type(n->type) + "{" + list(0) + "}";
    case Op::MakeSum: return type(n->type) + "{std::in_place_index<" + std::to_string(n->index) + ">, " + a(0) + "}";
    case Op::SumIs: return "(" + a(0) + ".index() == " + std::to_string(n->index) + ")";
    case Op::SumGet: return "std::get<" + std::to_string(n->index) + ">(" + a(0) + ")";
    case Op::Size: return "int32_t(" + a(0) + ".size())";
    case Op::Empty: return a(0) + ".empty()";
    case Op::Index: return a(0) + "[size_t(" + a(1) + ")]";
    case Op::Front: return a(0) + ".front()";
    case Op::Back: return a(0) + ".back()";
    case Op::Call: return helper(n);
    case Op::FnCall: return m_.functions[n->index]->name + "(s" + (n->a.empty() ? "" : ", " + list(0)) + ")";
    case Op::Select: return "(" + a(0) + " ? " + a(1) + " : " + a(2) + ")";
    case Op::Shape: return m_.classes[n->index].cpp + "::kShape";
    case Op::Concat: {
      std::string s = "std::string()";
      for (size_t i = 0; i < n->a.size(); ++i) s += " + " + expr(n->a[i]);
      return s;
    }
  }
  return "/* ? */";
}

// A declaration; a scratch variable is a buffer kept in the state and cleared.
void Printer::decl_stmt(const Stmt& s) {
  if (s.var->scratch) {
    std::string b = "b" + std::to_string(scratch_.size());
    scratch_.push_back(type(s.var->type) + " " + b + ";");
    line(type(s.var->type) + "& " + name(s.var) + " = s.scratch.v." + b + ";");
    line(name(s.var) + ".clear();");
    if (s.a) line(name(s.var) + " = " + expr(s.a) + ";");
    return;
  }
  line(type(s.var->type) + " " + name(s.var) + (s.a ? " = " + expr(s.a) : std::string("{}")) + ";");
}

// A loop that keeps the budget's counts in a local takes them from the core
// before it and gives them back after it (pass_budget_locals).
void Printer::loop_stmt(const Stmt& s) {
  const bool local = s.local_budget;
  if (local) {
    line("{");
    ++depth_;
    line("Budget budget = budget_of(s.core);");
    counts_ = "budget";
  }
  if (s.k == SK::ForEach) for_each_stmt(s);
  else for_range_stmt(s);
  if (local) {
    counts_ = "s.core";
    line("give_back(s.core, budget);");
    --depth_;
    line("}");
  }
}

// The list is bound once: charged by its size (unless short), then walked; or,
// where the loop moves it whole into the list its push fills, swapped there.
void Printer::for_each_stmt(const Stmt& s) {
  const std::string l = name(s.var) + "_list";
  line("{");
  if (s.move_value) {
    const std::string from = expr(s.a), into = expr(s.body[0]->a);
    if (s.charged) line("  charge_loop(" + counts_ + ", " + std::to_string(s.loc) + ", int64_t(" + from + ".size()));");
    line("  std::swap(" + into + ", " + from + ");");
    line("}");
    return;
  }
  line("  const auto& " + l + " = " + expr(s.a) + ";");
  if (s.charged && !s.charge_each)
    line("  charge_loop(" + counts_ + ", " + std::to_string(s.loc) + ", int64_t(" + l + ".size()));");
  line("  for (const " + type(s.var->type) + "& " + name(s.var) + " : " + l + ") {");
  ++depth_;
  if (s.charged && s.charge_each) line("  charge_loop(" + counts_ + ", " + std::to_string(s.loc) + ", int64_t(1));");
  block(s.body);
  --depth_;
  line("  }");
  line("}");
}

// A range loop, charged by its length (unless short).
void Printer::for_range_stmt(const Stmt& s) {
  const std::string v = name(s.var);
  line("{");
  line("  const int32_t " + v + "_first = " + expr(s.a) + ", " + v + "_end = " + expr(s.b) + ";");
  if (s.charged && !s.charge_each)
    line("  charge_loop(" + counts_ + ", " + std::to_string(s.loc) + ", int64_t(" + v + "_end) - " + v + "_first);");
  line("  for (int32_t " + v + " = " + v + "_first; " + v + " < " + v + "_end; ++" + v + ") {");
  ++depth_;
  if (s.charged && s.charge_each) line("  charge_loop(" + counts_ + ", " + std::to_string(s.loc) + ", int64_t(1));");
  block(s.body);
  --depth_;
  line("  }");
  line("}");
}

// A switch over an int, or over a sum's alternative (its index).
void Printer::switch_stmt(const Stmt& s) {
  const bool sum = s.a->type && s.a->type->k == TK::Sum;
  line("switch (" + expr(s.a) + (sum ? ".index()" : "") + ") {");
  for (const auto& [k, b] : s.cases) {
    line("  case " + std::to_string(k) + ": {");
    ++depth_;
    block(b);
    --depth_;
    line("    break;");
    line("  }");
  }
  line("  default: break;");
  line("}");
}

// A failure's message: a C string literal when it is all text (the common case:
// "head of an empty list"), which the out-of-line fail_at takes without building
// a std::string at the site; otherwise the string expression. Text holding a NUL
// byte stays a std::string (a C string would end there).
std::string Printer::message(const Node* n) {
  std::string text;
  auto all_text = [&](const Node* m) {
    if (m->op != Op::Text) return false;
    text += m->text;
    return true;
  };
  bool literal = n->op == Op::Concat ? std::all_of(n->a.begin(), n->a.end(), all_text) : all_text(n);
  if (!literal || text.find('\0') != std::string::npos) return expr(n);
  return quoted(text);
}

void Printer::stmt(const Stmt& s) {
  if (s.move_operands) {
    moving_node_ = s.k == SK::Let || s.k == SK::Decl ? s.a : s.b;
    moving_mask_ = s.move_operands;
  }
  switch (s.k) {
    case SK::Let:
      line((s.var->moved ? "" : "const ") + type(s.var->type) + " " + name(s.var) + " = " + expr(s.a) + ";");
      return;
    case SK::Decl: return decl_stmt(s);
    case SK::Bind:
      line("const " + type(s.var->type) + (s.var->is_ref ? "& " : " ") + name(s.var) + " = " + expr(s.a) + ";");
      return;
    case SK::Set:
      if (s.move_value && s.b->op == Op::Local && s.b->var->scratch) {
        line("std::swap(" + expr(s.a) + ", " + expr(s.b) + ");");  // the old storage becomes the buffer
        return;
      }
      line(expr(s.a) + " = " + (s.move_value ? "std::move(" + expr(s.b) + ")" : expr(s.b)) + ";");
      return;
    case SK::Push:
      line(expr(s.a) + ".push_back(" + (s.move_value ? "std::move(" + expr(s.b) + ")" : expr(s.b)) + ");");
      return;
    case SK::Eval: line(expr(s.a) + ";"); return;
    case SK::Swap: line("std::swap(" + expr(s.a) + ", " + expr(s.b) + ");"); return;
    case SK::If:
      line("if (" + expr(s.a) + ") {");
      block(s.body);
      if (!s.other.empty()) {
        line("} else {");
        block(s.other);
      }
      line("}");
      return;
    case SK::ForEach:
    case SK::ForRange: return loop_stmt(s);
    case SK::Switch: return switch_stmt(s);
    case SK::Block:
      line("{");
      block(s.body);
      line("}");
      return;
    case SK::Break: line("break;"); return;
    case SK::Return: line("return " + expr(s.a) + ";"); return;
    case SK::Fail: line("fail_at(" + std::to_string(s.loc) + ", " + message(s.a) + ");"); return;
    case SK::Comment: line("// " + s.text); return;
  }
}

void Printer::function(const Function& f, int index) {
  (void)index;
  names_.clear();
  counter_ = 0;
  std::string head;
  switch (f.kind) {
    case Function::Start: head = "static void start(State& s, uint64_t seed) {"; break;
    case Function::Step: head = "static void step(State& s) {"; break;
    case Function::Render:
      head = "static void render(State& s, Painter* paint, const std::vector<uint16_t>& pal) {";
      break;
    default: {
      head = "static " + std::string(f.ret ? type(f.ret) : "void") + " " + f.name + "(State& s";
      for (const Var* p : f.params)
        head += std::string(", ") + (p->mut ? "" : "const ") + type(p->type) + "& " + name(p);
      head += ") {";
    }
  }
  line(head);
  ++depth_;
  line("(void)s;");
  if (f.kind == Function::Start) line("s.core.start(seed, kOnClauses);");
  if (f.kind == Function::Step) line("s.core.have_prev = true;");
  if (f.kind == Function::Render) line("(void)paint;\n    (void)pal;");
  --depth_;
  block(f.body);
  ++depth_;
  if (f.kind == Function::Start) line("render(s, nullptr, {});");
  if (f.kind == Function::Step) line("s.core.clear_inputs();");
  if (f.ret) line("return {};");
  --depth_;
  line("}");
}

// The classes in order, each after the sums its fields hold (a field that holds
// an Int at one construction and a String at another is a sum), and then the
// other sums (some hold classes).
// A class comes after the classes its fields contain (classes_held by value;
// the specialiser refuses a class that contains itself), and a class named
// before it is printed (in a list, a sum) is declared first. With every field
// holding earlier classes, the classes print in their own order.
void Printer::declarations() {
  std::set<TypeP> printed;
  std::vector<int> state(m_.classes.size(), 0);  // 0 not yet, 1 printing its fields' classes, 2 printed
  std::set<int> declared;
  auto declare = [&](TypeP t) {
    std::vector<int> named;
    classes_held(t, false, named);
    for (int c : named)
      if (state[c] != 2 && declared.insert(c).second) line("struct " + m_.classes[c].cpp + ";");
  };
  std::function<void(TypeP)> need = [&](TypeP t) {
    if (!t) return;
    if (t->k == TK::List) return need(t->elem);
    if (t->k != TK::Sum || printed.count(t)) return;
    for (TypeP a : t->alts) need(a);
    declare(t);
    sum_alias(t);
    printed.insert(t);
  };
  std::function<void(int)> print_class = [&](int c) {
    if (state[c]) return;
    state[c] = 1;
    const ClassInfo& ci = m_.classes[c];
    for (TypeP t : ci.field_types) {
      std::vector<int> contained;
      classes_held(t, true, contained);
      for (int d : contained) print_class(d);
    }
    for (TypeP t : ci.field_types) {
      need(t);
      declare(t);
    }
    class_struct(ci);
    state[c] = 2;
  };
  for (size_t c = 0; c < m_.classes.size(); ++c) print_class(static_cast<int>(c));
  for (TypeP t : sums_)
    if (!printed.count(t)) {
      declare(t);
      sum_alias(t);
    }
}

void Printer::class_struct(const ClassInfo& c) {
  line("struct " + c.cpp + " {");
  ++depth_;
  for (size_t i = 0; i < c.fields.size(); ++i)
    line((c.field_types[i] ? type(c.field_types[i]) : std::string("Unit")) + " f" + std::to_string(i) + ";");
  // With Position identities tracked, an origin keeps the identity of the
  // Position it was given (the reference stores that very object).
  line(pos_type() + " origin;");
  if (c.mode == CellMode::Stored) line("std::vector<CellV> cells;");
  // No default member initialisers: a class nested in Prog with one is not
  // default-constructible until Prog is complete (CWG 1397), so a std::variant of
  // two such classes (a global or field holding either) had a deleted default
  // constructor and the module did not compile (tests/lowering/erasable_sum_global.au).
  // Every object is value-initialised ({}, aggregate or variant), so these start at 0.
  if (c.tracked) line("uint32_t uid;");
  if (c.rotatable) line("uint32_t group;");
  std::vector<std::string> members;
  for (size_t i = 0; i < c.fields.size(); ++i) members.push_back("v.f" + std::to_string(i));
  members.push_back("v.origin");
  if (c.mode == CellMode::Stored) members.push_back("v.cells");
  if (c.tracked) members.push_back("v.uid");
  if (c.rotatable) members.push_back("v.group");
  auto each = [&](const std::string& call) {
    for (const std::string& m : members) line("  " + call + m + ");");
  };
  // Hashed in one call, so that neighbouring one-word fields pair up (hash_fields).
  line("friend void hash_value(Hash& h, const " + c.cpp + "& v) {");
  std::string all;
  for (const std::string& m : members) all += ", " + m;
  line("  hash_fields(h" + all + ");");
  line("}");
  tally_function(c);
  line("friend void save_value(SnapshotWriter& w, const " + c.cpp + "& v) {");
  each("save_value(w, ");
  line("}");
  line("friend void load_value(SnapshotReader& r, " + c.cpp + "& v) {");
  each("load_value(r, ");
  line("}");
  if (c.shape_table) shape_table(c);
  --depth_;
  line("};");
}

// The cells every object of a Static class has, as {x, y, colour} (Op::Shape):
// a render loops over them instead of repeating its body once per cell.
void Printer::shape_table(const ClassInfo& c) {
  const std::vector<Node*>& cells = c.static_shape->a;
  line("static constexpr CellV kShape[" + std::to_string(cells.size()) + "] = {");
  for (size_t i = 0; i < cells.size(); i += 8) {
    std::string row = "   ";
    for (size_t j = i; j < std::min(cells.size(), i + 8); ++j)
      row += " {" + std::to_string(cells[j]->a[0]->imm) + ", " + std::to_string(cells[j]->a[1]->imm) + ", " +
             std::to_string(cells[j]->a[2]->imm) + "},";
    line(row);
  }
  line("};");
}

// The state check's count of one object (StateTally): the object, its fields with
// origin and elems, then its children last to first: elems (the list and its
// cells), origin, the fields in reverse.
// kTally: the cells of an object whose count never varies (its cells fixed, no
// field holding a list or an instance), or -1.
void Printer::tally_function(const ClassInfo& c) {
  const std::string fields = std::to_string(c.fields.size() + 2);
  const size_t shape = c.static_shape ? c.static_shape->a.size() : 0;
  bool constant = c.mode == CellMode::Static;
  for (TypeP t : c.field_types)
    constant = constant && (!t || t->k == TK::Int || t->k == TK::Bool || t->k == TK::Str || t->k == TK::Func);
  const int64_t k = static_cast<int64_t>(c.fields.size()) + 2 + 2 + 4 * static_cast<int64_t>(shape);
  line("static constexpr int64_t kTally = " + std::to_string(constant ? k : -1) + ";");
  line("friend bool tally_value(Tally& t, const Core& c, const " + c.cpp + "& v) {");
  line("  ++t.objects;");
  line("  t.cells += " + fields + ";");
  const std::string cells = c.mode == CellMode::Stored ? "int64_t(v.cells.size())" : std::to_string(shape);
  line("  if (tally_over(t, c)) return true;");
  line("  t.cells += 4 * " + cells + ";  // elems: the list, and each Cell's 3 fields");
  line("  if (tally_over(t, c)) return true;");
  line("  t.cells += 2;  // origin");
  for (size_t i = c.fields.size(); i-- > 0;) {
    line("  if (tally_over(t, c)) return true;");
    line("  tally_value(t, c, v.f" + std::to_string(i) + ");");
  }
  line("  return true;");
  line("}");
}

void Printer::sum_alias(TypeP t) {
  std::string alts;
  for (size_t i = 0; i < t->alts.size(); ++i) alts += (i ? ", " : "") + type(t->alts[i]);
  line("using " + type(t) + " = std::variant<" + alts + ">;");
}

void Printer::state() {
  line("struct Scratch {");
  for (const std::string& s : scratch_) line("  " + s);
  for (const Slot& s : m_.slots)
    if (in_scratch(s)) line("  " + (s.type ? type(s.type) : std::string("bool")) + " " + s.name + "{};");
  line("};");
  line("struct State {");
  ++depth_;
  line("Core core;");
  line("NoCopy<Scratch> scratch;");
  if (m_.runtime_order) line("GlobalOrder order;");
  if (m_.draw_order) line("DrawOrder drawn;");
  for (const Slot& s : m_.slots)
    if (!in_scratch(s)) line((s.type ? type(s.type) : std::string("bool")) + " " + s.name + "{};");
  --depth_;
  line("};");
}

void Printer::snapshot_functions() {
  auto each = [&](const std::string& call) {
    if (m_.runtime_order) line("  " + call + "s.order);");
    if (m_.draw_order) line("  " + call + "s.drawn);");
    for (const Slot& s : m_.slots)
      if (s.in_snapshot) line("  " + call + "s." + s.name + ");");
  };
  line("static uint64_t hash(const State& s) {");
  line("  Hash h;");
  line("  hash_core(h, s.core, kUsesRandom);");
  each("hash_value(h, ");
  line("  return h.h;");
  line("}");
  line("static void save(const State& s, SnapshotWriter& w) {");
  line("  (void)s;");
  line("  (void)w;");
  each("save_value(w, ");
  line("}");
  line("static void load(State& s, SnapshotReader& r) {");
  line("  (void)s;");
  line("  (void)r;");
  each("load_value(r, ");
  line("}");
}

// Every Sum type the module uses, alternatives before the sums holding them.
static void collect_sums(const Module& m, std::vector<TypeP>& out) {
  std::function<void(TypeP)> add = [&](TypeP t) {
    if (!t) return;
    if (t->k == TK::List) add(t->elem);
    if (t->k != TK::Sum) return;
    for (TypeP a : t->alts) add(a);
    if (std::find(out.begin(), out.end(), t) == out.end()) out.push_back(t);
  };
  for (const Var& v : m.arena.vars) add(v.type);
  for (const Node& n : m.arena.nodes) add(n.type);
  for (const Slot& s : m.slots) add(s.type);
  for (const ClassInfo& c : m.classes)
    for (TypeP t : c.field_types) add(t);
}

std::string Printer::run() {
  collect_sums(m_, sums_);
  // Functions first (into a buffer): they decide the scratch members.
  std::ostringstream functions;
  std::swap(out_, functions);
  for (size_t i = 0; i < m_.functions.size(); ++i)
    if (m_.functions[i]->kind == Function::Colour || m_.functions[i]->kind == Function::Helper) function(*m_.functions[i], static_cast<int>(i));
  for (size_t i = 0; i < m_.functions.size(); ++i)
    if (m_.functions[i]->kind != Function::Colour && m_.functions[i]->kind != Function::Helper) function(*m_.functions[i], static_cast<int>(i));
  snapshot_functions();
  std::swap(out_, functions);

  out_ << "struct Prog {\n";
  line("static constexpr const char* kProgramName = " + quoted(m_.name) + ";");
  line("static constexpr int kOnClauses = " + std::to_string(m_.on_clauses) + ";");
  line(std::string("static constexpr bool kUsesRandom = ") + (m_.uses_random ? "true" : "false") + ";");
  line("static constexpr int kGrid = " + std::to_string(m_.grid) + ";");
  line("static constexpr uint64_t kSnapshotLayout = " + hex64(snapshot_layout(m_)) + "ULL;");
  line("static const char* const kColours[];");
  line("static const char* const kStringText[];");
  line("static const char* const kRenderNames[];");
  line("static const ErrorSite kErrors[];");
  out_ << "\n";
  declarations();
  out_ << "\n";
  state();
  out_ << "\n";
  out_ << functions.str();
  out_ << "};\n\n";
  tables();
  return out_.str();
}

void Printer::tables() {
  out_ << "const char* const Prog::kColours[] = {\n";
  for (const std::string& q : m_.strings) {
    std::string inner = q.size() >= 2 ? q.substr(1, q.size() - 2) : q;
    out_ << "    " << quoted(lower_ascii(inner)) << ",\n";
  }
  out_ << "    nullptr};\n\n";
  out_ << "const char* const Prog::kStringText[] = {\n";  // as written, quotes included (render_all's JSON)
  for (const std::string& q : m_.strings) out_ << "    " << quoted(q) << ",\n";
  out_ << "    nullptr};\n\n";
  out_ << "const char* const Prog::kRenderNames[] = {\n";
  for (const std::string& n : m_.render_names) out_ << "    " << quoted(n) << ",\n";
  out_ << "    nullptr};\n\n";
  out_ << "const ErrorSite Prog::kErrors[] = {\n";
  auto source = [](SourceId id) {
    switch (id) {
      case SourceId::Program: return "nullptr";
      case SourceId::Stdlib: return "\"<stdlib>\"";
      case SourceId::Trigger: return "\"<trigger>\"";
      case SourceId::Internal: return "\"<internal>\"";
    }
    return "nullptr";
  };
  for (const ErrorLoc& l : m_.locations)
    out_ << "    {" << l.at.line << ", " << l.at.col << ", " << source(l.at.source) << ", "
         << (l.in_program ? "true" : "false") << ", " << l.program_at.line << ", " << l.program_at.col << ", "
         << quoted(l.prefix) << "},\n";
  out_ << "    {0, 0, nullptr, false, 0, 0, \"\"}};\n";
}

}  // namespace

std::string print_cpp(const Module& m) { return Printer(m).run(); }

// A value's layout in a snapshot, from its type: what save_value writes for it.
// An object is named by its class (the classes are described once, in
// snapshot_layout), so a class holding a list of itself ends.
namespace {
std::string layout_of(const Module& m, TypeP t) {
  if (!t) return "b";  // a slot of no type is a flag (state())
  switch (t->k) {
    case TK::Int: return "i";
    case TK::Str: return "s";
    case TK::Bool: return "b";
    case TK::Pos: return pos_type_of(m);
    case TK::Elem: return "e";
    case TK::Cell:
    case TK::Deferred: return "c";
    case TK::Obj: return "O" + std::to_string(t->cls);
    case TK::List: return "L(" + (t->elem ? layout_of(m, t->elem) : std::string("i")) + ")";
    case TK::Sum: {
      std::string alts;
      for (TypeP a : t->alts) alts += layout_of(m, a) + ",";
      return "S(" + alts + ")";
    }
    default: return "u";
  }
}
}  // namespace

// What a snapshot of this module holds and what its numbers mean (kSnapshotLayout):
// the saved slots and their types, the classes' members, the run-time orders,
// and the string table (a Str slot holds an index into it). A snapshot whose
// header names another layout is refused (CompiledProgramHost::load_state)
// rather than read field by field into the wrong slots (runtime/fnv1a.hpp).
uint64_t snapshot_layout(const Module& m) {
  std::string d = "autumn snapshot layout 1;";
  for (const ClassInfo& c : m.classes) {
    d += "class " + c.cpp + "{";
    for (TypeP t : c.field_types) d += layout_of(m, t) + ";";
    d += pos_type_of(m);
    if (c.mode == CellMode::Stored) d += ";cells";
    if (c.tracked) d += ";uid";
    if (c.rotatable) d += ";group";
    d += "}";
  }
  d += m.runtime_order ? "order;" : "";
  d += m.draw_order ? "drawn;" : "";
  for (const Slot& s : m.slots)
    if (s.in_snapshot) d += s.name + ":" + layout_of(m, s.type) + ";";
  for (const std::string& str : m.strings) d += std::to_string(str.size()) + ":" + str;
  return fnv1a(d);
}

}  // namespace autumn::lower
