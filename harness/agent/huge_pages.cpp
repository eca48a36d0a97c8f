// huge_pages — see huge_pages.hpp. The one system call, and the rounding.
#include "harness/agent/huge_pages.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>

namespace autumn::agent {

bool advise_huge_pages(const void* p, size_t bytes) {
  constexpr uintptr_t kHuge = kHugePage;
  const uintptr_t begin = reinterpret_cast<uintptr_t>(p);
  const uintptr_t first = round_up(begin, kHuge), last = round_down(begin + bytes, kHuge);
  if (p == nullptr || last <= first) return false;
  return madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE) == 0;
}

void release_unused(const void* used_end, const void* capacity_end) {
  constexpr uintptr_t kPage = 4096, kHuge = kHugePage;
  const uintptr_t used = reinterpret_cast<uintptr_t>(used_end);
  const uintptr_t first = round_up(used, kPage);
  const uintptr_t last = std::min(round_up(used, kHuge), round_down(reinterpret_cast<uintptr_t>(capacity_end), kPage));
  if (used_end != nullptr && first < last) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
}

}  // namespace autumn::agent
