// module_store — the on-disk module cache, trusted only after it is checked.
//
// Trust model (docs/design.md, "Trust: the module store"): the cache directory is
// the user's own. It is created 0700; an existing one is refused, as ssh's
// StrictModes does, when another user owns it or others may write to it (or to a
// parent that is not sticky), so nobody else can plant or swap an entry. Files
// are created 0600 and opened without following links. Within that directory a
// cache entry is still not trusted blindly: a manifest beside each module records
// the SHA-256 of its bytes, the digest of the program it was built from and the
// ABI version; the loader reads the module into memory, checks it, and loads
// exactly those bytes from a private memory file, so a truncated, corrupt or
// misplaced module is refused (and rebuilt) instead of crashing or running
// another program.
//
// This file holds the mechanics (directory checks, private files, manifests,
// loading from memory); harness/module_cache decides what to look up and build.
#pragma once
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace autumn::store {

namespace fs = std::filesystem;

// The cache directory to use: $AUTUMN_CACHE_DIR, else $XDG_CACHE_HOME/autumnc,
// else ~/.cache/autumnc; when that is unsafe or cannot be written, the private
// $TMPDIR/autumnc-cache-$UID (with a one-line warning on stderr). Empty, with
// *why, when neither can be used. Chosen once per process, resolved to a path
// without links; stale temporaries in it are removed then.
fs::path cache_dir(std::string* why);

// Creates the missing parts of `dir` 0700 and checks it ("" when usable). Sets
// *refused when it exists but is unsafe (owner, mode), not merely unwritable.
std::string prepare_dir(const fs::path& dir, fs::path* resolved, bool* refused);

// Removes temporaries (*.part, *.cpp, *.log, probe.*) older than `seconds`: what
// a killed compile leaves behind.
void clean_stale_temporaries(const fs::path& dir, long seconds);

// A new private file (0600, never through a link), written whole and renamed to
// `path`; "" or "cannot write PATH: reason".
std::string publish_file(const fs::path& path, std::string_view bytes, const std::string& tag);
// Creates `path` (which must not exist) 0600 and writes it; "" or the reason.
std::string write_new_file(const fs::path& path, std::string_view bytes);
// Reads a regular file of this user without following a link; "" or "PATH: reason".
std::string read_private_file(const fs::path& path, size_t limit, std::string* bytes);

// Whether writing `bytes` bytes into `dir` works; "" or "cannot write in DIR: reason"
// (names ENOSPC or EACCES when a compile failed without a word).
std::string probe_write(const fs::path& dir, size_t bytes);

// The lock file of an entry, mKEY.lock: held by the compile script while it
// builds the entry (harness/module_build), so that processes sharing a cache
// build each module once.
fs::path entry_lock_path(const fs::path& so);


struct Manifest {
  unsigned abi = 0;
  std::string program;  // program_digest() of the text the module was built from
  std::string so;       // SHA-256 of the module's bytes
};
// The manifest beside a module: mKEY.so -> mKEY.manifest.
fs::path manifest_path(const fs::path& so);
// The manifest's first lines; the compile appends "so <digest>\n".
std::string manifest_head(unsigned abi, const std::string& program);
std::optional<Manifest> parse_manifest(const std::string& text);

// Loads `bytes` (a shared library already verified) from a private memory file:
// nothing on disk can change between the check and the load, and every load is
// a new library (never a stale handle of an earlier one). Null, with *why.
std::shared_ptr<void> load_from_memory(const std::string& bytes, const std::string& name, std::string* why);

}  // namespace autumn::store
