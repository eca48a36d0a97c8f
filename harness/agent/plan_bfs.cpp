#include "harness/agent/plan_bfs.hpp"

#include <fmt/core.h>

#include <atomic>
#include <mutex>

#include "harness/agent/huge_pages.hpp"
#include "harness/agent/seen_set.hpp"
#include "harness/agent/state_hash_set.hpp"
#include "harness/agent/warm_blocks.hpp"

namespace autumn::agent {

std::atomic<bool> bfs_store_every_state_for_testing{false};

namespace {

constexpr size_t kShards = SeenSet::kShards;
size_t shard_of(uint64_t h) { return SeenSet::shard_of(h); }

class LayeredBfs {
 public:
  LayeredBfs(PlanProblem& p, const BfsSpec& spec)
      : p_(p), spec_(spec), start_(spec.start ? *spec.start : p.root()), A_(spec.actions.size()) {}
  ~LayeredBfs() { keep_workers(std::move(workers_)); }
  LayeredBfs(const LayeredBfs&) = delete;
  LayeredBfs& operator=(const LayeredBfs&) = delete;

  BfsOutcome run();

 private:
  struct Open {
    int64_t node = 0;
    uint32_t buffer = 0;  // snapshot: buffer, offset, size in its layer
    uint32_t size = 0;    // 0: not stored (never expanded, or replayed if it is)
    uint64_t offset = 0;
    std::unique_ptr<Environment> env;  // without snapshots; null: replayed
  };
  struct Layer {
    std::vector<Open, WarmAllocator<Open>> open;
    std::vector<std::vector<uint8_t>> buffers;
    // Nodes of the layer given no Open: placed while store_next_ was false, so
    // the node budget is spent before the search could expand them.
    size_t unplaced = 0;
  };
  // A new state of the chunk, as its worker lists it under its hash's shard:
  // 16 bytes, since each goes to one of 64 lists (stores scattered over 64
  // places); what else is known of it is appended to the worker's details, in
  // order (one stream of stores). With the whole record (48 bytes) in the
  // shard lists, two threads ran a third slower each than one (docs/design.md,
  // "Memory a search keeps for the next").
  struct Fresh {
    uint64_t hash;
    uint32_t index;   // (parent - begin) * A + action: below 2^32 (run() sizes chunks so)
    uint32_t detail;  // its entry in its worker's details
  };
  struct Detail {
    uint64_t offset;  // its snapshot's, in its worker's buffer of its side
    uint32_t size;    // 0: not stored
    bool hit, free;
    std::unique_ptr<Environment> env;  // kept instead of a snapshot
  };
  struct Pick {  // a Fresh in dedup's order, and its worker
    const Fresh* fresh;
    uint32_t worker;
  };
  struct alignas(64) Worker {  // each on its own cache lines: the threads write their own all the time
    std::unique_ptr<Environment> parent, replay_root;
    std::unique_ptr<Environment> scratch[2];  // successors: one stepped while the other is settled (expand_parent)
    StateHashSet local;  // this thread's states of this chunk so far
    FrameColours colours;
    std::vector<uint8_t> bytes[2];  // this chunk's new states: [0] this layer (free), [1] the next
    size_t last_bytes[2] = {0, 0};  // their size in the last chunk: the next one's reservation
    uint32_t largest = 0;           // the largest snapshot it has stored, or the root's
    std::vector<std::vector<Fresh>> fresh = std::vector<std::vector<Fresh>>(kShards);
    std::vector<Detail> details;  // this chunk's, in the order met
  };
  // The workers' memory (the chunk's set of states, the shards' lists of new
  // states) outlives a search: the next search takes it back (take_workers),
  // so it grows and faults its pages in once per process, not once per
  // search (docs/design.md, "Memory a search keeps for the next"). What a
  // search leaves is emptied first (keep_workers): the environments (of this
  // program's module), the palette's colour cache, any unplaced new states.
  struct KeptWorkers {
    std::mutex mu;
    std::vector<Worker> spare;  // guarded by mu; at most kept_workers_cap()
  };
  friend size_t autumn::agent::bfs_kept_workers_for_testing();
  friend void autumn::agent::bfs_drop_kept_workers_for_testing();
  static KeptWorkers& kept_workers();
  static std::vector<Worker> take_workers(size_t n);
  static void keep_workers(std::vector<Worker> workers) noexcept;

  bool is_free(size_t a) const { return !spec_.free.empty() && spec_.free[a]; }
  bool hit(const Environment& e, uint64_t h, Worker& W) const {
    return (spec_.targets && spec_.targets->contains(h)) || (spec_.goal && p_.goal().reached(e, W.colours));
  }
  std::vector<Action> path(int64_t node) const;
  std::unique_ptr<Environment> replay(int64_t node, const Environment& from) const;
  const Environment* load_parent(Open& open, Worker& W, std::unique_ptr<Environment>& owned, bool take) const;
  void expand_parent(size_t begin, size_t k, Worker& W, bool free_phase);
  // A successor stepped and hashed: seen before, or new (recorded, its state stored if `store`).
  struct Stepped {
    size_t action;
    uint64_t hash;
    int scratch;  // which of the worker's two
  };
  void settle(const Stepped& s, size_t k, Worker& W, bool store_free, bool store_next);
  bool expand_chunk(size_t begin, size_t end, bool free_phase);
  size_t next_shards_to_store(size_t begin, size_t end) const;
  // One phase of a layer over cur_.open (which grows in the free phase); a plan
  // or a stop ends the search (returns true, out_ set).
  bool phase(int layer, bool free_phase, int64_t& hit_node);
  void dedup();
  void place(size_t begin, bool free_phase);
  BfsOutcome finish(int64_t node, bool found);
  int target_of(int64_t node) const;

  PlanProblem& p_;
  const BfsSpec& spec_;
  const Environment& start_;
  const size_t A_;
  size_t free_count_[2] = {0, 0};  // actions per parent in a phase: [0] costing, [1] free
  size_t chunk_parents_ = 0;
  ThreadPool serial_{1};
  SeenSet seen_;
  std::vector<Node, WarmAllocator<Node>> nodes_;
  Layer cur_, next_;
  bool snapshots_ = false;
  uint64_t kept_ = 0;  // environments held (no snapshots)
  bool keep_env_ = false;
  bool store_next_ = true;   // this chunk stores the next layer's states (expand_chunk)
  // ...of the successors in shards below this one only (kShards: all): those the
  // node budget may let the search expand (next_shards_to_store).
  size_t store_shards_ = kShards;
  double win_rate_ = 1.0;  // new states per successor in the last costing chunk
  bool final_layer_ = false;  // the layer of cost max_cost - 1: no next layer is expanded
  uint32_t buffer_base_[2] = {0, 0};
  std::vector<Worker> workers_;
  std::vector<std::vector<Pick>> won_ = std::vector<std::vector<Pick>>(kShards);
  std::vector<std::vector<Pick>> merged_ = std::vector<std::vector<Pick>>(kShards);  // dedup's, kept for its storage
  std::vector<uint64_t> first_hit_ = std::vector<uint64_t>(kShards);
  std::vector<uint64_t> stored_ = std::vector<uint64_t>(kShards);  // per shard, for BfsOutcome::stored
  BfsOutcome out_;
  std::vector<uint64_t, WarmAllocator<uint64_t>> hash_of_;  // per node, for target lookups
};

// At most this many workers are kept (a search takes as many as it has threads),
// none when the warm-memory setting keeps nothing (warm_cap() 0: every search's
// memory is given back at its end).
size_t kept_workers_cap() { return warm_cap() == 0 ? 0 : 8; }

LayeredBfs::KeptWorkers& LayeredBfs::kept_workers() {
  static auto* kept = new KeptWorkers();  // never destroyed: it outlives every search
  return *kept;
}

std::vector<LayeredBfs::Worker> LayeredBfs::take_workers(size_t n) {
  std::vector<Worker> w;
  {
    KeptWorkers& k = kept_workers();
    std::lock_guard<std::mutex> lock(k.mu);
    while (w.size() < n && !k.spare.empty()) {
      w.push_back(std::move(k.spare.back()));
      k.spare.pop_back();
    }
  }
  w.resize(n);
  return w;
}

void LayeredBfs::keep_workers(std::vector<Worker> workers) noexcept {
  for (Worker& W : workers) {
    W.parent.reset();
    W.replay_root.reset();
    W.scratch[0].reset();
    W.scratch[1].reset();
    W.local.clear();
    W.colours = FrameColours{};
    W.bytes[0] = {};
    W.bytes[1] = {};
    W.last_bytes[0] = W.last_bytes[1] = 0;
    W.largest = 0;
    for (auto& list : W.fresh) list.clear();
    W.details.clear();
  }
  try {
    KeptWorkers& k = kept_workers();
    std::lock_guard<std::mutex> lock(k.mu);
    for (Worker& W : workers)
      if (k.spare.size() < kept_workers_cap()) k.spare.push_back(std::move(W));
  } catch (...) {  // the lock failed: the memory is freed instead
  }
}

std::vector<Action> LayeredBfs::path(int64_t node) const { return path_to(nodes_, spec_.actions, node); }

std::unique_ptr<Environment> LayeredBfs::replay(int64_t node, const Environment& from) const {
  auto e = from.clone();
  for (const Action& a : path(node))
    if (!e->step(a)) throw TaskError("replaying a search path failed: " + e->error());
  return e;
}

const Environment* LayeredBfs::load_parent(Open& open, Worker& W, std::unique_ptr<Environment>& owned,
                                           bool take) const {
  if (snapshots_ && open.size > 0) {
    if (!W.parent->load_state(cur_.buffers[open.buffer].data() + open.offset, open.size))
      throw TaskError("restoring a search state failed: " + W.parent->error());
    return W.parent.get();
  }
  if (!take) return open.env ? open.env.get() : (owned = replay(open.node, *W.replay_root)).get();
  owned = std::move(open.env);
  if (!owned) owned = replay(open.node, *W.replay_root);
  return owned.get();
}

// Successors are settled one action late: each one's slots in the seen set and
// in the chunk's set (cache misses in a large search) are fetched while the
// next action is stepped, then it is settled in action order, so the results
// are those of settling each at once.
void LayeredBfs::expand_parent(size_t begin, size_t k, Worker& W, bool free_phase) {
  Open& open = cur_.open[begin + k];
  if (nodes_[open.node].depth >= spec_.max_steps) return;
  std::unique_ptr<Environment> owned;
  const Environment* parent = load_parent(open, W, owned, !free_phase);
  // A child is stored (its snapshot, or its environment) only if it may be
  // expanded: below the depth limit, and for the next layer only while the
  // node budget can outlast this one (store_next_).
  const bool expandable = nodes_[open.node].depth + 1 < spec_.max_steps;
  const bool store_free = expandable, store_next = expandable && store_next_;
  bool pending = false;
  Stepped last{};
  int next = 0;
  for (size_t a = 0; a < A_; ++a) {
    if (is_free(a) != free_phase) continue;
    std::unique_ptr<Environment>& env = W.scratch[next];
    if (!env || !env->copy_from(*parent)) env = parent->clone();
    if (!env->step(spec_.actions[a])) continue;
    const uint64_t h = env->state_hash();
    seen_.prefetch(h);
    W.local.prefetch(h);
    if (pending) settle(last, k, W, store_free, store_next);
    last = Stepped{a, h, next};
    pending = true;
    next ^= 1;
  }
  if (pending) settle(last, k, W, store_free, store_next);
}

void LayeredBfs::settle(const Stepped& s, size_t k, Worker& W, bool store_free, bool store_next) {
  const uint64_t h = s.hash;
  if (seen_.contains(h) || !W.local.insert(h)) return;
  std::unique_ptr<Environment>& env = W.scratch[s.scratch];
  const int side = is_free(s.action) ? 0 : 1;
  std::vector<uint8_t>& bytes = W.bytes[side];
  Detail d{bytes.size(), 0, hit(*env, h, W), side == 0, nullptr};
  const bool store = side == 0 ? store_free : store_next && shard_of(h) < store_shards_;
  if (store && snapshots_) {
    env->save_state(bytes);
    d.size = static_cast<uint32_t>(bytes.size() - d.offset);
    W.largest = std::max(W.largest, d.size);
  } else if (store && keep_env_) {
    d.env = std::move(env);
  }
  const auto index = static_cast<uint32_t>(k * A_ + s.action);
  W.fresh[shard_of(h)].push_back(Fresh{h, index, static_cast<uint32_t>(W.details.size())});
  W.details.push_back(std::move(d));
}

// Expands cur_.open[begin, end) by the free actions or by the others; false when
// the time limit stopped it.
bool LayeredBfs::expand_chunk(size_t begin, size_t end, bool free_phase) {
  if (!free_phase)
    for (size_t i = begin; i < end; ++i)
      if (cur_.open[i].env) --kept_;  // the threads take (and free) the parents' environments
  keep_env_ = !snapshots_ && kept_ < p_.opts().keep_states;
  // The next layer is expanded only if there is one (max_cost) and the nodes
  // counted by the end of this one (every remaining parent by every costing
  // action) leave budget: otherwise its states would be stored and never read.
  // A node without a stored state is replayed from the root if it is ever
  // expanded (load_parent).
  store_next_ = free_phase || (!final_layer_ && out_.nodes + (cur_.open.size() - begin) * free_count_[0] < spec_.limit.nodes);
  store_shards_ = free_phase || !store_next_ ? kShards : next_shards_to_store(begin, end);
  buffer_base_[0] = static_cast<uint32_t>(cur_.buffers.size());
  buffer_base_[1] = static_cast<uint32_t>(next_.buffers.size());
  // Each worker's buffers start as large as its last chunk's and a half more,
  // or, when that is 4 MiB or more, as every successor of the chunk stored at
  // the largest snapshot size met so far (up to 256 MiB): grown by doubling
  // instead, they were copied and their pages faulted in again at each
  // doubling, and the first chunk of a wide layer follows a small one.
  // Reserved pages cost no memory until written, and past the first 2 MiB are
  // advised onto huge pages (huge_pages.hpp). Below 4 MiB a search is small,
  // and a reservation from the memory malloc holds costs no page faults.
  uint64_t largest = 0;
  for (const Worker& W : workers_) largest = std::max<uint64_t>(largest, W.largest);
  const bool stores[2] = {true, store_next_};
  for (Worker& W : workers_)
    for (int side = 0; side < 2; ++side) {
      uint64_t all = stores[side] ? (end - begin) * free_count_[side == 0 ? 1 : 0] * largest : 0;
      if (side == 1) all = all / kShards * store_shards_;
      if (all < 2 * kHugePage) all = 0;
      reserve_huge(W.bytes[side], std::max<uint64_t>(W.last_bytes[side] + W.last_bytes[side] / 2,
                                                     std::min<uint64_t>(all, uint64_t{256} << 20)));
    }
  std::atomic<bool> timed_out{false};
  std::atomic<size_t> expanded{0};  // parents whose successors were all generated
  // Waking the threads costs more than a small chunk's work (deep, narrow
  // searches): those run on the calling thread, with the same results.
  ThreadPool& pool = (end - begin) * A_ < 1024 ? serial_ : p_.pool();
  pool.parallel_for_worker(end - begin, [&](size_t k, unsigned w) {
    // A chunk can take long on a slow engine: the time limit is also checked per parent.
    if (timed_out.load(std::memory_order_relaxed) || spec_.limit.out_of_time()) {
      timed_out = true;
      return;
    }
    expand_parent(begin, k, workers_[w], free_phase);
    expanded.fetch_add(1, std::memory_order_relaxed);
  });
  // A chunk the time limit cut short is not placed, but its successors were
  // generated: counted, so that the rate of a slow engine (a chunk longer than
  // the limit) is not reported as a few successors in the whole time.
  out_.nodes += (timed_out ? expanded.load() : end - begin) * free_count_[free_phase ? 1 : 0];
  if (timed_out) return false;
  for (Worker& W : workers_) {
    W.local.clear();
    W.last_bytes[0] = W.bytes[0].size();
    W.last_bytes[1] = W.bytes[1].size();
    release_unused(W.bytes[0]);  // kept until the layer is done: only what it holds stays resident
    release_unused(W.bytes[1]);
    cur_.buffers.push_back(std::move(W.bytes[0]));
    next_.buffers.push_back(std::move(W.bytes[1]));
    W.bytes[0] = {};
    W.bytes[1] = {};
  }
  return true;
}

// How many of the hash shards' new states of the next layer this chunk stores.
// Without free actions, the next layer is expanded chunk by chunk in its open
// order until the node count reaches the budget, and this layer ends with a
// count known now; so the budget expands the next layer's first `expanded`
// entries and no more. This chunk's winners take the entries from the next
// layer's current size on, shard by shard (place), so only its lowest shards
// can fall within them. Which shards is estimated, at half the last chunk's
// rate of new states (too many shards cost only bytes): a parent left
// unstored is replayed from the start if it is expanded after all
// (load_parent), so the search is the same either way. A budget that ends a
// search early in a wide layer (gameOfLife's third: 4k of the 66k states of
// the second are expanded) stored every state of that layer before.
size_t LayeredBfs::next_shards_to_store(size_t begin, size_t end) const {
  if (free_count_[1] > 0 || bfs_store_every_state_for_testing.load()) return kShards;
  const uint64_t at_end = out_.nodes + (cur_.open.size() - begin) * free_count_[0];  // < the budget
  const uint64_t per_chunk = chunk_parents_ * free_count_[0];
  if (per_chunk == 0) return kShards;
  const uint64_t remaining = spec_.limit.nodes - at_end;
  const uint64_t chunks = remaining / per_chunk + (remaining % per_chunk != 0);
  if (chunks >= UINT64_MAX / chunk_parents_) return kShards;  // no budget to speak of
  const uint64_t expanded = chunks * chunk_parents_;
  const uint64_t placed = next_.open.size();
  if (placed >= expanded) return 0;
  const double per_shard = (end - begin) * free_count_[0] * win_rate_ * 0.5 / kShards;
  const double shards = static_cast<double>(expanded - placed) / std::max(per_shard, 1.0) + 2;
  return shards >= kShards ? kShards : static_cast<size_t>(shards);
}

void LayeredBfs::dedup() {
  // Room in the seen set for every new state of the chunk, before the threads insert.
  std::vector<size_t> incoming(kShards, 0);
  for (const Worker& W : workers_)
    for (size_t sh = 0; sh < kShards; ++sh) incoming[sh] += W.fresh[sh].size();
  seen_.reserve(incoming, p_.pool());
  p_.pool().parallel_for(kShards, [&](size_t sh) {
    // Each shard's lists are taken out of their tables while they grow (their
    // vector headers sit side by side, written on every push), and put back.
    std::vector<Pick> won = std::move(won_[sh]);
    won.clear();
    // The shard's new states of every worker in index order, the order a serial
    // search meets them (of equal states, the first wins)...
    std::vector<Pick> order = std::move(merged_[sh]);
    order.clear();
    std::vector<size_t> at(workers_.size(), 0);
    for (;;) {
      const Fresh* f = nullptr;
      size_t from = 0;
      for (size_t w = 0; w < workers_.size(); ++w) {
        const auto& list = workers_[w].fresh[sh];
        if (at[w] < list.size() && (!f || list[at[w]].index < f->index)) f = &list[at[w]], from = w;
      }
      if (!f) break;
      ++at[from];
      order.push_back(Pick{f, static_cast<uint32_t>(from)});
    }
    // ...then into the seen set, each insert's table slots fetched a few ahead:
    // the set outgrows the caches, and a miss per insert was most of this phase.
    constexpr size_t kAhead = 8;
    // Counted here and written once: neighbouring shards' counters share a
    // cache line, and the other thread settles the shard beside this one.
    uint64_t stored = 0, first_hit = UINT64_MAX;
    for (size_t i = 0; i < order.size(); ++i) {
      if (i + kAhead < order.size()) seen_.prefetch(order[i + kAhead].fresh->hash);
      const Pick p = order[i];
      if (!seen_.insert(p.fresh->hash)) continue;
      won.push_back(p);
      const Detail& d = workers_[p.worker].details[p.fresh->detail];
      stored += d.size > 0 || d.env;  // its state was kept
      if (d.hit) first_hit = std::min<uint64_t>(first_hit, p.fresh->index);
    }
    stored_[sh] += stored;
    first_hit_[sh] = first_hit;
    won_[sh] = std::move(won);
    merged_[sh] = std::move(order);
  });
}

// Winners become nodes: free ones join this layer, the others the next. Each
// shard writes its own slots; without free actions every winner joins the next
// layer, written in place there (no serial pass over the winners), or, when the
// budget ends before that layer could be expanded, only as a node (its path and
// hash, for a hit): its Open would never be read.
void LayeredBfs::place(size_t begin, bool free_phase) {
  std::vector<size_t> offset(kShards + 1, 0);
  for (size_t sh = 0; sh < kShards; ++sh) offset[sh + 1] = offset[sh] + won_[sh].size();
  const size_t node_base = nodes_.size();
  resize_huge(nodes_, node_base + offset[kShards]);
  resize_huge(hash_of_, nodes_.size());
  const bool direct = !free_phase && free_count_[1] == 0;  // every winner joins next_
  const bool unplaced = direct && !store_next_;             // ...and is never expanded: no Open
  const size_t open_base = next_.open.size();
  if (unplaced) next_.unplaced += offset[kShards];
  else if (direct) resize_huge(next_.open, open_base + offset[kShards]);
  std::vector<Open> placed(direct ? 0 : offset[kShards]);
  std::vector<uint8_t> free(direct ? 0 : offset[kShards]);
  std::vector<uint64_t> kept(kShards, 0);
  p_.pool().parallel_for(kShards, [&](size_t sh) {
    uint64_t kept_here = 0;  // written once (neighbouring shards' counters share a cache line)
    for (size_t j = 0; j < won_[sh].size(); ++j) {
      const Pick p = won_[sh][j];
      const Fresh& f = *p.fresh;
      Detail& d = workers_[p.worker].details[f.detail];
      const size_t slot = offset[sh] + j;
      const Open& parent = cur_.open[begin + f.index / A_];
      nodes_[node_base + slot] = {parent.node, static_cast<int32_t>(f.index % A_),
                                  nodes_[parent.node].depth + 1};
      hash_of_[node_base + slot] = f.hash;
      if (unplaced) continue;
      Open& o = direct ? next_.open[open_base + slot] : placed[slot];
      o.node = static_cast<int64_t>(node_base + slot);
      o.buffer = buffer_base_[d.free ? 0 : 1] + p.worker;
      o.offset = d.offset;
      o.size = d.size;
      o.env = std::move(d.env);
      kept_here += o.env ? 1 : 0;
      if (!direct) free[slot] = d.free;
    }
    kept[sh] = kept_here;
  });
  for (uint64_t k : kept) kept_ += k;
  for (size_t i = 0; i < placed.size(); ++i) (free[i] ? cur_ : next_).open.push_back(std::move(placed[i]));
  for (Worker& W : workers_) {
    for (auto& list : W.fresh) list.clear();
    W.details.clear();
  }
}

int LayeredBfs::target_of(int64_t node) const {
  if (!spec_.targets) return -1;
  auto it = spec_.targets->find(hash_of_[node]);
  return it == spec_.targets->end() ? -1 : it->second;
}

BfsOutcome LayeredBfs::finish(int64_t node, bool found) {
  out_.distinct += seen_.size();
  out_.stored = 1;  // the root
  for (uint64_t n : stored_) out_.stored += n;
  if (found) {
    out_.found = true;
    out_.plan = path(node);
    out_.target = target_of(node);
    FrameColours colours;
    auto e = replay(node, start_);
    if (spec_.goal && p_.goal().reached(*e, colours)) out_.target = -1;
  }
  return std::move(out_);
}

bool LayeredBfs::phase(int layer, bool free_phase, int64_t& hit_node) {
  // A layer the search cannot expand (its nodes unplaced): the budget is spent.
  if (cur_.unplaced > 0 && out_.nodes >= spec_.limit.nodes) {
    out_.note = fmt::format("bfs ({} actions): node budget spent at depth {}", A_, layer + 1);
    return true;
  }
  // cur_.open grows during the free phase: each chunk ends where the open list
  // ended when it began, and the next starts there.
  for (size_t begin = 0, end = 0; begin < cur_.open.size(); begin = end) {
    end = std::min(cur_.open.size(), begin + chunk_parents_);
    if (out_.nodes >= spec_.limit.nodes) {
      out_.note = fmt::format("bfs ({} actions): node budget spent at depth {}", A_, layer + 1);
      return true;
    }
    if (spec_.limit.out_of_time() || !expand_chunk(begin, end, free_phase)) {
      out_.timed_out = spec_.limit.clock->out_of_time();
      out_.note = fmt::format("bfs ({} actions): {} at depth {}", A_, spec_.limit.time_note(), layer + 1);
      return true;
    }
    dedup();
    if (!free_phase) {
      size_t won = 0;
      for (const auto& list : won_) won += list.size();
      win_rate_ = static_cast<double>(won) / static_cast<double>(std::max<size_t>(1, (end - begin) * free_count_[0]));
    }
    const uint64_t index = *std::min_element(first_hit_.begin(), first_hit_.end());
    const size_t placed_from = nodes_.size();
    place(begin, free_phase);
    if (index == UINT64_MAX) continue;
    // The hit's node: winners were placed shard by shard; find it by (parent, action).
    const int64_t parent = cur_.open[begin + index / A_].node;
    for (size_t n = placed_from; n < nodes_.size() && hit_node < 0; ++n)
      if (nodes_[n].parent == parent && nodes_[n].action == static_cast<int32_t>(index % A_)) hit_node = static_cast<int64_t>(n);
    out_.cost = layer + (free_phase ? 0 : 1);
    return true;
  }
  return false;
}

BfsOutcome LayeredBfs::run() {
  chunk_parents_ = std::max<size_t>(256, 65536 / std::max<size_t>(A_, 1));
  // A successor's index in its chunk, (parent - begin) * A + action, is 32 bits (Fresh).
  if (A_ > UINT32_MAX) throw TaskError("a search of more than 2^32 actions");
  chunk_parents_ = std::min<size_t>(chunk_parents_, UINT32_MAX / std::max<size_t>(A_, 1));
  // Room for the whole budget up front (address space only until written),
  // and for the chunk that crosses it (the budget is checked between chunks):
  // grown by doubling, the node table was copied on the serial path of a chunk.
  const size_t room = static_cast<size_t>(std::min<uint64_t>(spec_.limit.nodes, uint64_t{1} << 22)) + chunk_parents_ * A_ + 1;
  reserve_huge(nodes_, room);
  reserve_huge(hash_of_, room);
  nodes_ = {{-1, -1, 0}};
  const uint64_t h0 = start_.state_hash();
  hash_of_ = {h0};
  {
    std::vector<size_t> one(kShards, 0);
    one[shard_of(h0)] = 1;
    seen_.reserve(one, serial_);
    seen_.insert(h0);
  }
  {
    FrameColours colours;
    if ((spec_.targets && spec_.targets->contains(h0)) || (spec_.goal && p_.goal().reached(start_, colours)))
      return finish(0, true);
  }
  for (size_t a = 0; a < A_; ++a) ++free_count_[is_free(a) ? 1 : 0];
  cur_.buffers.resize(1);
  snapshots_ = start_.save_state(cur_.buffers[0]);
  cur_.open.resize(1);
  cur_.open[0].size = static_cast<uint32_t>(cur_.buffers[0].size());
  if (!snapshots_) cur_.open[0].env = start_.clone(), kept_ = 1;
  workers_ = take_workers(p_.pool().size());
  for (Worker& W : workers_) {  // one thread clones
    W.parent = start_.clone(), W.replay_root = start_.clone();
    W.largest = snapshots_ ? cur_.open[0].size : 0;  // the root's: the first chunk's reservation
  }
  for (int layer = 0; layer < spec_.max_cost; ++layer) {
    final_layer_ = layer + 1 >= spec_.max_cost;
    // The layer's closure under free actions first, so that no state of this
    // cost is first met as the next layer's.
    int64_t hit_node = -1;
    if ((free_count_[1] > 0 && phase(layer, true, hit_node)) || phase(layer, false, hit_node))
      return finish(hit_node, hit_node >= 0);
    // Without free actions the next layer is complete once generated; with them
    // only its closure, built in the next round, completes it.
    out_.depth_done = layer + (free_count_[1] > 0 ? 0 : 1);
    cur_ = std::move(next_);
    next_ = Layer{};
    if (cur_.open.empty() && cur_.unplaced == 0) {
      out_.exhausted = true;
      out_.note = fmt::format("bfs ({} actions): every reachable state seen by cost {}", A_, layer + 1);
      return finish(0, false);
    }
  }
  out_.note = fmt::format("bfs ({} actions): no plan of cost <= {}", A_, spec_.max_cost);
  return finish(0, false);
}

}  // namespace

BfsOutcome bfs(PlanProblem& problem, const BfsSpec& spec) { return LayeredBfs(problem, spec).run(); }

size_t bfs_kept_workers_for_testing() {
  auto& k = LayeredBfs::kept_workers();
  std::lock_guard<std::mutex> lock(k.mu);
  return k.spare.size();
}

void bfs_drop_kept_workers_for_testing() {
  auto& k = LayeredBfs::kept_workers();
  std::lock_guard<std::mutex> lock(k.mu);
  k.spare.clear();
}

}  // namespace autumn::agent
