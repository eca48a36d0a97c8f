// host — start-up, the step algorithm and the host render.
//
// start(): builtins in the reference's order, the stdlib, SpecialConditionTriggered,
// the program's statements in source order, initialisers in initnext hash order,
// then a render. step(): prev snapshot, clear updated flags, trigger, on-clauses in
// source order against live state, NEXT for variables no clause assigned (hash
// order), clear inputs. Nothing is rendered during a step. Each public entry runs
// on the deep stack with fresh budgets (interpreter.hpp); start-up and every step
// end with check_state(), and the render checks GRID_SIZE against its range,
// reporting at its definition.
#include "compiler/interpret/interpreter.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::interp {

Interpreter::Interpreter(std::shared_ptr<const Program> program)
    : program_(std::move(program)), names_(program_->names) {
  const size_t nsyms = program_->symbols.size();
  gvalues_.resize(nsyms);
  gdefined_.resize(nsyms, 0);
  gupdated_.resize(nsyms, 0);
  gtypes_.resize(nsyms);
  render_order_ = RenderOrder(nsyms);
  init_expr_.resize(nsyms);
  next_expr_.resize(nsyms);
  global_ = new_scope(ScopeKind::Global, Ref<Scope>());
  env_ = global_;

  t_number_ = make_type(TypeKind::Number);
  t_string_ = make_type(TypeKind::String);
  t_bool_ = make_type(TypeKind::Bool);
  t_unknown_ = make_type(TypeKind::Unknown);
  t_func_ = make_type(TypeKind::Func);
  t_expr_ = make_type(TypeKind::Expr);
  t_default_list_ = make_type(TypeKind::List, t_unknown_);
  c_position_ = make_class("Position", {names_.x, names_.y}, {"x", "y"}, {t_number_, t_number_});
  c_cell_ = make_class("Cell", {names_.x, names_.y, names_.color}, {"x", "y", "color"},
                       {t_expr_, t_expr_, t_expr_});
  c_rendered_ = make_class("RenderedElem", {names_.position, names_.color}, {"position", "color"},
                           {c_position_, t_string_});
}

Interpreter::~Interpreter() {
  // Break the class -> bound instance -> class cycles.
  for (auto& c : classes_) c->bound.reset();
  env_.reset();
}

void Interpreter::start(uint64_t seed) {
  entry([&] {
    start_up(seed);
    check_state();
    render_all(nullptr);
  });
}

void Interpreter::start_up(uint64_t seed) {
  rng_.reseed(seed);
  define_global(names_.GRID_SIZE, Value::number(16));
  for (int i = 0; i < kBuiltinCount; ++i) {
    const Builtin b = static_cast<Builtin>(i);
    define_global(program_->builtin_syms[i], make_function(FuncObj::Kind::Native, b, nullptr, nullptr));
    if (b == kTypesDefinedAfter) {
      gtypes_[names_.Bool] = t_bool_;
      gtypes_[names_.String] = t_string_;
      gtypes_[names_.Number] = t_number_;
      gtypes_[names_.Int] = t_number_;
      gtypes_[names_.Position] = c_position_;
      gtypes_[names_.Cell] = c_cell_;
      gtypes_[names_.RenderedElem] = c_rendered_;
    }
  }

  for (const Stmt& st : program_->stdlib_stmts) run_statement(st);
  assign(names_.SpecialConditionTriggered, Value::boolean(false));
  for (const Stmt& st : program_->stmts) run_statement(st);

  std::vector<int> order = init_map_order_.order();
  for (int s : order) {
    const size_t height = eval_stack_.size();
    try {
      Value v = eval_value(*init_expr_[s]);
      define(env_.get(), s, std::move(v));
    } catch (...) {
      forget_unwound_frames();
      const RuntimeError e = unwound(height);
      RuntimeError wrapped("initialising '" + program_->name(s) + "': " + e.what());
      wrapped.loc = e.loc;
      wrapped.located = e.located;
      wrapped.program_loc = e.program_loc;
      wrapped.in_program = e.in_program;
      throw wrapped;
    }
  }
}

void Interpreter::step(const Action& input) {
  entry([&] {
    step_once(input);
    check_state();
  });
}

// An on-clause's condition: a Bool, or a function of no arguments returning one.
bool Interpreter::condition_holds(const Stmt& st) {
  auto located = [&](const std::string& msg) {
    RuntimeError e(msg);
    locate(e, *st.cond);
    return e;
  };
  Value c = eval_value(*st.cond);
  if (c.is(VKind::Bool)) return c.num != 0;
  if (!c.is(VKind::Function)) throw located("an on-clause condition must be a Bool, got " + shown_type(type_string(type_of(c))));
  std::vector<Value> none;
  Value r;
  const size_t height = eval_stack_.size();
  try {
    r = call_function(c, none);
  } catch (...) {
    forget_unwound_frames();
    RuntimeError e = unwound(height);
    locate(e, *st.cond);
    throw e;
  }
  if (!r.is(VKind::Bool))
    throw located("an on-clause condition function must return a Bool, got " + shown_type(type_string(type_of(r))));
  return r.num != 0;
}

void Interpreter::step_once(const Action& input) {
  press(input);
  // 1. Snapshot for prev: the values (shared, not deep-copied) and the map order.
  have_prev_ = true;
  prev_values_ = gvalues_;
  prev_defined_ = gdefined_;
  prev_keys_ = gorder_.order();
  // 2. Clear the updated flags.
  std::fill(gupdated_.begin(), gupdated_.end(), 0);
  // 3. Trigger, evaluated on the state before this step's updates.
  if (program_->trigger) {
    Value c = eval_value(*program_->trigger);
    assign(names_.SpecialConditionTriggered, Value::boolean(truthy(c)));
  }
  // 4. On-clauses in source order, each seeing the effects of the earlier ones.
  for (size_t i = 0; i < on_clauses_.size(); ++i) {
    const Stmt& st = *on_clauses_[i];
    if (condition_holds(st)) {
      covered_[i] = 1;
      eval_value(*st.body);
    }
  }
  // 5. NEXT for every initnext variable no clause assigned, in hash order.
  std::vector<int> order = init_map_order_.order();
  for (int s : order) {
    if (is_updated(s)) continue;
    if (!gdefined_[s]) continue;  // erased by removeObj
    Value v = eval_value(*next_expr_[s]);
    try {
      assign(s, std::move(v));
    } catch (RuntimeError& e) {  // the assignment's own checks: located at the NEXT expression
      forget_unwound_frames();
      if (!e.located) {
        e.loc = next_expr_[s]->loc;
        e.located = true;
        e.program_loc = e.loc;
        e.in_program = e.loc.source == SourceId::Program;
      }
      throw;
    }
  }
  // 6. Inputs last only for one step.
  click_ = left_ = right_ = up_ = down_ = false;
}

std::vector<Sym> Interpreter::render_order() const { return render_order_.order(); }

int Interpreter::render(std::vector<RenderedCell>* cells) {
  int size = 0;
  entry([&] { size = render_all(cells); });
  return size;
}

int Interpreter::step_and_render(const Action& input, std::vector<RenderedCell>* cells) {
  int size = 0;
  entry([&] {
    step_once(input);
    check_state();
    begin_budget();
    size = render_all(cells);
  });
  return size;
}

int Interpreter::start_and_render(uint64_t seed, std::vector<RenderedCell>* cells) {
  int size = 0;
  entry([&] {
    start_up(seed);
    check_state();
    render_all(nullptr);
    begin_budget();
    size = render_all(cells);
  });
  return size;
}

int Interpreter::render_all(std::vector<RenderedCell>* cells) {
  occupied_.clear();
  std::vector<RenderedCell> local;
  std::vector<RenderedCell>& out = cells ? *cells : local;
  out.clear();
  Value all = make_empty_list();
  for (Sym s : render_order()) {
    if (!gdefined_[s]) continue;
    Value elems = render_value(gvalues_[s]);
    for (const Value& r : elems.as<ListObj>()->items) {
      const Value& pos = r.as<InstanceObj>()->fields[0];
      const Value& colour = r.as<InstanceObj>()->fields[1];
      const auto& xy = pos.as<InstanceObj>()->fields;
      if (!xy[0].is(VKind::Number) || !xy[1].is(VKind::Number) || !colour.is(VKind::String))
        fail("malformed rendered element");
      out.push_back(RenderedCell{xy[0].num, xy[1].num, colour.str, s});
      occupied_.insert((static_cast<int64_t>(xy[0].num) << 32) ^ static_cast<uint32_t>(xy[1].num));
      all.as<ListObj>()->items.push_back(r);
    }
  }
  Value* g = lookup(names_.GRID_SIZE);
  if (!g) fail_at_definition(names_.GRID_SIZE, "GRID_SIZE is not defined when rendering");
  if (!g->is(VKind::Number)) fail_at_definition(names_.GRID_SIZE, limits::grid_size_type_error(shown_type(type_string(type_of(*g)))));
  if (std::string why = limits::grid_size_error(g->num); !why.empty()) fail_at_definition(names_.GRID_SIZE, why);
  int size = g->num;
  assign(names_.cacheRendered, all);
  return size;
}

std::string Interpreter::background() const {
  Sym s = names_.background;
  if (!gdefined_[s] || !gvalues_[s].is(VKind::String)) return "black";
  const std::string& b = *gvalues_[s].str;
  return b.size() >= 2 ? b.substr(1, b.size() - 2) : std::string();
}

bool Interpreter::triggered() const {
  Sym s = names_.SpecialConditionTriggered;
  return gdefined_[s] && gvalues_[s].is(VKind::Bool) && gvalues_[s].num;
}

int Interpreter::covered_on_clause_count() const {
  int n = 0;
  for (char c : covered_) n += c;
  return n;
}

std::string Interpreter::describe(const RuntimeError& e) const {
  SourceLoc at = e.in_program ? e.program_loc : e.loc;
  if (at.source == SourceId::Program && relocation_) std::tie(at.line, at.col) = relocation_->at(at.line, at.col);
  const std::string& file =
      at.source == SourceId::Program && !source_name_.empty() ? source_name_ : program_->file_name(at.source);
  std::string msg = format_diagnostic(file, at, "runtime error", e.what());
  if (e.in_program && e.located && e.loc.source != SourceId::Program && e.loc.source != SourceId::Internal)
    msg += diagnostic_inside(program_->file_name(e.loc.source), e.loc.line, e.loc.col);
  return msg;
}

}  // namespace autumn::interp
