// module_store — directory checks, private files, manifests and loading from
// memory for the module cache (the trust model is in module_store.hpp). Every
// failure comes back as a one-line reason naming the path and the system's
// error, never as an exception or a signal.
#include "harness/module_store.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <iostream>
#include <sstream>
#include <utility>
#include <vector>

namespace autumn::store {
namespace {

std::string errno_text() { return std::strerror(errno); }

std::string octal_mode(mode_t m) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(m & 07777));
  return buf;
}

// ---------------------------------------------------------------------------- the directory

// The system's temporary directory ($TMPDIR, else /tmp); empty when that is not a directory.
fs::path temp_dir() {
  std::error_code ec;
  fs::path t = fs::temp_directory_path(ec);
  return ec ? fs::path() : t;
}

fs::path private_temp_cache() {
  const fs::path t = temp_dir();
  return (t.empty() ? fs::path("/tmp") : t) / ("autumnc-cache-" + std::to_string(geteuid()));
}

fs::path configured_cache_dir() {
  if (const char* d = std::getenv("AUTUMN_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "autumnc";
  if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".cache" / "autumnc";
  return private_temp_cache();
}

// mkdir -p, each directory it creates 0700.
std::string make_private_dirs(const fs::path& dir) {
  fs::path so_far;
  for (const fs::path& part : dir.lexically_normal()) {
    so_far /= part;
    if (mkdir(so_far.c_str(), 0700) != 0 && errno != EEXIST) return so_far.string() + ": " + errno_text();
  }
  return "";
}

// ssh's StrictModes: the directory is this user's and nobody else may write to it.
std::string unsafe_dir(const fs::path& dir, const struct stat& st) {
  if (!S_ISDIR(st.st_mode)) return "not a directory";
  if (st.st_uid != geteuid())
    return "owned by uid " + std::to_string(st.st_uid) + ", not by this user (uid " + std::to_string(geteuid()) + ")";
  if (st.st_mode & (S_IWGRP | S_IWOTH)) return "writable by other users (mode " + octal_mode(st.st_mode) + ")";
  return "";
}

// A parent another user could rename the directory out of: owned by someone
// other than root or this user, or writable by others without the sticky bit.
std::string unsafe_parent(const fs::path& dir) {
  for (fs::path p = dir.parent_path(); !p.empty(); p = p.parent_path()) {
    struct stat st;
    if (stat(p.c_str(), &st) != 0) return p.string() + ": " + errno_text();
    if (st.st_uid != 0 && st.st_uid != geteuid())
      return "its parent " + p.string() + " is owned by uid " + std::to_string(st.st_uid);
    if ((st.st_mode & (S_IWGRP | S_IWOTH)) && !(st.st_mode & S_ISVTX))
      return "its parent " + p.string() + " is writable by other users (mode " + octal_mode(st.st_mode) + ")";
    if (p == p.root_path()) break;
  }
  return "";
}

// The chosen directory, or why there is none; warns on stderr when it falls back.
std::pair<fs::path, std::string> choose_dir() {
  const fs::path dir = configured_cache_dir();
  fs::path resolved;
  bool refused = false;
  const std::string problem = prepare_dir(dir, &resolved, &refused);
  if (problem.empty()) return {resolved, ""};
  const fs::path tmp = private_temp_cache();
  bool tmp_refused = false;
  const std::string tmp_problem = temp_dir().empty() ? "no temporary directory" : prepare_dir(tmp, &resolved, &tmp_refused);
  const std::string said = (refused ? "refusing the module cache " : "cannot write the module cache ") + dir.string();
  if (tmp_problem.empty()) {
    std::cerr << "autumn: warning: " << said << " (" << problem << "); using " << resolved.string() << "\n";
    return {resolved, ""};
  }
  return {fs::path(), "no usable module cache (" + dir.string() + ": " + problem + "; " + tmp.string() + ": " +
                          tmp_problem + ")"};
}

// ---------------------------------------------------------------------------- files

// Opens for reading without following a link and without blocking on a FIFO.
int open_no_follow(const fs::path& path) { return open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK); }

std::string write_all(int fd, std::string_view bytes) {
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return errno_text();
    done += static_cast<size_t>(n);
  }
  return "";
}

std::string read_all(int fd, size_t size, std::string* bytes) {
  bytes->assign(size, '\0');
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(fd, bytes->data() + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno_text();
    if (n == 0) break;  // shrank while being read
    done += static_cast<size_t>(n);
  }
  bytes->resize(done);
  return "";
}

bool old_temporary(const fs::directory_entry& e, time_t cutoff) {
  const std::string name = e.path().filename().string();
  const auto ends = [&](const char* s) { return name.size() > std::strlen(s) && name.ends_with(s); };
  if (!(ends(".part") || ends(".cpp") || ends(".log") || name.starts_with("probe."))) return false;
  struct stat st;
  return lstat(e.path().c_str(), &st) == 0 && !S_ISDIR(st.st_mode) && st.st_mtime < cutoff;
}

}  // namespace

fs::path cache_dir(std::string* why) {
  static const std::pair<fs::path, std::string> chosen = [] {
    auto c = choose_dir();
    if (!c.first.empty()) clean_stale_temporaries(c.first, 3600);
    return c;
  }();
  if (chosen.first.empty()) *why = chosen.second;
  return chosen.first;
}

std::string prepare_dir(const fs::path& dir, fs::path* resolved, bool* refused) {
  *refused = false;
  if (std::string e = make_private_dirs(dir); !e.empty()) return e;
  char* real = realpath(dir.c_str(), nullptr);
  if (!real) return errno_text();
  *resolved = real;
  free(real);
  struct stat st;
  if (stat(resolved->c_str(), &st) != 0) return errno_text();
  std::string unsafe = unsafe_dir(*resolved, st);
  if (unsafe.empty()) unsafe = unsafe_parent(*resolved);
  if (!unsafe.empty()) return *refused = true, unsafe;
  return probe_write(*resolved, 0);
}

void clean_stale_temporaries(const fs::path& dir, long seconds) {
  const time_t cutoff = std::time(nullptr) - seconds;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::error_code ignored;
    if (old_temporary(e, cutoff)) fs::remove(e.path(), ignored);
  }
}

fs::path entry_lock_path(const fs::path& so) {
  fs::path lock = so;
  lock.replace_extension(".lock");
  return lock;
}

std::string write_new_file(const fs::path& path, std::string_view bytes) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return "cannot write " + path.string() + ": " + errno_text();
  std::string e = write_all(fd, bytes);
  if (close(fd) != 0 && e.empty()) e = errno_text();
  if (e.empty()) return "";
  unlink(path.c_str());
  return "cannot write " + path.string() + ": " + e;
}

std::string publish_file(const fs::path& path, std::string_view bytes, const std::string& tag) {
  const fs::path tmp = path.string() + "." + tag + ".part";
  unlink(tmp.c_str());  // left by a killed process whose pid and thread this one reuses
  if (std::string e = write_new_file(tmp, bytes); !e.empty()) return e;
  if (rename(tmp.c_str(), path.c_str()) == 0) return "";
  const std::string e = "cannot write " + path.string() + ": " + errno_text();
  unlink(tmp.c_str());
  return e;
}

std::string read_private_file(const fs::path& path, size_t limit, std::string* bytes) {
  const int fd = open_no_follow(path);
  if (fd < 0) return path.string() + ": " + (errno == ELOOP ? "a symbolic link (not followed)" : errno_text());
  struct stat st;
  std::string e;
  if (fstat(fd, &st) != 0) e = errno_text();
  else if (!S_ISREG(st.st_mode)) e = "not a regular file";
  else if (st.st_uid != geteuid()) e = "owned by uid " + std::to_string(st.st_uid);
  else if (static_cast<size_t>(st.st_size) > limit) e = "larger than " + std::to_string(limit) + " bytes";
  else e = read_all(fd, static_cast<size_t>(st.st_size), bytes);
  close(fd);
  return e.empty() ? "" : path.string() + ": " + e;
}

std::string probe_write(const fs::path& dir, size_t bytes) {
  std::string probe = (dir / "probe.XXXXXX").string();
  const int fd = mkstemp(probe.data());  // 0600
  if (fd < 0) return "cannot write in " + dir.string() + ": " + errno_text();
  std::string e = write_all(fd, std::string(bytes, '\0'));
  if (e.empty() && bytes && fsync(fd) != 0) e = errno_text();
  close(fd);
  unlink(probe.c_str());
  return e.empty() ? "" : "cannot write in " + dir.string() + ": " + e;
}

// ---------------------------------------------------------------------------- manifests

fs::path manifest_path(const fs::path& so) { return fs::path(so).replace_extension(".manifest"); }

std::string manifest_head(unsigned abi, const std::string& program) {
  return "autumn module manifest v1\nabi " + std::to_string(abi) + "\nprogram " + program + "\n";
}

std::optional<Manifest> parse_manifest(const std::string& text) {
  std::istringstream in(text);
  std::string line, key;
  if (!std::getline(in, line) || line != "autumn module manifest v1") return std::nullopt;
  Manifest m;
  if (!(in >> key >> m.abi) || key != "abi") return std::nullopt;
  if (!(in >> key >> m.program) || key != "program") return std::nullopt;
  if (!(in >> key >> m.so) || key != "so") return std::nullopt;
  if (m.program.size() != 64 || m.so.size() != 64) return std::nullopt;
  return m;
}

// ---------------------------------------------------------------------------- loading

namespace {

// A /proc/self/fd path to `fd` that names no library already loaded: glibc
// recognises a loaded library by its name before it looks at the file, so a
// descriptor number an earlier module was loaded from (and may still be loaded
// under) is skipped by dup'ing past it. The numbers passed over go to *spare.
std::string unused_fd_path(int* fd, std::vector<int>* spare) {
  for (;;) {
    const std::string path = "/proc/self/fd/" + std::to_string(*fd);
    void* earlier = dlopen(path.c_str(), RTLD_LAZY | RTLD_NOLOAD);
    if (!earlier) return path;
    dlclose(earlier);
    spare->push_back(*fd);
    *fd = dup(*fd);
    if (*fd < 0) return "";
  }
}

}  // namespace

std::shared_ptr<void> load_from_memory(const std::string& bytes, const std::string& name, std::string* why) {
  int fd = memfd_create(name.c_str(), MFD_CLOEXEC);
  if (fd < 0) return *why = "memfd_create: " + errno_text(), nullptr;
  std::vector<int> spare;
  std::string path;
  if (std::string e = write_all(fd, bytes); !e.empty()) *why = "cannot copy the module into memory: " + e;
  else if ((path = unused_fd_path(&fd, &spare)).empty()) *why = "dup: " + errno_text();
  void* h = path.empty() ? nullptr : dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h && !path.empty()) *why = std::string("cannot load compiled module: ") + dlerror();
  for (int f : spare) close(f);
  if (fd >= 0) close(fd);  // the library stays mapped
  if (!h) return nullptr;
  return std::shared_ptr<void>(h, [](void* p) { dlclose(p); });
}

}  // namespace autumn::store
