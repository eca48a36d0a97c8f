// fnv1a — the 64-bit FNV-1a hash of bytes, the one copy: a module's source hash
// (compiler/emit), its snapshot layout digest (compiler/lower/print_cpp). Not
// for anything an adversary chooses to collide (the module store digests with
// SHA-256, harness/digest).
#pragma once
#include <cstdint>
#include <string_view>

namespace autumn {

inline constexpr uint64_t kFnv1aBasis = 0xcbf29ce484222325ULL;

// Continues `h` (kFnv1aBasis to start) over the bytes of `s`.
inline uint64_t fnv1a(std::string_view s, uint64_t h = kFnv1aBasis) {
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

}  // namespace autumn
