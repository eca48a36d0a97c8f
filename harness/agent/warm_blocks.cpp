// warm_blocks — see warm_blocks.hpp. The cache is a list of kept blocks under
// one mutex: a search takes and gives a handful of blocks, each as it grows a
// table, so the list is short and the lock is never on a hot path.
#include "harness/agent/warm_blocks.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <deque>
#include <mutex>
#include <new>
#include <unordered_map>

#include "harness/agent/huge_pages.hpp"  // kHugePage, round_up

namespace autumn::agent {
namespace {

size_t whole_pages(size_t bytes) { return round_up(bytes, kHugePage); }

// A new 2 MiB-aligned mapping of `bytes` (whole huge pages). Not advised
// here: the caller advises what it will fill (advise_new_buffer's rule).
void* map_block(size_t bytes) {
  const size_t span = bytes + kHugePage;
  void* raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t begin = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t first = round_up(begin, kHugePage);
  if (first > begin) munmap(raw, first - begin);
  const uintptr_t end = begin + span, last = first + bytes;
  if (end > last) munmap(reinterpret_cast<void*>(last), end - last);
  return reinterpret_cast<void*>(first);
}

struct Kept {
  void* p;
  size_t bytes;  // whole huge pages
};

// Invariants: kept_ holds blocks no one uses, oldest first; total_ is the sum
// of their sizes and at most warm_cap(). lent_ maps each block in use to its
// size, which may exceed what its taker asked for (a larger kept block fitted).
class Cache {
 public:
  void* take(size_t bytes, bool zeroed) {
    const size_t want = whole_pages(bytes);
    Kept k{nullptr, want};
    {
      std::lock_guard<std::mutex> lock(mu_);
      auto best = kept_.end();
      for (auto it = kept_.begin(); it != kept_.end(); ++it)
        if (it->bytes >= want && (best == kept_.end() || it->bytes < best->bytes)) best = it;
      if (best != kept_.end()) {
        k = *best;
        total_ -= k.bytes;
        kept_.erase(best);
        lent_.emplace(k.p, k.bytes);
      }
    }
    if (k.p != nullptr) {
      if (zeroed) std::memset(k.p, 0, bytes);
      return k.p;
    }
    k.p = map_block(want);  // a fresh mapping is zero
    std::lock_guard<std::mutex> lock(mu_);
    lent_.emplace(k.p, k.bytes);
    return k.p;
  }
  void give(void* p) noexcept {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = lent_.find(p);
    if (it == lent_.end()) std::abort();  // not a block of this cache: a caller's bug
    const Kept k{p, it->second};
    lent_.erase(it);
    if (k.bytes > warm_cap()) {
      munmap(k.p, k.bytes);
      return;
    }
    kept_.push_back(k);
    total_ += k.bytes;
    while (total_ > warm_cap()) {
      munmap(kept_.front().p, kept_.front().bytes);
      total_ -= kept_.front().bytes;
      kept_.pop_front();
    }
  }
  size_t kept_bytes() {
    std::lock_guard<std::mutex> lock(mu_);
    return total_;
  }
  void drop_all() noexcept {  // the kept blocks; blocks in use stay lent
    std::lock_guard<std::mutex> lock(mu_);
    for (const Kept& k : kept_) munmap(k.p, k.bytes);
    kept_.clear();
    total_ = 0;
  }

 private:
  std::mutex mu_;
  std::deque<Kept> kept_;
  std::unordered_map<void*, size_t> lent_;
  size_t total_ = 0;
};

// Never destroyed: a search's buffers may be given back during static
// destruction (a thread pool's workers outliving main's locals).
Cache& cache() {
  static Cache* c = new Cache;
  return *c;
}

}  // namespace

size_t warm_cap_for(const char* setting, size_t ram) {
  const size_t fallback = std::min(size_t{1} << 30, ram / 8);
  if (setting == nullptr) return fallback;
  char* end = nullptr;
  errno = 0;
  const long long mib = std::strtoll(setting, &end, 10);
  if (end != setting && *end == 0 && errno == 0 && mib >= 0 && mib <= (1LL << 20)) return static_cast<size_t>(mib) << 20;
  std::fprintf(stderr, "autumn: AUTUMN_WARM_MEMORY_MB='%s' is not a number of MiB from 0 to 1048576; keeping up to %zu MiB\n",
               setting, fallback >> 20);
  return fallback;
}

size_t warm_cap() {
  static const size_t cap = [] {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    const size_t ram = pages > 0 && page > 0 ? static_cast<size_t>(pages) * static_cast<size_t>(page) : 0;
    return warm_cap_for(std::getenv("AUTUMN_WARM_MEMORY_MB"), ram);
  }();
  return cap;
}

void* warm_take(size_t bytes, bool zeroed) { return cache().take(std::max(bytes, size_t{1}), zeroed); }
void warm_give(void* p) noexcept {
  if (p != nullptr) cache().give(p);
}
size_t warm_kept_bytes() { return cache().kept_bytes(); }
void warm_drop_all() noexcept { cache().drop_all(); }

}  // namespace autumn::agent
