// snapshot_header — the 16 bytes every compiled state snapshot opens with.
//
// "AUTS", the runtime's snapshot format (the encoding of the core and of
// values; raised by hand when either changes) and the module's layout digest
// (Prog::kSnapshotLayout, compiler/lower/print_cpp.hpp: the saved slots, the
// classes' members and the string table). CompiledProgramHost::load_state
// refuses bytes whose header is not its own, with the reason; a host that can
// rebuild a state another way (the Python drop-in replays the episode's log)
// compares headers first, so that another build's state is replayed rather
// than reported as corrupt. docs/design.md, "Trust: states, outputs and long steps".
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "runtime/environment.hpp"

namespace autumn::rt {

inline constexpr uint32_t kSnapshotMagic = 0x53545541;  // "AUTS", little-endian
// 2 (2026-12-03): a CellV is written field by field, 22 bytes, not as its
// 24-byte struct with two bytes of padding.
inline constexpr uint32_t kSnapshotFormat = 2;
inline constexpr size_t kSnapshotHeaderBytes = 16;  // magic, format (u32 each), layout (u64)

// Whether two snapshots were written by the same format and layout: the one
// question a host asks before choosing to load (a header alone says nothing of
// whether the rest is valid; load_state checks that).
inline bool same_snapshot_header(const uint8_t* a, size_t a_size, const uint8_t* b, size_t b_size) {
  return a_size >= kSnapshotHeaderBytes && b_size >= kSnapshotHeaderBytes &&
         std::memcmp(a, b, kSnapshotHeaderBytes) == 0;
}

// Whether `data` is a snapshot of another build of `env`'s module: `env` writes
// snapshots, and theirs open with another header. A host that can rebuild the
// state another way (the Python drop-in replays its log) does so, and one that
// cannot says so, instead of calling the bytes corrupt. Saves one snapshot of
// `env` to learn its header (a host's load path, not a hot one); nullopt when
// `env` cannot save (it failed), and each host decides what not knowing means.
inline std::optional<bool> from_another_build(const Environment& env, const uint8_t* data, size_t size) {
  std::vector<uint8_t> own;
  if (!env.save_state(own)) return std::nullopt;
  return !same_snapshot_header(own.data(), own.size(), data, size);
}

}  // namespace autumn::rt
