// ir_print — the lowering IR as text (see ir_print.hpp).
#include "compiler/lower/ir_print.hpp"

#include <iterator>

namespace autumn::lower {

namespace {

using namespace ir;

// Names in enum order; the static_asserts keep each table as long as its enum.
constexpr const char* kIrOpNames[] = {
    "lit",     "text",     "local",    "global",  "slot",  "member", "add",   "sub",   "mul",    "neg",
    "div",     "mod",      "lt",       "le",      "gt",    "ge",     "eq",    "ne",    "not",    "and",
    "or",      "make_pos", "make_elem", "make_obj", "make_cell", "make_list", "make_sum", "sum_is", "sum_get",
    "size",    "empty",    "index",    "front",   "back",  "call",   "fn_call", "concat", "select",
    "shape"};
static_assert(std::size(kIrOpNames) == static_cast<size_t>(Op::Shape) + 1);

constexpr const char* kIrMemberNames[] = {"x",     "y",     "position", "color",  "origin", "field",  "uid", "group",
                                        "cell_x", "cell_y", "cell_colour", "cell_dx", "cell_dy", "cell_dc", "cells"};
static_assert(std::size(kIrMemberNames) == static_cast<size_t>(Member::Cells) + 1);

constexpr const char* kIrHelperNames[] = {
    "rng_next",     "occupancy_free", "id_of",       "id_transfer",   "new_uid",     "sqrt",
    "define_global", "erase_global",  "order_keys",  "click_pos",     "click_define", "reserve",
    "append",       "clear",          "str_of_int",  "str_of_str",    "occupancy_clear", "occupancy_add",
    "paint_begin",  "paint",          "paint_global", "paint_end", "set_triggered", "covered",    "have_prev",   "input_flag",
    "rot_turn",     "rot_of",         "rotated",     "tally_begin",   "tally_global", "tally_rendered",
    "check_length", "charge_built", "note_drawn", "drawn_keys"};
static_assert(std::size(kIrHelperNames) == static_cast<size_t>(Helper::DrawnKeys) + 1);

constexpr const char* kIrStmtNames[] = {"let",   "decl",  "bind",   "set",    "push",   "eval",    "if",   "for_each",
                                      "for_range", "switch", "block", "break", "return", "fail", "comment", "swap"};
static_assert(std::size(kIrStmtNames) == static_cast<size_t>(SK::Swap) + 1);

constexpr const char* kIrFunctionKinds[] = {"start", "step", "render", "colour", "helper"};

std::string ir_var_text(const Var* v) {
  if (!v) return "<no var>";
  return "v" + std::to_string(v->id) + (v->hint.empty() ? "" : "_" + v->hint);
}

class IrTextPrinter {
 public:
  explicit IrTextPrinter(const Module& m) : m_(m) {}

  std::string node(const Node* n) const {
    if (!n) return "<null>";
    std::string s = kIrOpNames[static_cast<size_t>(n->op)];
    switch (n->op) {
      case Op::Lit:
        s += " " + (n->type && n->type->k == TK::Str ? "str#" + std::to_string(n->imm) : std::to_string(n->imm));
        break;
      case Op::Text: s += " \"" + n->text + "\""; break;
      case Op::Local: s += " " + ir_var_text(n->var); break;
      case Op::Global:
      case Op::Slot: s += " " + slot_name(n->slot); break;
      case Op::Member:
        s += "." + std::string(kIrMemberNames[static_cast<size_t>(n->member)]);
        if (n->member == Member::Field) s += "#" + std::to_string(n->index);
        break;
      case Op::MakeObj:
      case Op::Shape: s += " " + class_name(n->index); break;
      case Op::MakeSum:
      case Op::SumIs:
      case Op::SumGet: s += " #" + std::to_string(n->index); break;
      case Op::Call:
        s += " " + std::string(kIrHelperNames[static_cast<size_t>(n->helper)]);
        if (n->imm) s += " site " + std::to_string(n->imm);
        break;
      case Op::FnCall: s += " fn#" + std::to_string(n->index); break;
      default: break;
    }
    if (!n->a.empty()) {
      s += "(";
      for (size_t i = 0; i < n->a.size(); ++i) s += (i ? ", " : "") + node(n->a[i]);
      s += ")";
    }
    if (n->type) s += ": " + type_text(n->type);
    return s;
  }

  void block(const Block& b, int depth, std::string& out) const {
    for (const Stmt* s : b) stmt(s, depth, out);
  }

  void stmt(const Stmt* s, int depth, std::string& out) const {
    const std::string pad(static_cast<size_t>(depth) * 2, ' ');
    if (!s) {
      out += pad + "<null statement>\n";
      return;
    }
    std::string line = kIrStmtNames[static_cast<size_t>(s->k)];
    if (s->var) {
      line += " " + ir_var_text(s->var) + ": " + (s->var->type ? type_text(s->var->type) : "<untyped>");
      if (s->k == SK::Bind) line += s->var->is_ref ? " [ref]" : " [copy]";
      if (s->var->scratch) line += " [scratch]";
    }
    const bool binds = s->k == SK::Let || s->k == SK::Decl || s->k == SK::Bind;
    const bool loop = s->k == SK::ForEach || s->k == SK::ForRange;
    if (s->a) line += (binds ? " = " : loop ? " in " : " ") + node(s->a);
    if (s->b) line += (loop ? " .. " : s->k == SK::Push ? " <- " : s->k == SK::Swap ? ", " : " = ") + node(s->b);
    if (s->k == SK::Comment) line += " " + s->text;
    if ((s->k == SK::ForEach || s->k == SK::ForRange) && !s->charged) line += " [uncharged]";
    if ((s->k == SK::ForEach || s->k == SK::ForRange) && s->charged && s->charge_each) line += " [charged each]";
    if (s->k == SK::ForEach || s->k == SK::ForRange || s->k == SK::Fail) line += " @site " + std::to_string(s->loc);
    if (s->move_value) line += " [move]";
    if (s->local_budget) line += " [local budget]";
    out += pad + line + "\n";
    block(s->body, depth + 1, out);
    if (!s->other.empty()) {
      out += pad + "else\n";
      block(s->other, depth + 1, out);
    }
    for (const auto& [alt, body] : s->cases) {
      out += pad + "case #" + std::to_string(alt) + "\n";
      block(body, depth + 1, out);
    }
  }

  std::string function(const Function& f) const {
    std::string out = "fn " + f.name + " (" + kIrFunctionKinds[static_cast<size_t>(f.kind)] + ")";
    for (const Var* p : f.params) out += " " + ir_var_text(p) + ": " + (p && p->type ? type_text(p->type) : "?");
    if (f.ret) out += " -> " + type_text(f.ret);
    out += "\n";
    block(f.body, 1, out);
    return out;
  }

 private:
  std::string slot_name(int slot) const {
    if (slot < 0 || static_cast<size_t>(slot) >= m_.slots.size()) return "<slot " + std::to_string(slot) + ">";
    return m_.slots[static_cast<size_t>(slot)].name;
  }
  std::string class_name(int cls) const {
    if (cls < 0 || static_cast<size_t>(cls) >= m_.classes.size()) return "<class " + std::to_string(cls) + ">";
    return m_.classes[static_cast<size_t>(cls)].name;
  }

  const Module& m_;
};

}  // namespace

const char* stmt_kind_name(ir::SK k) { return kIrStmtNames[static_cast<size_t>(k)]; }

std::string type_text(TypeP t) {
  if (!t) return "<none>";
  switch (t->k) {
    case TK::Int: return "int";
    case TK::Bool: return "bool";
    case TK::Str: return "str";
    case TK::Pos: return "pos";
    case TK::Elem: return "elem";
    case TK::Cell: return "cell";
    case TK::Obj: return "obj#" + std::to_string(t->cls);
    case TK::List: return "list<" + (t->elem ? type_text(t->elem) : std::string("empty")) + ">";
    case TK::Func: return "func";
    case TK::Class: return "class#" + std::to_string(t->cls);
    case TK::Sum: {
      std::string s = "sum{";
      for (size_t i = 0; i < t->alts.size(); ++i) s += (i ? "|" : "") + type_text(t->alts[i]);
      return s + "}";
    }
    case TK::Deferred: return "deferred#" + std::to_string(t->cls);
    case TK::Never: return "never";
  }
  return "?";
}

std::string print_node(const Module& m, const ir::Node* n) { return IrTextPrinter(m).node(n); }

std::string print_ir(const Module& m) {
  IrTextPrinter p(m);
  std::string out = "module " + m.name + "\n";
  for (size_t i = 0; i < m.slots.size(); ++i)
    out += "slot " + std::to_string(i) + " " + m.slots[i].name + ": " +
           (m.slots[i].type ? type_text(m.slots[i].type) : "bool") + "\n";
  for (size_t i = 0; i < m.functions.size(); ++i)
    out += "\n#" + std::to_string(i) + " " + (m.functions[i] ? p.function(*m.functions[i]) : "<null function>\n");
  return out;
}

}  // namespace autumn::lower
