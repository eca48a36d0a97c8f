#include "harness/agent/thread_pool.hpp"

#include <cerrno>
#include <chrono>
#include <stdexcept>
#include <string>
#include <system_error>

namespace autumn::agent {

std::atomic<unsigned> ThreadPool::fail_worker_for_testing{0};

// A worker the system refuses (a process or memory limit) stops and joins the
// ones already started, then says so: a half-built pool would otherwise be
// destroyed with its workers still waiting (and its condition variable with them).
ThreadPool::ThreadPool(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  size_ = threads;
  for (unsigned i = 1; i < size_; ++i) {
    try {
      if (i == fail_worker_for_testing.load()) throw std::system_error(EAGAIN, std::generic_category());
      workers_.emplace_back([this, i] { worker_loop(i); });
    } catch (const std::system_error& e) {
      stop_workers();
      throw std::runtime_error("cannot start thread " + std::to_string(i + 1) + " of " + std::to_string(size_) +
                               " (" + e.what() + "); ask for fewer threads");
    }
  }
}

ThreadPool::~ThreadPool() { stop_workers(); }

void ThreadPool::stop_workers() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
  workers_.clear();
}

void ThreadPool::run_indices(unsigned id) {
  for (;;) {
    size_t i = next_.fetch_add(1, std::memory_order_relaxed);
    if (i >= n_) return;
    try {
      (*body_)(i, id);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mu_);
      if (!error_) error_ = std::current_exception();
    }
  }
}

void ThreadPool::worker_loop(unsigned id) {
  uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    run_indices(id);
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (--busy_ == 0) done_.notify_all();
    }
  }
}

void ThreadPool::parallel_for(size_t n, const std::function<void(size_t)>& body) {
  parallel_for_worker(n, [&body](size_t i, unsigned) { body(i); });
}

void ThreadPool::parallel_for(size_t n, const std::function<void(size_t)>& body, const std::function<void()>& waiting) {
  parallel_for_worker(n, [&body](size_t i, unsigned) { body(i); }, waiting);
}

void ThreadPool::parallel_for_worker(size_t n, const std::function<void(size_t, unsigned)>& body,
                                     const std::function<void()>& waiting) {
  if (n == 0) return;
  if (workers_.empty() || n == 1) {
    for (size_t i = 0; i < n; ++i) body(i, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mu_);
    body_ = &body;
    n_ = n;
    next_.store(0);
    error_ = nullptr;
    busy_ = static_cast<unsigned>(workers_.size());
    ++generation_;
  }
  wake_.notify_all();
  run_indices(0);
  std::exception_ptr err;
  {
    std::unique_lock<std::mutex> lock(mu_);
    if (waiting) {
      while (!done_.wait_for(lock, std::chrono::milliseconds(20), [&] { return busy_ == 0; })) {
        lock.unlock();
        waiting();
        lock.lock();
      }
    }
    done_.wait(lock, [&] { return busy_ == 0; });
    body_ = nullptr;
    err = error_;
    error_ = nullptr;
  }
  if (err) std::rethrow_exception(err);
}

}  // namespace autumn::agent
