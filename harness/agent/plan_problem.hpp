// plan_problem — what every planning strategy shares: the search model, the one
// goal test, the action set, the one clock, and the search tree.
//
// The search model is the task's program, or its step-local-click model
// (click_model.hpp) when the analysis allows it and the two agree frame for frame
// on a few random episodes (a guard against a mistake in the analysis): there
// clicks that change nothing merge with noop. Plans are always replayed on the
// program itself (planning.cpp). The environment is reset with the seed the
// agent assumes (SolveOptions::env_seed, default 0: the benchmark's).
//
// Goal: the masked cells of the goal grid; reached(frame) is the only goal test.
// distance() ranks frames for best-first: `shape` counts cells where one side
// shows the goal's background (its most common masked colour) and the other does
// not, `colour` all differing cells, and (when asked) `travel` breaks their ties: for each
// differing cell of a non-background goal colour, the grid distance to the
// nearest cell of that colour in the frame. Moving an object towards its goal
// square leaves the counts as they are (one wrong cell traded for another);
// travel is what falls, so best-first is not blind on such plateaus.
//
// Clock: one stopwatch started with the solve; the time limit and node budget
// are the whole solve's. A strategy runs under a Limit, a share of what is left
// (a deadline on that clock and a node count), so later stages still get their
// turn on a slow engine. Without a time limit nothing depends on timing.
//
// Tree: nodes (parent, action index into the strategy's action list, depth);
// path() rebuilds a plan. Strategies build their own trees.
#pragma once
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "harness/agent/click_model.hpp"
#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

class Goal {
 public:
  explicit Goal(const Task& task);
  struct Dist {
    int shape = 0, colour = 0;
    int64_t travel = 0;  // at most cells() * travel_cap()
  };
  // The priority of a distance: shape, then colour, then travel (smaller first).
  int64_t rank(const Dist& d) const {
    const int64_t counts = static_cast<int64_t>(d.shape) * (cells() + 1) + d.colour;
    return counts * (static_cast<int64_t>(cells()) * travel_cap() + 1) + d.travel;
  }
  bool reached(const TaskFrame& f) const;
  // The same test on an environment's frame, mapped through a thread's colour map.
  bool reached(const Environment& e, FrameColours& colours) const;
  Dist distance(const TaskFrame& f, bool with_travel = false) const;
  int cells() const { return static_cast<int>(mask_.size()); }
  const std::vector<uint32_t>& mask_cells() const { return mask_; }
  // Masked cells where `f` differs from the goal.
  std::vector<uint32_t> differing(const TaskFrame& f) const;
  // Tests cells where the goal differs from `first` before the others (a state
  // not at the goal usually fails on one of them at once).
  void order_tests(const TaskFrame& first);
  const ColourTable& colours() const { return task_.colours; }

 private:
  // A cell's travel when the frame shows none of its colour.
  int travel_cap() const { return task_.goal.width + task_.goal.height; }
  int64_t travel(const TaskFrame& f) const;

  const Task& task_;
  std::vector<uint32_t> mask_;   // masked cells, row-major
  std::vector<uint32_t> order_;  // masked cells in test order
  int16_t background_ = 0;
};

class Clock {
 public:
  Clock(double time_limit, uint64_t nodes) : time_limit_(time_limit), nodes_(nodes) {}
  double seconds() const { return watch_.seconds(); }
  bool out_of_time() const { return time_limit_ > 0 && seconds() > time_limit_; }
  double time_limit() const { return time_limit_; }
  uint64_t node_budget() const { return nodes_; }

 private:
  Stopwatch watch_;
  double time_limit_;
  uint64_t nodes_;
};

// What a strategy may spend: up to `nodes` successors of its own, until
// `deadline` on the clock (0: the clock's own time limit only).
struct Limit {
  const Clock* clock = nullptr;
  uint64_t nodes = 0;
  double deadline = 0;
  bool out_of_time() const { return clock->out_of_time() || (deadline > 0 && clock->seconds() > deadline); }
  // `f` (0 < f <= 1) of what this limit leaves once `spent` of its nodes are
  // gone: that share of the remaining nodes (counted from zero) and, when there
  // is an end in time, a deadline that far between now and that end.
  Limit fraction(double f, uint64_t spent) const;
  // Why it stopped, for notes.
  std::string time_note() const;
};

struct Node {
  int64_t parent;
  int32_t action;
  int32_t depth;
};

// The plan from the root (node 0) to `node`: the actions of its ancestors'
// edges, first to last.
std::vector<Action> path_to(std::span<const Node> nodes, const std::vector<Action>& actions, int64_t node);

// What one strategy run reports.
struct SearchOutcome {
  bool found = false;
  std::vector<Action> plan;
  uint64_t nodes = 0;     // successors generated (environment steps)
  uint64_t distinct = 0;  // distinct states seen
  uint64_t lookahead_steps = 0;
  int depth_done = 0;     // layers fully searched (bfs); horizons fully tried (fill)
  bool exhausted = false; // every reachable state seen within the depth limit
  bool timed_out = false;
  std::string note;       // why it stopped without a plan
};

class PlanProblem {
 public:
  PlanProblem(const Task& task, const SolveOptions& opts, ThreadPool& pool);

  const Task& task() const { return task_; }
  const SolveOptions& opts() const { return opts_; }
  ThreadPool& pool() { return pool_; }
  const Goal& goal() const { return goal_; }
  const Environment& root() const { return *root_; }
  const Clock& clock() const { return clock_; }
  const InputUse& inputs() const { return inputs_; }
  const std::vector<Action>& actions() const { return actions_; }
  int grid() const { return grid_; }
  bool stochastic() const { return stochastic_; }
  const std::string& model() const { return model_; }  // "program" or "click-reset model"
  const std::string& model_note() const { return model_note_; }
  // A share of what is left: `fraction` of the remaining time and of the nodes
  // not yet `spent`; with `keep_time`, the time left is counted to that
  // fraction of the time limit before its end.
  Limit share(double fraction, uint64_t spent, double keep_time = 0) const;
  TaskFrame frame_of(const Environment& e) const { return task_frame(e.frame(), e.palette(), task_.colours); }
  // Frame after each of `plan`'s actions from `start` (the root when null); stops early on a failed step.
  std::vector<TaskFrame> replay_frames(const std::vector<Action>& plan, const Environment* start = nullptr) const;
  // Index of the first frame of `plan` (0: the start) at the goal, or -1.
  int first_goal(const std::vector<Action>& plan) const;

 private:
  void choose_model(std::shared_ptr<const Program> program, const std::string& path);
  bool models_agree(const Environment& a, const Environment& b) const;

  const Task& task_;
  const SolveOptions& opts_;
  ThreadPool& pool_;
  Goal goal_;
  Clock clock_;
  InputUse inputs_;
  std::unique_ptr<Environment> root_;
  std::vector<Action> actions_;
  int grid_ = 0;
  bool stochastic_ = false;
  std::string model_ = "program", model_note_;
};

// A state's noop future, what best-first and the beam rank a successor by: from
// a copy of the state, up to `noops` noop steps. `key` is the goal rank
// (Goal::rank) at its best on the state's frame and the frames on the way,
// which stop once a frame repeats its predecessor (things have come to rest);
// or, with `at_end`, the rank after exactly `noops` steps. A goal frame on the
// way stops it. `digest` joins the state's frame and the last frame seen, so
// look-alike states whose futures differ are told apart. One scorer per thread
// (it reuses its frame buffers).
struct Future {
  int64_t key = 0;
  int goal_noops = -1;  // the goal shows after this many noops (0: at once)
  uint64_t steps = 0;   // noop steps run
  uint64_t digest = 0;
};

class FutureScorer {
 public:
  Future score(const PlanProblem& p, const Environment& e, int noops, bool at_end, bool travel);

 private:
  FrameColours colours_;
  TaskFrame frame_, prev_;
};

// A plan's tail run from a state, as the fill and local search judge a plan:
// step `e` through plan[from..], testing the goal on every frame after a step.
// goal_at is the number of plan actions after which the goal first shows (the
// run stops there); otherwise rank is the goal's rank (FutureScorer::score, no
// noops) at the last frame (RankAt::Last) or at the best frame, `before`
// included (RankAt::Best). A step that fails gives {kNoRank, -1}.
constexpr int64_t kNoRank = std::numeric_limits<int64_t>::max();
struct TailRun {
  int64_t rank = kNoRank;
  int goal_at = -1;
};
enum class RankAt { Last, Best };
TailRun run_tail(const PlanProblem& p, Environment& e, const std::vector<Action>& plan, size_t from,
                 FutureScorer& scorer, RankAt at, bool travel, int64_t before = kNoRank);

// Runs each(env, k, worker) for every k < count on a clone of `base` of its own,
// in parallel, and destroys each clone when its k is done. The clones are made
// here, on the calling thread: an environment is never cloned from two threads
// at once (an interpreted one cannot be). `worker` indexes per-thread scratch.
void on_clones(ThreadPool& pool, const Environment& base, size_t count,
               const std::function<void(Environment&, size_t, unsigned)>& each);

// Plans as text, for notes and summaries.
std::string plan_text(const std::vector<Action>& plan);
size_t moves_of(const std::vector<Action>& plan);  // actions other than noop

}  // namespace autumn::agent
