// hash_order — the iteration order of libstdc++'s std::unordered_map<std::string, T>.
//
// The reference interpreter keeps its globals and its initnext registrations in
// std::unordered_map, and iterates them: initialiser order, NEXT order, allObjs,
// prev-by-id and one-argument removeObj all follow the container's bucket walk.
// That order is a pure function of the key insert/erase history, so we replay the
// history through a model of GCC 12's hashtable (prime rehash policy, singly linked
// node list with "before-begin" bucket pointers) instead of depending on whichever
// standard library this project happens to be built with.
//
// API
//   uint64_t  libstdcxx_string_hash(std::string_view)   std::hash<std::string> of GCC
//   HashOrder::insert(key, hash)   key is a small dense integer; no-op if present
//   HashOrder::erase(key)          no-op if absent
//   HashOrder::contains(key)
//   HashOrder::for_each(f)         f(key) in iteration order
//   HashOrder::order()             the keys in iteration order
//   HashOrder::bucket_count(), next_resize(), hash_of(key)
//   HashOrder::restore(buckets, next_resize, [(key, hash)] in iteration order)
//                                  rebuilds the map those three describe (snapshots)
//
// Invariant: two HashOrders fed the same insert/erase sequence iterate identically,
// and identically to std::unordered_map<std::string,...> under libstdc++ (GCC 12).
#pragma once
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

namespace autumn {

uint64_t libstdcxx_string_hash(std::string_view s);

class HashOrder {
 public:
  void insert(int key, uint64_t hash);
  void erase(int key);
  bool contains(int key) const {
    return key >= 0 && key < static_cast<int>(present_.size()) && present_[key];
  }
  size_t size() const { return count_; }
  std::vector<int> order() const;
  size_t bucket_count() const { return bucket_count_; }
  size_t next_resize() const { return next_resize_; }
  uint64_t hash_of(int key) const { return hash_[key]; }
  // The iteration order, bucket count and resize threshold determine the map:
  // bucket b's entry is the node before b's first node in the list. Throws
  // std::invalid_argument on a description no history produces.
  void restore(size_t bucket_count, size_t next_resize, const std::vector<std::pair<int, uint64_t>>& keys);
  template <class F>
  void for_each(F&& f) const {
    for (int p = first_; p != kNone; p = next_[p]) f(p);
  }

 private:
  static constexpr int kNone = -1;   // end of list / empty bucket
  static constexpr int kHead = -2;   // the before-begin sentinel
  int after(int n) const { return n == kHead ? first_ : next_[n]; }
  void link(int n, int v) { (n == kHead ? first_ : next_[n]) = v; }
  size_t bucket_of(int key) const { return hash_[key] % bucket_count_; }
  void grow_to(int key);
  void rehash(size_t new_count);

  std::vector<int> next_;
  std::vector<uint64_t> hash_;
  std::vector<char> present_;
  std::vector<int> buckets_{kNone};
  size_t bucket_count_ = 1;
  size_t next_resize_ = 0;
  size_t count_ = 0;
  int first_ = kNone;
};

}  // namespace autumn
