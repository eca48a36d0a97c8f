// output — checked writes (output.hpp). POSIX calls rather than ofstream: a
// stream's failbit does not say why, and the reason is what a user needs.
#include "compiler/read/output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

namespace autumn {

std::string write_file(const std::filesystem::path& path, const std::string& text) {
  auto failed = [&](int err) { return "cannot write " + path.string() + ": " + std::strerror(err); };
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return failed(errno);
  const char* p = text.data();
  size_t left = text.size();
  int err = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      err = n < 0 ? errno : EIO;
      break;
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0) return {};
  std::error_code ignored;
  std::filesystem::remove(path, ignored);  // no half file left standing as if written
  return failed(err);
}

int finish_stdout(const char* tool, int status) {
  std::cout.flush();
  errno = 0;
  const bool ok = std::fflush(stdout) == 0 && !std::ferror(stdout) && std::cout.good();
  if (ok) return status;
  int err = errno;
  if (err == 0) {
    // The write that failed was an earlier one (the buffer filled mid-run) and its
    // errno is gone: the output is already incomplete, so one more byte, written
    // directly, asks the descriptor for the reason.
    if (::write(STDOUT_FILENO, "\n", 1) < 0) err = errno;
  }
  std::fprintf(stderr, "%s: cannot write the standard output: %s\n", tool,
               err ? std::strerror(err) : "the stream failed");
  return status == 0 ? 1 : status;
}

}  // namespace autumn
