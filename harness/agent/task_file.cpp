#include "harness/agent/task_file.hpp"

#include <fmt/core.h>

#include <climits>
#include <fstream>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <sstream>
#include <unordered_map>

#include "harness/engine.hpp"
#include "harness/trace_check.hpp"
#include "runtime/diagnostic.hpp"

namespace autumn::agent {

using nlohmann::json;

namespace {

const char* const kAutumnBenchColours[] = {
    "transparent", "black",     "gray",      "grey",      "gold",     "green",         "mediumpurple",
    "purple",      "white",     "yellow",    "blue",      "red",      "orange",        "sandybrown",
    "brown",       "pink",      "lightblue", "orangered", "skyblue",  "lightcyan",     "lightgreen",
    "magenta",     "darkgray",  "darkgrey",  "darkblue",  "darkgreen", "darkred",      "tan",
    "lightpink",   "crimson",   "goldenrod", "steelblue", "coral",    "silver",        "seagreen",
    "limegreen",   "cyan",      "lightgray", "maroon",    "darkorange"};

std::string trim(std::string_view s) {
  size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return "";
  size_t e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

std::string read_file(const fs::path& p) {
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw TaskError(p.string() + ": is a folder, not a file");
  std::ifstream in(p, std::ios::binary);
  if (!in) throw TaskError(p.string() + ": cannot open file");
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

}  // namespace

// ---------------------------------------------------------------------------- colours

struct ColourTable::Impl {
  std::vector<std::string> names;  // table ids ("" for holes)
  std::unordered_map<std::string, int> ids;
  fs::path source;
  mutable std::shared_mutex mu;  // guards the interned extension below
  mutable std::vector<std::string> extra;
  mutable std::unordered_map<std::string, int> extra_ids;

  void set(int id, const std::string& name) {
    if (static_cast<size_t>(id) >= names.size()) names.resize(id + 1);
    names[id] = name;
    ids.emplace(name, id);
  }
};

std::string one_line(std::string_view message) {
  const std::string s = shown(message);
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    if (c == '\n') out += "\\n";
    else out += c;
  }
  return out;
}

ColourTable::ColourTable() : impl_(std::make_shared<Impl>()) {
  int id = 0;
  for (const char* n : kAutumnBenchColours) impl_->set(id++, n);
}

ColourTable ColourTable::from_yaml(std::string_view text, const std::string& where) {
  ColourTable t;
  t.impl_ = std::make_shared<Impl>();
  std::istringstream in{std::string(text)};
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    std::string l = trim(line);
    if (l.empty() || l[0] == '#') continue;
    size_t colon = l.find(':');
    if (colon == std::string::npos) throw TaskError(fmt::format("{}:{}: expected 'ID: name'", where, line_no));
    std::string key = trim(l.substr(0, colon));
    std::string value = trim(l.substr(colon + 1));
    if (size_t hash = value.find(" #"); hash != std::string::npos) value = trim(value.substr(0, hash));
    if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') && value.back() == value.front())
      value = value.substr(1, value.size() - 2);
    int id = -1;
    try {
      size_t used = 0;
      id = std::stoi(key, &used);
      if (used != key.size()) id = -1;
    } catch (const std::exception&) {
      id = -1;
    }
    if (id < 0 || id > 4095) throw TaskError(fmt::format("{}:{}: bad colour id '{}'", where, line_no, key));
    if (static_cast<size_t>(id) < t.impl_->names.size() && !t.impl_->names[id].empty())
      throw TaskError(fmt::format("{}:{}: colour id {} defined twice", where, line_no, id));
    if (value.empty()) throw TaskError(fmt::format("{}:{}: colour {} has no name", where, line_no, id));
    t.impl_->set(id, lower_ascii(value));
  }
  if (t.impl_->names.empty()) throw TaskError(where + ": no colours");
  return t;
}

ColourTable ColourTable::load(const fs::path& yaml) {
  ColourTable t = from_yaml(read_file(yaml), yaml.string());
  t.impl_->source = yaml;
  return t;
}

ColourTable ColourTable::for_task(const fs::path& task_file) {
  fs::path dir = task_file.parent_path();
  for (const fs::path& d : {dir, dir.parent_path()}) {
    fs::path p = (d.empty() ? fs::path(".") : d) / "color_dict.yaml";
    if (fs::exists(p)) return load(p);
  }
  return ColourTable();
}

int ColourTable::table_size() const { return static_cast<int>(impl_->names.size()); }

bool ColourTable::in_table(int id) const {
  return id >= 0 && id < table_size() && !impl_->names[id].empty();
}

int ColourTable::find(std::string_view name) const {
  auto it = impl_->ids.find(std::string(name));
  return it == impl_->ids.end() ? -1 : it->second;
}

std::string ColourTable::name(int id) const {
  if (in_table(id)) return impl_->names[id];
  std::shared_lock lock(impl_->mu);
  size_t k = static_cast<size_t>(id - table_size());
  if (id >= table_size() && k < impl_->extra.size()) return impl_->extra[k];
  return "?";
}

int ColourTable::frame_id(std::string_view name) const {
  std::string key(name);
  if (auto it = impl_->ids.find(key); it != impl_->ids.end()) return it->second;
  {
    std::shared_lock lock(impl_->mu);
    if (auto it = impl_->extra_ids.find(key); it != impl_->extra_ids.end()) return it->second;
  }
  std::unique_lock lock(impl_->mu);
  if (auto it = impl_->extra_ids.find(key); it != impl_->extra_ids.end()) return it->second;
  int id = table_size() + static_cast<int>(impl_->extra.size());
  impl_->extra.push_back(key);
  impl_->extra_ids.emplace(key, id);
  return id;
}

int ColourTable::add(const std::string& name) {
  if (int id = find(name); id >= 0) return id;
  // Interned ids are relative to the table size: drop them rather than renumber.
  auto fresh = std::make_shared<Impl>();
  fresh->names = impl_->names;
  fresh->ids = impl_->ids;
  fresh->source = impl_->source;
  impl_ = fresh;
  int id = table_size();
  impl_->set(id, name);
  return id;
}

std::string ColourTable::to_yaml() const {
  std::string out;
  for (int i = 0; i < table_size(); ++i)
    if (in_table(i)) out += fmt::format("{}: {}\n", i, impl_->names[i]);
  return out;
}

const fs::path& ColourTable::source() const { return impl_->source; }

std::vector<int16_t> colour_ids(const Palette& p, const ColourTable& colours) {
  std::vector<int16_t> map(p.size());
  for (size_t i = 0; i < p.size(); ++i) map[i] = static_cast<int16_t>(colours.frame_id(p.name(static_cast<uint16_t>(i))));
  return map;
}

TaskFrame task_frame(const Frame& f, const Palette& p, const ColourTable& colours) {
  const std::vector<int16_t> map = colour_ids(p, colours);
  TaskFrame out(f.cells.size());
  for (size_t i = 0; i < f.cells.size(); ++i) out[i] = map[f.cells[i]];
  return out;
}

uint64_t frame_digest(const TaskFrame& f) {
  uint64_t h = 1469598103934665603ull;
  for (int16_t c : f) h = (h ^ static_cast<uint16_t>(c)) * 1099511628211ull;
  return h;
}

// ---------------------------------------------------------------------------- grids

json Grid::to_json() const {
  json rows = json::array();
  for (int y = 0; y < height; ++y) {
    json row = json::array();
    for (int x = 0; x < width; ++x) row.push_back(at(x, y));
    rows.push_back(row);
  }
  return rows;
}

Grid crop(const TaskFrame& frame, int size, const Rect& r) {
  Grid g;
  g.width = r.w;
  g.height = r.h;
  g.cells.reserve(static_cast<size_t>(r.w) * r.h);
  for (int y = r.y; y < r.y + r.h; ++y)
    for (int x = r.x; x < r.x + r.w; ++x) g.cells.push_back(frame[static_cast<size_t>(y) * size + x]);
  return g;
}

bool consistent(const TaskFrame& frame, int size, const Grid& obs) {
  if (obs.width != size || obs.height != size || frame.size() != obs.cells.size()) return false;
  for (size_t i = 0; i < frame.size(); ++i)
    if (obs.cells[i] != 0 && obs.cells[i] != frame[i]) return false;
  return true;
}

namespace {

Grid parse_grid(const json& j, const std::string& where, const ColourTable& colours, bool binary = false) {
  if (!j.is_array() || j.empty()) throw TaskError(where + ": expected a non-empty array of rows");
  Grid g;
  g.height = static_cast<int>(j.size());
  for (size_t y = 0; y < j.size(); ++y) {
    const json& row = j[y];
    if (!row.is_array() || row.empty()) throw TaskError(fmt::format("{}: row {} is not a non-empty array", where, y));
    if (y == 0) g.width = static_cast<int>(row.size());
    if (static_cast<int>(row.size()) != g.width)
      throw TaskError(fmt::format("{}: row {} has {} cells, row 0 has {}", where, y, row.size(), g.width));
    for (size_t x = 0; x < row.size(); ++x) {
      if (!row[x].is_number_integer())
        throw TaskError(fmt::format("{}: cell [{}][{}] is not an integer", where, y, x));
      int64_t v = row[x].get<int64_t>();
      if (binary ? (v != 0 && v != 1) : !colours.in_table(static_cast<int>(std::clamp<int64_t>(v, -1, 1 << 20))))
        throw TaskError(fmt::format("{}: cell [{}][{}] = {} is not {}", where, y, x, v,
                                    binary ? "0 or 1" : "a colour id of the colour table"));
      g.cells.push_back(static_cast<int16_t>(v));
    }
  }
  return g;
}

const json& field(const json& j, const char* key, const std::string& where) {
  auto it = j.find(key);
  if (it == j.end()) throw TaskError(fmt::format("{}: missing field \"{}\"", where, key));
  return *it;
}

// A JSON integer that fits an int; nullopt for anything else (a float, a
// string, or an integer out of range, which get<int>() would wrap silently).
std::optional<int> as_int(const json& v) {
  if (v.is_number_unsigned()) {
    const uint64_t u = v.get<uint64_t>();
    return u <= static_cast<uint64_t>(INT_MAX) ? std::optional<int>(static_cast<int>(u)) : std::nullopt;
  }
  if (!v.is_number_integer()) return std::nullopt;
  const int64_t i = v.get<int64_t>();
  return i >= INT_MIN && i <= INT_MAX ? std::optional<int>(static_cast<int>(i)) : std::nullopt;
}

std::string string_field(const json& j, const char* key, const std::string& where) {
  const json& v = field(j, key, where);
  if (!v.is_string() || v.get<std::string>().empty())
    throw TaskError(fmt::format("{}: field \"{}\" must be a non-empty string", where, key));
  return v.get<std::string>();
}

}  // namespace

json action_to_json(const Action& a) {
  switch (a.kind) {
    case Action::Kind::Noop: return {{"type", "noop"}};
    case Action::Kind::Left: return {{"type", "left"}};
    case Action::Kind::Right: return {{"type", "right"}};
    case Action::Kind::Up: return {{"type", "up"}};
    case Action::Kind::Down: return {{"type", "down"}};
    case Action::Kind::Click: return {{"type", "click"}, {"x", a.x}, {"y", a.y}};
  }
  return {{"type", "noop"}};
}

Action action_from_json(const json& j, const std::string& where) {
  std::string why;
  if (j.is_string()) {
    auto a = parse_action(j.get<std::string>(), &why);
    if (!a) throw TaskError(where + ": " + why);
    return *a;
  }
  if (!j.is_object()) throw TaskError(where + ": expected an action object");
  std::string type = string_field(j, "type", where);
  if (type == "click") {
    const json& x = field(j, "x", where);
    const json& y = field(j, "y", where);
    if (!x.is_number_integer() || !y.is_number_integer())
      throw TaskError(where + ": click coordinates must be integers");
    const std::optional<int> cx = as_int(x), cy = as_int(y);
    if (!cx || !cy) throw TaskError(where + ": click coordinates are out of the 32-bit range");
    return Action::click(*cx, *cy);
  }
  auto a = parse_action(type, &why);
  if (!a || a->kind == Action::Kind::Click) throw TaskError(fmt::format("{}: unknown action type '{}'", where, type));
  return *a;
}

const char* type_name(TaskType t) {
  switch (t) {
    case TaskType::MaskedFramePrediction: return "masked_frame_prediction";
    case TaskType::ChangeDetection: return "change_detection";
    case TaskType::Planning: return "planning";
  }
  return "?";
}

const char* short_name(TaskType t) {
  switch (t) {
    case TaskType::MaskedFramePrediction: return "mfp";
    case TaskType::ChangeDetection: return "cd";
    case TaskType::Planning: return "planning";
  }
  return "?";
}

namespace {

// The observations of a masked-frame-prediction task, and the masked rectangle:
// the bounding box of the hidden cells of the final frame.
void parse_observations(const json& j, const std::string& w, Task& t) {
  const json& obs = field(j, "observations", w);
  if (!obs.is_array() || obs.empty()) throw TaskError(w + ": \"observations\" must be a non-empty array");
  for (size_t i = 0; i < obs.size(); ++i) {
    std::string where = fmt::format("{}: observations[{}]", w, i);
    if (!obs[i].is_object()) throw TaskError(where + ": expected an object");
    Observation o;
    if (i > 0) o.action = action_from_json(field(obs[i], "action", where), where + ".action");
    o.grid = parse_grid(field(obs[i], "masked_grid", where), where + ".masked_grid", t.colours);
    const Grid& first = i == 0 ? o.grid : t.observations[0].grid;
    if (o.grid.width != o.grid.height)
      throw TaskError(fmt::format("{}.masked_grid: grid is {}x{}, frames are square", where, o.grid.width,
                                  o.grid.height));
    if (o.grid.width != first.width)
      throw TaskError(fmt::format("{}.masked_grid: grid is {}x{} but observation 0 is {}x{}", where, o.grid.width,
                                  o.grid.height, first.width, first.height));
    t.observations.push_back(std::move(o));
  }
  const Grid& last = t.observations.back().grid;
  int x0 = last.width, y0 = last.height, x1 = -1, y1 = -1;
  for (int y = 0; y < last.height; ++y)
    for (int x = 0; x < last.width; ++x)
      if (last.at(x, y) == 0) {
        x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
      }
  if (x1 < 0) throw TaskError(w + ": the final observation has no masked cells");
  t.masked = {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

// The choices (each the masked rectangle's size) and the answer, if given.
void parse_choices(const json& j, const std::string& w, Task& t) {
  const json& choices = field(j, "choices", w);
  if (!choices.is_array() || choices.size() < 2) throw TaskError(w + ": \"choices\" must be an array of at least two grids");
  for (size_t i = 0; i < choices.size(); ++i) {
    std::string where = fmt::format("{}: choices[{}]", w, i);
    Grid g = parse_grid(choices[i], where, t.colours);
    if (g.width != t.masked.w || g.height != t.masked.h)
      throw TaskError(fmt::format("{}: choice is {}x{} (width x height) but the masked region is {}x{}", where,
                                  g.width, g.height, t.masked.w, t.masked.h));
    t.choices.push_back(std::move(g));
  }
  for (const char* key : {"answer", "correct_idx"}) {
    auto it = j.find(key);
    if (it == j.end()) continue;
    if (!it->is_number_integer() || it->get<int64_t>() < 0 || it->get<int64_t>() >= static_cast<int64_t>(t.choices.size()))
      throw TaskError(fmt::format("{}: \"{}\" must be a choice index", w, key));
    t.answer = it->get<int>();
    break;
  }
}

// A planning task's goal, its mask and the reference plan, if given.
void parse_goal(const json& j, const std::string& w, Task& t) {
  t.goal = parse_grid(field(j, "goal", w), w + ": goal", t.colours);
  t.mask = parse_grid(field(j, "mask", w), w + ": mask", t.colours, /*binary=*/true);
  if (t.goal.width != t.goal.height)
    throw TaskError(fmt::format("{}: goal is {}x{}, frames are square", w, t.goal.width, t.goal.height));
  if (t.mask.width != t.goal.width || t.mask.height != t.goal.height)
    throw TaskError(fmt::format("{}: mask is {}x{} but goal is {}x{}", w, t.mask.width, t.mask.height, t.goal.width,
                                t.goal.height));
  if (auto it = j.find("reference_plan"); it != j.end()) {
    if (!it->is_array()) throw TaskError(w + ": \"reference_plan\" must be an array of actions");
    for (size_t i = 0; i < it->size(); ++i)
      t.reference_plan.push_back(action_from_json((*it)[i], fmt::format("{}: reference_plan[{}]", w, i)));
  }
}

}  // namespace

Task parse_task(const json& j, const fs::path& file, ColourTable colours) {
  const std::string w = file.filename().string();
  if (!j.is_object()) throw TaskError(w + ": a task file is a JSON object");
  Task t;
  t.file = file;
  t.name = file.stem().string();
  t.colours = std::move(colours);
  std::string type = string_field(j, "type", w);
  if (type == "masked_frame_prediction") t.type = TaskType::MaskedFramePrediction;
  else if (type == "change_detection") t.type = TaskType::ChangeDetection;
  else if (type == "planning") t.type = TaskType::Planning;
  else throw TaskError(fmt::format("{}: unknown task type '{}'", w, type));
  t.program = string_field(j, "program", w);
  if (auto it = j.find("seed"); it != j.end()) {
    if (!it->is_number_unsigned()) throw TaskError(w + ": field \"seed\" must be a non-negative integer");
    t.env_seed = it->get<uint64_t>();
  }
  switch (t.type) {
    case TaskType::MaskedFramePrediction:
      parse_observations(j, w, t);
      parse_choices(j, w, t);
      break;
    case TaskType::ChangeDetection: t.wrong_program = string_field(j, "wrong_program", w); break;
    case TaskType::Planning: parse_goal(j, w, t); break;
  }
  return t;
}

Task load_task(const fs::path& file) {
  std::string text = read_file(file);
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // a syntax error, or a number out of range (1e400)
    throw TaskError(file.filename().string() + ": not valid JSON: " + json_error_text(e));
  }
  return parse_task(j, file, ColourTable::for_task(file));
}

bool meant_as_task(const fs::path& file) {
  if (file.extension() != ".json") return false;
  std::ifstream in(file, std::ios::binary);
  if (!in) return true;  // unreadable: loading it says why
  json j = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return true;  // not valid JSON: loading it says where
  return j.is_object() && j.contains("type");
}

// ---------------------------------------------------------------------------- programs

fs::path default_programs_dir(const fs::path& task_file) {
  fs::path dir = task_file.parent_path();
  if (dir.empty()) dir = ".";
  return (dir / ".." / "programs").lexically_normal();
}

fs::path resolve_program(const fs::path& dir, const std::string& name) {
  std::vector<fs::path> tried;
  std::vector<std::string> stems = {name};
  const std::string wrong = "_wrong";
  if (name.size() > wrong.size() && name.compare(name.size() - wrong.size(), wrong.size(), wrong) == 0)
    stems.push_back(name.substr(0, name.size() - wrong.size()) + "_change_detection_wrong_program");
  for (const auto& stem : stems)
    for (const char* ext : {".sexp", ".au"}) {
      fs::path p = dir / (stem + ext);
      if (fs::is_regular_file(p)) return p;
      tried.push_back(p.filename());
    }
  std::string names;
  for (size_t i = 0; i < tried.size(); ++i) names += (i ? (i + 1 == tried.size() ? " or " : ", ") : "") + tried[i].string();
  throw TaskError(fmt::format("unknown program '{}' (no {} in {})", name, names, dir.string()));
}

std::shared_ptr<const Program> load_program_checked(const fs::path& path, const std::optional<std::string>& trigger) {
  try {
    return load_program_file(path.string(), trigger);
  } catch (const CompileError& e) {
    throw TaskError(e.formatted());
  }
}

std::shared_ptr<const Program> load_program_checked_text(const std::string& text, const std::string& name,
                                                         const std::optional<std::string>& trigger) {
  try {
    return load_program(SourceFile{name, text, SourceId::Program}, trigger);
  } catch (const CompileError& e) {
    throw TaskError(e.formatted());
  }
}

std::unique_ptr<Environment> make_env_checked(const std::string& engine, std::shared_ptr<const Program> program) {
  std::string why;
  auto env = make_environment(engine, std::move(program), &why);
  if (!env) throw TaskError(why);
  return env;
}

std::string load_trigger_condition(const fs::path& answers_file) {
  std::string text = read_file(answers_file);
  json j = json::parse(text, nullptr, false);
  const std::string w = answers_file.filename().string();
  if (!j.is_object()) throw TaskError(w + ": an answers file is a JSON object");
  return string_field(j, "condition", w);
}

Answers load_answers(const fs::path& file) {
  const std::string w = file.filename().string();
  json j;
  try {
    j = json::parse(read_file(file));
  } catch (const json::exception& e) {
    throw TaskError(w + ": not valid JSON: " + json_error_text(e));
  }
  if (!j.is_object()) throw TaskError(w + ": an answers file is a JSON object");
  Answers a;
  a.file = file;
  if (auto it = j.find("seed"); it != j.end()) {
    if (!it->is_number_unsigned()) throw TaskError(w + ": field \"seed\" must be a non-negative integer");
    a.seed = it->get<uint64_t>();
  }
  for (const char* key : {"correct_idx", "answer"})
    if (auto it = j.find(key); it != j.end() && !a.correct_idx) {
      const std::optional<int> idx = it->is_number_unsigned() ? as_int(*it) : std::nullopt;
      if (!idx) throw TaskError(fmt::format("{}: \"{}\" must be a choice index", w, key));
      a.correct_idx = *idx;
    }
  if (auto it = j.find("reference_plan"); it != j.end()) {
    if (!it->is_array()) throw TaskError(w + ": \"reference_plan\" must be an array of actions");
    for (size_t i = 0; i < it->size(); ++i)
      a.reference_plan.push_back(action_from_json((*it)[i], fmt::format("{}: reference_plan[{}]", w, i)));
  }
  if (j.contains("condition")) a.condition = string_field(j, "condition", w);
  if (auto it = j.find("t_star"); it != j.end()) {
    const std::optional<int> t = it->is_number_unsigned() ? as_int(*it) : std::nullopt;
    if (!t) throw TaskError(w + ": field \"t_star\" must be a non-negative integer of at most 2^31 - 1");
    a.t_star = *t;
  }
  return a;
}

std::optional<fs::path> find_answers(const Task& task) {
  fs::path dir = task.file.parent_path();
  if (dir.empty()) dir = ".";
  std::vector<fs::path> candidates = {dir / ".." / "answers" / (task.name + ".json")};
  if (task.type == TaskType::ChangeDetection)
    candidates.push_back(dir / ".." / "answers" / (task.program + "_change_detection.json"));
  candidates.push_back(dir / (task.name + ".answers.json"));
  for (const fs::path& c : candidates)
    if (fs::is_regular_file(c)) return c.lexically_normal();
  return std::nullopt;
}

}  // namespace autumn::agent
