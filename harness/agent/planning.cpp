#include "harness/agent/planning.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <random>

#include "harness/agent/plan_beam.hpp"
#include "harness/agent/plan_best_first.hpp"
#include "harness/agent/plan_bfs.hpp"
#include "harness/agent/plan_fill.hpp"
#include "harness/agent/plan_focus.hpp"
#include "harness/agent/plan_local.hpp"
#include "harness/agent/plan_shorten.hpp"

namespace autumn::agent {

namespace {

// The planner over one PlanProblem: --search auto is the table kAutoStages
// (planning.hpp gives each stage's account, docs/design.md prints the table);
// the other modes run one stage with the whole budget. Each stage adds its
// figures to the result and returns true when it found the plan.
class Planner {
 public:
  Planner(PlanProblem& p, PlanResult& r) : p_(p), r_(r), moves_(p.opts().cost == "moves") {}

  void run();  // defined after the tables

  // What a stage does once it has found a plan.
  enum class Role {
    Decisive,  // its plan ends the sequence
    Search,    // the later Search stages are skipped; the Polish ones run
    Polish,    // runs only once a plan is found, to improve it
  };
  struct Stage {
    const char* name;
    const char* when;  // `applies`, in words (the table in docs/design.md)
    double share;      // of what is left when it starts (a stage may divide it further)
    bool (Planner::*applies)() const;
    bool (Planner::*run)(double share);
    Role role;
    bool checks_time;  // skipped once the time or the nodes are spent
  };
  static const Stage kAutoStages[];

 private:
  struct Mode {
    const char* name;
    void (Planner::*run)();
  };
  static const Mode kModes[];

  void run_auto();

  // The modes other than auto.
  void mode_bfs() { full_bfs(1.0); }
  void mode_paper() { paper_bfs(); }
  void mode_best_first() { best_first_stage(p_.actions(), "best-first"); }
  void mode_fill() { fill_stage(p_.actions(), p_.actions(), 1.0, p_.opts().max_plan); }
  void mode_local() {
    if (positional()) focus_sets();
    local_stage(focus(), 1.0);
  }
  void mode_skeleton() {
    if (positional()) focus_sets();
    skeleton_stage(focus(), 1.0);
  }
  void mode_beam() {
    if (positional()) focus_sets();
    if (beam_stage(focus(), "beam", 0.5) && !out_of_time()) horizon_stage(focus(), "beam");
  }

  // When the auto stages apply.
  bool always() const { return true; }
  bool not_positional() const { return !positional(); }
  bool by_steps() const { return !moves_; }
  // Cost steps, positional clicks and arrows: the fill and skeleton stages.
  bool fills() const { return !moves_ && positional() && has_arrows(); }
  bool unproven_by_steps() const { return !moves_ && !r_.shortest; }

  // The auto stages, each on the share its row gives.
  bool auto_bfs(double part) { return full_bfs(part); }
  bool auto_focused(double part) { return focused_stages(part); }
  bool auto_early_fill(double part) { return fill_stage(p_.actions(), focus(), part, 12); }
  bool auto_moves(double part) { return moves_stage(part); }
  bool auto_beam(double part) { return beam_stage(focus(), "beam" + focus_name(), part); }
  bool auto_late_fill(double part) { return fill_stage(focus(), focus(), part, p_.opts().max_plan); }
  bool auto_local(double part) { return local_stage(focus(), part, !fills()); }
  bool auto_skeleton(double part) { return skeleton_stage(focus(), part); }
  bool auto_best_first_near(double part) {
    return best_first_stage(focus(), "best-first" + focus_name(), part);
  }
  bool auto_best_first(double part) { return best_first_stage(p_.actions(), "best-first", part); }
  bool auto_horizon(double) {
    horizon_stage(focus(), "beam" + focus_name());
    return true;
  }

  // The actions the stages after the focused ones search, and how methods name them.
  std::vector<Action> focus() const { return positional() ? near_or_reaching() : p_.actions(); }
  std::string focus_name() const { return positional() ? ", clicks near or reaching the changes" : ""; }

 private:
  bool positional() const { return p_.inputs().clicks == ClickUse::Position && p_.actions().size() > 6; }
  bool out_of_time() const { return p_.clock().out_of_time() || r_.nodes >= p_.clock().node_budget(); }
  // `f` of what is left to the stages, the local stage's reserve kept back.
  Limit share(double f) const { return p_.share(f, r_.nodes + reserve_, reserve_ > 0 ? kLocalTime : 0); }

  void note(const std::string& why) {
    if (!why.empty()) r_.note += (r_.note.empty() ? "" : "; ") + why;
  }
  void add(const SearchOutcome& o) {
    r_.nodes += o.nodes;
    r_.distinct += o.distinct;
    r_.lookahead_steps += o.lookahead_steps;
    r_.timed_out = r_.timed_out || o.timed_out;
    if (!o.found) note(o.note);
  }
  void found(const std::vector<Action>& plan, const std::string& method, bool proven) {
    reserve_ = 0;  // the local and skeleton stages run only while no plan is found
    r_.found = true;
    r_.plan = plan;
    r_.found_length = plan.size();
    r_.method = method;
    r_.shortest = proven;
  }

  BfsOutcome run_bfs(const std::vector<Action>& actions, bool free_noop, const Limit& limit) {
    BfsSpec spec;
    spec.actions = actions;
    if (free_noop) {
      spec.free.assign(actions.size(), 0);
      for (size_t a = 0; a < actions.size(); ++a) spec.free[a] = actions[a].kind == Action::Kind::Noop;
    }
    spec.max_cost = p_.opts().depth;
    spec.max_steps = p_.opts().max_plan;
    spec.limit = limit;
    BfsOutcome o = bfs(p_, spec);
    add(o);
    return o;
  }

  // Stage 1: the full action set under the task's cost; a plan is proven cheapest.
  bool full_bfs(double part) {
    BfsOutcome o = run_bfs(p_.actions(), moves_, share(part));
    r_.bfs_depth_done = o.depth_done;
    r_.proven_bound = o.depth_done;
    r_.exhausted = o.exhausted;
    if (!o.found) return false;
    found(o.plan, moves_ ? "bfs by moves" : "bfs", true);
    if (moves_) shorten(p_.actions());  // fewer waiting steps, same moves
    return true;
  }

  // --search paper (--protocol paper): the AutumnBench paper's simulator agent.
  // Plain BFS by steps over paper_action_set() (breadth 10), depth --depth (the
  // protocol's 10); the first plan of the shallowest layer, as found.
  bool paper_bfs() {
    BfsSpec spec;
    spec.actions = paper_action_set(p_.grid(), p_.opts().seed);
    spec.max_cost = p_.opts().depth;
    spec.max_steps = p_.opts().depth;
    spec.limit = share(1.0);
    BfsOutcome o = bfs(p_, spec);
    add(o);
    r_.bfs_depth_done = o.depth_done;
    r_.exhausted = o.exhausted;
    if (!o.found) {
      note(fmt::format("the paper's BFS (breadth {}, depth {}) found no plan", spec.actions.size(), spec.max_cost));
      return false;
    }
    found(o.plan, "paper bfs", false);  // shortest over its ten actions, not over them all
    return true;
  }

  struct Focus {
    const char* what;
    std::vector<Action> actions;
  };
  // The focused click sets, each joined by the mode clicks.
  std::vector<Focus> focus_sets() {
    const std::vector<Action>& all = p_.actions();
    const std::vector<uint32_t> changed = p_.goal().differing(p_.frame_of(p_.root()));
    hidden_ = hidden_clicks(p_, all, changed);
    auto with_hidden = [&](const std::vector<Action>& focus) { return unite(all, focus, hidden_); };
    std::vector<Focus> sets = {
        {"clicks on the cells the goal changes", with_hidden(near_clicks(p_, all, changed, 0, false))},
        {"clicks whose effect reaches the cells the goal changes", with_hidden(reaching_clicks(p_, all, changed))},
        {"clicks within 1 of the cells the goal changes", with_hidden(near_clicks(p_, all, changed, 1, false))},
        {"clicks within 3 of the cells the goal changes", with_hidden(near_clicks(p_, all, changed, 3, false))},
        {"clicks in the goal region", with_hidden(near_clicks(p_, all, p_.goal().mask_cells(), 0, true))},
    };
    reaching_ = sets[1].actions;
    near1_ = sets[2].actions;
    return sets;
  }

  // Stage 2: BFS over focused click sets; proven when no cheaper plan can exist.
  bool focused_stages(double part) {
    const std::vector<Action>& all = p_.actions();
    std::vector<std::vector<Action>> tried;
    for (const Focus& f : focus_sets()) {
      if (out_of_time()) break;
      if (f.actions.size() == all.size() || std::find(tried.begin(), tried.end(), f.actions) != tried.end()) continue;
      tried.push_back(f.actions);
      BfsOutcome o = run_bfs(f.actions, moves_, share(part));
      if (!o.found) continue;
      const bool proven = o.cost <= r_.proven_bound + 1;
      found(o.plan, std::string(moves_ ? "bfs by moves, " : "bfs, ") + f.what, proven);
      if (!proven) shorten(all);
      return true;
    }
    return false;
  }

  std::vector<Action> near_or_reaching() const { return unite(p_.actions(), reaching_, near1_); }  // hidden_ included

  // Stage 3 (cost steps): few moves and a long wait; the plan is then shortened in steps.
  bool moves_stage(double part) {
    const std::vector<Action> actions = focus();
    BfsOutcome o = run_bfs(actions, true, share(part));
    if (!o.found) return false;
    found(o.plan, "bfs by moves, then shortened", false);
    shorten(actions);
    return true;
  }

  bool has_arrows() const {
    for (const Action& a : p_.actions())
      if (a.kind != Action::Kind::Noop && a.kind != Action::Kind::Click) return true;
    return false;
  }

  // Stage 3a (cost steps): the arrows first, then clicks into their waiting
  // steps (plan_fill.hpp), for worlds where the arrows set a mode that the
  // things clicks place then follow; horizons from the proven bound (or the
  // last horizon an earlier fill stage tried) up to `last_horizon`. Stage 4a
  // runs it again on the horizons up to the plan length limit: a goal that is
  // a late moment of a moving world (snow piling up while rocks are placed).
  // `actions`: the skeletons' moves and the clicks filled in; `focus`: what
  // shortening searches.
  bool fill_stage(const std::vector<Action>& actions, const std::vector<Action>& focus, double part,
                  int last_horizon) {
    FillSpec spec;
    spec.first_horizon = std::max(r_.proven_bound, fill_done_) + 1;
    spec.last_horizon = std::min(p_.opts().max_plan, last_horizon);
    if (spec.first_horizon > spec.last_horizon) return false;
    spec.limit = share(part);
    const SearchOutcome o = fill_search(p_, actions, spec);
    fill_done_ = std::max(fill_done_, o.depth_done);
    add(o);
    if (!o.found) return false;
    found(o.plan, "fill: arrows, then clicks in their waiting steps", false);
    shorten(focus);
    return true;
  }

  bool best_first_stage(const std::vector<Action>& actions, const std::string& method, double part = 1.0) {
    // Frame pruning first, then travel as the tie-break, then neither pruning nor travel.
    struct Pass {
      bool prune, travel;
      double part;
    };
    const Pass passes[] = {{true, false, 0.5}, {true, true, 0.5}, {false, false, 1.0}};
    SearchOutcome o;
    const Pass* used = nullptr;
    for (const Pass& pass : passes) {
      if (used && out_of_time()) break;
      o = best_first(p_, actions, pass.prune, pass.travel, share(part * pass.part));
      add(o);
      used = &pass;
      if (o.found) break;
    }
    if (!o.found) return false;
    found(o.plan, used->travel ? method + ", travel" : method, false);
    shorten(actions);
    return true;
  }

  // Stage 4: layered beam search (plan_beam.hpp) scored by the settled future,
  // at widths 8 and 32, each plan found bounding the next search.
  bool beam_stage(const std::vector<Action>& actions, const std::string& method, double part) {
    const Limit limit = share(part);
    const uint64_t start = r_.nodes;
    std::vector<Action> best;
    std::string how;
    int max_len = p_.opts().max_plan;
    for (size_t width : {8, 32}) {
      while (max_len > 0 && !limit.out_of_time() && r_.nodes - start < limit.nodes) {
        const SearchOutcome o = beam(p_, actions, {width, max_len, false, rest_of(limit, start)});
        add(o);
        if (!o.found) break;
        best = o.plan;
        how = fmt::format("{} {}", method, width);
        max_len = static_cast<int>(best.size()) - 1;
      }
    }
    if (best.empty()) return false;
    found(best, how, false);
    shorten(actions);
    return true;
  }

  // Stage 4b: local search over whole plans (plan_local.hpp) of 32 actions
  // (0.7 of the share), then of 64 (the rest; with `long_plans` only, else the
  // rest goes back to the stages after), for a goal that is one late moment of
  // a busy world; then, while the share lasts, over plans one shorter than the
  // best found (half of what is left each; the goal may show earlier in a
  // plan, so each is a new search).
  bool local_stage(const std::vector<Action>& actions, double part, bool long_plans = true) {
    reserve_ = 0;
    const Limit limit = share(part);
    const uint64_t start = r_.nodes;
    auto search = [&](int length, double of_rest) {
      LocalSpec spec;
      spec.length = length;
      spec.seed = p_.opts().seed;
      spec.limit = rest_of(limit, start).fraction(of_rest, 0);
      const SearchOutcome o = local_search(p_, actions, spec);
      add(o);
      if (o.found) {
        found(o.plan, fmt::format("local search over plans of {}", length), false);
        shorten(actions);
      }
      return o.found;
    };
    const int max_plan = p_.opts().max_plan;
    bool got = search(std::min(32, max_plan), 0.7);
    if (!got && long_plans && max_plan > 32 && !out_of_time()) got = search(std::min(64, max_plan), 1.0);
    if (!got) return false;
    while (!r_.shortest && r_.plan.size() > 1 && !limit.out_of_time() && r_.nodes - start < limit.nodes)
      if (!search(static_cast<int>(r_.plan.size()) - 1, 0.5)) break;
    return true;
  }

  // Stage 4c (worlds of arrows and placing clicks): a skeleton, then its
  // clicks. Local search over the non-click actions alone (plan_local.hpp;
  // plans of 32, 0.9 of the share) offers its best skeleton before each
  // restart that follows a new best, even where no skeleton reaches the goal;
  // cut at its best frame, its steps take clicks (plan_fill.hpp,
  // fill_skeleton), and the first skeleton so completed ends the stage.
  // Example (flood_defense, a goal 25 random actions away): the goal's water
  // comes from the spring's moves alone, its five sandbags from clicks. Local
  // search over moves finds, after about 1.5 million steps, a skeleton that
  // differs from the goal in the five bag cells only; the fill puts the bag
  // clicks in place of a noop and four moves that the water does not need: a
  // 25-action plan.
  // Tests: tests/agent_test.cpp (AgentPlanning.SkeletonStageFillsIdleMoves,
  // AgentPlanning.SkeletonSearchEndsWhenAnOfferIsCompleted).
  bool skeleton_stage(const std::vector<Action>& focus, double part) {
    reserve_ = 0;
    const Limit limit = share(part);
    std::vector<Action> moves;
    for (const Action& a : p_.actions())
      if (a.kind != Action::Kind::Click) moves.push_back(a);
    SearchOutcome filled;
    size_t offers = 0;
    LocalSpec spec;
    spec.length = std::min(32, p_.opts().max_plan);
    spec.seed = p_.opts().seed;
    spec.limit = limit.fraction(0.9, 0);
    spec.offer = [&](std::vector<Action> skeleton) {
      skeleton.resize(best_frame(skeleton));
      if (skeleton.empty() || limit.out_of_time()) return false;
      ++offers;
      filled = fill_skeleton(p_, focus, skeleton, limit);
      r_.nodes += filled.nodes;
      return filled.found;
    };
    const SearchOutcome o = local_search(p_, moves, spec);
    add(o);
    if (o.found) {
      found(o.plan, "local search over moves", false);
      shorten(focus);
      return true;
    }
    if (!filled.found) {
      note(fmt::format("fill: no clicks in the steps of {} skeleton{} reach the goal", offers, offers == 1 ? "" : "s"));
      return false;
    }
    found(filled.plan, "skeleton: local search over moves, then clicks in its steps", false);
    shorten(focus);
    return true;
  }

  // The number of `plan`'s actions after which its frame is nearest the goal
  // (by rank with travel, as local search judges; the last such frame, so a
  // world that holds still after it keeps its later steps as slots for clicks).
  size_t best_frame(const std::vector<Action>& plan) {
    const std::vector<TaskFrame> frames = p_.replay_frames(plan);
    r_.nodes += frames.size() - 1;
    const Goal& goal = p_.goal();
    int64_t best = kNoRank;
    size_t at = 0;
    for (size_t t = 1; t < frames.size(); ++t) {
      const int64_t rank = goal.rank(goal.distance(frames[t], true));
      if (rank <= best) best = rank, at = t;
    }
    return at;
  }

  // Stage 6: a plan not proven cheapest, from stages 3-5, may be long because the
  // goal exists at one moment that it reached late. Beam searches scored at a
  // fixed horizon, horizons from the proven bound up to below the plan's
  // length; the first plan found replaces it when shorter.
  void horizon_stage(const std::vector<Action>& actions, const std::string& method) {
    const Limit limit = share(1.0);
    const uint64_t start = r_.nodes;
    // Wide where the action set is small (arrows alone): about 2,000 successors a layer.
    const size_t width = std::max<size_t>(8, 2048 / actions.size());
    int horizon = r_.proven_bound + 1;
    for (; horizon < static_cast<int>(r_.plan.size()); ++horizon) {
      if (limit.out_of_time() || r_.nodes - start >= limit.nodes) break;
      SearchOutcome o = beam(p_, actions, {width, horizon, true, rest_of(limit, start)});
      o.note.clear();  // one note for all horizons, below
      add(o);
      if (!o.found) continue;
      if (o.plan.size() < r_.plan.size()) {
        found(o.plan, fmt::format("{} {} at horizon {}", method, width, horizon), false);
        shorten(actions);
      }
      return;
    }
    if (horizon > r_.proven_bound + 1)
      note(fmt::format("beam {} at horizons {}..{}: no shorter plan", width, r_.proven_bound + 1, horizon - 1));
  }

  // What is left of `limit` after the nodes spent since `start`.
  Limit rest_of(const Limit& limit, uint64_t start) const {
    Limit l = limit;
    l.nodes = limit.nodes - std::min(limit.nodes, r_.nodes - start);
    return l;
  }

  void shorten(const std::vector<Action>& actions) {
    ShortenStats stats;
    r_.plan = shorten_plan(p_, r_.plan, actions, share(1.0), moves_, stats);
    r_.nodes += stats.nodes;
    r_.shortcuts = stats.shortcuts;
    r_.relocated = stats.relocated;
    // A plan as cheap as the proven bound allows is proven after all.
    const int cost = static_cast<int>(moves_ ? moves_of(r_.plan) : r_.plan.size());
    if (cost <= r_.proven_bound + 1) r_.shortest = true;
  }

  PlanProblem& p_;
  PlanResult& r_;
  const bool moves_;
  std::vector<Action> reaching_, near1_, hidden_;  // focused_stages' sets (near1_ and reaching_ with hidden_)
  int fill_done_ = 0;  // horizons the fill stages have tried in full
  // Nodes of the budget kept back for the local and skeleton stages: every
  // stage before them shares what is left without them (share()), and the
  // time up to kLocalTime of the time limit before its end (a slow program
  // spends its time before its nodes: flood_defense, at about 130,000 steps a
  // second, had spent 97 of its 120 s when local search began); zero once
  // either runs or a plan is found. Local search edits whole plans from the
  // start, so it needs steps by the million where the stages before it have
  // spent a budget on layers.
  static constexpr double kLocalReserve = 0.4, kLocalTime = 0.5;
  uint64_t reserve_ = 0;
};

using R = Planner::Role;
const Planner::Stage Planner::kAutoStages[] = {
    {"bfs", "clicks told apart by position", 0.1, &Planner::positional, &Planner::auto_bfs, R::Decisive, false},
    {"bfs", "otherwise", 0.5, &Planner::not_positional, &Planner::auto_bfs, R::Decisive, false},
    {"focused bfs", "clicks told apart by position (each of five click sets)", 1.0 / 8, &Planner::positional,
     &Planner::auto_focused, R::Decisive, false},
    {"fill", "cost steps, positional clicks and arrows (horizons to 12)", 0.25, &Planner::fills,
     &Planner::auto_early_fill, R::Search, true},
    {"bfs by moves", "cost steps", 0.5, &Planner::by_steps, &Planner::auto_moves, R::Search, true},
    {"beam", "always", 0.1, &Planner::always, &Planner::auto_beam, R::Search, true},
    {"fill", "as fill above (horizons to --max-plan)", 0.5, &Planner::fills, &Planner::auto_late_fill, R::Search,
     true},
    {"local", "always", 0.8, &Planner::always, &Planner::auto_local, R::Search, true},
    {"skeleton", "as fill above", 0.8, &Planner::fills, &Planner::auto_skeleton, R::Search, true},
    {"best-first", "clicks told apart by position (the focused clicks)", 1.0, &Planner::positional,
     &Planner::auto_best_first_near, R::Search, true},
    {"best-first", "always (every action)", 1.0, &Planner::always, &Planner::auto_best_first, R::Search, true},
    {"horizon beam", "cost steps, the plan not proven cheapest", 1.0, &Planner::unproven_by_steps,
     &Planner::auto_horizon, R::Polish, true},
};

const Planner::Mode Planner::kModes[] = {
    {"bfs", &Planner::mode_bfs},           {"paper", &Planner::mode_paper}, {"best-first", &Planner::mode_best_first},
    {"fill", &Planner::mode_fill},         {"local", &Planner::mode_local}, {"skeleton", &Planner::mode_skeleton},
    {"beam", &Planner::mode_beam},
};

void Planner::run() {
  const std::string& search = p_.opts().search;
  if (search == "auto") return run_auto();
  for (const Mode& m : kModes)
    if (search == m.name) return (this->*m.run)();
}

void Planner::run_auto() {
  reserve_ = static_cast<uint64_t>(static_cast<double>(p_.clock().node_budget()) * kLocalReserve);
  for (const Stage& s : kAutoStages) {
    if ((s.role == Role::Polish) != r_.found) continue;
    if (!(this->*s.applies)() || (s.checks_time && out_of_time())) continue;
    if ((this->*s.run)(s.share) && s.role == Role::Decisive) return;
  }
}

}  // namespace

std::vector<PlanStageRow> auto_plan_stages() {
  std::vector<PlanStageRow> rows;
  for (const Planner::Stage& s : Planner::kAutoStages) {
    const char* role = s.role == Planner::Role::Decisive ? "decisive" : s.role == Planner::Role::Search ? "search" : "polish";
    rows.push_back({s.name, s.when, s.share, role});
  }
  return rows;
}

std::vector<Action> paper_action_set(int grid, uint64_t seed) {
  std::vector<Action> actions = {Action::noop(), Action{Action::Kind::Left}, Action{Action::Kind::Right},
                                 Action{Action::Kind::Up}, Action{Action::Kind::Down}};
  std::mt19937_64 rng(seed ^ 0x70617065722d6266ull);  // "paper-bf"
  const int cells = grid * grid;
  const int clicks = std::min(kPaperBreadth - static_cast<int>(actions.size()), cells);
  std::vector<int> chosen;
  while (static_cast<int>(chosen.size()) < clicks) {
    const int c = static_cast<int>(rng() % static_cast<uint64_t>(cells));
    if (std::find(chosen.begin(), chosen.end(), c) == chosen.end()) chosen.push_back(c);
  }
  for (int c : chosen) actions.push_back(Action::click(c % grid, c / grid));
  return actions;
}

PlanResult solve_planning(const Task& task, const SolveOptions& opts, ThreadPool& pool) {
  if (task.type != TaskType::Planning) throw TaskError(task.file.string() + ": not a planning task");
  if (std::string why = unknown_name("search", opts.search, search_names()); !why.empty()) throw TaskError(why);
  if (std::string why = unknown_name("cost", opts.cost, cost_names()); !why.empty()) throw TaskError(why);
  PlanResult r;
  r.cost = opts.cost;
  PlanProblem problem(task, opts, pool);  // starts the one clock, then loads the program
  const double setup_seconds = problem.clock().seconds();
  r.stochastic = problem.stochastic();
  r.env_seed = task.env_seed;
  r.click_use = click_use_name(problem.inputs().clicks);
  r.actions = problem.actions().size();
  r.model = problem.model();
  r.model_note = problem.model_note();
  if (problem.goal().reached(problem.frame_of(problem.root()))) {
    r.found = r.shortest = true;
    r.method = "bfs";
  } else {
    Planner(problem, r).run();
  }
  r.seconds = problem.clock().seconds();
  r.search_seconds = r.seconds - setup_seconds;
  if (r.found) r.verified = plan_reaches_goal(task, opts, r.plan);
  return r;
}

bool plan_reaches_goal(const Task& task, const SolveOptions& opts, const std::vector<Action>& plan, uint64_t env_seed) {
  auto program = load_program_checked(task_program_path(task, opts, task.program));
  auto env = make_env_checked(opts.engine, program);
  if (!env->reset(env_seed) || env->frame().size != task.goal.width) return false;
  const Goal goal(task);
  FrameColours colours;
  if (goal.reached(*env, colours)) return true;
  for (const Action& a : plan) {
    if (!env->step(a)) return false;
    if (goal.reached(*env, colours)) return true;
  }
  return false;
}

nlohmann::json planning_json(const PlanResult& r) {
  nlohmann::json plan = nlohmann::json::array();
  for (const auto& a : r.plan) plan.push_back(format_action(a));
  auto or_null = [&](auto v) { return r.found ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j = {{"found", r.found},
                      {"plan", r.found ? plan : nlohmann::json(nullptr)},
                      {"length", or_null(r.plan.size())},
                      {"moves", or_null(moves_of(r.plan))},
                      {"cost", r.cost},
                      {"method", r.method},
                      {"shortest", r.shortest},
                      {"proven_optimal", r.shortest},
                      {"proven_bound", r.proven_bound},
                      {"found_length", or_null(r.found_length)},
                      {"shortcuts", r.shortcuts},
                      {"relocated_clicks", r.relocated},
                      {"bfs_depth_done", r.bfs_depth_done},
                      {"nodes", r.nodes},
                      {"distinct_states", r.distinct},
                      {"action_set", r.actions},
                      {"click_use", r.click_use},
                      {"search_model", r.model},
                      {"stochastic", r.stochastic},
                      {"env_seed", r.env_seed},
                      {"verified", r.verified},
                      {"seconds", r.seconds},
                      {"search_seconds", r.search_seconds},
                      {"nodes_per_second", per_second(static_cast<double>(r.nodes), r.search_seconds)}};
  if (!r.note.empty()) j["note"] = r.note;
  if (!r.model_note.empty()) j["search_model_note"] = r.model_note;
  if (r.stochastic) j["assumed_seed"] = "the planner simulates the environment with seed " + std::to_string(r.env_seed);
  return j;
}

std::string planning_summary(const PlanResult& r) {
  std::string s;
  if (r.found) {
    const size_t cost = r.cost == "moves" ? moves_of(r.plan) : r.plan.size();
    s += fmt::format("plan ({} action{}, {} move{}; {}; {}): {}\n", r.plan.size(), r.plan.size() == 1 ? "" : "s",
                     moves_of(r.plan), moves_of(r.plan) == 1 ? "" : "s", r.method,
                     r.shortest ? fmt::format("proven cheapest in {}", r.cost)
                                : fmt::format("not proven cheapest: no plan costs <= {} {}", r.proven_bound, r.cost),
                     plan_text(r.plan));
    if (r.found_length != r.plan.size())
      s += fmt::format("shortened from {} actions ({} shortcut{}, {} click{} moved into a waiting step)\n",
                       r.found_length, r.shortcuts, r.shortcuts == 1 ? "" : "s", r.relocated,
                       r.relocated == 1 ? "" : "s");
    (void)cost;
    s += fmt::format("replayed on a fresh environment: {}\n", r.verified ? "reaches the goal" : "DOES NOT reach the goal");
  } else {
    s += "no plan found\n";
  }
  if (!r.note.empty()) s += r.note + "\n";
  s += fmt::format("search: {} actions per state (clicks: {}; {}), {} nodes generated, {} distinct states\n", r.actions,
                   r.click_use, r.model, r.nodes, r.distinct);
  if (!r.model_note.empty()) s += "search model: " + r.model_note + "\n";
  if (r.stochastic)
    s += fmt::format("stochastic program: the plan holds for the environment seed {} the planner assumed\n", r.env_seed);
  s += fmt::format("time: {:.3f} s ({:.3f} s searching, {:.0f} nodes/s)\n", r.seconds, r.search_seconds,
                   per_second(static_cast<double>(r.nodes), r.search_seconds));
  return s;
}

}  // namespace autumn::agent
