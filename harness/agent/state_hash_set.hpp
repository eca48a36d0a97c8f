// state_hash_set — a set of 64-bit state hashes for the BFS (plan_bfs.cpp): each
// worker's states of the current chunk. The probing (hash_probe) is shared
// with the seen set (seen_set.hpp), whose shards' tables lie in one buffer.
//
// Open addressing with linear probing over a power-of-two table of the hashes
// themselves (0 marks an empty slot; the zero hash is a flag of its own), at
// most half full. clear() keeps the table. It replaced absl::flat_hash_set
// here, measured on the BFS (docs/design.md, "The many-object tail"): absl's
// clear() frees a table above 127 slots, so each worker's per-chunk set was
// re-allocated, faulted in and regrown by rehashing every chunk, and Debian's
// build of its insert calls into the shared library (a thread-local read per
// insert, its debug-build placement); on paint, a cheap program, the sets were
// a third of the search and page faults (which take the address-space lock
// both threads need) kept two threads from doubling it.
// Test: tests/paint_marks_test.cpp (StateHashSet.*).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace autumn::agent {

// Linear probing over a power-of-two table of nonzero hashes (0 marks an empty
// slot), from the high bits of a multiply: the hashes are mixed, but a shard's
// share their top bits and an engine's low bits need not be uniform.
namespace hash_probe {
inline size_t slot(uint64_t h, int shift) { return static_cast<size_t>((h * 0x9e3779b97f4a7c15ULL) >> shift); }
// Fetches the cache line at p. Not __builtin_prefetch: to g++ 12 at -O2 the
// builtin has no side effect, and in SeenSet::prefetch, inlined into the BFS,
// it was removed: the binary held no prefetch instruction for either set
// (docs/design.md, "The prefetch that was not there", with a reproducer).
// An asm volatile is never removed.
inline void prefetch(const void* p) {
#if defined(__x86_64__) || defined(__i386__)
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
#else
  __builtin_prefetch(p);
#endif
}
// Puts nonzero h into table t (which has a free slot); true if it was not there.
inline bool insert(uint64_t* t, size_t mask, int shift, uint64_t h) {
  for (size_t i = slot(h, shift);; i = (i + 1) & mask) {
    if (t[i] == h) return false;
    if (t[i] == 0) {
      t[i] = h;
      return true;
    }
  }
}
inline bool contains(const uint64_t* t, size_t mask, int shift, uint64_t h) {
  for (size_t i = slot(h, shift);; i = (i + 1) & mask) {
    if (t[i] == h) return true;
    if (t[i] == 0) return false;
  }
}
}  // namespace hash_probe

class StateHashSet {
 public:
  // Inserts h; true if it was not there.
  bool insert(uint64_t h) {
    if (h == 0) {
      const bool fresh = !zero_;
      zero_ = true;
      return fresh;
    }
    if ((count_ + 1) * 2 > slots_.size()) grow();
    if (!hash_probe::insert(slots_.data(), mask_, shift_, h)) return false;
    ++count_;
    return true;
  }
  bool contains(uint64_t h) const {
    if (h == 0) return zero_;
    return count_ > 0 && hash_probe::contains(slots_.data(), mask_, shift_, h);
  }
  // Fetches h's slot into the cache ahead of an insert or a lookup.
  void prefetch(uint64_t h) const {
    if (!slots_.empty()) hash_probe::prefetch(&slots_[hash_probe::slot(h, shift_)]);
  }
  size_t size() const { return count_ + (zero_ ? 1 : 0); }
  // Empties the set, keeping its table.
  void clear() {
    if (count_ > 0) std::fill(slots_.begin(), slots_.end(), 0);
    count_ = 0;
    zero_ = false;
  }

 private:
  void grow() {
    std::vector<uint64_t> old(slots_.empty() ? 512 : slots_.size() * 2, 0);
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    shift_ = 64 - __builtin_ctzll(slots_.size());
    count_ = 0;
    for (uint64_t h : old)
      if (h != 0) insert(h);
  }

  // Invariants: slots_ is empty or a power of two long, with count_ nonzero
  // entries, at most half of it; mask_ and shift_ are its size's; zero_ is
  // whether the zero hash is in the set.
  std::vector<uint64_t> slots_;
  size_t count_ = 0;
  size_t mask_ = 0;
  int shift_ = 64;
  bool zero_ = false;
};

}  // namespace autumn::agent
