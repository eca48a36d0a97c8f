// limits — the interpreter's side of runtime/limits.hpp.
//
// Budgets are per entry (start-up, a step, a render, a host API call): the cells
// created and the calls made start from zero at each. check_state() counts the
// state after start-up and after each step as values (a list held twice counts
// twice), iteratively and stopping at the first limit crossed, so its cost is
// bounded by the limits whatever the sharing; an excess is reported at the
// definition of the largest global so far (Program::definitions).
#include <algorithm>

#include "compiler/interpret/interpreter.hpp"

namespace autumn::interp {

void Interpreter::begin_budget() {
  step_cells_ = 0;
  step_calls_ = 0;
  internal_ = 0;
}

void Interpreter::count_cells(int64_t n) {
  if (internal_) return;
  step_cells_ += n;
  if (step_cells_ > limits_.cells) fail(limits::created_cells_error(limits_.cells));
}

void Interpreter::check_length(int64_t n) {
  if (!internal_ && n > limits_.list_length) fail(limits::list_length_error(n, limits_.list_length));
}

void Interpreter::append(ListObj* list, Value v) {
  check_length(static_cast<int64_t>(list->items.size()) + 1);
  count_cells(1);
  list->items.push_back(std::move(v));
}

void Interpreter::fail_call_depth(const Expr& lambda, const Expr* site) {
  std::string name;
  if (site && !site->kids.empty()) {
    const Expr& callee = *site->kids[0];
    if (callee.kind == ExprKind::Var) name = program_->name(callee.name);
    else if (callee.kind == ExprKind::Get) name = callee.text;
  }
  if (name.empty() && &lambda == program_->render_lambda.get()) name = "render";
  fail(limits::call_depth_error(limits_.call_depth, name));
}

void Interpreter::fail_at_definition(Sym s, const std::string& msg) {
  RuntimeError err(msg);
  const SourceLoc at = program_->definitions[s];
  if (at.line > 0) {
    err.loc = at;
    err.located = true;
    err.program_loc = at;
    err.in_program = at.source == SourceId::Program;
  }
  throw err;
}

namespace {

struct Tally {
  int64_t objects = 0, cells = 0;
};

// Counts one global's value as a tree into `t`, stopping once either total
// passes its limit; false when the value nests deeper than allowed. `work` is
// scratch space.
bool tally_value(const Value& root, Tally& t, const Limits& lim, std::vector<std::pair<const Value*, int>>& work) {
  work.assign(1, {&root, 1});
  while (!work.empty() && t.objects <= lim.objects && t.cells <= lim.cells) {
    auto [v, depth] = work.back();
    work.pop_back();
    if (depth > limits::kMaxValueNesting) return false;
    const std::vector<Value>* kids = nullptr;
    if (v->is(VKind::List)) {
      kids = &v->as<ListObj>()->items;
    } else if (v->is(VKind::Instance)) {
      const InstanceObj* in = v->as<InstanceObj>();
      kids = &in->fields;
      if (in->cls->object) ++t.objects;
    }
    if (!kids) continue;
    t.cells += static_cast<int64_t>(kids->size());
    for (const Value& k : *kids)
      if (k.is(VKind::List) || k.is(VKind::Instance)) work.emplace_back(&k, depth + 1);
  }
  return true;
}

}  // namespace

void Interpreter::check_state() {
  Tally total;
  Sym most_objects = -1, most_cells = -1;
  int64_t max_objects = -1, max_cells = -1;
  std::vector<std::pair<const Value*, int>> work;
  gorder_.for_each([&](int s) {
    const Value& v = gvalues_[s];
    if (!v.is(VKind::List) && !v.is(VKind::Instance)) return;
    Tally one;
    if (!tally_value(v, one, limits_, work)) fail_at_definition(s, limits::value_nesting_error());
    if (one.objects > max_objects) max_objects = one.objects, most_objects = s;
    if (one.cells > max_cells) max_cells = one.cells, most_cells = s;
    total.objects += one.objects;
    total.cells += one.cells;
    if (total.objects > limits_.objects)
      fail_at_definition(most_objects, limits::objects_error(limits_.objects, program_->name(most_objects)));
    if (total.cells > limits_.cells)
      fail_at_definition(most_cells, limits::state_cells_error(limits_.cells, program_->name(most_cells)));
  });
}

}  // namespace autumn::interp
