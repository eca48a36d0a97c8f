#include "harness/progress.hpp"

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <iostream>
#include <mutex>
#include <thread>

namespace autumn {

// ---------------------------------------------------------------------------- Progress

Progress::Progress(std::string command, size_t total) : command_(std::move(command)), total_(total), tty_(isatty(2)) {}

void Progress::item(size_t index, const std::string& name) {
  if (total_ < 2) return;
  if (tty_) std::cerr << "\r\033[K" << command_ << ": " << index + 1 << "/" << total_ << " " << name << std::flush;
  else std::cerr << command_ << ": " << index + 1 << "/" << total_ << " " << name << "\n";
}

void Progress::done() {
  if (total_ >= 2 && tty_) std::cerr << "\r\033[K" << std::flush;
}

// ---------------------------------------------------------------------------- Heartbeat

struct Heartbeat::Impl {
  std::mutex mu;
  std::condition_variable cv;
  bool stop = false;
  bool printed = false;
  std::thread thread;
};

Heartbeat::Heartbeat(std::string label) : impl_(std::make_unique<Impl>()) {
  const bool tty = isatty(2);
  impl_->thread = std::thread([impl = impl_.get(), label = std::move(label), tty] {
    const auto start = std::chrono::steady_clock::now();
    const auto period = std::chrono::seconds(tty ? 1 : 10);
    std::unique_lock<std::mutex> lock(impl->mu);
    while (!impl->cv.wait_for(lock, period, [impl] { return impl->stop; })) {
      const auto s = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - start);
      std::cerr << (tty ? "\r\033[K" : "") << label << ": " << s.count() << " s" << (tty ? "" : "\n") << std::flush;
      impl->printed = true;
    }
    if (impl->printed && tty) std::cerr << "\r\033[K" << std::flush;
  });
}

Heartbeat::~Heartbeat() {
  {
    std::lock_guard<std::mutex> lock(impl_->mu);
    impl_->stop = true;
  }
  impl_->cv.notify_all();
  impl_->thread.join();
}

}  // namespace autumn
