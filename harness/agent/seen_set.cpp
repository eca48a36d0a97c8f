// seen_set — see seen_set.hpp: the growth of every shard's table at once.
#include "harness/agent/seen_set.hpp"

#include <algorithm>
#include <new>

#include "harness/agent/huge_pages.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/agent/warm_blocks.hpp"

namespace autumn::agent {

void SeenSet::reserve(const std::vector<size_t>& incoming, ThreadPool& pool) {
  size_t need = 0;  // the most nonzero hashes a shard may hold
  for (size_t sh = 0; sh < kShards; ++sh) need = std::max(need, shards_[sh].count + incoming[sh]);
  if (need * 2 <= per_shard_) return;
  // Starts small: a search of a few thousand states (most of the planner's)
  // keeps its tables in memory malloc already holds, instead of a fresh mapping.
  size_t per = std::max<size_t>(per_shard_, 16);
  while (need * 2 > per) per *= 2;
  std::unique_ptr<uint64_t[], Free> old = zeroed_slots(per * kShards);
  advise_new_buffer(old.get(), per * kShards * sizeof(uint64_t), per_shard_ * kShards * sizeof(uint64_t));
  old.swap(slots_);
  const size_t old_per = per_shard_;
  per_shard_ = per;
  mask_ = per - 1;
  shift_ = 64 - __builtin_ctzll(per);
  pool.parallel_for(kShards, [&](size_t sh) {
    shards_[sh].count = 0;
    for (size_t i = 0; i < old_per; ++i)
      if (const uint64_t h = old[sh * old_per + i]; h != 0) insert(h);
  });
}

void SeenSet::Free::operator()(uint64_t* p) const {
  if (bytes >= kWarmMin) warm_give(p);
  else std::free(p);
}

std::unique_ptr<uint64_t[], SeenSet::Free> SeenSet::zeroed_slots(size_t count) {
  const size_t bytes = count * sizeof(uint64_t);
  void* p = bytes >= kWarmMin ? warm_take(bytes, true) : std::calloc(count, sizeof(uint64_t));
  if (!p) throw std::bad_alloc();
  return std::unique_ptr<uint64_t[], Free>(static_cast<uint64_t*>(p), Free{bytes});
}

size_t SeenSet::size() const {
  size_t n = 0;
  for (const Shard& s : shards_) n += s.count + (s.zero ? 1 : 0);
  return n;
}

}  // namespace autumn::agent
