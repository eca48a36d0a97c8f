// builtins — the native functions of the reference interpreter, and rendering.
//
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

Value Interpreter::call_builtin(Builtin b, std::vector<Value>& args) {
  const char* const name = builtin_name(b);  // for error messages only
  const size_t n = args.size();
  // A builtin of one argument count: checked here, from the table, before its case.
  if (std::string why = builtin_arity_error(b, n); !why.empty()) fail(why);
  auto list_arg = [&](size_t i) -> ListObj* {
    if (!args[i].is(VKind::List))
      fail(std::string(name) + ": argument " + std::to_string(i + 1) + " must be a list, got " +
           shown_type(type_string(type_of(args[i]))));
    return args[i].as<ListObj>();
  };
  auto func_arg = [&](size_t i) -> const Value& {
    if (!args[i].is(VKind::Function))
      fail(std::string(name) + ": argument " + std::to_string(i + 1) + " must be a function, got " +
           shown_type(type_string(type_of(args[i]))));
    return args[i];
  };
  auto num_arg = [&](size_t i) -> int32_t {
    if (!args[i].is(VKind::Number))
      fail(std::string(name) + ": argument " + std::to_string(i + 1) + " must be a number, got " +
           shown_type(type_string(type_of(args[i]))));
    return args[i].num;
  };
  auto call1 = [&](const Value& f, const Value& x) {
    std::vector<Value> a{x};
    return call_function(f, a);
  };
  auto grid_size = [&]() -> int32_t {
    Value* g = lookup(names_.GRID_SIZE);
    if (!g) fail("GRID_SIZE is not defined");
    if (!g->is(VKind::Number)) fail("GRID_SIZE must be a number");
    return g->num;
  };

  switch (b) {
    case Builtin::Map: {
      const Value& f = func_arg(0);
      ListObj* l = list_arg(1);
      Value out = make_empty_list();
      std::vector<Value> items = l->items;  // the callback may not change what we iterate
      for (const Value& x : items) append(out.as<ListObj>(), call1(f, x));
      return out;
    }
    case Builtin::Filter: {
      const Value& f = func_arg(0);
      ListObj* l = list_arg(1);
      Value out = make_empty_list();
      std::vector<Value> items = l->items;
      for (const Value& x : items)
        if (truthy(call1(f, x))) list_add(out.as<ListObj>(), x);
      return out;
    }
    case Builtin::Foldl: {
      const Value& f = func_arg(0);
      Value acc = args[1];
      ListObj* l = list_arg(2);
      std::vector<Value> items = l->items;
      for (const Value& x : items) {
        std::vector<Value> a{acc, x};
        acc = call_function(f, a);
      }
      return acc;
    }
    case Builtin::Concat: {
      ListObj* l = list_arg(0);
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
    case Builtin::Length: return Value::number(static_cast<int32_t>(list_arg(0)->items.size()));
    case Builtin::Head: {
      ListObj* l = list_arg(0);
      if (l->items.empty()) fail("head of an empty list");
      return l->items.front();
    }
    case Builtin::Tail: {  // the *last* element, as in the reference
      ListObj* l = list_arg(0);
      if (l->items.empty()) fail("tail of an empty list");
      return l->items.back();
    }
    case Builtin::At: {
      ListObj* l = list_arg(0);
      if (l->items.empty()) fail("at: empty list");
      int32_t i = num_arg(1);
      if (i < 0 || static_cast<size_t>(i) >= l->items.size()) fail("at: index " + std::to_string(i) + " out of bounds");
      return l->items[i];
    }
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
    case Builtin::Defined: {
      if (!args[0].is(VKind::String)) fail("defined: the argument must be a string");
      std::string nm = *args[0].str;
      if (!nm.empty() && nm[0] == '"') nm = nm.substr(1, nm.size() - 2);
      Sym s = program_->symbols.find(nm);
      return Value::boolean(s >= 0 && gdefined_[s]);
    }
    case Builtin::ArrayEqual: {
      ListObj* a = list_arg(0);
      ListObj* c = list_arg(1);
      if (a->items.size() != c->items.size()) fail("arrayEqual: lists of different lengths");
      Value out = make_empty_list();
      for (size_t i = 0; i < a->items.size(); ++i)
        list_add(out.as<ListObj>(), Value::boolean(equals(a->items[i], c->items[i])));
      return out;
    }
    case Builtin::Sqrt: {
      int32_t v = num_arg(0);
      if (v < 0) fail("sqrt of a negative number");
      return Value::number(static_cast<int32_t>(std::sqrt(static_cast<double>(v))));
    }
    case Builtin::Prev: return builtin_prev(args[0]);
    case Builtin::Any: {
      if (n != 1 && n != 2) fail("any takes 1 or 2 arguments, got " + std::to_string(n));
      if (n == 2) func_arg(0);
      ListObj* l = list_arg(n - 1);
      std::vector<Value> items = l->items;
      for (const Value& x : items)
        if (truthy(n == 2 ? call1(args[0], x) : x)) return Value::boolean(true);
      return Value::boolean(false);
    }
    case Builtin::IsList: return Value::boolean(args[0].is(VKind::List));
    case Builtin::UniformChoice: {
      if (n == 0) fail("uniformChoice needs a list");
      ListObj* l = list_arg(0);
      if (l->items.empty()) fail("uniformChoice of an empty list");
      if (n == 1) return l->items[rng_.next(l->items.size())];
      int32_t count = num_arg(1);
      if (count < 1) fail("uniformChoice: the count must be at least 1");
      check_length(count);
      Value out = make_empty_list();
      std::vector<Value> items = l->items;
      for (int32_t i = 0; i < count; ++i) list_add(out.as<ListObj>(), items[rng_.next(items.size())]);
      return out;
    }
    case Builtin::AdjPositions: {
      if (!args[0].is(VKind::Instance) || args[0].as<InstanceObj>()->cls != c_position_)
        fail("adjPositions: the argument must be a Position");
      const auto& f = args[0].as<InstanceObj>()->fields;
      int32_t x = f[0].num, y = f[1].num;
      int32_t g = grid_size();
      std::vector<Value> out;
      const int32_t cand[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
      for (auto& c : cand)
        if (c[0] >= 0 && c[0] < g && c[1] >= 0 && c[1] < g) out.push_back(make_position(c[0], c[1]));
      count_cells(static_cast<int64_t>(out.size()));
      return make_list(std::move(out));
    }
    case Builtin::AddObj: {
      ListObj* l = list_arg(0);
      if (!args[1].is(VKind::Instance) && !args[1].is(VKind::List))
        fail("addObj: the second argument must be an object or a list, got " + shown_type(type_string(type_of(args[1]))));
      const size_t added = args[1].is(VKind::Instance) ? 1 : args[1].as<ListObj>()->items.size();
      check_length(static_cast<int64_t>(l->items.size() + added));
      Value out = copy_value(args[0]);  // every existing element is copied (fresh ids)
      if (args[1].is(VKind::Instance)) {
        list_add(out.as<ListObj>(), args[1]);
      } else {
        for (const Value& x : args[1].as<ListObj>()->items) append(out.as<ListObj>(), x);
      }
      return out;
    }
    case Builtin::IsFreePos: {
      if (!args[0].is(VKind::Instance) || args[0].as<InstanceObj>()->cls != c_position_)
        fail("isFreePos: the argument must be a Position");
      const auto& f = args[0].as<InstanceObj>()->fields;
      if (!f[0].is(VKind::Number) || !f[1].is(VKind::Number)) fail("isFreePos: non-numeric position");
      return Value::boolean(!occupied_.count(pos_key(f[0].num, f[1].num)));
    }
    case Builtin::Range: {
      int32_t a = num_arg(0), c = num_arg(1);
      check_length(static_cast<int64_t>(c) - a);
      Value out = make_empty_list();
      for (int32_t i = a; i < c; ++i) list_add(out.as<ListObj>(), Value::number(i));
      return out;
    }
    case Builtin::Print: return args[0];
    case Builtin::RemoveObj: {
      if (n == 0) fail("removeObj needs an argument (the reference interpreter crashes here)");
      if (n == 1) {
        // Erases the first global (in map order) holding this very object.
        if (args[0].is_heap()) {
          int id = args[0].obj->id;
          int victim = -1;
          gorder_.for_each([&](int s) {
            if (victim < 0 && gvalues_[s].is_heap() && gvalues_[s].obj->id == id) victim = s;
          });
          if (victim >= 0) erase_global(victim);
        }
        return args[0];
      }
      if (n > 2) fail("removeObj takes 1 or 2 arguments, got " + std::to_string(n));
      const Value& what = args[1];
      if (!what.is(VKind::Function) && !what.is(VKind::Instance) && !what.is(VKind::List))
        fail("removeObj: the second argument must be a function, an object or a list");
      ListObj* l = list_arg(0);
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
    case Builtin::UpdateObj: {
      if (n < 2 || n > 3) fail("updateObj takes 2 or 3 arguments, got " + std::to_string(n));
      if (args[0].is(VKind::List)) {
        if (n == 2) {
          std::vector<Value> a{args[1], args[0]};
          return call_builtin(Builtin::Map, a);
        }
        if (!args[1].is(VKind::Function) || !args[2].is(VKind::Function))
          fail("updateObj: the second and third arguments must be functions");
        Value out = make_empty_list();
        std::vector<Value> items = args[0].as<ListObj>()->items;
        for (const Value& x : items) {
          if (truthy(call1(args[2], x))) list_add(out.as<ListObj>(), call1(args[1], x));
          else list_add(out.as<ListObj>(), x);
        }
        return out;
      }
      if (!args[0].is(VKind::Instance)) fail("updateObj: the first argument must be an object or a list");
      if (n == 3) {
        Value copy = copy_value(args[0]);
        if (!args[1].is(VKind::String)) fail("updateObj: the field name must be a string");
        std::string field = *args[1].str;
        if (!field.empty() && (field[0] == '"' || field[0] == '\'')) field = field.substr(1, field.size() - 2);
        InstanceObj* in = copy.as<InstanceObj>();
        Sym s = program_->symbols.find(field);
        int i = s < 0 ? -1 : in->cls->field_index(s);
        if (i < 0) fail("updateObj: object of class '" + in->cls->name + "' has no field '" + field + "'");
        in->fields[i] = args[2];
        return copy;
      }
      return call1(func_arg(1), args[0]);
    }
    case Builtin::RandomPositions: {
      int32_t bound = num_arg(0);
      if (bound < 0) fail("randomPositions: the grid size must not be negative");
      int32_t count = num_arg(1);
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
      if (n < 1 || n > 2) fail("allPositions takes 1 or 2 arguments");
      int32_t w = num_arg(0);
      if (w < 0) fail("allPositions: negative size");
      int32_t h = w;
      if (n == 2) {
        h = num_arg(1);
        if (h < 0) fail("allPositions: negative size");
      }
      check_length(static_cast<int64_t>(w) * h);
      Value out = make_empty_list();
      for (int32_t i = 0; i < w; ++i)
        for (int32_t j = 0; j < h; ++j) list_add(out.as<ListObj>(), make_position(i, j));
      return out;
    }
    case Builtin::Clicked: {
      if (!click_) return Value::boolean(false);
      define_global(names_.click, make_position(click_x_, click_y_));
      if (n == 0) return Value::boolean(true);
      if (n > 1) fail("clicked takes 0 or 1 arguments, got " + std::to_string(n));
      Value elems = render_value(args[0]);
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
    case Builtin::IsWithinBounds: {
      Value elems = render_value(args[0]);
      int32_t g = grid_size();
      for (const Value& r : elems.as<ListObj>()->items) {
        const auto& xy = r.as<InstanceObj>()->fields[0].as<InstanceObj>()->fields;
        if (xy[0].num < 0 || xy[0].num >= g || xy[1].num < 0 || xy[1].num >= g) return Value::boolean(false);
      }
      return Value::boolean(true);
    }
    case Builtin::AllObjs: return all_objs();
    case Builtin::Rotate: {
      if (!args[0].is(VKind::Instance)) fail("rotate: the argument must be an object");
      Value copy = copy_value(args[0]);
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
  }
  fail("unknown builtin");
}

}  // namespace autumn::interp
