// specialise — the staged interpreter: program AST to typed IR (pass 2 of lower).
//
// The specialiser walks the program the way the interpreter evaluates it
// (compiler/interpret/eval.cpp is the model for every case) but, instead of
// values, it produces IR and static types. Every call is inlined at its call
// site, so the dynamic scope chain at each point is known statically: a name
// resolves to a C++ variable, a state slot, or a chain of them guarded by
// run-time "is it bound now?" flags where binding depends on the run. Start-up
// is specialised statement by statement, the step once for all steps.
//
// Types are found by the same walk (the "typing walk"): a run starts from the
// types it has learnt so far (hints.hpp: globals, locals by definition site,
// object fields, which objects need identity, which globals can be erased);
// where a value does not fit the type a slot was given, the slot's type is
// widened in the hints and the walk is repeated. The IR of a walk whose hints
// changed is dropped. The final walk's IR is the module. (Why the types are not
// found by a separate pass: docs/design.md, "The lowering", on types.)
//
// The walk's collaborators each keep their own state: IrBuilder (ir_builder.hpp:
// the insertion point, dead code, effects), ScopeChain (scope_chain.hpp: the
// static scopes), Hints (hints.hpp: what walks learnt), the builtins'
// lowerings, one per builtin in a table indexed by the Builtin enum
// (spec_builtins.cpp), and ErrorSites (error_sites.hpp: where the walk is, for
// the errors it compiles in). The Specialiser itself keeps the rest of the
// walk's state: the globals and the map order, the cells being made.
//
// Split over spec_*.cpp by topic: scopes and assignment (spec_scope), expressions
// (spec_expr), calls and objects (spec_call), builtins (spec_builtins,
// spec_builtins_state), cells and rendering (spec_cells), values: equality,
// truthiness, coercion, type strings, sums (spec_values), the global map
// (spec_globals), the host algorithm: start, step, render (spec_host), and the
// driver, temporaries, failures and type strings (spec_core).
#pragma once
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/lower/error_sites.hpp"
#include "compiler/lower/facts.hpp"
#include "compiler/lower/hints.hpp"
#include "compiler/lower/ir_builder.hpp"
#include "compiler/lower/module.hpp"
#include "compiler/lower/scope_chain.hpp"

namespace autumn::lower {

// A value during specialisation.
struct SVal {
  TypeP type = nullptr;       // null: no value (an initnext or type declaration)
  ir::Node* code = nullptr;   // null for values with nothing at run time (functions, classes)
  ir::Node* konst = nullptr;  // the value when known at compile time (Lit, MakePos, MakeList trees)
  bool fresh = false;         // just made: nobody else holds this object
  std::vector<ir::Node*> parts;  // a list literal: its elements' values (concat appends them directly)
};

// A global of the program: its state slots and what is known about it here.
struct Global {
  Sym sym = -1;
  TypeP type = nullptr;          // slot type (Func/Class values have no slot)
  int value = -1, defined = -1, updated = -1, prev = -1, prev_defined = -1;
  int saved = -1;  // the step's first store moved the value into `prev`
  enum State : uint8_t { Undefined, Defined, Runtime } state = Undefined;
  bool initnext = false;
  const Expr* init = nullptr;
  const Expr* next = nullptr;
  std::optional<SVal> constant;  // start-up: a value known at compile time
};

class Specialiser {
 public:
  Specialiser(const Program& p, const Facts& f, Module& m, Hints& hints);
  // One walk over the whole program. Throws Unsupported.
  void run();

  // Everything below is the walk's own: the spec_*.cpp files implement it, and
  // only specialise_program (spec_core.cpp) makes a Specialiser.
 private:

  // --- shared by the spec_*.cpp files -------------------------------------------
  // Where the walk is in the program, for error sites (error_sites.hpp).
  ErrorSites sites_;
  // Where the IR goes, and whether the code being written is dead (ir_builder.hpp).
  IrBuilder ir_;
  SVal let(SVal v, const std::string& hint = "t");  // into an immutable temporary
  void fail(const std::string& msg);                  // a static message
  // The list-length budget (runtime/limits.hpp) before a list is built: its
  // length formed by `how` (ir::LengthOf) from `args`; `known`, when the
  // length is known now (no check when it is within every budget).
  void check_length(ir::LengthOf how, std::vector<ir::Node*> args, std::optional<int64_t> known = std::nullopt);
  // The cells budget's per-step part: a program construct is about to give a
  // new list these elements (docs/design.md, "Limits"). Not in a cell's trial.
  void charge_built(ir::LengthOf how, std::vector<ir::Node*> args);
  void charge_one_built();
  void fail(std::vector<ir::Node*> message_parts);    // strings and StrOfInt nodes
  SVal never();                                       // the value of dead code
  SVal empty_list();                                  // a list known to be empty

  // Types and naming
  Types& T() { return m_.types; }
  const std::string& nm(Sym s) const { return p_.name(s); }
  int string_id(const std::string& quoted);
  std::string type_string(TypeP t);          // the reference's type string
  void check_appends(TypeP elem, const char* what);
  void check_kept_type(const SVal& x, ir::Var* last);
  std::string shown(TypeP t);                // as an error names it (no list: embedded)
  TypeP declared_type(const TypeExpr& te);   // a (: x T) declaration; null: unknown name
  bool check_printable(TypeP t);             // false: the type string is an error (emitted)

  std::map<Sym, const TypeExpr*> global_decls_;  // (: x T) at the top level

  // Values (spec_values.cpp)
  SVal coerce(SVal v, TypeP to);             // v must fit `to`
  ir::Node* truthy(const SVal& v);           // Bool node
  SVal equals(const SVal& a, const SVal& b);
  SVal narrow(const SVal& v, TK want, const std::function<void(const SVal&)>& bad);
  SVal split(const SVal& v, const std::function<SVal(const SVal&)>& per_alternative);
  SVal join_blocks(ir::Stmt* stmt, std::vector<ir::Block*> blocks, std::vector<std::function<SVal()>> producers,
                   bool value_used, bool report);
  SVal join_branches(ir::Node* cond, const std::function<SVal()>& then_f, const std::function<SVal()>& else_f,
                     bool value_used);
  std::optional<int64_t> const_int(const SVal& v) const;
  void note_identity(TypeP t);               // identity numbers of t are observed
  ir::Node* id_of(const SVal& v);            // the identity number an object shows
  SVal fresh_identity(SVal v);               // a just-made object (its uid is fresh)
  void transfer_identity(const SVal& v, const SVal& old);
  std::vector<Sym> instance_fields(TypeP t);
  SVal instance_equals(const SVal& x, const SVal& y);
  SVal list_equals(const SVal& x, const SVal& y);
  SVal cells_equal(const SVal& x, const SVal& y);

  // Expressions (spec_expr.cpp)
  SVal lower(const Expr& e);
  SVal lower_value(const Expr& e);           // errors on no-value and type values
  SVal lower_discarded(const Expr& e);       // a statement: the value is not used
  bool value_unused_ = false;
  SVal lower_var(const Expr& e);
  SVal lower_binary(const Expr& e);
  SVal lower_logical(const Expr& e);
  SVal lower_unary(const Expr& e);
  SVal lower_if(const Expr& e, bool unused);
  SVal lower_let(const Expr& e, bool unused);
  SVal lower_list(const Expr& e);
  SVal lower_get(const Expr& e);
  SVal arithmetic(const Expr& e, const SVal& a, const SVal& b);
  SVal get_field(const SVal& obj, Sym field, const std::string& raw);
  SVal auto_call(SVal v);                    // and/or and on-clauses call function values

  // Scopes and assignment (spec_scope.cpp)
  ScopeChain scopes_;                        // the static scopes over the globals (scope_chain.hpp)
  std::map<Sym, Global> globals_;
  Global* global(Sym s);                     // null: never a global
  Global& global_slot(Sym s, TypeP t);       // the global's slots, made on first use
  SVal read_name(Sym s, const Expr& at);
  SVal read_global(Global& g);
  void assign(Sym s, SVal v, const Expr& at);
  SVal lower_assign(const Expr& e, bool unused);
  void define_local(SScope& sc, Sym s, SVal v, const void* site);
  void define_global(Global& g, SVal v);
  bool store_function(Global& g, const SVal& v);
  void store_global(Global& g, SVal v, const Expr& at, bool mark_updated);
  void store_checked(TypeP slot_type, ir::Node* place, SVal v, Sym s, const std::function<void(TypeP)>& widen,
                     const std::function<void()>& before_write = nullptr);
  void check_declared(Sym s, const SVal& v);
  struct Candidate;                          // a binding a name may read (spec_scope.cpp)
  std::vector<Candidate> resolve(Sym sym);   // innermost first; guarded ones may be unbound
  SVal read_binding(Binding& b);
  bool assigned_anywhere(Sym s) const { return f_.assigned.count(s) > 0; }

  // Calls and objects (spec_call.cpp)
  SVal lower_call(const Expr& e);
  SVal call_value(const SVal& f, std::vector<SVal>& args, const Expr& at);
  SVal call_render(const Expr& e);
  bool render_value_shortcut(const Expr& lambda, const std::vector<SVal>& args);
  SVal inline_lambda(const Expr& lambda, std::vector<SVal>& args, const Expr& at, ScopeKind kind = ScopeKind::Local);
  SVal construct(int cls, std::vector<SVal>& args, const Expr& at);
  SVal make_position(SVal x, SVal y);
  SVal construct_builtin_class(int c, std::vector<SVal>& args);
  SVal make_instance(int cls, std::vector<SVal>& values, const SVal& cells);
  void check_field_type(int cls, size_t i, TypeP declared, const SVal& value);
  bool check_copy(const SVal& o);
  void widen_field(int cls, int field, TypeP t);
  void bind(SScope& sc, Sym s, const SVal& v, std::pair<const void*, Sym> key);
  SVal built(ir::Var* v);  // a list or value finished building: immutable from here
  // A loop a builtin runs by itself (range, concat, allPositions, addObj's copy,
  // ...), charging nothing to the calls budget (spec_call.cpp).
  ir::Stmt* builtin_loop(ir::SK kind);
  SVal instance_field(const SVal& v, Sym f);
  SVal make_list(const std::vector<SVal>& items);
  bool list_tag_may_pass(TypeP value, TypeP declared);
  std::string class_name(int c) const;
  std::optional<int> type_named(Sym s) const;
  std::string where(SourceLoc loc) const;
  std::vector<std::pair<const Expr*, std::vector<TypeP>>> inline_sigs_;  // inlined calls, innermost last
  struct BoundMethod {
    SVal obj;
    ir::Block* block = nullptr;
  };
  std::map<int, BoundMethod> bound_;  // class -> the instance whose render was fetched last

  // Builtins (spec_builtins.cpp, spec_builtins_state.cpp). call_builtin checks
  // the argument count (from the builtin table) and splits sum-typed arguments,
  // then calls the builtin's lowering from lowerings(), indexed by the Builtin
  // enum. A lowering gets the builtin it lowers (one may serve several), the
  // lowered arguments, and the call (for error sites).
  SVal call_builtin(Builtin b, std::vector<SVal>& args, const Expr& at);
  using Lowering = SVal (Specialiser::*)(Builtin b, std::vector<SVal>& a, const Expr& at);
  static const std::array<Lowering, kBuiltinCount>& lowerings();
  SVal builtin_iterate(Builtin b, std::vector<SVal>& a, const Expr& at);  // map, filter, any, foldl
  SVal builtin_concat(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_length(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_head_tail(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_at(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_range(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_array_equal(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_is_list(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_print(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_sqrt(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_uniform_choice(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_random_positions(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_all_positions(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_adj_positions(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_is_free_pos(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_within_bounds(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_add_obj(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_update_obj(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_remove_obj(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_clicked(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_arrow(Builtin b, std::vector<SVal>& a, const Expr& at);  // left, right, up, down
  SVal builtin_defined(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_all_objs(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_prev(Builtin b, std::vector<SVal>& a, const Expr& at);  // prev of a value
  [[noreturn]] SVal builtin_render_all(Builtin b, std::vector<SVal>& a, const Expr& at);
  SVal builtin_rotate(Builtin b, std::vector<SVal>& a, const Expr& at);
  // Their parts.
  bool need(Builtin b, size_t n);  // builtin_arity_error: fails (and false) on a wrong count
  bool check_kind(Builtin b, const std::vector<SVal>& a, size_t i, TK k, const char* what);
  ir::Node* int_text(ir::Node* n);
  SVal call1(const SVal& f, const SVal& x, const Expr& at);
  SVal grid_size(const Expr& at);
  bool unroll(const SVal& l) const;
  SVal iterate_loop(Builtin b, std::vector<SVal>& a, const SVal& l, const Expr& at,
                    const std::function<SVal(const SVal&)>& apply);
  SVal fold(const SVal& f, const SVal& init, const SVal& l, const Expr& at);
  void define_click();
  SVal add_obj(const SVal& l, const SVal& x);
  SVal renew_identity(const SVal& v);
  SVal set_field(const SVal& o, const std::string& field, const SVal& v);
  SVal rebuilt_with(const SVal& o, int field, const SVal& v);  // set_field, built in place
  SVal update_filtered(const SVal& l, const SVal& f, const SVal& pred, const Expr& at);
  SVal remove_from(const SVal& l, const SVal& what, const Expr& at);
  ir::Node* same_identity_any(const SVal& x, const std::vector<SVal>& others);

  // The global map (spec_globals.cpp)
  std::vector<Sym> start_defines_;  // start-up's definitions, in order (the map's history)
  std::vector<Sym> global_order(bool with_click);
  // `slotless`: also the defined globals without a slot (constants, cacheRendered).
  void for_each_global_in_order(const std::function<void(Global&)>& visit, bool slotless = false);
  // The state budget (runtime/limits.hpp) at the end of start-up and of a step.
  void check_state();
  bool order_changes_in_steps() const;
  void walk_runtime_order(const std::function<void(Global&)>& visit, bool slotless);
  void switch_over_keys(ir::Helper keys, const char* hint, const std::vector<Global*>& globals,
                        const std::function<void(Global&)>& visit);
  void order_insert(Sym s);         // the run-time order (when kept) learns s
  void note_definition(Global& g);  // g's first definition
  TypeP all_objs_type();
  void for_each_listed_object(const std::function<void(const SVal&)>& each,
                              const std::function<void(const SVal&)>& whole = nullptr);
  SVal all_objs();
  SVal filter_all_objs(const SVal& f, const Expr& list, const Expr& at);
  bool calls_all_objs(const Expr& e);  // e is ((allObjs)), allObjs the builtin there
  bool means_builtin(Sym s, Builtin b);  // s names builtin b here (no binding or global shadows it)
  SVal lower_filter_call(const SVal& callee, const Expr& e);
  SVal remove_global(const SVal& v);
  SVal lower_prev(const Expr& call);
  SVal prev_of_name(Sym s);
  void save_for_prev(Global& g);
  SVal prev_of_value(const SVal& v, const Expr& at);

  // Cells and rendering (spec_cells.cpp)
  SVal construct_cell(const Expr& e);
  SVal trial(const Expr& arg, SScope& capture, int which, int* deferred_index);
  int capture_mode_ = 0;               // > 0: evaluating a cell argument in its capture scope
  // Nested split()s in progress. Each nests the next alternative's code in a
  // switch case, so a chain of sum-typed values multiplies code and C++ stack:
  // beyond kMaxSplitDepth the program is the embedded engine's.
  int split_depth_ = 0;
  static constexpr int kMaxSplitDepth = 12;
  ir::Block* capture_block_ = nullptr;
  bool trial_failed_ = false;
  size_t trial_fail_depth_ = 0;  // the scopes visible where the trial failed (1: the capture's alone)
  bool trial_varies_ = false;  // the trial called a builtin of kReadsChangingState: not fixed
  // Per class rendered by its shared function (Stored), the names some render
  // call site binds in a local scope: a deferred argument's free name would
  // resolve there, but the shared function sees the globals (finish_classes).
  std::map<int, std::set<Sym>> stored_render_binds_;
  void note_reads(Builtin b);
  void check_render_callers(int cls);
  void dynamic_names(const DeferredArg& da, std::set<Sym>& out);
  std::map<Sym, ir::Node*> captured_konst_;
  bool object_cells(int cls, const SVal& cells, std::vector<ir::Node*>& ops);
  SVal object_cell_list(const SVal& o);
  SVal eval_deferred(int d, const SVal* obj, const SVal& cell);
  SVal call_deferred(const SVal& f);
  SVal render_value(const SVal& v, const Expr& at);  // List<Elem>
  using ElemSink = std::function<void(ir::Node* elem)>;
  void render_into(const SVal& v, const ElemSink& sink);
  void render_into(const SVal& v, ir::Node* out);
  void render_object(const SVal& o, const ElemSink& sink);
  void render_cells(const SVal& o, const ElemSink& sink);
  // renderValue's parameter while its shortcut renders (else -1): bound to each
  // object rendered, as the interpreter's nested renderValue calls bind it.
  Sym render_value_param_ = -1;
  bool tabulable(const ir::Node& shape) const;
  void render_shape_table(int cls, ir::Node* origin, const SVal& turns, const ElemSink& sink);
  bool renders(TypeP t) const;
  SVal deferred_colour(int d, const SVal& o, const SVal& cell);
  // A render's own error (a colour that is not a String, a coordinate that is not
  // a Number) is the program's, at the cell argument evaluated last: `arg`,
  // unless the error already has a place in the program.
  void fail_at_cell_arg(const Expr* arg, const std::string& msg);
  // The one number-colour argument of cells of `cls` (null when none is known);
  // checked again by finish_classes, when every cell has been made.
  const Expr* number_colour_of(int cls);
  std::vector<std::pair<int, const Expr*>> number_colour_uses_;
  int colour_function(int d, int cls, const SVal& cell);
  std::map<std::pair<int, int>, int> colour_fns_;
  SVal call_render_method(int cls);
  void finish_classes();
  void check_containment();
  std::string cell_value_error(int which, TypeP got);
  void check_rotated_order(int cls);
  void check_rotated_cells(int cls);
  bool cells_made_fresh(const Expr& e, const ClassInfo& ci, const std::vector<Sym>& bound) const;
  void load_shapes();
  int stored_render_function(int cls);
  std::vector<int> constructing_;                    // classes whose constructor is running

  // The host algorithm (spec_host.cpp)
  void specialise_start();
  void define_class(const Stmt& st);
  void check_render_lookups(const Stmt& st);
  void specialise_step();
  void publish_trigger();
  void specialise_render();
  bool drawn_late(const Global& g) const;
  void on_clause(size_t i, const Stmt& st);
  void next_update(Sym s);
  bool is_own_prev(const Expr& e, Sym x);
  bool in_start_ = false;
  bool in_step_ = false;

  const Program& p_;
  Module& m_;
  Hints& h_;
  const Facts& f_;
  std::vector<char> class_defined_;  // start-up: the object statement has run
};

bool has_fail(const ir::Block& b);

// Runs walks until the hints settle; fills the module. Throws Unsupported.
void specialise_program(const Program& p, Module& m);

}  // namespace autumn::lower
