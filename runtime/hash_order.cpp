// See hash_order.hpp. The constants are GCC 12's: _Hash_bytes seed 0xc70f6907,
// the MurmurHash2-64A multiplier, and the head of __prime_list used by
// _Prime_rehash_policy (maximum load factor 1).
#include "runtime/hash_order.hpp"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <stdexcept>

namespace autumn {
namespace {
constexpr uint64_t kMul = 0xc6a4a7935bd1e995ULL;
uint64_t shift_mix(uint64_t v) { return v ^ (v >> 47); }
constexpr size_t kPrimes[] = {13,      29,      59,      127,     257,     541,
                              1109,    2357,    5087,    10273,   20753,   42043,
                              85229,   172933,  351061,  712697,  1447153, 2938679,
                              5967347, 12121973};
}  // namespace

uint64_t libstdcxx_string_hash(std::string_view s) {
  const size_t len = s.size();
  const size_t aligned = len & ~size_t{7};
  uint64_t h = 0xc70f6907ULL ^ (len * kMul);
  for (size_t i = 0; i < aligned; i += 8) {
    uint64_t w;
    std::memcpy(&w, s.data() + i, 8);  // little-endian load, as on x86-64
    h ^= shift_mix(w * kMul) * kMul;
    h *= kMul;
  }
  if (len & 7) {
    uint64_t tail = 0;
    for (size_t i = len; i-- > aligned;) tail = (tail << 8) | static_cast<unsigned char>(s[i]);
    h ^= tail;
    h *= kMul;
  }
  h = shift_mix(h) * kMul;
  return shift_mix(h);
}

void HashOrder::grow_to(int key) {
  if (key >= static_cast<int>(present_.size())) {
    size_t n = std::max<size_t>(key + 1, present_.size() * 2);
    next_.resize(n, kNone);
    hash_.resize(n, 0);
    present_.resize(n, 0);
  }
}

void HashOrder::rehash(size_t new_count) {
  std::vector<int> buckets(new_count, kNone);
  int p = first_;
  first_ = kNone;
  size_t prev_bucket = 0;
  while (p != kNone) {
    int q = next_[p];
    size_t c = hash_[p] % new_count;
    if (buckets[c] == kNone) {
      next_[p] = first_;
      first_ = p;
      buckets[c] = kHead;
      if (next_[p] != kNone) buckets[prev_bucket] = p;
      prev_bucket = c;
    } else {
      next_[p] = after(buckets[c]);
      link(buckets[c], p);
    }
    p = q;
  }
  bucket_count_ = new_count;
  buckets_ = std::move(buckets);
}

void HashOrder::insert(int key, uint64_t hash) {
  if (contains(key)) return;  // an existing key never moves
  grow_to(key);
  if (count_ + 1 > next_resize_) {
    size_t want = std::max<size_t>(count_ + 1, next_resize_ ? 0 : 11);
    if (want >= bucket_count_) {
      size_t target = std::max<size_t>(want + 1, 2 * bucket_count_);
      size_t chosen = 0;
      for (size_t prime : kPrimes)
        if (prime >= target) { chosen = prime; break; }
      if (!chosen) throw std::length_error("HashOrder: too many keys");
      next_resize_ = chosen;
      rehash(chosen);
    } else {
      next_resize_ = bucket_count_;
    }
  }
  hash_[key] = hash;
  present_[key] = 1;
  ++count_;
  size_t c = bucket_of(key);
  if (buckets_[c] != kNone) {
    next_[key] = after(buckets_[c]);
    link(buckets_[c], key);
  } else {
    next_[key] = first_;
    first_ = key;
    if (next_[key] != kNone) buckets_[bucket_of(next_[key])] = key;
    buckets_[c] = kHead;
  }
}

void HashOrder::erase(int key) {
  if (!contains(key)) return;
  size_t c = bucket_of(key);
  int prev = buckets_[c];
  while (after(prev) != key) prev = after(prev);
  int nx = next_[key];
  if (prev == buckets_[c]) {
    if (nx == kNone || bucket_of(nx) != c) {
      if (nx != kNone) buckets_[bucket_of(nx)] = buckets_[c];
      buckets_[c] = kNone;
    }
  } else if (nx != kNone && bucket_of(nx) != c) {
    buckets_[bucket_of(nx)] = prev;
  }
  link(prev, nx);
  next_[key] = kNone;
  present_[key] = 0;
  --count_;
}

void HashOrder::restore(size_t bucket_count, size_t next_resize, const std::vector<std::pair<int, uint64_t>>& keys) {
  if (bucket_count == 0 || bucket_count > kPrimes[std::size(kPrimes) - 1] || keys.size() > bucket_count)
    throw std::invalid_argument("HashOrder: bad bucket count");
  *this = HashOrder{};
  bucket_count_ = bucket_count;
  next_resize_ = next_resize;
  buckets_.assign(bucket_count, kNone);
  int prev = kHead;
  for (const auto& [key, hash] : keys) {
    if (key < 0 || contains(key)) throw std::invalid_argument("HashOrder: bad key");
    grow_to(key);
    hash_[key] = hash;
    present_[key] = 1;
    ++count_;
    link(prev, key);
    next_[key] = kNone;
    if (buckets_[bucket_of(key)] == kNone) buckets_[bucket_of(key)] = prev;
    prev = key;
  }
}

std::vector<int> HashOrder::order() const {
  std::vector<int> out;
  out.reserve(count_);
  for_each([&](int k) { out.push_back(k); });
  return out;
}

}  // namespace autumn
