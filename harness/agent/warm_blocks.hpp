// warm_blocks — large search buffers kept for the next search instead of
// being handed back to the kernel.
//
// On this project's VM, memory the process has never touched costs about
// 2.5 ms a MiB at its first write (the host backs it then: 0.4 GB/s), while
// memory it has touched before is rewritten at 10 GB/s; freed memory is soon
// given back to the host (free page reporting), so the next search pays again.
// A BFS of a million successors on a 256-object program (peak RSS 130 MiB)
// spent a tenth of its time in the kernel zeroing new pages, most of it for
// the seen set's growing tables, and on two threads their page faults
// serialised: the growth took longer than on one thread (docs/design.md,
// "Warm memory"). The planner runs search after search, and bench-agent
// repeats them: each took fresh memory for the same buffers.
//
// So the search's largest buffers (the seen set's tables, the node and hash
// tables) come from a process-wide cache of blocks of at least kWarmMin bytes:
// a block given back is kept (up to warm_cap() bytes in all, the oldest
// dropped first) and handed to the next request it fits, zeroed when asked.
// A block is whole 2 MiB pages, 2 MiB aligned; its user advises it onto huge
// pages as before (huge_pages.hpp). Nothing a buffer holds depends on where
// it came from. A process that has searched keeps up to warm_cap() bytes
// mapped for the next search (resident: what the searches wrote).
// Test: tests/agent_test.cpp (AgentWarmBlocks.*).
#pragma once

#include <cstddef>
#include <memory>

namespace autumn::agent {

inline constexpr size_t kWarmMin = size_t{2} << 20;

// A block of at least `bytes` (>= kWarmMin): a kept one if one fits (the
// smallest that does), else a new mapping. Zero throughout its first `bytes`
// if `zeroed`. Throws std::bad_alloc.
void* warm_take(size_t bytes, bool zeroed);
// Gives back a block warm_take returned (the cache knows its size): kept for
// a later take while the cache holds no more than warm_cap(), else unmapped.
void warm_give(void* p) noexcept;
// The most the cache keeps: $AUTUMN_WARM_MEMORY_MB MiB (0: nothing is kept,
// every block is unmapped when given back), by default an eighth of the
// machine's memory and at most 1 GiB. Read once per process.
size_t warm_cap();
// warm_cap's rule for a setting (null: unset) and a machine of `ram` bytes; a
// setting that is not a number from 0 to 2^20 is reported on stderr and the
// default used.
size_t warm_cap_for(const char* setting, size_t ram);
// Bytes kept now (tests), and dropping them all (blocks in use are not kept).
size_t warm_kept_bytes();
void warm_drop_all() noexcept;

// An allocator for std::vector: allocations of kWarmMin bytes or more are warm
// blocks, smaller ones std::allocator's (deallocate tells them apart by size,
// as allocate did).
template <class T>
struct WarmAllocator {
  using value_type = T;
  WarmAllocator() = default;
  template <class U>
  WarmAllocator(const WarmAllocator<U>&) noexcept {}
  T* allocate(size_t n) {
    if (n * sizeof(T) >= kWarmMin) return static_cast<T*>(warm_take(n * sizeof(T), false));
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, size_t n) noexcept {
    if (n * sizeof(T) >= kWarmMin) warm_give(p);
    else std::allocator<T>().deallocate(p, n);
  }
  template <class U>
  bool operator==(const WarmAllocator<U>&) const noexcept {
    return true;
  }
};

}  // namespace autumn::agent
