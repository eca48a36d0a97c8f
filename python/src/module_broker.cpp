// module_broker — one compiled prototype per exact program text (and trigger) for
// the Python package; the module cache does the finding and building.
#include "python/src/module_broker.hpp"

#include <chrono>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include "compiler/emit/emit_module.hpp"
#include "harness/module_build.hpp"
#include "harness/module_cache.hpp"
#include "harness/module_key.hpp"

namespace autumn::py {
namespace {

std::shared_ptr<const Prototype> build(std::shared_ptr<const Program> program) {
  auto p = std::make_shared<Prototype>();
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<Environment> env = make_compiled_environment(program, &p->why);
  p->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!env) return p;
  env->reset(0);
  std::vector<uint8_t> probe;
  p->specialised = !env->failed() && env->save_state(probe);
  p->env = std::move(env);
  return p;
}

void fulfil(std::promise<std::shared_ptr<const Prototype>>& promise, std::shared_ptr<const Program> program) {
  try {
    promise.set_value(build(std::move(program)));
  } catch (const std::exception& e) {
    auto p = std::make_shared<Prototype>();
    p->why = e.what();
    promise.set_value(p);
  }
}

struct Job {
  std::shared_ptr<std::promise<std::shared_ptr<const Prototype>>> promise;
  std::shared_ptr<const Program> program;
};

// Guarded by mu. Invariants: `futures` holds every request ever made (a key is
// built at most once); a request not yet started is in `waiting`, newest last;
// `workers` threads are running, at most module_compile_slots(), and a worker
// leaves only when `waiting` is empty. Never destroyed: a compile still running
// at process exit finds them alive.
std::mutex mu;
auto* futures = new std::unordered_map<std::string, PrototypeFuture>();
auto* waiting = new std::vector<Job>();
int workers = 0;

// A worker takes the newest request first: the program a client opened last is
// the one it is stepping (a drop-in client opening seventy programs in turn),
// and a caller blocked in get() has just asked. At most module_compile_slots()
// at once per process: more would only queue on the cache's compile slots,
// where (flock being unfair) seventy waiters of one process starved every other
// process's single compile for minutes.
void work() {
  for (;;) {
    Job job;
    {
      std::lock_guard<std::mutex> lock(mu);
      if (waiting->empty()) {
        --workers;
        return;
      }
      job = std::move(waiting->back());
      waiting->pop_back();
    }
    fulfil(*job.promise, std::move(job.program));
  }
}

}  // namespace

PrototypeFuture request_compiled(const std::shared_ptr<const Program>& program) {
  std::optional<std::string> trigger;
  if (!program->trigger_text.empty()) trigger = program->trigger_text;
  // The exact text and trigger (a 64-bit hash could pair a program with another's module).
  const std::string key = program_digest(program->file.text, trigger);
  std::lock_guard<std::mutex> lock(mu);
  auto it = futures->find(key);
  if (it != futures->end()) return it->second;
  auto promise = std::make_shared<std::promise<std::shared_ptr<const Prototype>>>();
  PrototypeFuture f = promise->get_future().share();
  (*futures)[key] = f;
  waiting->push_back({promise, program});
  // std::async's future would block process exit until a compile finishes;
  // detached workers and promises do not.
  if (workers < module_compile_slots()) {
    ++workers;
    std::thread(work).detach();
  }
  return f;
}

size_t wait_for_compiles(const std::function<void(size_t)>& before) {
  std::vector<PrototypeFuture> pending;
  {
    std::lock_guard<std::mutex> lock(mu);
    for (auto& [key, f] : *futures)
      if (!is_ready(f)) pending.push_back(f);
  }
  if (!pending.empty() && before) before(pending.size());
  for (auto& f : pending) f.wait();
  return pending.size();
}

bool is_ready(const PrototypeFuture& f) {
  return f.valid() && f.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

std::unique_ptr<Environment> instantiate(const Prototype& p) {
  return p.env ? p.env->clone() : nullptr;
}

}  // namespace autumn::py
