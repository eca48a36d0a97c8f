// huge_pages — large search buffers on transparent huge pages.
//
// A buffer the search is about to fill (the node table, a seen-set shard's
// table, a chunk's snapshots) is asked to be backed by 2 MiB pages
// (madvise(MADV_HUGEPAGE)) before anything is written to it, so that filling it
// takes one page fault per 2 MiB instead of one per 4 KiB. On this project's
// VM a BFS of a million successors took 60k page faults, which cost more time
// than the settling of the successors (docs/design.md, "Page faults"). Only
// the untouched part of the buffer is advised, rounded inward to whole 2 MiB
// pages; below that nothing is done. It is a hint: with THP off ("never")
// the kernel ignores it, and nothing a buffer holds depends on it. A huge page
// is resident whole once written at all, so a buffer reserved beyond its use
// gives back the rest of its last page when it is done (release_unused).
// Test: tests/agent_test.cpp (AgentHugePages.*).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <vector>

namespace autumn::agent {

// Advises [p, p + bytes) rounded inward to 2 MiB boundaries; true if a range
// was advised (and the kernel accepted it).
bool advise_huge_pages(const void* p, size_t bytes);

// Gives back the pages of [used_end, capacity_end) that filling up to
// used_end may have brought in: the rest of a huge page that used_end falls
// in. A buffer that is done growing, with a reservation far beyond its use,
// then holds no more than its use rounded up to 4 KiB.
void release_unused(const void* used_end, const void* capacity_end);

// The first 2 MiB of a buffer stays on small pages unless it already holds
// that much: most of the planner's searches are small, and a huge page is
// zeroed whole at its first write (measured: searches of a few thousand
// nodes ran at half speed when every buffer's first page was huge).
inline constexpr size_t kHugePage = size_t{2} << 20;

// x rounded up or down to a multiple of `page` (a power of two).
constexpr uintptr_t round_up(uintptr_t x, uintptr_t page) { return (x + page - 1) & ~(page - 1); }
constexpr uintptr_t round_down(uintptr_t x, uintptr_t page) { return x & ~(page - 1); }

// Advises a buffer of `bytes` at p that nothing has written yet, taking the
// place of one that held `held` bytes: all of it if that was 2 MiB or more,
// else all but its first 2 MiB (kHugePage's rule).
inline void advise_new_buffer(const void* p, size_t bytes, size_t held) {
  const size_t from = held >= kHugePage ? 0 : std::min(bytes, kHugePage);
  advise_huge_pages(static_cast<const char*>(p) + from, bytes - from);
}

// v.reserve(n), the new buffer advised before v's elements are moved into it
// (reserve() itself would copy them onto small pages first).
template <class T, class A>
void reserve_huge(std::vector<T, A>& v, size_t n) {
  if (n <= v.capacity()) return;
  std::vector<T, A> w(v.get_allocator());
  w.reserve(n);
  advise_new_buffer(w.data(), w.capacity() * sizeof(T), v.size() * sizeof(T));
  w.insert(w.end(), std::make_move_iterator(v.begin()), std::make_move_iterator(v.end()));
  v.swap(w);
}

// release_unused over v's unused capacity.
template <class T, class A>
void release_unused(const std::vector<T, A>& v) {
  if (v.size() * sizeof(T) < kHugePage) return;  // within the small pages (reserve_huge)
  release_unused(v.data() + v.size(), v.data() + v.capacity());
}

// v.resize(n), growing by doubling into advised capacity.
template <class T, class A>
void resize_huge(std::vector<T, A>& v, size_t n) {
  if (n > v.capacity()) reserve_huge(v, std::max(n, v.capacity() * 2));
  v.resize(n);
}

}  // namespace autumn::agent
