#include "harness/agent/planning.hpp"

#include <fmt/core.h>

#include <absl/container/flat_hash_set.h>

#include <atomic>
#include <queue>
#include <unordered_map>

#include "harness/agent/click_model.hpp"

namespace autumn::agent {

namespace {

using HashSet = absl::flat_hash_set<uint64_t>;

struct NodeRec {
  int64_t parent;
  int32_t action;
  int32_t depth;
};

class Planner {
 public:
  Planner(const Task& task, const SolveOptions& opts, ThreadPool& pool, PlanResult& r)
      : task_(task), opts_(opts), pool_(pool), r_(r) {}

  void run() {
    auto program = load_program_checked(task_program_path(task_, opts_, task_.program));
    root_ = make_env_checked(opts_.engine, program);
    if (!root_->reset(task_.env_seed)) throw TaskError(task_.program + ": " + root_->error());
    size_ = root_->frame().size;
    if (size_ != task_.goal.width)
      throw TaskError(fmt::format("{}: goal is {}x{} but program '{}' has GRID_SIZE {}", task_.file.filename().string(),
                                  task_.goal.width, task_.goal.height, task_.program, size_));
    r_.stochastic = !root_->deterministic();
    r_.env_seed = task_.env_seed;
    ClickUse use = analyse_click_use(*program);
    r_.click_use = click_use_name(use);
    actions_ = search_actions(use, size_);
    r_.actions = actions_.size();
    init_heuristic();
    goal_order_ = changed_cells();
    {
      std::vector<uint8_t> first(task_.mask.cells.size(), 0);
      for (uint32_t i : goal_order_) first[i] = 1;
      for (uint32_t i : mask_index_)
        if (!first[i]) goal_order_.push_back(i);
    }
    for (unsigned w = 0; w < pool_.size(); ++w) roots_.push_back(root_->clone());
    search_clock_ = Stopwatch();
    struct RecordSearchTime {
      PlanResult& r;
      const Stopwatch& clock;
      ~RecordSearchTime() { r.search_seconds = clock.seconds(); }
    } record{r_, search_clock_};

    if (distance(task_frame(root_->frame(), root_->palette(), task_.colours)).colour == 0) {
      r_.found = true;
      r_.shortest = true;
      r_.method = "bfs";
      return;
    }
    const std::string& search = opts_.search;
    if (search != "auto" && search != "bfs" && search != "best-first")
      throw TaskError("unknown search '" + search + "' (auto, bfs, best-first)");
    const uint64_t N = opts_.nodes;
    if (search == "bfs") {
      r_.method = "bfs";
      r_.shortest = bfs(opts_.depth, N);
      return;
    }
    if (search == "auto") {
      r_.method = "bfs";
      if (use != ClickUse::Position) {
        if (bfs(opts_.depth, N / 4)) {
          r_.shortest = true;
          return;
        }
      } else if (positional_click_search()) {
        return;
      }
    }
    r_.method = "best-first";
    if (best_first(true, N) || (budget_left() && best_first(false, N))) shorten();
  }

  // The auto search for programs that tell click positions apart. Clicks on every
  // cell make full layers beyond the first unaffordable (on a slow engine even
  // the second): the full action set proves plans of one action shortest; then
  // BFS stages focus clicks near the cells where the goal differs from the
  // initial frame (what a click changes is usually near it), widening, and on
  // the goal region (the mask's bounding box); then best-first with clicks near
  // the changes, for goals too deep for BFS (things that move after being
  // placed). A focused plan at most one action longer than the deepest full
  // layer searched is still proven shortest; longer ones are not. Returns true
  // when a plan was found; otherwise the full best-first search follows.
  bool positional_click_search() {
    const uint64_t N = opts_.nodes;
    if (bfs(std::min(1, opts_.depth), N / 10)) {
      r_.shortest = true;
      return true;
    }
    const int proven = r_.bfs_depth_done;
    const std::vector<Action> all = actions_;
    const std::vector<uint32_t> changed = changed_cells();
    struct Focus {
      const char* what;
      std::vector<Action> actions;
    };
    const Focus stages[] = {
        {"clicks on the cells the goal changes", focused_actions(all, changed, 0, false)},
        {"clicks whose effect reaches the cells the goal changes", reaching_actions(all, changed)},
        {"clicks within 1 of the cells the goal changes", focused_actions(all, changed, 1, false)},
        {"clicks within 3 of the cells the goal changes", focused_actions(all, changed, 3, false)},
        {"clicks in the goal region", focused_actions(all, mask_index_, 0, true)},
    };
    std::vector<std::vector<Action>> tried;
    for (const Focus& f : stages) {
      if (out_of_time()) break;
      if (f.actions.size() == all.size() || std::find(tried.begin(), tried.end(), f.actions) != tried.end()) continue;
      tried.push_back(f.actions);
      actions_ = f.actions;
      // Each stage gets an eighth of the node budget and of the time left, so a
      // slow engine still reaches the later stages and best-first.
      if (opts_.time_limit > 0)
        stage_deadline_ = clock_.seconds() + std::max(0.0, opts_.time_limit - clock_.seconds()) / 8;
      const bool found = bfs(opts_.depth, r_.nodes + N / 8);
      stage_deadline_ = 0;
      if (found) {
        r_.method = std::string("bfs, ") + f.what;
        r_.shortest = r_.plan.size() <= static_cast<size_t>(proven) + 1;
        return true;
      }
    }
    // Best-first over clicks near the changes or reaching them (a thing placed
    // away from its goal cells that falls or drifts onto them).
    actions_ = unite(all, stages[1].actions, stages[2].actions);
    if (actions_.size() < all.size() && !out_of_time()) {
      r_.method = "best-first, clicks near or reaching the cells the goal changes";
      if (best_first(true, r_.nodes + (N - std::min(N, r_.nodes)) / 2)) {
        shorten();
        return true;
      }
    }
    actions_ = all;
    return false;
  }

 private:
  // Distance to the goal on the mask: `shape` counts cells where one side shows
  // the goal's background (its most common masked colour) and the other does not;
  // `colour` counts all differing cells (0: at the goal). Best-first orders by
  // shape first, then colour: things must be in the right places before their
  // colours matter.
  struct Dist {
    int shape = 0, colour = 0;
    int64_t key(int cells) const { return static_cast<int64_t>(shape) * (cells + 1) + colour; }
  };

  void init_heuristic() {
    std::unordered_map<int16_t, int> counts;
    for (size_t i = 0; i < task_.goal.cells.size(); ++i)
      if (task_.mask.cells[i]) {
        ++counts[task_.goal.cells[i]];
        mask_index_.push_back(static_cast<uint32_t>(i));
      }
    int best = -1;
    for (const auto& [c, n] : counts)
      if (n > best || (n == best && c < background_)) best = n, background_ = c;
  }

  int mask_cells() const { return static_cast<int>(mask_index_.size()); }

  Dist distance(const TaskFrame& f) const {
    Dist d;
    if (f.size() != task_.mask.cells.size()) return {mask_cells() + 1, mask_cells() + 1};  // GRID_SIZE changed
    for (uint32_t i : mask_index_) {
      int16_t g = task_.goal.cells[i];
      if (g != f[i]) {
        ++d.colour;
        if ((g == background_) != (f[i] == background_)) ++d.shape;
      }
    }
    return d;
  }

  std::vector<Action> path_to(int64_t node) const {
    std::vector<Action> plan;
    for (int64_t n = node; n > 0; n = nodes_[n].parent) plan.push_back(actions_[nodes_[n].action]);
    std::reverse(plan.begin(), plan.end());
    return plan;
  }

  // A node's state, rebuilt from a root copy that no other thread uses.
  std::unique_ptr<Environment> replay(int64_t node, const Environment& root) const {
    auto e = root.clone();
    for (const Action& a : path_to(node))
      if (!e->step(a)) throw TaskError("replaying a search path failed: " + e->error());
    return e;
  }

  struct Succ {
    std::unique_ptr<Environment> env;
    uint64_t hash = 0;
    uint64_t frame_hash = 0;
    Dist dist;
    bool ok = false;      // false: the step failed or the state was already seen
    int64_t key = 0;      // best-first priority (with the settling look-ahead)
    int goal_noops = -1;  // look-ahead: the goal shows after this many noops
    uint64_t steps = 0;   // look-ahead steps run
  };

  // A best-first thread's reused buffers: frames are mapped without allocating.
  struct Lookahead {
    FrameColours colours;
    TaskFrame frame, prev;
  };

  // Best-first's successor by action `a` of `e`, a fresh clone of its parent: env,
  // hash, distance (with the settling look-ahead); not ok when its state is
  // already in `seen` (read-only here). One environment is never used by two
  // threads at once (clone() is not safe to call concurrently on one
  // environment), so the caller makes the clones.
  void expand_one(std::unique_ptr<Environment> e, size_t a, const HashSet& seen, Lookahead& L, Succ& out) {
    if (!e->step(actions_[a])) return;
    uint64_t h = e->state_hash();
    if (seen.count(h)) return;
    L.colours.map(e->frame(), e->palette(), task_.colours, L.prev);
    out.dist = distance(L.prev);
    out.frame_hash = frame_digest(L.prev);
    out.key = out.dist.key(mask_cells());
    if (out.dist.colour > 0) settle(*e, L, out);
    out.hash = h;
    out.env = std::move(e);
    out.ok = true;
  }

  // Destroys environments on the pool (freeing big object graphs is not cheap).
  void discard(std::vector<std::unique_ptr<Environment>>& trash) {
    pool_.parallel_for(trash.size(), [&](size_t i) { trash[i].reset(); });
    trash.clear();
  }

  // The settling look-ahead of best-first: from a copy of `e`, step noops until
  // the frame stops changing (at most 2 * GRID_SIZE steps); the priority is the
  // best distance seen on the way, the state's own included. Falling, flowing and
  // sliding things then count where they come to rest, and things that keep
  // moving (a global velocity, endless gravity) count where they pass the goal,
  // instead of leaving long plateaus; a goal frame on the way ends the search
  // (the plan gets those noops). The last frame joins the frame-pruning digest:
  // an action that changes no cell now but changes the future (a velocity, a
  // mode) is not pruned as a repeat of its parent's frame.
  // L.prev holds e's frame on entry.
  void settle(const Environment& e, Lookahead& L, Succ& out) const {
    auto probe = e.clone();
    TaskFrame& f = L.frame;
    TaskFrame& prev = L.prev;
    for (int k = 1; k <= 2 * size_; ++k) {
      if (!probe->step(Action::noop())) break;
      ++out.steps;
      L.colours.map(probe->frame(), probe->palette(), task_.colours, f);
      Dist d = distance(f);
      if (d.colour == 0) {
        out.goal_noops = k;
        out.key = 0;
        return;
      }
      out.key = std::min(out.key, d.key(mask_cells()));
      if (f == prev) break;
      prev.swap(f);  // keeps both buffers
    }
    out.frame_hash = out.frame_hash * 0x9E3779B97F4A7C15ull ^ frame_digest(prev);
  }

  bool budget_left() const { return r_.nodes < opts_.nodes; }
  bool past_time_limit() const { return opts_.time_limit > 0 && clock_.seconds() > opts_.time_limit; }
  // Past the time limit, or past the current stage's share of it.
  bool out_of_time() const {
    return past_time_limit() || (stage_deadline_ > 0 && clock_.seconds() > stage_deadline_);
  }
  // What stopped a search for time, for the notes; marks the result timed out
  // only when the whole time limit is spent.
  std::string time_note() {
    if (past_time_limit()) {
      r_.timed_out = true;
      return fmt::format("time limit {} s reached", opts_.time_limit);
    }
    return "its share of the time limit spent";
  }
  void reset_tree() {
    nodes_ = {{-1, -1, 0}};
    envs_.clear();
    envs_.push_back(root_->clone());
    stored_ = 1;
  }
  // Adds a node, keeping `env` while under the keep_states cap (otherwise it is
  // left in `env` for the caller to discard).
  int64_t add_node(int64_t parent, size_t action, int depth, std::unique_ptr<Environment>& env) {
    int64_t id = static_cast<int64_t>(nodes_.size());
    nodes_.push_back({parent, static_cast<int32_t>(action), depth});
    if (env && stored_ < opts_.keep_states) {
      envs_.push_back(std::move(env));
      ++stored_;
    } else {
      envs_.emplace_back();
    }
    return id;
  }
  std::unique_ptr<Environment> take_env(int64_t id) {
    if (!envs_[id]) return nullptr;
    --stored_;
    return std::move(envs_[id]);
  }
  void finish(HashSet& seen) {
    r_.distinct += seen.size();
    envs_.clear();
    stored_ = 0;
  }

  // Goal test straight on an environment's frame, through the thread's colour map.
  bool at_goal(const Environment& e, FrameColours& colours) const {
    const Frame& f = e.frame();
    const std::vector<int16_t>& colour_of = colours.ids(e.palette(), task_.colours);
    if (f.cells.size() != task_.mask.cells.size()) return false;
    for (uint32_t i : goal_order_)
      if (colour_of[f.cells[i]] != task_.goal.cells[i]) return false;
    return true;
  }

  // The masked cells where the goal differs from the initial frame.
  std::vector<uint32_t> changed_cells() const {
    TaskFrame f = task_frame(root_->frame(), root_->palette(), task_.colours);
    std::vector<uint32_t> out;
    for (uint32_t i : mask_index_)
      if (i < f.size() && f[i] != task_.goal.cells[i]) out.push_back(i);
    return out;
  }

  // The non-click actions of `all`, and its clicks within Chebyshev distance r of
  // one of `cells` — or, with `box`, of their bounding box.
  std::vector<Action> focused_actions(const std::vector<Action>& all, const std::vector<uint32_t>& cells, int r,
                                      bool box) const {
    std::vector<uint8_t> near(static_cast<size_t>(size_) * size_, 0);
    auto mark = [&](int x0, int y0, int x1, int y1) {
      for (int y = std::max(0, y0 - r); y <= std::min(size_ - 1, y1 + r); ++y)
        for (int x = std::max(0, x0 - r); x <= std::min(size_ - 1, x1 + r); ++x) near[static_cast<size_t>(y) * size_ + x] = 1;
    };
    int bx0 = size_, by0 = size_, bx1 = -1, by1 = -1;
    for (uint32_t i : cells) {
      const int x = static_cast<int>(i) % size_, y = static_cast<int>(i) / size_;
      if (box) bx0 = std::min(bx0, x), by0 = std::min(by0, y), bx1 = std::max(bx1, x), by1 = std::max(by1, y);
      else mark(x, y, x, y);
    }
    if (box && bx1 >= 0) mark(bx0, by0, bx1, by1);
    std::vector<Action> out;
    for (const Action& a : all)
      if (a.kind != Action::Kind::Click ||
          (a.x >= 0 && a.y >= 0 && a.x < size_ && a.y < size_ && near[static_cast<size_t>(a.y) * size_ + a.x]))
        out.push_back(a);
    return out;
  }

  // The actions of `all` that are in `a` or `b` (both subsets of `all`), in `all`'s order.
  static std::vector<Action> unite(const std::vector<Action>& all, const std::vector<Action>& a,
                                   const std::vector<Action>& b) {
    std::vector<Action> out;
    size_t i = 0, j = 0;
    for (const Action& x : all) {
      bool in = false;
      if (i < a.size() && a[i] == x) ++i, in = true;
      if (j < b.size() && b[j] == x) ++j, in = true;
      if (in) out.push_back(x);
    }
    return out;
  }

  // The non-click actions of `all`, and the clicks whose effect, from the initial
  // state, reaches one of `cells`: the click, then noops, against noops alone,
  // for up to `depth` steps (2 * GRID_SIZE at most); a click counts when a frame
  // differs from the baseline's at one of the cells. A falling block lands, a
  // spreading fill arrives, a button recolours something far away.
  std::vector<Action> reaching_actions(const std::vector<Action>& all, const std::vector<uint32_t>& cells) const {
    const int steps = std::max(1, std::min(opts_.depth, 2 * size_));
    std::vector<TaskFrame> baseline;
    {
      auto e = root_->clone();
      for (int t = 0; t < steps && e->step(Action::noop()); ++t)
        baseline.push_back(task_frame(e->frame(), e->palette(), task_.colours));
    }
    std::vector<Action> clicks;
    for (const Action& a : all)
      if (a.kind == Action::Kind::Click) clicks.push_back(a);
    std::vector<uint8_t> reaches(clicks.size(), 0);
    std::vector<std::unique_ptr<Environment>> envs;
    for (size_t i = 0; i < clicks.size(); ++i) envs.push_back(root_->clone());  // cloned here: one thread
    pool_.parallel_for(clicks.size(), [&](size_t i) {
      Environment& e = *envs[i];
      for (size_t t = 0; t < baseline.size() && !reaches[i]; ++t) {
        if (!e.step(t == 0 ? clicks[i] : Action::noop())) break;
        TaskFrame f = task_frame(e.frame(), e.palette(), task_.colours);
        for (uint32_t c : cells)
          if (c < f.size() && f[c] != baseline[t][c]) reaches[i] = 1;
      }
      envs[i].reset();
    });
    std::vector<Action> out;
    size_t k = 0;
    for (const Action& a : all)
      if (a.kind != Action::Kind::Click || reaches[k++]) out.push_back(a);
    return out;
  }

  // Breadth-first search, layer by layer, in chunks of parents, three parallel
  // phases per chunk:
  //  expand: each parent is expanded by one thread; per action it copies the
  //    parent into the thread's scratch environment (copy_from: no allocation),
  //    steps and hashes. A state seen in an earlier chunk (the shared sets,
  //    read-only now) or earlier in the same thread's share of this chunk is
  //    dropped on the spot; new ones are goal-tested, saved as a snapshot into
  //    the thread's byte buffer (or kept as an environment when the engine has
  //    no snapshots), and listed under their hash's shard.
  //  dedup: per shard, the threads' lists are merged in (parent, action) order
  //    and inserted into that shard's seen set: the first occurrence wins.
  //  place: winners become nodes and next-layer entries, shard by shard at
  //    offsets fixed beforehand.
  // The seen set is split into shards so that dedup runs in parallel; the
  // snapshots stay in the buffers the threads wrote (one per thread and chunk).
  // Which state wins, the first goal (lowest (parent, action) among winners) and
  // the order of the next layer (shard, then (parent, action)) do not depend on
  // the thread count, so neither does the plan. Chunk size does not either.
  static constexpr int kShardBits = 6;
  static constexpr size_t kShards = size_t{1} << kShardBits;
  static size_t shard_of(uint64_t h) { return static_cast<size_t>(h >> (64 - kShardBits)); }

  bool bfs(int max_depth, uint64_t budget) {
    std::vector<HashSet> seen(kShards);
    const uint64_t root_hash = root_->state_hash();
    seen[shard_of(root_hash)].insert(root_hash);
    nodes_ = {{-1, -1, 0}};
    struct Open {
      int64_t node = 0;
      uint32_t buffer = 0;               // snapshot: layer buffer, offset, size
      uint32_t size = 0;
      uint64_t offset = 0;
      std::unique_ptr<Environment> env;  // without snapshots; null: replayed
    };
    std::vector<std::vector<uint8_t>> layer_buffers(1), next_buffers;
    const bool snapshots = root_->save_state(layer_buffers[0]);
    std::vector<Open> frontier(1);
    frontier[0].size = static_cast<uint32_t>(layer_buffers[0].size());
    if (!snapshots) frontier[0].env = root_->clone();
    uint64_t kept = snapshots ? 0 : 1;  // environments held by frontier + next
    struct Fresh {
      uint64_t index;  // (parent - begin) * A + action
      uint64_t hash;
      uint64_t offset;
      uint32_t size;
      uint32_t buffer;
      bool goal;
      std::unique_ptr<Environment> env;
    };
    struct Worker {
      std::unique_ptr<Environment> parent, scratch;
      HashSet local;
      FrameColours goal;
      std::vector<uint8_t> bytes;  // snapshots of this chunk's new states
      std::vector<std::vector<Fresh>> fresh = std::vector<std::vector<Fresh>>(kShards);
    };
    std::vector<Worker> workers(pool_.size());
    for (Worker& W : workers) W.parent = root_->clone();  // here: clones are made by one thread
    const size_t A = actions_.size();
    const size_t chunk_parents = std::max<size_t>(256, 65536 / A);
    std::vector<std::vector<Fresh*>> won(kShards);
    std::vector<uint64_t> first_goal(kShards);
    auto done = [&](bool ok) {
      for (const HashSet& s : seen) r_.distinct += s.size();
      return ok;
    };
    auto note = [&](const std::string& why) {
      r_.note += (r_.note.empty() ? "" : "; ") + fmt::format("bfs ({} actions): {}", A, why);
    };
    for (int depth = 1; depth <= max_depth; ++depth) {
      std::vector<Open> next;
      next_buffers.clear();
      for (size_t begin = 0; begin < frontier.size(); begin += chunk_parents) {
        if (r_.nodes >= budget) {
          note(fmt::format("node budget spent at depth {}", depth));
          return done(false);
        }
        if (out_of_time()) {
          note(fmt::format("{} at depth {}", time_note(), depth));
          return done(false);
        }
        const size_t end = std::min(frontier.size(), begin + chunk_parents);
        for (size_t p = begin; p < end; ++p)
          if (frontier[p].env) --kept;  // the threads take (and free) the parents' environments
        const bool keep_env = !snapshots && kept < opts_.keep_states;
        const uint32_t buffer_base = static_cast<uint32_t>(next_buffers.size());
        // expand
        std::atomic<bool> timed_out{false};
        // Waking the threads costs more than a small chunk's work (deep, narrow
        // searches): those run on the calling thread, with the same results.
        ThreadPool& pool = (end - begin) * A < 1024 ? serial_ : pool_;
        pool.parallel_for_worker(end - begin, [&](size_t k, unsigned w) {
          // A chunk can take long on a slow engine: the time limit is also checked per parent.
          if (timed_out.load(std::memory_order_relaxed) || out_of_time()) {
            timed_out = true;
            return;
          }
          Worker& W = workers[w];
          Open& open = frontier[begin + k];
          std::unique_ptr<Environment> owned;
          const Environment* parent = nullptr;
          if (snapshots) {
            if (!W.parent->load_state(layer_buffers[open.buffer].data() + open.offset, open.size))
              throw TaskError("restoring a search state failed: " + W.parent->error());
            parent = W.parent.get();
          } else {
            owned = std::move(open.env);
            if (!owned) owned = replay(open.node, *roots_[w]);
            parent = owned.get();
          }
          for (size_t a = 0; a < A; ++a) {
            if (!W.scratch || !W.scratch->copy_from(*parent)) W.scratch = parent->clone();
            if (!W.scratch->step(actions_[a])) continue;
            const uint64_t h = W.scratch->state_hash();
            if (seen[shard_of(h)].contains(h) || !W.local.insert(h).second) continue;
            Fresh f{k * A + a, h, W.bytes.size(), 0, buffer_base + w, at_goal(*W.scratch, W.goal), nullptr};
            if (snapshots) {
              W.scratch->save_state(W.bytes);
              f.size = static_cast<uint32_t>(W.bytes.size() - f.offset);
            } else if (keep_env) {
              f.env = std::move(W.scratch);
            }
            W.fresh[shard_of(h)].push_back(std::move(f));
          }
        });
        if (timed_out) {
          note(fmt::format("{} at depth {}", time_note(), depth));
          return done(false);
        }
        r_.nodes += (end - begin) * A;
        for (Worker& W : workers) {
          W.local.clear();
          next_buffers.push_back(std::move(W.bytes));
          W.bytes = {};
        }
        // dedup
        pool.parallel_for(kShards, [&](size_t sh) {
          won[sh].clear();
          first_goal[sh] = UINT64_MAX;
          std::vector<size_t> at(workers.size(), 0);
          for (;;) {
            Fresh* f = nullptr;
            size_t from = 0;
            for (size_t w = 0; w < workers.size(); ++w) {
              const auto& list = workers[w].fresh[sh];
              if (at[w] < list.size() && (!f || list[at[w]].index < f->index)) f = &workers[w].fresh[sh][at[w]], from = w;
            }
            if (!f) break;
            ++at[from];
            if (!seen[sh].insert(f->hash).second) continue;
            won[sh].push_back(f);
            if (f->goal && first_goal[sh] == UINT64_MAX) first_goal[sh] = f->index;
          }
        });
        uint64_t goal_index = UINT64_MAX;
        for (uint64_t g : first_goal) goal_index = std::min(goal_index, g);
        if (goal_index != UINT64_MAX) {
          const int64_t id = static_cast<int64_t>(nodes_.size());
          nodes_.push_back({frontier[begin + goal_index / A].node, static_cast<int32_t>(goal_index % A), depth});
          r_.found = true;
          r_.plan = path_to(id);
          return done(true);
        }
        // place
        std::vector<size_t> offset(kShards + 1, 0);
        for (size_t sh = 0; sh < kShards; ++sh) offset[sh + 1] = offset[sh] + won[sh].size();
        const size_t node_base = nodes_.size(), next_base = next.size();
        nodes_.resize(node_base + offset[kShards]);
        next.resize(next_base + offset[kShards]);
        pool.parallel_for(kShards, [&](size_t sh) {
          for (size_t j = 0; j < won[sh].size(); ++j) {
            Fresh& f = *won[sh][j];
            const size_t slot = offset[sh] + j;
            nodes_[node_base + slot] = {frontier[begin + f.index / A].node, static_cast<int32_t>(f.index % A), depth};
            Open& o = next[next_base + slot];
            o.node = static_cast<int64_t>(node_base + slot);
            o.buffer = f.buffer;
            o.offset = f.offset;
            o.size = f.size;
            o.env = std::move(f.env);
          }
        });
        if (!snapshots)
          for (size_t i = next_base; i < next.size(); ++i) kept += next[i].env ? 1 : 0;
        for (Worker& W : workers)
          for (auto& list : W.fresh) list.clear();
      }
      r_.bfs_depth_done = depth;
      frontier = std::move(next);
      layer_buffers.swap(next_buffers);
      if (frontier.empty()) {
        note(fmt::format("every reachable state seen by depth {}", depth));
        r_.exhausted = true;
        return done(false);
      }
    }
    note(fmt::format("no plan of length <= {}", max_depth));
    return done(false);
  }

  bool best_first(bool prune_frames, uint64_t budget) {
    HashSet seen = {root_->state_hash()};
    HashSet seen_frames = {
        frame_digest(task_frame(root_->frame(), root_->palette(), task_.colours))};
    reset_tree();
    struct Open {
      int64_t h;
      int g;
      int64_t node;
      bool operator>(const Open& o) const {
        if (h != o.h) return h > o.h;
        if (g != o.g) return g > o.g;
        return node > o.node;
      }
    };
    std::priority_queue<Open, std::vector<Open>, std::greater<Open>> open;
    std::vector<Lookahead> lookahead(pool_.size());
    open.push({0, 0, 0});
    const size_t A = actions_.size();
    auto stop = [&](const std::string& why) {
      if (!r_.note.empty()) r_.note += "; ";
      r_.note += why;
      finish(seen);
      return false;
    };
    while (!open.empty()) {
      if (r_.nodes >= budget) return stop(fmt::format("best-first ({} actions): node budget spent", A));
      if (out_of_time()) return stop("best-first: " + time_note());
      Open top = open.top();
      open.pop();
      if (top.g >= opts_.max_plan) continue;
      std::unique_ptr<Environment> parent = take_env(top.node);
      if (!parent) parent = replay(top.node, *root_);
      std::vector<Succ> succ(A);
      std::vector<std::unique_ptr<Environment>> clones;
      for (size_t a = 0; a + 1 < A; ++a) clones.push_back(parent->clone());
      clones.push_back(std::move(parent));
      pool_.parallel_for_worker(A, [&](size_t a, unsigned w) {
        expand_one(std::move(clones[a]), a, seen, lookahead[w], succ[a]);
      });
      r_.nodes += A;
      std::vector<std::unique_ptr<Environment>> trash;
      for (size_t a = 0; a < A; ++a) {
        Succ& s = succ[a];
        r_.lookahead_steps += s.steps;
        if (!s.ok || !seen.insert(s.hash).second || (prune_frames && !seen_frames.insert(s.frame_hash).second)) {
          if (s.env) trash.push_back(std::move(s.env));
          continue;
        }
        int64_t id = add_node(top.node, a, top.g + 1, s.env);
        if (s.env) trash.push_back(std::move(s.env));
        if (s.dist.colour == 0 || s.goal_noops > 0) {
          r_.found = true;
          r_.plan = path_to(id);
          r_.plan.insert(r_.plan.end(), static_cast<size_t>(std::max(0, s.goal_noops)), Action::noop());
          finish(seen);
          return true;
        }
        open.push({s.key, top.g + 1, id});
      }
      discard(trash);
    }
    return stop(fmt::format("best-first: no plan of length <= {}", opts_.max_plan));
  }

  // Number of actions of `plan` after which the goal is first reached, or -1.
  int reaches(const std::vector<Action>& plan) const {
    auto e = root_->clone();
    for (size_t i = 0; i < plan.size(); ++i) {
      if (!e->step(plan[i])) return -1;
      if (distance(task_frame(e->frame(), e->palette(), task_.colours)).colour == 0) return static_cast<int>(i + 1);
    }
    return -1;
  }

  // Drop single actions, last to first, while the goal stays reached; repeat
  // while that helps.
  void shorten() {
    std::vector<Action> plan = r_.plan;
    for (bool changed = true; changed;) {
      changed = false;
      for (size_t i = plan.size(); i-- > 0;) {
        if (i >= plan.size()) continue;
        std::vector<Action> cand = plan;
        cand.erase(cand.begin() + static_cast<std::ptrdiff_t>(i));
        int k = reaches(cand);
        if (k < 0) continue;
        cand.resize(static_cast<size_t>(k));
        plan = std::move(cand);
        changed = true;
      }
    }
    r_.plan = plan;
  }

  Stopwatch clock_;         // since the solve began (the time limit)
  double stage_deadline_ = 0;  // on clock_; 0: none
  Stopwatch search_clock_;  // since the set-up ended
  const Task& task_;
  const SolveOptions& opts_;
  ThreadPool& pool_;
  ThreadPool serial_{1};  // runs inline on the calling thread
  PlanResult& r_;
  std::unique_ptr<Environment> root_;
  std::vector<std::unique_ptr<Environment>> roots_;  // one per pool thread, for replays
  int size_ = 0;
  std::vector<Action> actions_;
  int16_t background_ = 0;
  std::vector<uint32_t> mask_index_;  // the masked cells, row-major
  // The masked cells in goal-test order: those where the goal differs from the
  // initial frame first (a state not at the goal usually fails on one of them at
  // once), then the rest.
  std::vector<uint32_t> goal_order_;
  std::vector<NodeRec> nodes_;
  std::vector<std::unique_ptr<Environment>> envs_;  // per node; null when not kept
  uint64_t stored_ = 0;
};

}  // namespace

PlanResult solve_planning(const Task& task, const SolveOptions& opts, ThreadPool& pool) {
  if (task.type != TaskType::Planning) throw TaskError(task.file.string() + ": not a planning task");
  Stopwatch clock;
  PlanResult r;
  Planner(task, opts, pool, r).run();
  r.seconds = clock.seconds();
  if (r.found) r.verified = plan_reaches_goal(task, opts, r.plan);
  return r;
}

bool plan_reaches_goal(const Task& task, const SolveOptions& opts, const std::vector<Action>& plan) {
  auto program = load_program_checked(task_program_path(task, opts, task.program));
  auto env = make_env_checked(opts.engine, program);
  if (!env->reset(task.env_seed) || env->frame().size != task.goal.width) return false;
  auto at_goal = [&] {
    TaskFrame f = task_frame(env->frame(), env->palette(), task.colours);
    if (f.size() != task.mask.cells.size()) return false;
    for (size_t i = 0; i < f.size(); ++i)
      if (task.mask.cells[i] && task.goal.cells[i] != f[i]) return false;
    return true;
  };
  if (at_goal()) return true;
  for (const Action& a : plan) {
    if (!env->step(a)) return false;
    if (at_goal()) return true;
  }
  return false;
}

nlohmann::json planning_json(const PlanResult& r) {
  nlohmann::json plan = nlohmann::json::array();
  for (const auto& a : r.plan) plan.push_back(format_action(a));
  nlohmann::json j = {{"found", r.found},
                      {"plan", r.found ? plan : nlohmann::json(nullptr)},
                      {"length", r.found ? nlohmann::json(r.plan.size()) : nlohmann::json(nullptr)},
                      {"method", r.method},
                      {"shortest", r.shortest},
                      {"bfs_depth_done", r.bfs_depth_done},
                      {"nodes", r.nodes},
                      {"distinct_states", r.distinct},
                      {"action_set", r.actions},
                      {"click_use", r.click_use},
                      {"stochastic", r.stochastic},
                      {"env_seed", r.env_seed},
                      {"verified", r.verified},
                      {"seconds", r.seconds},
                      {"nodes_per_second", per_second(static_cast<double>(r.nodes), r.seconds)}};
  if (!r.note.empty()) j["note"] = r.note;
  if (r.stochastic) j["oracle"] = "the planner simulates with the environment's seed (privileged oracle)";
  return j;
}

std::string planning_summary(const PlanResult& r) {
  std::string s;
  if (r.found) {
    std::string acts;
    for (size_t i = 0; i < r.plan.size(); ++i) acts += (i ? ", " : "") + format_action(r.plan[i]);
    s += fmt::format("plan ({} action{}, {}{}): {}\n", r.plan.size(), r.plan.size() == 1 ? "" : "s", r.method,
                     r.shortest ? ", shortest" : ", not guaranteed shortest", acts.empty() ? "(none needed)" : acts);
    s += fmt::format("replayed on a fresh environment: {}\n", r.verified ? "reaches the goal" : "DOES NOT reach the goal");
  } else {
    s += "no plan found\n";
  }
  if (!r.note.empty()) s += r.note + "\n";
  s += fmt::format("search: {} actions per state (clicks: {}), {} nodes generated, {} distinct states\n", r.actions,
                   r.click_use, r.nodes, r.distinct);
  if (r.stochastic)
    s += fmt::format("stochastic program: the planner simulates with the environment's seed {} "
                     "(the privileged oracle of the AutumnBench paper)\n",
                     r.env_seed);
  s += fmt::format("time: {:.3f} s, {:.0f} nodes/s\n", r.seconds, per_second(static_cast<double>(r.nodes), r.seconds));
  return s;
}

}  // namespace autumn::agent
