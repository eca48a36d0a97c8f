// thread_pool — a small fixed pool of std::threads for data-parallel loops.
//
// parallel_for(n, body) runs body(0..n-1), each index exactly once, on the pool's
// workers and the calling thread, and returns when all are done. Results must be
// written to per-index slots: callers merge them afterwards in index order, which
// is what keeps every agent result independent of the thread count. The first
// exception thrown by a body is rethrown in the caller (the other indices still
// run). A pool of size 1 runs everything inline on the caller. parallel_for is not
// reentrant: one caller at a time, and bodies must not call it. A thread the
// system refuses is a std::runtime_error from the constructor, nothing left running.
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace autumn::agent {

class ThreadPool {
 public:
  // threads == 0: std::thread::hardware_concurrency() (at least 1).
  explicit ThreadPool(unsigned threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return size_; }
  void parallel_for(size_t n, const std::function<void(size_t)>& body);
  // Same; once the caller has no index left to run, it calls waiting() about
  // every 20 ms until the workers are done (a host polls for Ctrl-C there; it
  // must not throw).
  void parallel_for(size_t n, const std::function<void(size_t)>& body, const std::function<void()>& waiting);
  // Same, also passing the id (0..size()-1) of the thread running the index, for
  // per-thread scratch state; 0 is the calling thread.
  void parallel_for_worker(size_t n, const std::function<void(size_t, unsigned)>& body,
                           const std::function<void()>& waiting = nullptr);
  // Tests only: nonzero k makes the constructor's k-th worker fail to start, as
  // when the system refuses a thread (the constructor then throws runtime_error).
  static std::atomic<unsigned> fail_worker_for_testing;

 private:
  void stop_workers();
  void worker_loop(unsigned id);
  void run_indices(unsigned id);

  unsigned size_ = 1;
  std::vector<std::thread> workers_;
  std::mutex mu_;
  std::condition_variable wake_, done_;
  bool stop_ = false;
  uint64_t generation_ = 0;
  unsigned busy_ = 0;  // workers still inside the current job
  const std::function<void(size_t, unsigned)>* body_ = nullptr;
  size_t n_ = 0;
  std::atomic<size_t> next_{0};
  std::exception_ptr error_;
};

}  // namespace autumn::agent
