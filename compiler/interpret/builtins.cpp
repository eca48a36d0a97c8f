// builtins — the native functions of the reference interpreter, and rendering.
//
// call_builtin checks the argument count the builtin table fixes, then hands
// the call to its family (functions over lists, lists, the grid, objects, the
// host); BuiltinArgs holds the checks of an argument's kind that all share.
// Each builtin checks its arguments as the reference does and builds its result
// list the same way, because the way a list is built decides its type tag
// (inferred from the elements, the shared default tag, or re-tagged per append),
// and tags are visible through list equality. Every list a builtin builds is
// length-checked before it is built and its cells counted (runtime/limits.hpp).
#include <cmath>
#include <functional>
#include <unordered_set>

#include "compiler/interpret/interpreter.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::interp {
namespace {

int64_t pos_key(int x, int y) { return (static_cast<int64_t>(x) << 32) ^ static_cast<uint32_t>(y); }

}  // namespace

// Renders an object, or a (nested) list of objects, by calling each object's
// render method; anything else renders as nothing.
Value Interpreter::render_value(const Value& v) {
  Nest nest(value_depth_);
  check_value_depth();
  if (v.is(VKind::List)) {
    std::vector<Value> all;
    for (const Value& item : v.as<ListObj>()->items) {
      Value part = render_value(item);
      for (const Value& r : part.as<ListObj>()->items) all.push_back(r);
    }
    return make_list(std::move(all));  // rendering machinery: not counted
  }
  if (v.is(VKind::Instance) && v.as<InstanceObj>()->cls->has_render) {
    Value method = get_field(v, names_.render, "render");
    // A field named render is what get_field finds first (found by a stress program:
    // a Number there crashed the process).
    if (!method.is(VKind::Function)) {  // the render's machinery: at the object's definition
      RuntimeError err("only functions and classes can be called, got " + shown_type(type_string(type_of(method))));
      if (const Stmt* def = v.as<InstanceObj>()->cls->object) {
        err.program_loc = def->loc;
        err.in_program = def->loc.source == SourceId::Program;
      }
      throw err;
    }
    std::vector<Value> none;
    Value r = call_function(method, none);
    if (!r.is(VKind::List)) fail("render did not produce a list");
    return r;
  }
  return make_empty_list();
}

Value Interpreter::builtin_prev(const Value& arg) {
  if (!have_prev_) fail("prev used before the first step");
  if (arg.is(VKind::String)) {
    std::string name = *arg.str;
    if (!name.empty() && name[0] == '"') name = name.substr(1, name.size() - 2);
    Sym s = program_->symbols.find(name);
    if (s < 0 || !prev_defined_[s]) fail("prev: '" + name + "' had no value at the start of the step");
    return prev_values_[s];
  }
  // By identity: scan the snapshot in *its* map order, which is that of a map
  // filled in the live map's iteration order.
  if (arg.is_heap()) {
    HashOrder snapshot_order;
    for (Sym s : prev_keys_) snapshot_order.insert(s, program_->symbols.hash(s));
    int id = arg.obj->id;
    Value found;
    bool ok = false;
    snapshot_order.for_each([&](int s) {
      if (!ok && prev_values_[s].is_heap() && prev_values_[s].obj->id == id) {
        found = prev_values_[s];
        ok = true;
      }
    });
    if (ok) return found;
  }
  fail("prev: no variable held this value at the start of the step");
}

Value Interpreter::all_objs() {
  Value out = make_empty_list();
  ListObj* list = out.as<ListObj>();
  std::function<void(const Value&)> collect = [&](const Value& v) {
    Nest nest(value_depth_);
    check_value_depth();
    if (v.is(VKind::List)) {
      for (const Value& item : v.as<ListObj>()->items) collect(item);
    } else if (v.is(VKind::Instance) && v.as<InstanceObj>()->cls->has_render) {
      append(list, v);
    }
  };
  gorder_.for_each([&](int s) { collect(gvalues_[s]); });
  return out;
}

// The arguments of one builtin call, and the checks every builtin shares: an
// argument of the wrong kind is "NAME: argument I must be a KIND, got TYPE".
struct Interpreter::BuiltinArgs {
  Interpreter& in;
  Builtin b;
  std::vector<Value>& v;
  size_t size() const { return v.size(); }
  Value& operator[](size_t i) { return v[i]; }
  [[noreturn]] void wrong(size_t i, const char* kind) {
    in.fail(std::string(builtin_name(b)) + ": argument " + std::to_string(i + 1) + " must be " + kind + ", got " +
            shown_type(in.type_string(in.type_of(v[i]))));
  }
  ListObj* list(size_t i) {
    if (!v[i].is(VKind::List)) wrong(i, "a list");
    return v[i].as<ListObj>();
  }
  const Value& func(size_t i) {
    if (!v[i].is(VKind::Function)) wrong(i, "a function");
    return v[i];
  }
  int32_t num(size_t i) {
    if (!v[i].is(VKind::Number)) wrong(i, "a number");
    return v[i].num;
  }
};

Value Interpreter::call1(const Value& f, const Value& x) {
  std::vector<Value> a{x};
  return call_function(f, a);
}

int32_t Interpreter::grid_size_now() {
  Value* g = lookup(names_.GRID_SIZE);
  if (!g) fail("GRID_SIZE is not defined");
  if (!g->is(VKind::Number)) fail("GRID_SIZE must be a number");
  return g->num;
}

// Checks the argument count the table fixes, then runs the builtin's family.
Value Interpreter::call_builtin(Builtin b, std::vector<Value>& args) {
  if (std::string why = builtin_arity_error(b, args.size()); !why.empty()) fail(why);
  BuiltinArgs a{*this, b, args};
  switch (b) {
    case Builtin::Map: case Builtin::Filter: case Builtin::Foldl: case Builtin::Any: case Builtin::UpdateObj:
      return builtin_higher_order(b, a);
    case Builtin::Concat: case Builtin::Length: case Builtin::Head: case Builtin::Tail: case Builtin::At:
    case Builtin::ArrayEqual: case Builtin::IsList: case Builtin::Range:
      return builtin_lists(b, a);
    case Builtin::AdjPositions: case Builtin::IsFreePos: case Builtin::RandomPositions: case Builtin::AllPositions:
    case Builtin::IsWithinBounds: case Builtin::UniformChoice:
      return builtin_grid(b, a);
    case Builtin::AddObj: case Builtin::RemoveObj: case Builtin::Rotate: case Builtin::AllObjs:
    case Builtin::RenderAll:
      return builtin_objects(b, a);
    case Builtin::Clicked: case Builtin::Left: case Builtin::Right: case Builtin::Up: case Builtin::Down:
    case Builtin::Defined: case Builtin::Prev: case Builtin::Sqrt: case Builtin::Print:
      return builtin_host(b, a);
  }
  fail("unknown builtin");
}

// Functions over lists: map, filter, foldl, any and updateObj's function forms.
Value Interpreter::builtin_higher_order(Builtin b, BuiltinArgs& a) {
  switch (b) {
    case Builtin::Map: {
      const Value& f = a.func(0);
      ListObj* l = a.list(1);
      Value out = make_empty_list();
      std::vector<Value> items = l->items;  // the callback may not change what we iterate
      for (const Value& x : items) append(out.as<ListObj>(), call1(f, x));
      return out;
    }
    case Builtin::Filter: {
      const Value& f = a.func(0);
      ListObj* l = a.list(1);
      Value out = make_empty_list();
      std::vector<Value> items = l->items;
      for (const Value& x : items)
        if (truthy(call1(f, x))) list_add(out.as<ListObj>(), x);
      return out;
    }
    case Builtin::Foldl: {
      const Value& f = a.func(0);
      Value acc = a[1];
      ListObj* l = a.list(2);
      std::vector<Value> items = l->items;
      for (const Value& x : items) {
        std::vector<Value> pair{acc, x};
        acc = call_function(f, pair);
      }
      return acc;
    }
    case Builtin::Any: {
      if (a.size() != 1 && a.size() != 2) fail("any takes 1 or 2 arguments, got " + std::to_string(a.size()));
      if (a.size() == 2) a.func(0);
      ListObj* l = a.list(a.size() - 1);
      std::vector<Value> items = l->items;
      for (const Value& x : items)
        if (truthy(a.size() == 2 ? call1(a[0], x) : x)) return Value::boolean(true);
      return Value::boolean(false);
    }
    case Builtin::UpdateObj: {
      if (a.size() < 2 || a.size() > 3) fail("updateObj takes 2 or 3 arguments, got " + std::to_string(a.size()));
      if (a[0].is(VKind::List)) {
        if (a.size() == 2) {
          std::vector<Value> swapped{a[1], a[0]};
          return call_builtin(Builtin::Map, swapped);
        }
        if (!a[1].is(VKind::Function) || !a[2].is(VKind::Function))
          fail("updateObj: the second and third arguments must be functions");
        Value out = make_empty_list();
        std::vector<Value> items = a[0].as<ListObj>()->items;
        for (const Value& x : items) {
          if (truthy(call1(a[2], x))) list_add(out.as<ListObj>(), call1(a[1], x));
          else list_add(out.as<ListObj>(), x);
        }
        return out;
      }
      if (!a[0].is(VKind::Instance)) fail("updateObj: the first argument must be an object or a list");
      if (a.size() == 3) {
        Value copy = copy_value(a[0]);
        if (!a[1].is(VKind::String)) fail("updateObj: the field name must be a string");
        std::string field = *a[1].str;
        if (!field.empty() && (field[0] == '"' || field[0] == '\'')) field = field.substr(1, field.size() - 2);
        InstanceObj* in = copy.as<InstanceObj>();
        Sym s = program_->symbols.find(field);
        int i = s < 0 ? -1 : in->cls->field_index(s);
        if (i < 0) fail("updateObj: object of class '" + in->cls->name + "' has no field '" + field + "'");
        in->fields[i] = a[2];
        return copy;
      }
      return call1(a.func(1), a[0]);
    }
    default: break;
  }
  fail("unknown builtin");
}

// Lists as values: their length and elements, concat, range, arrayEqual, isList.
Value Interpreter::builtin_lists(Builtin b, BuiltinArgs& a) {
  switch (b) {
    case Builtin::Concat: {
      ListObj* l = a.list(0);
      int64_t total = 0;
      for (const Value& x : l->items) {
        if (!x.is(VKind::List)) fail("concat: every element must be a list");
        total += static_cast<int64_t>(x.as<ListObj>()->items.size());
      }
      check_length(total);
      count_cells(total);
      Value out = make_empty_list();
      for (const Value& x : l->items)
        for (const Value& y : x.as<ListObj>()->items) out.as<ListObj>()->items.push_back(y);
      return out;
    }
    case Builtin::Length: return Value::number(static_cast<int32_t>(a.list(0)->items.size()));
    case Builtin::Head: {
      ListObj* l = a.list(0);
      if (l->items.empty()) fail("head of an empty list");
      return l->items.front();
    }
    case Builtin::Tail: {  // the *last* element, as in the reference
      ListObj* l = a.list(0);
      if (l->items.empty()) fail("tail of an empty list");
      return l->items.back();
    }
    case Builtin::At: {
      ListObj* l = a.list(0);
      if (l->items.empty()) fail("at: empty list");
      int32_t i = a.num(1);
      if (i < 0 || static_cast<size_t>(i) >= l->items.size()) fail("at: index " + std::to_string(i) + " out of bounds");
      return l->items[i];
    }
    case Builtin::ArrayEqual: {
      ListObj* x = a.list(0);
      ListObj* y = a.list(1);
      if (x->items.size() != y->items.size()) fail("arrayEqual: lists of different lengths");
      Value out = make_empty_list();
      for (size_t i = 0; i < x->items.size(); ++i)
        list_add(out.as<ListObj>(), Value::boolean(equals(x->items[i], y->items[i])));
      return out;
    }
    case Builtin::IsList: return Value::boolean(a[0].is(VKind::List));
    case Builtin::Range: {
      const int32_t from = a.num(0), to = a.num(1);
      check_length(static_cast<int64_t>(to) - from);
      Value out = make_empty_list();
      for (int32_t i = from; i < to; ++i) list_add(out.as<ListObj>(), Value::number(i));
      return out;
    }
    default: break;
  }
  fail("unknown builtin");
}

// Positions and the grid: adjacency, occupancy, bounds, and the random draws.
Value Interpreter::builtin_grid(Builtin b, BuiltinArgs& a) {
  switch (b) {
    case Builtin::AdjPositions: {
      if (!a[0].is(VKind::Instance) || a[0].as<InstanceObj>()->cls != c_position_)
        fail("adjPositions: the argument must be a Position");
      const auto& f = a[0].as<InstanceObj>()->fields;
      int32_t x = f[0].num, y = f[1].num;
      int32_t g = grid_size_now();
      std::vector<Value> out;
      const int32_t cand[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
      for (auto& c : cand)
        if (c[0] >= 0 && c[0] < g && c[1] >= 0 && c[1] < g) out.push_back(make_position(c[0], c[1]));
      count_cells(static_cast<int64_t>(out.size()));
      return make_list(std::move(out));
    }
    case Builtin::IsFreePos: {
      if (!a[0].is(VKind::Instance) || a[0].as<InstanceObj>()->cls != c_position_)
        fail("isFreePos: the argument must be a Position");
      const auto& f = a[0].as<InstanceObj>()->fields;
      if (!f[0].is(VKind::Number) || !f[1].is(VKind::Number)) fail("isFreePos: non-numeric position");
      return Value::boolean(!occupied_.count(pos_key(f[0].num, f[1].num)));
    }
    case Builtin::RandomPositions: {
      int32_t bound = a.num(0);
      if (bound < 0) fail("randomPositions: the grid size must not be negative");
      int32_t count = a.num(1);
      check_length(count);
      Value out = make_empty_list();
      for (int32_t i = 0; i < count; ++i) {
        int32_t x = static_cast<int32_t>(rng_.next(static_cast<uint64_t>(bound)));
        int32_t y = static_cast<int32_t>(rng_.next(static_cast<uint64_t>(bound)));
        list_add(out.as<ListObj>(), make_position(x, y));
      }
      return out;
    }
    case Builtin::AllPositions: {
      if (a.size() < 1 || a.size() > 2) fail("allPositions takes 1 or 2 arguments");
      int32_t w = a.num(0);
      if (w < 0) fail("allPositions: negative size");
      int32_t h = w;
      if (a.size() == 2) {
        h = a.num(1);
        if (h < 0) fail("allPositions: negative size");
      }
      check_length(static_cast<int64_t>(w) * h);
      Value out = make_empty_list();
      for (int32_t i = 0; i < w; ++i)
        for (int32_t j = 0; j < h; ++j) list_add(out.as<ListObj>(), make_position(i, j));
      return out;
    }
    case Builtin::IsWithinBounds: {
      Value elems = render_value(a[0]);
      int32_t g = grid_size_now();
      for (const Value& r : elems.as<ListObj>()->items) {
        const auto& xy = r.as<InstanceObj>()->fields[0].as<InstanceObj>()->fields;
        if (xy[0].num < 0 || xy[0].num >= g || xy[1].num < 0 || xy[1].num >= g) return Value::boolean(false);
      }
      return Value::boolean(true);
    }
    case Builtin::UniformChoice: {
      if (a.size() == 0) fail("uniformChoice needs a list");
      ListObj* l = a.list(0);
      if (l->items.empty()) fail("uniformChoice of an empty list");
      if (a.size() == 1) return l->items[rng_.next(l->items.size())];
      int32_t count = a.num(1);
      if (count < 1) fail("uniformChoice: the count must be at least 1");
      check_length(count);
      Value out = make_empty_list();
      std::vector<Value> items = l->items;
      for (int32_t i = 0; i < count; ++i) list_add(out.as<ListObj>(), items[rng_.next(items.size())]);
      return out;
    }
    default: break;
  }
  fail("unknown builtin");
}

// Objects and the state: adding, removing, rotating, every object, renderAll.
Value Interpreter::builtin_objects(Builtin b, BuiltinArgs& a) {
  switch (b) {
    case Builtin::AddObj: {
      ListObj* l = a.list(0);
      if (!a[1].is(VKind::Instance) && !a[1].is(VKind::List))
        fail("addObj: the second argument must be an object or a list, got " + shown_type(type_string(type_of(a[1]))));
      const size_t added = a[1].is(VKind::Instance) ? 1 : a[1].as<ListObj>()->items.size();
      check_length(static_cast<int64_t>(l->items.size() + added));
      Value out = copy_value(a[0]);  // every existing element is copied (fresh ids)
      if (a[1].is(VKind::Instance)) {
        list_add(out.as<ListObj>(), a[1]);
      } else {
        for (const Value& x : a[1].as<ListObj>()->items) append(out.as<ListObj>(), x);
      }
      return out;
    }
    case Builtin::RemoveObj: return builtin_remove_obj(a);
    case Builtin::Rotate: return builtin_rotate(a);
    case Builtin::AllObjs: return all_objs();
    case Builtin::RenderAll: {
      Value out = make_empty_list();
      std::vector<Sym> order = definition_order_;
      for (Sym s : order) {
        if (!gdefined_[s]) continue;
        Value r = render_value(gvalues_[s]);
        for (const Value& e : r.as<ListObj>()->items) append(out.as<ListObj>(), e);
      }
      Ref<Scope> saved = env_;
      env_ = global_;
      assign(names_.cacheRendered, out);
      env_ = saved;
      return out;
    }
    default: break;
  }
  fail("unknown builtin");
}

// rotate: every cell of the object's construction turns (x, y) -> (-y, x).
Value Interpreter::builtin_rotate(BuiltinArgs& a) {
  if (!a[0].is(VKind::Instance)) fail("rotate: the argument must be an object");
  Value copy = copy_value(a[0]);
  InstanceObj* in = copy.as<InstanceObj>();
  int ei = in->cls->field_index(names_.elems);
  if (ei < 0) fail("rotate: the object has no cells");
  if (!in->fields[ei].is(VKind::List)) fail("rotate: elems is not a list");
  // The cells are shared with every object derived from the same construction:
  // all of them turn (x, y) -> (-y, x).
  for (const Value& cell : in->fields[ei].as<ListObj>()->items) {
    if (!cell.is(VKind::Instance)) fail("rotate: elems must hold cells");
    InstanceObj* c = cell.as<InstanceObj>();
    int xi = c->cls->field_index(names_.x), yi = c->cls->field_index(names_.y);
    if (xi < 0 || yi < 0 || !c->fields[xi].is(VKind::Deferred) || !c->fields[yi].is(VKind::Deferred))
      fail("rotate: cells must have x and y expressions");
    Value old_x = c->fields[xi];
    DeferredObj* xd = old_x.as<DeferredObj>();
    DeferredObj* yd = c->fields[yi].as<DeferredObj>();
    // A turn adds one to one coordinate's nesting: the two together are the
    // cell's turns so far, the count the compiled engine keeps per group.
    if (xd->turns + yd->turns >= limits::kMaxRotations) fail(limits::rotation_nesting_error());
    Expr neg{ExprKind::Unary, yd->expr->loc};
    neg.unary = UnOp::Neg;
    neg.text = "-";
    neg.kids = {yd->expr};
    DeferredObj* nx = new DeferredObj;
    nx->id = next_id();
    nx->expr = make_expr(std::move(neg));
    nx->env = xd->env;
    nx->turns = yd->turns + 1;
    c->fields[xi] = Value::heap(VKind::Deferred, nx);
    c->fields[yi] = old_x;
  }
  return copy;
}

// removeObj: one argument erases the global holding that object; two filter a list.
Value Interpreter::builtin_remove_obj(BuiltinArgs& a) {
  if (a.size() == 0) fail("removeObj needs an argument (the reference interpreter crashes here)");
  if (a.size() == 1) {
    // Erases the first global (in map order) holding this very object.
    if (a[0].is_heap()) {
      int id = a[0].obj->id;
      int victim = -1;
      gorder_.for_each([&](int s) {
        if (victim < 0 && gvalues_[s].is_heap() && gvalues_[s].obj->id == id) victim = s;
      });
      if (victim >= 0) erase_global(victim);
    }
    return a[0];
  }
  if (a.size() > 2) fail("removeObj takes 1 or 2 arguments, got " + std::to_string(a.size()));
  const Value& what = a[1];
  if (!what.is(VKind::Function) && !what.is(VKind::Instance) && !what.is(VKind::List))
    fail("removeObj: the second argument must be a function, an object or a list");
  ListObj* l = a.list(0);
  std::vector<Value> items = l->items;
  std::vector<Value> kept;
  if (what.is(VKind::Function)) {
    for (const Value& x : items)
      if (!truthy(call1(what, x))) kept.push_back(x);
  } else if (what.is(VKind::Instance)) {
    int id = what.obj->id;
    for (const Value& x : items)
      if (!(x.is_heap() && x.obj->id == id)) kept.push_back(x);
  } else {
    std::unordered_set<int> ids;
    for (const Value& x : what.as<ListObj>()->items)
      if (x.is_heap()) ids.insert(x.obj->id);
    for (const Value& x : items)
      if (!(x.is_heap() && ids.count(x.obj->id))) kept.push_back(x);
  }
  count_cells(static_cast<int64_t>(kept.size()));
  return make_list(std::move(kept));
}

// What the step reads from the host and the state (inputs, definedness, prev),
// and the arithmetic and printing the reference puts among its builtins.
Value Interpreter::builtin_host(Builtin b, BuiltinArgs& a) {
  switch (b) {
    case Builtin::Clicked: {
      if (!click_) return Value::boolean(false);
      define_global(names_.click, make_position(click_x_, click_y_));
      if (a.size() == 0) return Value::boolean(true);
      if (a.size() > 1) fail("clicked takes 0 or 1 arguments, got " + std::to_string(a.size()));
      Value elems = render_value(a[0]);
      for (const Value& r : elems.as<ListObj>()->items) {
        const Value& pos = r.as<InstanceObj>()->fields[0];
        const auto& xy = pos.as<InstanceObj>()->fields;
        if (xy[0].num == click_x_ && xy[1].num == click_y_) return Value::boolean(true);
      }
      return Value::boolean(false);
    }
    case Builtin::Left: return Value::boolean(left_);
    case Builtin::Right: return Value::boolean(right_);
    case Builtin::Up: return Value::boolean(up_);
    case Builtin::Down: return Value::boolean(down_);
    case Builtin::Defined: {
      if (!a[0].is(VKind::String)) fail("defined: the argument must be a string");
      std::string nm = *a[0].str;
      if (!nm.empty() && nm[0] == '"') nm = nm.substr(1, nm.size() - 2);
      Sym s = program_->symbols.find(nm);
      return Value::boolean(s >= 0 && gdefined_[s]);
    }
    case Builtin::Prev: return builtin_prev(a[0]);
    case Builtin::Sqrt: {
      int32_t v = a.num(0);
      if (v < 0) fail("sqrt of a negative number");
      return Value::number(static_cast<int32_t>(std::sqrt(static_cast<double>(v))));
    }
    case Builtin::Print: return a[0];
    default: break;
  }
  fail("unknown builtin");
}

}  // namespace autumn::interp
