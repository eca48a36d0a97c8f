// host_api — the parts of the reference's host API that the Environment protocol
// does not cover, for the Python binding's drop-in Interpreter (python/).
//
// The reference host sets input flags with click()/left()/... and steps later, so
// several inputs can be pending at once: press() sets one flag without stepping,
// and step(Action::noop()) then runs with every pressed flag. evaluate_to_string
// and execute_statement run against the global scope between steps, exactly as
// the reference's evaluateToString / tmpExecuteStmt do with its interpreter;
// environment_string prints the global scope in the reference's toJson layout
// (map iteration orders from the libstdc++ model; instance values printed
// without the render-method suffix, as everywhere in this interpreter).
#include <cstdio>

#include "compiler/interpret/interpreter.hpp"

namespace autumn::interp {

void Interpreter::press(const Action& input) {
  switch (input.kind) {
    case Action::Kind::Noop: break;
    case Action::Kind::Left: left_ = true; break;
    case Action::Kind::Right: right_ = true; break;
    case Action::Kind::Up: up_ = true; break;
    case Action::Kind::Down: down_ = true; break;
    case Action::Kind::Click:
      click_ = true;
      click_x_ = input.x;
      click_y_ = input.y;
      break;
  }
}

std::string Interpreter::evaluate_to_string(const Expr& e) {
  std::string out;
  entry([&] {
    env_ = global_;
    Value v = eval(e);
    out = v.is(VKind::None) ? "NULL" : value_string(v);
  });
  return out;
}

// tmpExecuteStmt: an assignment runs (an initnext one also defines its variable
// with the initial value at once), an on-clause is added, anything else runs.
void Interpreter::execute_statement(const Stmt& st) {
  entry([&] {
    env_ = global_;
    run_statement(st);
    if (st.kind != StmtKind::Expr || st.expr->kind != ExprKind::Assign) return;
    const Expr& value = *st.expr->kids.at(0);
    if (value.kind == ExprKind::InitNext) define_global(st.expr->name, eval_value(*value.kids.at(0)));
  });
}

int Interpreter::frame_rate() const {
  Sym s = program_->symbols.find("FRAME_RATE");
  if (s < 0 || !gdefined_[s]) return 16;
  return gvalues_[s].is(VKind::Number) ? gvalues_[s].num : -1;
}

namespace {

std::string json_escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (c == '"') out += "\\\"";
    else out += c;
  }
  return out;
}

}  // namespace

std::string Interpreter::environment_string() {
  std::string out;
  entry([&] { out = environment_text(); });
  return out;
}

std::string Interpreter::environment_text() {
  const SymbolTable& syms = program_->symbols;
  // The reference copies the global map into a second map, in the first one's
  // iteration order, and prints that one.
  HashOrder copied;
  for (int s : gorder_.order()) copied.insert(s, syms.hash(s));
  const std::string indent = "   ";
  std::string out = "{\n" + indent + "\"varValues\": {\n";
  for (int s : copied.order())
    out += indent + "    \"" + syms.name(s) + "\": \"" + json_escaped(value_string(gvalues_[s])) + "\",\n";
  out += indent + "  },\n" + indent + "\"typeValues\": {\n";
  HashOrder types;
  for (size_t s = 0; s < gtypes_.size(); ++s)
    if (gtypes_[s]) types.insert(static_cast<int>(s), syms.hash(static_cast<Sym>(s)));
  for (int s : types.order())
    out += indent + "    \"" + syms.name(s) + "\": \"" + type_string(gtypes_[s].get()) + "\",\n";
  out += indent + "  }\n}\n";
  return out;
}

}  // namespace autumn::interp
