// make_cd — see make_cd.hpp. The program is read once with the reader (for the
// source locations of its forms); every candidate is one TextEdit (a byte range and
// its replacement, "$G$" standing for the guard) applied together with the clock's
// insertion, and is judged only by running it against recorded original episodes.
#include "harness/agent/make_cd.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "compiler/read/output.hpp"
#include "compiler/read/sexpr.hpp"
#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

namespace {

using nlohmann::json;

constexpr int kEpisodes = 4;
constexpr size_t kMaxCandidates = 80;

bool debug() {
  const char* v = std::getenv("AUTUMN_CD_DEBUG");
  return v && std::string(v) == "1";
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw TaskError("cannot read " + p.string());
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

// ------------------------------------------------------------------ source text and byte ranges

struct TextEdit {
  size_t begin = 0, end = 0;
  std::string text;
};

class SourceText {
 public:
  explicit SourceText(const std::string& text) : text_(text) {
    starts_.push_back(0);
    for (size_t i = 0; i < text_.size(); ++i)
      if (text_[i] == '\n') starts_.push_back(i + 1);
  }
  size_t offset(const SourceLoc& loc) const { return starts_.at(loc.line - 1) + loc.col - 1; }
  // The bytes of a form; nullopt for an atom not spelled as it reads (escapes).
  std::optional<std::pair<size_t, size_t>> span(const Sexp& s) const {
    size_t b = offset(s.loc);
    if (s.is_list) return std::make_pair(b, offset(s.end) + 1);
    if (text_.compare(b, s.text.size(), s.text) != 0) return std::nullopt;
    return std::make_pair(b, b + s.text.size());
  }
  std::string slice(std::pair<size_t, size_t> r) const { return text_.substr(r.first, r.second - r.first); }
  const std::string& text() const { return text_; }

 private:
  const std::string& text_;
  std::vector<size_t> starts_;
};

std::string apply_edits(const std::string& text, std::vector<TextEdit> edits) {
  std::sort(edits.begin(), edits.end(), [](const TextEdit& a, const TextEdit& b) { return a.begin > b.begin; });
  std::string out = text;
  for (const TextEdit& e : edits) out.replace(e.begin, e.end - e.begin, e.text);
  return out;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t i = s.find(from); i != std::string::npos; i = s.find(from, i + to.size())) s.replace(i, from.size(), to);
  return s;
}

bool is_call(const Sexp& s, const std::string& head) {
  return s.is_list && !s.items.empty() && !s.items[0].is_list && !s.items[0].is_string && s.items[0].text == head;
}

std::optional<int> int_atom(const Sexp& s) {
  if (s.is_list || s.is_string || s.text.empty()) return std::nullopt;
  try {
    size_t used = 0;
    int v = std::stoi(s.text, &used);
    if (used == s.text.size()) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

std::string unquote(const std::string& t) { return t.size() >= 2 ? t.substr(1, t.size() - 2) : t; }

template <typename F>
void walk(const Sexp& s, const Sexp* parent, F&& f) {
  f(s, parent);
  if (s.is_list)
    for (const Sexp& c : s.items) walk(c, &s, f);
}

// ------------------------------------------------------------------ the program and its clock

struct ProgramForms {
  const Sexp* program = nullptr;  // (program ...)
  std::set<std::string> symbols, strings;
  std::string clock;
};

ProgramForms scan_program(const Sexp& root, const std::string& name) {
  ProgramForms p;
  if (root.items.empty() || !is_call(root.items[0], "program"))
    throw TaskError(name + ": expected the program to start with (program ...)");
  p.program = &root.items[0];
  walk(*p.program, nullptr, [&](const Sexp& s, const Sexp*) {
    if (!s.is_list) (s.is_string ? p.strings.insert(unquote(s.text)) : p.symbols.insert(s.text));
  });
  p.clock = "cdClock";
  for (int i = 2; p.symbols.count(p.clock); ++i) p.clock = "cdClock" + std::to_string(i);
  return p;
}

TextEdit clock_edit(const SourceText& src, const ProgramForms& p) {
  size_t at = src.offset(p.program->items[0].loc) + std::string("program").size();
  return {at, at,
          fmt::format("\n  (: {0} Number)\n  (= {0} (initnext 0 (+ (prev {0}) 1)))", p.clock)};
}

// ------------------------------------------------------------------ candidates

struct Candidate {
  TextEdit edit;           // "$G$" in its text: the guard
  std::string op = ">=";   // the guard: (op clock N)
  std::string change;      // description, "$N$" for the number
};

// A colour the program never names (so the change is always visible), seeded.
std::string new_colour(const ProgramForms& p, const std::string& old, std::mt19937_64& rng) {
  static const std::set<std::string> skip = {"transparent", "grey", "darkgrey", "gray", "darkgray"};
  ColourTable table;
  std::vector<std::string> free;
  for (int id = 1; id < table.table_size(); ++id) {
    std::string n = table.name(id);
    if (!skip.count(n) && !p.strings.count(n) && n != old) free.push_back(n);
  }
  return free[rng() % free.size()];
}

// Colour literals: strings the colour table knows or that a Cell paints.
void colour_candidates(const SourceText& src, const ProgramForms& p, std::mt19937_64& rng,
                       std::vector<Candidate>& out) {
  ColourTable table;
  walk(*p.program, nullptr, [&](const Sexp& s, const Sexp* parent) {
    if (!s.is_string) return;
    std::string old = unquote(s.text);
    if (table.find(old) <= 0 && !(parent && is_call(*parent, "Cell"))) return;
    auto r = src.span(s);
    if (!r) return;
    std::string nc = new_colour(p, old, rng);
    out.push_back({{r->first, r->second, fmt::format("(if $G$ then \"{}\" else {})", nc, s.text)},
                   ">=",
                   fmt::format("colour {} (line {}) is drawn \"{}\" from {} $N$ on", s.text, s.loc.line, nc, p.clock)});
  });
}

const std::map<std::string, std::string>& opposite_moves() {
  static const std::map<std::string, std::string> m = {
      {"moveLeft", "moveRight"}, {"moveRight", "moveLeft"}, {"moveUp", "moveDown"}, {"moveDown", "moveUp"},
      {"moveLeftNoCollision", "moveRightNoCollision"}, {"moveRightNoCollision", "moveLeftNoCollision"},
      {"moveUpNoCollision", "moveDownNoCollision"}, {"moveDownNoCollision", "moveUpNoCollision"}};
  return m;
}

// A literal direction inside an on-clause body, reversed under the guard.
void direction_in(const SourceText& src, const ProgramForms& p, const Sexp& s, int line, std::vector<Candidate>& out) {
  auto r = src.span(s);
  if (!r) return;
  std::string reversed;
  if (is_call(s, "Position") && s.items.size() == 3) {
    auto dx = int_atom(s.items[1]), dy = int_atom(s.items[2]);
    if (!dx || !dy || (*dx == 0 && *dy == 0)) return;
    reversed = fmt::format("(Position {} {})", -*dx, -*dy);
  } else if (!s.is_list && opposite_moves().count(s.text)) {
    reversed = opposite_moves().at(s.text);
  } else {
    return;
  }
  std::string old = src.slice(*r);
  out.push_back({{r->first, r->second, fmt::format("(if $G$ then {} else {})", reversed, old)},
                 ">=",
                 fmt::format("{} in the on-clause at line {} becomes {} from {} $N$ on", old, line, reversed, p.clock)});
}

void direction_candidates(const SourceText& src, const ProgramForms& p, std::vector<Candidate>& out) {
  for (const Sexp& st : p.program->items)
    if (is_call(st, "on") && st.items.size() >= 3)
      for (size_t i = 2; i < st.items.size(); ++i)
        walk(st.items[i], nullptr, [&](const Sexp& s, const Sexp*) { direction_in(src, p, s, st.loc.line, out); });
}

// ------------------------------------------------------------------ episodes of the original

struct Shot {
  int size = 0;
  TaskFrame cells;
  bool operator==(const Shot&) const = default;
};

struct CdEpisode {
  std::vector<Action> actions;
  std::vector<Shot> shots;  // shots[t]: the state after step t
};

Shot shot(const Environment& env, const ColourTable& colours) {
  return {env.frame().size, task_frame(env.frame(), env.palette(), colours)};
}

// `steps` random actions (an action the program fails under is taken back and
// another drawn, as make-task's other episodes do).
CdEpisode original_episode(Environment& env, uint64_t env_seed, int steps, std::mt19937_64& rng,
                           const ColourTable& colours) {
  if (!env.reset(env_seed)) throw TaskError(env.error());
  CdEpisode ep;
  ep.shots.push_back(shot(env, colours));
  const int grid = env.frame().size;
  std::unique_ptr<Environment> cur = env.clone();
  for (int t = 0; t < steps; ++t) {
    std::string error;
    for (int tries = 0; tries < 20 && static_cast<int>(ep.actions.size()) == t; ++tries) {
      Action a = random_action(rng, grid, 5);
      auto next = cur->clone();
      if (!next->step(a)) {
        error = next->error();
        continue;
      }
      cur = std::move(next);
      ep.actions.push_back(a);
      ep.shots.push_back(shot(*cur, colours));
    }
    if (static_cast<int>(ep.actions.size()) == t) throw TaskError("the program fails under every action tried: " + error);
  }
  return ep;
}

// A spawn: cells showing the frame's most common colour in every episode around t*.
std::vector<std::pair<int, int>> quiet_cells(const std::vector<CdEpisode>& eps, int k) {
  const Shot& ref = eps[0].shots[k];
  std::map<int16_t, int> count;
  for (int16_t c : ref.cells) ++count[c];
  int16_t common = std::max_element(count.begin(), count.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
  std::vector<std::pair<int, int>> cells;
  for (size_t i = 0; i < ref.cells.size(); ++i) {
    bool quiet = true;
    for (const CdEpisode& e : eps)
      for (int t = std::max(0, k - 1); t <= k + 1 && quiet; ++t)
        quiet = e.shots[t].size == ref.size && e.shots[t].cells[i] == common;
    if (quiet) cells.emplace_back(static_cast<int>(i % ref.size), static_cast<int>(i / ref.size));
  }
  return cells;
}

// Constructor arguments for an object type's fields (simple types only).
std::optional<std::string> field_values(const Sexp& object_def, const std::string& colour) {
  std::string args;
  for (size_t i = 2; i < object_def.items.size(); ++i) {
    const Sexp& f = object_def.items[i];
    if (!is_call(f, ":") || f.items.size() != 3) continue;
    const std::string& type = f.items[2].is_list ? std::string() : f.items[2].text;
    if (type == "Number") args += "1 ";
    else if (type == "Bool") args += "false ";
    else if (type == "String") args += "\"" + colour + "\" ";
    else return std::nullopt;
  }
  return args;
}

// A new last on-clause adding an object of an existing type to a list global.
void spawn_candidates(const SourceText& src, const ProgramForms& p, const std::vector<CdEpisode>& eps, int k,
                      std::mt19937_64& rng, std::vector<Candidate>& out) {
  std::map<std::string, const Sexp*> objects;
  for (const Sexp& st : p.program->items)
    if (is_call(st, "object") && st.items.size() >= 3 && !st.items[1].is_list) objects[st.items[1].text] = &st;
  std::vector<std::pair<int, int>> cells = quiet_cells(eps, k);
  if (cells.empty()) return;
  const size_t at = src.offset(p.program->end);
  for (const Sexp& st : p.program->items) {
    if (!is_call(st, ":") || st.items.size() != 3 || !is_call(st.items[2], "List") || st.items[2].items.size() != 2)
      continue;
    const std::string& list = st.items[1].text;
    auto obj = objects.find(st.items[2].items[1].text);
    if (obj == objects.end()) continue;
    auto args = field_values(*obj->second, new_colour(p, "", rng));
    if (!args) continue;
    auto [x, y] = cells[rng() % cells.size()];
    std::string thing = fmt::format("({} {}(Position {} {}))", obj->first, *args, x, y);
    out.push_back({{at, at, fmt::format("  (on $G$ (= {0} (addObj {0} {1})))\n", list, thing)},
                   "==",
                   fmt::format("a {} {} is added to {} when {} is $N$", obj->first, thing, list, p.clock)});
  }
}

// ------------------------------------------------------------------ checking a candidate

// Empty when the changed program matches the original before t*, differs at t*,
// and t* is the first state the trigger holds on, in every episode.
std::string check(const std::string& engine, const std::shared_ptr<const Program>& changed,
                  const std::vector<CdEpisode>& eps, uint64_t env_seed, const ColourTable& colours, int& t_star) {
  for (size_t e = 0; e < eps.size(); ++e) {
    auto env = make_env_checked(engine, changed);
    if (!env->reset(env_seed)) return "fails at reset: " + env->error();
    std::optional<int> ts, differs;
    if (!(shot(*env, colours) == eps[e].shots[0])) differs = 0;
    // The trigger of state t is known after step t + 1: run on past the difference.
    for (size_t t = 1; t <= eps[e].actions.size() && !(differs && ts); ++t) {
      if (!env->step(eps[e].actions[t - 1])) return fmt::format("fails at step {}: {}", t, env->error());
      if (!ts && env->triggered()) ts = static_cast<int>(t) - 1;
      if (!differs && !(shot(*env, colours) == eps[e].shots[t])) differs = static_cast<int>(t);
    }
    if (!ts) return fmt::format("episode {}: the condition never holds", e);
    if (e > 0 && *ts != t_star) return fmt::format("episode {}: t* {} (episode 0: {})", e, *ts, t_star);
    t_star = *ts;
    if (!differs) return fmt::format("episode {}: no difference by step {}", e, eps[e].actions.size());
    if (*differs != *ts) return fmt::format("episode {}: first differs at state {}, t* is {}", e, *differs, *ts);
  }
  return "";
}

struct CandidateTrial {
  std::string changed_text, change, reason;
  int t_star = -1;
};

CandidateTrial try_candidate(const Candidate& c, int n, const std::string& text, const TextEdit& clock,
                             const std::string& name, const std::string& trigger, const std::vector<CdEpisode>& eps,
                             const MakeTaskOptions& opts, const ColourTable& colours, const std::string& clock_name) {
  CandidateTrial tr;
  TextEdit e = c.edit;
  e.text = replace_all(e.text, "$G$", fmt::format("({} {} {})", c.op, clock_name, n));
  tr.changed_text = apply_edits(text, {clock, e});
  tr.change = replace_all(c.change, "$N$", std::to_string(n));
  try {
    auto changed = load_program_checked_text(tr.changed_text, name, trigger);
    tr.reason = check("interp", changed, eps, opts.env_seed, colours, tr.t_star);
    if (tr.reason.empty() && opts.engine != "interp")
      tr.reason = check(opts.engine, changed, eps, opts.env_seed, colours, tr.t_star);
  } catch (const std::exception& ex) {
    tr.reason = ex.what();
  }
  return tr;
}

fs::path prompts_dir(const MakeTaskOptions& opts) {
  if (opts.out.empty()) throw TaskError("a change-detection task needs --out DIR/prompts/NAME_cd.json");
  fs::path dir = opts.out.parent_path();
  if (dir.filename() != "prompts")
    throw TaskError("--out " + opts.out.string() + " must be in a folder named prompts/ (the programs and answers "
                    "go beside it)");
  return dir;
}

MadeCd made_from(const CandidateTrial& tr, const std::string& text, int k, const MakeTaskOptions& opts,
                 const std::string& condition) {
  MadeCd made;
  const std::string stem = opts.program.stem().string();
  made.prompt = {{"type", "change_detection"}, {"program", stem}, {"wrong_program", stem + "_wrong"}};
  made.answers = {{"condition", condition},
                  {"seed", opts.env_seed},
                  {"t_star", tr.t_star},
                  {"change", tr.change},
                  {"generator", {{"tool", "autumn make-task"}, {"seed", opts.seed}, {"steps", k}}}};
  made.original_text = text;
  made.changed_text = tr.changed_text;
  made.steps = k;
  made.t_star = tr.t_star;
  made.change = tr.change;
  return made;
}

// Writes `text` to `p` unless an identical file is there; a differing one is an error.
bool put_file(const fs::path& p, const std::string& text, bool refuse_differing) {
  if (fs::exists(p)) {
    if (read_text(p) == text) return false;
    if (refuse_differing) throw TaskError(p.string() + " exists and differs; not overwriting");
  }
  if (std::string why = write_file(p, text); !why.empty()) throw TaskError(why);
  return true;
}

}  // namespace

MadeCd make_cd(const MakeTaskOptions& opts) {
  prompts_dir(opts);
  std::mt19937_64 rng(opts.seed);
  const int k = opts.steps > 0 ? opts.steps : 6 + static_cast<int>(rng() % 15);
  const std::string text = read_text(opts.program);
  const std::string stem = opts.program.stem().string();
  auto original = load_program_checked(opts.program);
  SourceText src(text);
  Sexp root = read_sexprs(SourceFile{opts.program.string(), text, SourceId::Program});
  ProgramForms p = scan_program(root, opts.program.string());
  const TextEdit clock = clock_edit(src, p);
  const std::string condition = fmt::format(">= {} {}", p.clock, k);
  const ColourTable colours;

  std::vector<CdEpisode> eps;
  auto env = make_env_checked("interp", original);
  for (int e = 0; e < kEpisodes; ++e) {
    std::mt19937_64 erng(opts.seed * 0x9e3779b97f4a7c15ull + static_cast<uint64_t>(e) + 1);
    eps.push_back(original_episode(*env, opts.env_seed, k + 2, erng, colours));
  }
  std::vector<Candidate> cands;
  colour_candidates(src, p, rng, cands);
  direction_candidates(src, p, cands);
  spawn_candidates(src, p, eps, k, rng, cands);
  std::shuffle(cands.begin(), cands.end(), rng);
  if (cands.size() > kMaxCandidates) cands.resize(kMaxCandidates);

  std::string last;
  for (const Candidate& c : cands)
    for (int n : {k, k - 1}) {
      if (n < 0) continue;
      CandidateTrial tr = try_candidate(c, n, text, clock, stem + "_wrong", condition, eps, opts, colours, p.clock);
      if (tr.reason.empty()) return made_from(tr, text, k, opts, condition);
      if (debug()) std::cerr << "make-task cd: rejected: " << tr.change << ": " << tr.reason << "\n";
      last = tr.change + ": " + tr.reason;
    }
  throw TaskError(fmt::format("no change of program '{}' ({} candidates) shows exactly when {} first holds{}", stem,
                              cands.size(), condition, last.empty() ? "" : "; last rejected: " + last));
}

std::vector<std::string> write_cd(const MadeCd& made, const MakeTaskOptions& opts) {
  const fs::path dir = prompts_dir(opts);
  const fs::path root = dir.parent_path().empty() ? fs::path(".") : dir.parent_path();
  const std::string stem = opts.program.stem().string(), ext = opts.program.extension().string();
  const fs::path original = root / "programs" / (stem + ext), changed = root / "programs" / (stem + "_wrong" + ext);
  const fs::path answers = root / "answers" / (stem + "_change_detection.json");
  for (const fs::path& p : {original, changed})  // refuse before writing anything
    if (fs::exists(p) && read_text(p) != (p == original ? made.original_text : made.changed_text))
      throw TaskError(p.string() + " exists and differs; not overwriting");
  for (const fs::path& d : {dir, root / "programs", root / "answers"}) fs::create_directories(d);
  std::vector<std::string> notes;
  put_file(opts.out, format_task_json(made.prompt), false);
  notes.push_back("wrote " + opts.out.string());
  if (put_file(original, made.original_text, true)) notes.push_back("copied the program to " + original.string());
  if (put_file(changed, made.changed_text, true)) notes.push_back("wrote the changed program " + changed.string());
  put_file(answers, made.answers.dump(2) + "\n", false);
  notes.push_back(fmt::format("wrote {} (t* = {}: {})", answers.string(), made.t_star, made.change));
  return notes;
}

}  // namespace autumn::agent
