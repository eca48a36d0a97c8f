// module_broker — compiled environments for the Python package, without blocking.
//
// The module cache (harness/module_cache) finds or builds a program's module,
// which can take a C++ compile. request() queues that for a background worker
// (at most as many as the cache's compile slots, the newest request first) the
// first time a program (text + trigger) is asked for and returns a shared
// future of a *prototype*: an environment reset once, from which sessions clone
// theirs (a clone never touches the cache, whose lock a compile of another
// program may be holding). A null prototype carries the reason it could not be
// built. Programs with a non-bundled standard library never get here: modules
// are built with the bundled one.
#pragma once
#include <functional>
#include <future>
#include <memory>
#include <string>

#include "compiler/analyse/program.hpp"
#include "runtime/environment.hpp"

namespace autumn::py {

struct Prototype {
  std::shared_ptr<const Environment> env;  // null when the engine cannot serve the program
  std::string why;
  bool specialised = false;  // snapshots supported (specialised code, not the embedded interpreter)
  double seconds = 0;        // time to find or build the module
};

using PrototypeFuture = std::shared_future<std::shared_ptr<const Prototype>>;

PrototypeFuture request_compiled(const std::shared_ptr<const Program>& program);
// Blocks until every compile started so far has finished (the package calls it
// at interpreter exit, so that no compile thread outlives the process's statics).
// Calls before(n) first when n > 0 are still running; returns n.
size_t wait_for_compiles(const std::function<void(size_t)>& before = nullptr);
bool is_ready(const PrototypeFuture& f);
// A fresh environment from a ready prototype (null if the prototype is null).
std::unique_ptr<Environment> instantiate(const Prototype& p);

}  // namespace autumn::py
