// values — construction, copying, type strings, printed forms and equality.
//
// Printed forms matter because list equality compares them (tag included), and
// type strings matter because assignment and construction compare them. Both
// follow the reference's formats; see docs/autumn-semantics.md §3.
#include "compiler/interpret/interpreter.hpp"
#include "compiler/parse/ast_print.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::interp {

void DeferredObj::release_children(Dying& dying) { env.release_into(dying); }

TypeRef Interpreter::make_type(TypeKind k, TypeRef elem) {
  Ref<TypeObj> t(new TypeObj);
  t->kind = k;
  t->elem = std::move(elem);
  return t;
}

TypeRef Interpreter::make_class(const std::string& name, std::vector<Sym> field_syms,
                                std::vector<std::string> field_names, std::vector<TypeRef> field_types) {
  TypeRef t = make_type(TypeKind::Class);
  t->name = name;
  t->field_syms = std::move(field_syms);
  t->field_names = std::move(field_names);
  t->field_types = std::move(field_types);
  classes_.push_back(t);
  return t;
}

Value Interpreter::make_function(FuncObj::Kind kind, Builtin b, const Expr* lambda, TypeObj* cls) {
  FuncObj* f = new FuncObj;
  f->id = next_id();
  f->kind = kind;
  f->builtin = b;
  f->lambda = lambda;
  f->cls = cls;
  return Value::heap(VKind::Function, f);
}

TypeObj* Interpreter::type_of(const Value& v) {
  switch (v.kind) {
    case VKind::Number: return t_number_.get();
    case VKind::Bool: return t_bool_.get();
    case VKind::String: return t_string_.get();
    case VKind::List: return v.as<ListObj>()->tag.get();
    case VKind::Instance: return v.as<InstanceObj>()->cls.get();
    case VKind::Function: return t_func_.get();
    case VKind::Deferred: return t_expr_.get();
    default: return t_unknown_.get();
  }
}

const std::string& Interpreter::type_string(TypeObj* t) {
  if (t->str_ready) return t->cached_str;
  Nest nest(value_depth_);
  check_value_depth();
  std::string s;
  switch (t->kind) {
    case TypeKind::Number: s = "Number"; break;
    case TypeKind::String: s = "String"; break;
    case TypeKind::Bool: s = "Bool"; break;
    case TypeKind::Unknown: s = "Unknown"; break;
    case TypeKind::Func: s = "AutumnFunc"; break;
    case TypeKind::Expr: s = "Expr"; break;
    case TypeKind::List: s = "List<" + type_string(t->elem.get()) + ">"; break;
    case TypeKind::Class:
      s = "class " + t->name + " {";
      for (size_t i = 0; i < t->field_types.size(); ++i) {
        if (!t->field_types[i])
          fail("class '" + t->name + "' has field '" + t->field_names[i] +
               "' of an unknown type (the reference interpreter crashes here)");
        s += t->field_names[i] + ": " + type_string(t->field_types[i].get()) + ", ";
      }
      s += "}";
      break;
  }
  t->cached_str = std::move(s);
  t->str_ready = true;
  return t->cached_str;
}

Value Interpreter::make_list(std::vector<Value> items) {
  TypeObj* elem = t_unknown_.get();
  bool mixed = false;
  for (const Value& v : items) {
    TypeObj* t = type_of(v);
    if (t == t_unknown_.get()) continue;
    if (elem == t_unknown_.get()) elem = t;
    else if (elem != t) {
      mixed = true;
      break;
    }
  }
  ListObj* l = new ListObj;
  l->id = next_id();
  l->items = std::move(items);
  l->tag = mixed ? t_unknown_ : make_type(TypeKind::List, TypeRef(elem));
  return Value::heap(VKind::List, l);
}

Value Interpreter::make_empty_list() {
  ListObj* l = new ListObj;
  l->id = next_id();
  l->tag = t_default_list_;
  return Value::heap(VKind::List, l);
}

void Interpreter::list_add(ListObj* list, Value v) {
  check_length(static_cast<int64_t>(list->items.size()) + 1);
  count_cells(1);
  TypeObj* tag = list->tag.get();
  if (tag->kind != TypeKind::List) fail("cannot append to a list of mixed element types");
  TypeObj* elem = tag->elem.get();
  TypeObj* vt = type_of(v);
  if (elem->kind != TypeKind::Unknown && !v.is(VKind::Instance) && type_string(vt) != type_string(elem))
    fail("list element type mismatch: got " + shown_type(type_string(vt)) + ", expected " + shown_type(type_string(elem)));
  list->tag = make_type(TypeKind::List, TypeRef(vt));
  list->items.push_back(std::move(v));
}

Value Interpreter::make_instance(TypeObj* cls, std::vector<Value> fields) {
  if (fields.size() != cls->field_syms.size())
    fail("'" + cls->name + "' takes " + std::to_string(cls->field_syms.size()) + " field value(s), got " +
         std::to_string(fields.size()));
  for (size_t i = 0; i < fields.size(); ++i) {
    TypeObj* decl = cls->field_types[i].get();
    if (!decl) continue;
    const std::string& have = type_string(type_of(fields[i]));
    const std::string& want = type_string(decl);
    if (have != want && have != "List<Unknown>" && want != "List<Unknown>")
      fail("field '" + cls->field_names[i] + "' of '" + cls->name + "' must be " + shown_type(want) + ", got " +
           shown_type(have));
  }
  count_cells(static_cast<int64_t>(fields.size()));
  InstanceObj* in = new InstanceObj;
  in->id = next_id();
  in->cls = TypeRef(cls);
  in->fields = std::move(fields);
  return Value::heap(VKind::Instance, in);
}

Value Interpreter::make_position(int x, int y) {
  return make_instance(c_position_.get(), {Value::number(x), Value::number(y)});
}

Value Interpreter::copy_value(const Value& v) {
  Nest nest(value_depth_);
  check_value_depth();
  switch (v.kind) {
    case VKind::List: {
      count_cells(static_cast<int64_t>(v.as<ListObj>()->items.size()));
      std::vector<Value> items;
      for (const Value& item : v.as<ListObj>()->items) items.push_back(copy_value(item));
      return make_list(std::move(items));
    }
    case VKind::Instance: {
      InstanceObj* in = v.as<InstanceObj>();
      return make_instance(in->cls.get(), in->fields);
    }
    case VKind::Deferred: {
      DeferredObj* d = new DeferredObj;
      d->id = next_id();
      d->expr = v.as<DeferredObj>()->expr;
      d->env = v.as<DeferredObj>()->env;
      d->turns = v.as<DeferredObj>()->turns;
      return Value::heap(VKind::Deferred, d);
    }
    default:
      return v;
  }
}

bool Interpreter::truthy(const Value& v) const {
  switch (v.kind) {
    case VKind::Bool: return v.num != 0;
    case VKind::List: return !v.as<ListObj>()->items.empty();
    case VKind::None: return false;
    default: return true;
  }
}

// ---------------------------------------------------------------------------
// Printed forms

std::string Interpreter::value_string(const Value& v) {
  Nest nest(value_depth_);
  check_value_depth();
  count_cells(1);  // printing is work proportional to the value: budgeted like building it
  switch (v.kind) {
    case VKind::Number: return "(" + std::to_string(v.num) + ": N)";
    case VKind::String: return "(" + *v.str + ": S)";
    case VKind::Bool: return v.num ? "(true: Bool)" : "(false: Bool)";
    case VKind::List: {
      ListObj* l = v.as<ListObj>();
      std::string s = "([";
      for (size_t i = 0; i < l->items.size(); ++i) {
        if (i) s += ", ";
        s += value_string(l->items[i]);
      }
      return s + "] :" + type_string(l->tag.get()) + ")";
    }
    case VKind::Instance: {
      // The reference appends a description of the class's render method, bound
      // to whichever instance fetched it last. It is the same text for every
      // instance of a class at any one moment, so it never decides an equality,
      // and it is left out here.
      InstanceObj* in = v.as<InstanceObj>();
      TypeObj* cls = in->cls.get();
      std::string s = cls->name + "{";
      for (size_t i = 0; i < in->fields.size(); ++i) {
        TypeObj* decl = cls->field_types[i].get();
        const std::string& have = type_string(type_of(in->fields[i]));
        if (!decl) type_string(cls);  // fails: unknown field type
        const std::string& want = type_string(decl);
        if (have != want && want != "List<Unknown>" && have != "List<Unknown>")
          fail("field '" + cls->field_names[i] + "' of '" + cls->name + "' holds a " + shown_type(have) +
               " where " + shown_type(want) + " was declared");
        s += (i ? "," : "") + cls->field_names[i] + ": " + value_string(in->fields[i]);
      }
      if (in->fields.empty()) s += "None";
      return s + "}";
    }
    case VKind::Function: {
      FuncObj* f = v.as<FuncObj>();
      if (f->kind == FuncObj::Kind::Lambda) {
        std::string s;
        s = ast_to_string(program_->symbols, *f->lambda);
        return "<native fn: " + s + ">";
      }
      if (f->kind == FuncObj::Kind::Method) return "<method: >";
      return "<native fn: builtin " + std::to_string(static_cast<int>(f->builtin)) + ">";
    }
    case VKind::Deferred: {
      return "(" + ast_to_string(program_->symbols, *v.as<DeferredObj>()->expr) + ": Expr)";
    }
    default: return "null";
  }
}

bool Interpreter::equals(const Value& a, const Value& b) {
  Nest nest(value_depth_);
  check_value_depth();
  switch (a.kind) {
    case VKind::Number:
      if (b.is(VKind::Number)) return a.num == b.num;
      if (b.is(VKind::Bool)) return a.num == (b.num ? 1 : 0);  // asymmetric, as in the reference
      return false;
    case VKind::String: return b.is(VKind::String) && *a.str == *b.str;
    case VKind::Bool: return b.is(VKind::Bool) && a.num == b.num;
    case VKind::List: return b.is(VKind::List) && value_string(a) == value_string(b);
    case VKind::Instance: {
      if (!b.is(VKind::Instance)) return false;
      InstanceObj* x = a.as<InstanceObj>();
      InstanceObj* y = b.as<InstanceObj>();
      TypeObj* cx = x->cls.get();
      TypeObj* cy = y->cls.get();
      if (cx->field_syms.size() != cy->field_syms.size()) return false;
      for (size_t i = 0; i < cx->field_syms.size(); ++i) {
        int j = cy->field_index(cx->field_syms[i]);
        if (j < 0) return false;
        if (!equals(x->fields[i], y->fields[j])) return false;
      }
      return true;
    }
    case VKind::Function: return b.is(VKind::Function) && a.obj.get() == b.obj.get();
    case VKind::Deferred:
      return b.is(VKind::Deferred) && a.as<DeferredObj>()->expr.get() == b.as<DeferredObj>()->expr.get();
    default: return false;
  }
}

}  // namespace autumn::interp
