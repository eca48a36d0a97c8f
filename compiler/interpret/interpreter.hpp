// interpreter — the reference-exact tree-walking interpreter (back end: interpret).
//
// This is the semantic oracle of the project: it reproduces BasisResearch/Autumn.cpp
// frame for frame, bugs included (docs/autumn-semantics.md, docs/conformance-notes.md).
// The model follows the reference closely where behaviour is observable:
//  * a dynamic scope chain (functions are not closures; `let` is not binding;
//    assignment walks the chain; unknown names are defined in the current scope);
//  * the global map's key history replayed through the libstdc++ order model
//    (allObjs, prev-by-id, removeObj), and the initnext map's (start-up and NEXT);
//  * identity numbers transferred on assignment; shared mutable cells; deferred
//    cell expressions with capture scopes; list type tags;
//  * occupancy refreshed only by the host render.
//
// API (one interpreter = one episode, like the reference's fresh Interpreter):
//   Interpreter(program)          ready to start
//   start(seed)                   run the stdlib and program, initialise, render
//   step(action)                  inputs, one step (no render)
//   render(&cells)                the host render_all(): refreshes occupancy
//   triggered(), coverage
// Errors are thrown as RuntimeError; after one, the interpreter must not be used.
//
// Limits (runtime/limits.hpp): every public entry that evaluates runs on the deep
// stack (deep_stack.hpp) with fresh per-step budgets; eval() counts its nesting,
// call_lambda the call depth and the step's calls, the list builders the list
// lengths and the cells created, and check_state() the state after start-up and
// after every step. Only the program's constructs count: the machinery of
// rendering (render methods, flattening) does not, deferred cell expressions do.
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/analyse/render_order.hpp"
#include "compiler/interpret/deep_stack.hpp"
#include "compiler/interpret/scope.hpp"
#include "compiler/interpret/value.hpp"
#include "runtime/action.hpp"
#include "runtime/diagnostic.hpp"
#include "runtime/hash_order.hpp"
#include "runtime/limits.hpp"
#include "runtime/rng.hpp"

namespace autumn::interp {

class RuntimeError : public std::runtime_error {
 public:
  explicit RuntimeError(const std::string& msg) : std::runtime_error(msg) {}
  SourceLoc loc;          // innermost construct
  bool located = false;
  SourceLoc program_loc;  // innermost construct in the user's program
  bool in_program = false;
};

// Sets err's locations to e's unless an inner construct already did.
void locate(RuntimeError& err, const Expr& e);

// One rendered cell of the host render, in render order.
struct RenderedCell {
  int x, y;
  const std::string* color;  // with quotes
  Sym name = -1;             // the global it was drawn from (the render_all() JSON key)
};

class Interpreter {
 public:
  explicit Interpreter(std::shared_ptr<const Program> program);
  ~Interpreter();
  Interpreter(const Interpreter&) = delete;
  Interpreter& operator=(const Interpreter&) = delete;

  void start(uint64_t seed);
  void step(const Action& input);
  // Host render_all(): fills `cells` (may be null), refreshes occupancy, assigns
  // cacheRendered, returns GRID_SIZE.
  int render(std::vector<RenderedCell>* cells);
  // step() then render() (start() then render()) in one entry: the host's
  // sequence, switching to the deep stack once instead of twice.
  int step_and_render(const Action& input, std::vector<RenderedCell>* cells);
  int start_and_render(uint64_t seed, std::vector<RenderedCell>* cells);
  std::string background() const;  // `background` without its quotes

  bool triggered() const;
  int on_clause_count() const { return static_cast<int>(on_clauses_.size()); }
  int covered_on_clause_count() const;
  // "file:line:col: runtime error: message"
  std::string describe(const RuntimeError& e) const;
  // The path named for the program's own locations in describe() (a compiled
  // module knows only its text; the host names the file).
  void set_source_name(std::string path) { source_name_ = std::move(path); }
  void set_relocation(std::shared_ptr<const Relocation> r) { relocation_ = std::move(r); }
  void set_limits(const Limits& l) { limits_ = limits::normalised(l); }
  const Limits& limits() const { return limits_; }
  // A deep copy sharing nothing mutable with this one (safe to use on another
  // thread); taken between steps.
  std::unique_ptr<Interpreter> clone() const;
  // Digest of everything that decides future frames (snapshot.cpp).
  uint64_t state_hash();
  const Program& program() const { return *program_; }
  // The random generator (the particle filter's seed groups, environment.hpp).
  WrappedMinstd& rng() { return rng_; }
  const WrappedMinstd& rng() const { return rng_; }

  // --- the reference's host API beyond the Environment protocol (host_api.cpp),
  // for the Python binding. press() sets an input for the next step without
  // stepping (the reference host may set several); the others run between steps
  // against the global scope and may throw RuntimeError like step().
  void press(const Action& input);
  std::string evaluate_to_string(const Expr& e);  // the value's printed form, "NULL" for none
  void execute_statement(const Stmt& st);         // tmp_execute_stmt; `st` must outlive this
  std::string environment_string();               // get_environment_string()
  int frame_rate() const;                         // FRAME_RATE; 16 when undefined, -1 when not a Number

 private:
  friend struct Builtins;
  using Bindings = std::vector<Binding>;

  // --- start-up and steps (host.cpp), inside an entry
  void start_up(uint64_t seed);
  void step_once(const Action& input);
  bool condition_holds(const Stmt& on_clause);
  int render_all(std::vector<RenderedCell>* cells);
  std::string environment_text();

  // --- evaluation (eval.cpp)
  Value eval(const Expr& e);
  Value eval_node(const Expr& e);  // eval()'s cases
  Value eval_binary(const Expr& e);
  Value eval_unary(const Expr& e);
  Value eval_let(const Expr& e);
  Value eval_set(const Expr& e);
  Value eval_type_decl(const Expr& e);
  Value eval_value(const Expr& e);  // errors on types and non-values
  Value eval_call(const Expr& e);
  Value eval_assign(const Expr& e);
  Value construct_cell(const Expr& e, TypeObj* cls);
  Value call_function(const Value& f, std::vector<Value>& args, const Expr* site = nullptr);
  // `site`: the call expression, for naming the callee when the depth limit stops it.
  Value call_lambda(const Expr& lambda, std::vector<Value>& args, ScopeKind kind = ScopeKind::Local,
                    const Expr* site = nullptr);
  Value call_deferred(DeferredObj* d);
  Value call_render_method(TypeObj* cls);
  Value get_field(const Value& obj, Sym field, const std::string& raw);
  void run_statement(const Stmt& st);
  TypeRef resolve_type(const TypeExpr& t);

  // --- scopes (eval.cpp)
  Value* lookup(Sym s);
  TypeObj* lookup_type(Sym s);
  void assign(Sym s, Value v);
  void define(Scope* scope, Sym s, Value v);
  void define_global(Sym s, Value v);
  void erase_global(Sym s);
  bool is_updated(Sym s);
  TypeObj* find_declared(Sym s, bool* found);
  Ref<Scope> new_scope(ScopeKind kind, Ref<Scope> parent);

  // --- values (values.cpp)
  int next_id() { return ++id_counter_; }
  Value make_list(std::vector<Value> items);  // tag inferred from elements
  Value make_empty_list();                    // the shared default List<Unknown> tag
  void list_add(ListObj* list, Value v);      // append with the tag rule
  Value make_instance(TypeObj* cls, std::vector<Value> fields);  // field type checks
  Value make_position(int x, int y);
  Value make_function(FuncObj::Kind kind, Builtin b, const Expr* lambda, TypeObj* cls);
  Value copy_value(const Value& v);           // the reference's copy()
  TypeObj* type_of(const Value& v);
  const std::string& type_string(TypeObj* t);
  std::string value_string(const Value& v);
  bool equals(const Value& a, const Value& b);
  bool truthy(const Value& v) const;
  TypeRef make_type(TypeKind k, TypeRef elem = {});
  TypeRef make_class(const std::string& name, std::vector<Sym> field_syms,
                     std::vector<std::string> field_names, std::vector<TypeRef> field_types);

  // --- rendering helpers (builtins.cpp)
  Value render_value(const Value& v);  // list of RenderedElems (instances with render)
  Value call_builtin(Builtin b, std::vector<Value>& args);
  struct BuiltinArgs;  // the arguments and their shared checks (builtins.cpp)
  Value builtin_higher_order(Builtin b, BuiltinArgs& a);
  Value builtin_lists(Builtin b, BuiltinArgs& a);
  Value builtin_grid(Builtin b, BuiltinArgs& a);
  Value builtin_objects(Builtin b, BuiltinArgs& a);
  Value builtin_rotate(BuiltinArgs& a);
  Value builtin_remove_obj(BuiltinArgs& a);
  Value builtin_host(Builtin b, BuiltinArgs& a);
  Value call1(const Value& f, const Value& x);
  int32_t grid_size_now();  // GRID_SIZE as a builtin reads it
  Value builtin_prev(const Value& arg);
  Value all_objs();
  std::vector<Sym> render_order() const;
  int grid_size_for_render();

  [[noreturn]] void fail(const std::string& msg);
  void poll_interrupt();  // fails with interrupted_error() when the host asks (runtime/interrupt.hpp)
  // In a catch (...) handler of a caller of eval(): the error being handled,
  // located at the frames it unwound (eval_stack_ above `height`, then cut
  // off) innermost first, as if each frame had caught and located it: an
  // eval() frame at its expression, a render method's by its rule.
  // std::bad_alloc and std::length_error thrown inside an eval() frame become
  // "out of memory"; any other exception is rethrown unchanged.
  RuntimeError unwound(size_t height);
  // In a handler that swallows the error: its frames (above `height`) cut off.
  void drop_unwound(size_t height) { eval_stack_.resize(std::min(height, eval_stack_.size())); }
  // A render method's frame on the way out of an error (eval.cpp, call_render_method).
  void locate_in_render(RuntimeError& e, TypeObj* cls) const;

  // --- limits (limits.cpp)
  // Runs an entry's work (start-up, a step, a render, a host API call) on the
  // deep stack with fresh budgets.
  template <class F>
  void entry(F&& f);
  void begin_budget();
  void count_cells(int64_t n);             // cells created (lists, fields, printed values)
  void check_length(int64_t n);            // a list of n elements is about to exist
  void append(ListObj* list, Value v);     // push_back, counted and length-checked
  [[noreturn]] void fail_call_depth(const Expr& lambda, const Expr* site);
  [[noreturn]] void fail_at_definition(Sym s, const std::string& msg);
  void check_state();                      // the state's objects, cells and nesting
  struct Nest {                            // RAII depth counter
    explicit Nest(int64_t& d) : d_(++d) {}
    ~Nest() { --d_; }
    int64_t& d_;
  };
  // Inside a Nest over value_depth_: fails past limits::kMaxValueNesting.
  void check_value_depth() {
    if (value_depth_ > limits::kMaxValueNesting) fail(limits::value_nesting_error());
  }
  struct CopyOnly {};
  Interpreter(const Interpreter& other, CopyOnly);

  std::shared_ptr<const Program> program_;
  const WellKnownNames& names_;
  std::string source_name_;  // empty: the program's own file name
  std::shared_ptr<const Relocation> relocation_;  // where the program's locations moved (null: nowhere)
  Limits limits_;
  int64_t eval_depth_ = 0, call_depth_ = 0, value_depth_ = 0;
  // The frames running now, outermost first: an eval() of `expr`, or a render
  // method of class `render` (expr null). Pushed on entry, popped on a normal
  // return only, so a throw leaves its frames here. Invariant: at a catch site
  // that saved the size as `height` before its call, the entries above `height`
  // are exactly the frames the exception unwound; every such site hands them to
  // unwound() (or cuts them off, drop_unwound(), when it swallows the error)
  // before going on. Errors are located here once, innermost frame first,
  // instead of by a catch and rethrow in every frame (a rethrow per frame made
  // recursion to the call-depth limit slow, and quadratic under ASan).
  struct Frame {
    const Expr* expr;
    TypeObj* render;
  };
  std::vector<Frame> eval_stack_;
  int64_t step_cells_ = 0, step_calls_ = 0;
  int64_t internal_ = 0;                    // > 0: inside rendering machinery, nothing is counted
  const char* stack_floor_ = nullptr;      // deep_stack.hpp
  SourceLoc last_cell_arg_;                // the cell argument a render evaluated last
  WrappedMinstd rng_;
  int id_counter_ = 0;

  // Global scope: values indexed by symbol; key history through the order model.
  Ref<Scope> global_;
  std::vector<Value> gvalues_;
  std::vector<char> gdefined_;
  std::vector<char> gupdated_;
  HashOrder gorder_;
  std::vector<Sym> definition_order_;  // every definition, repeats included (renderAll)
  RenderOrder render_order_;           // the host render's order (render_order.hpp)
  std::vector<TypeRef> gtypes_;  // type definitions by name
  Ref<Scope> env_;               // current scope

  // initnext registrations
  std::vector<ExprPtr> init_expr_, next_expr_;  // by symbol
  HashOrder init_map_order_;

  // prev snapshot: global values at the start of the step
  bool have_prev_ = false;
  std::vector<Value> prev_values_;
  std::vector<char> prev_defined_;
  std::vector<Sym> prev_keys_;  // live iteration order when taken

  std::vector<const Stmt*> on_clauses_;
  std::vector<char> covered_;

  // inputs
  bool click_ = false, left_ = false, right_ = false, up_ = false, down_ = false;
  int click_x_ = -1, click_y_ = -1;

  std::unordered_set<int64_t> occupied_;
  std::vector<TypeRef> classes_;  // every class made, to break render-binding cycles

  // shared type objects
  TypeRef t_number_, t_string_, t_bool_, t_unknown_, t_func_, t_expr_, t_default_list_;
  TypeRef c_position_, c_cell_, c_rendered_;
};

template <class F>
void Interpreter::entry(F&& f) {
  on_deep_stack([&] {
    stack_floor_ = stack_floor();
    begin_budget();
    const size_t height = eval_stack_.size();
    try {
      f();
    } catch (...) {
      forget_unwound_frames();
      throw unwound(height);
    }
  });
}

}  // namespace autumn::interp
