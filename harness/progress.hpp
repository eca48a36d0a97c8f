// progress — what long-running commands say on stderr while they work.
//
// Progress counts items (programs, tasks): redrawn in place on a terminal, a
// line per item otherwise (logs), silent for a single item. Heartbeat is for one
// long step with nothing to count (a planning search): every second on a
// terminal, every ten seconds otherwise, it says how long it has been running,
// starting only after the first period, so quick commands stay quiet.
#pragma once
#include <cstddef>
#include <memory>
#include <string>

namespace autumn {

class Progress {
 public:
  Progress(std::string command, size_t total);
  void item(size_t index, const std::string& name);  // before item `index` (0-based)
  void done();

 private:
  std::string command_;
  size_t total_;
  bool tty_;
};

// A one-line note on stderr every few seconds while a long step runs ("solve:
// 12 s"), so that a silent search does not look hung. Stops when destroyed.
class Heartbeat {
 public:
  explicit Heartbeat(std::string label);
  ~Heartbeat();
  Heartbeat(const Heartbeat&) = delete;
  Heartbeat& operator=(const Heartbeat&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace autumn
