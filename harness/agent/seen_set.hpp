// seen_set — the BFS's set of every state hash met (plan_bfs.cpp), in shards
// that threads fill at once.
//
// A hash's shard is its top kShardBits bits. Each shard is an open-addressed
// table probed as StateHashSet's is (hash_probe in state_hash_set.hpp; the
// zero hash a flag, at most half full), and all the shards'
// tables lie side by side in one buffer, all of one size, grown together.
// The search alternates phases: threads read the set (contains, prefetch)
// while they expand a chunk; then reserve() makes room for the chunk's new
// states, and threads insert, each into shards no other thread is inserting
// into. The tables were once 64 separate StateHashSets: each doubling of each
// allocated fresh memory, and their page faults were a third of a cheap
// program's search (docs/design.md, "Page faults"); one buffer grown by
// doubling is advised onto huge pages (huge_pages.hpp).
// Test: tests/agent_test.cpp (AgentSeenSet.*).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "harness/agent/state_hash_set.hpp"

namespace autumn::agent {

class ThreadPool;

class SeenSet {
 public:
  static constexpr int kShardBits = 6;
  static constexpr size_t kShards = size_t{1} << kShardBits;
  static size_t shard_of(uint64_t h) { return static_cast<size_t>(h >> (64 - kShardBits)); }

  // Room for incoming[sh] more hashes in each shard sh (kShards counts):
  // afterwards that many inserts need no growth. Runs the rehash of a growth
  // on `pool`. Nothing else may use the set meanwhile.
  void reserve(const std::vector<size_t>& incoming, ThreadPool& pool);
  // Inserts h; true if it was not there. Its shard must have room (reserve);
  // threads may insert at once into different shards.
  bool insert(uint64_t h) {
    Shard& s = shards_[shard_of(h)];
    if (h == 0) {
      const bool fresh = !s.zero;
      s.zero = true;
      return fresh;
    }
    if (!hash_probe::insert(table(shard_of(h)), mask_, shift_, h)) return false;
    ++s.count;
    return true;
  }
  bool contains(uint64_t h) const {
    const Shard& s = shards_[shard_of(h)];
    if (h == 0) return s.zero;
    return s.count > 0 && hash_probe::contains(table(shard_of(h)), mask_, shift_, h);
  }
  // Fetches h's slot into the cache ahead of an insert or a lookup.
  void prefetch(uint64_t h) const {
    if (per_shard_ > 0) hash_probe::prefetch(table(shard_of(h)) + hash_probe::slot(h, shift_));
  }
  size_t size() const;

 private:
  uint64_t* table(size_t shard) { return slots_.get() + shard * per_shard_; }
  const uint64_t* table(size_t shard) const { return slots_.get() + shard * per_shard_; }

  // Each shard's count alone on its cache line: threads insert into
  // neighbouring shards at once, and every insert writes its count.
  struct alignas(64) Shard {
    size_t count = 0;  // nonzero hashes in its table
    bool zero = false;  // whether the zero hash is in the set
  };
  // Invariants: slots_ holds kShards tables of per_shard_ slots (0 or a power
  // of two, at least twice every shard's count), shard sh's at sh * per_shard_;
  // mask_ and shift_ are per_shard_'s.
  // Zeroed memory, not a vector: a small table from calloc (a fresh mapping is
  // zero already, which calloc does not write again: a vector's resize zeroed
  // it a second time, in one thread, 6% of paint's search); a large one a warm
  // block (warm_blocks.hpp), memory an earlier search touched, zeroed.
  struct Free {
    size_t bytes;  // value-initialised (0) in an empty slots_
    void operator()(uint64_t* p) const;
  };
  static std::unique_ptr<uint64_t[], Free> zeroed_slots(size_t count);
  std::unique_ptr<uint64_t[], Free> slots_;
  size_t per_shard_ = 0;
  size_t mask_ = 0;
  int shift_ = 64;
  std::vector<Shard> shards_ = std::vector<Shard>(kShards);
};

}  // namespace autumn::agent
