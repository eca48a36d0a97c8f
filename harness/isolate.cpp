// isolate — fork, run, read the child's result from a pipe (see isolate.hpp).
#include "harness/isolate.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>

namespace autumn {

namespace {

// A child's work that threw: its message goes back as the death, exit status 70.
constexpr int kChildThrew = 70;

void write_to_pipe(int fd, const std::string& s) {
  for (size_t at = 0; at < s.size();) {
    const ssize_t n = ::write(fd, s.data() + at, s.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) _exit(kChildThrew + 1);
    at += static_cast<size_t>(n);
  }
}

std::string read_pipe(int fd) {
  std::string out;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return out;
    out.append(buf, static_cast<size_t>(n));
  }
}

std::string child_ending(int status, const std::string& said) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = strsignal(sig);
    return "was killed by signal " + std::to_string(sig) + " (" + (name ? name : "unknown") + ")";
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == kChildThrew && !said.empty()) return "failed: " + said;
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status)) + " before its result";
  return "ended in an unknown way";
}

}  // namespace

Isolated run_isolated(const std::function<std::string()>& work) {
  Isolated r;
  int fds[2];
  if (pipe(fds) != 0) {
    r.death = std::string("could not be started (pipe: ") + std::strerror(errno) + ")";
    return r;
  }
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);  // else the child's copies of unwritten output could be written twice
  const pid_t pid = fork();
  if (pid < 0) {
    r.death = std::string("could not be started (fork: ") + std::strerror(errno) + ")";
    close(fds[0]);
    close(fds[1]);
    return r;
  }
  if (pid == 0) {
    close(fds[0]);
    std::string out;
    int status = 0;
    try {
      out = work();
    } catch (const std::exception& e) {
      out = e.what();
      status = kChildThrew;
    } catch (...) {
      out = "an exception that is not a std::exception";
      status = kChildThrew;
    }
    write_to_pipe(fds[1], out);
    std::cerr.flush();
    _exit(status);
  }
  close(fds[1]);
  std::string said = read_pipe(fds[0]);
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      r.death = std::string("could not be waited for (") + std::strerror(errno) + ")";
      return r;
    }
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    r.finished = true;
    r.output = std::move(said);
  } else {
    r.death = child_ending(status, said);
  }
  return r;
}

}  // namespace autumn
