// bind_envs — autumnc.Env and autumnc.VecEnv (their Python faces, with the
// action and observation spaces, are in autumnc/envs.py).
//
// Env is one episode with a Gymnasium-shaped reset/step; reset() with the seed
// it already has copies the initial state it saved instead of starting the
// program again. In "auto" mode it runs on the interpreter while the program's
// module compiles and moves to the compiled engine at a later reset (results
// are the same on both). VecEnv holds N slots (vec_env.hpp) and steps them with
// the GIL released into buffers it owns: the arrays step() returns are the same
// objects every time, overwritten in place. A VecEnv takes one call at a time:
// a second thread calling it meanwhile gets RuntimeError (OneCaller). Ctrl-C
// during a long interpreted step or reset raises KeyboardInterrupt within
// about 20 ms of the handler's turn (interruptible_batch): the batch is then
// half done, and step() asks for a reset.
#include <unistd.h>

#include <atomic>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "compiler/interpret/interpreted_env.hpp"
#include "python/src/bindings.hpp"
#include "python/src/interruptible.hpp"
#include "python/src/module_broker.hpp"
#include "python/src/programs.hpp"
#include "python/src/vec_env.hpp"

namespace pb = pybind11;

namespace autumn::py_bind {
namespace {

struct Spec {
  py::LoadedProgram loaded;
  std::string engine;
  py::PrototypeFuture proto;
};

Spec make_spec(const std::string& text, const std::string& name, const std::string& engine,
               const std::optional<std::string>& trigger) {
  if (engine != "auto" && engine != "compiled" && engine != "interp")
    throw std::invalid_argument("unknown engine '" + engine + "' (expected auto, compiled or interp)");
  Spec s{py::load(text, name, trigger.value_or(""), std::nullopt), engine, {}};
  if (engine != "interp") s.proto = py::request_compiled(s.loaded.program);
  return s;
}

// A fresh environment: compiled when allowed and (unless `wait`) ready.
std::unique_ptr<Environment> make_env(const Spec& s, bool wait) {
  if (s.engine != "interp" && (wait || py::is_ready(s.proto))) {
    std::shared_ptr<const py::Prototype> p = s.proto.get();
    if (p->env) return py::instantiate(*p);
    if (s.engine == "compiled")
      throw std::runtime_error("the compiled engine cannot serve " + s.loaded.program->file.name + ": " + p->why);
  }
  return std::make_unique<InterpretedEnvironment>(s.loaded.program);
}

pb::array_t<uint8_t> observe(Environment& env, py::PaletteMap& colours) {
  const Frame& f = env.frame();
  pb::array_t<uint8_t> out({f.size, f.size});
  colours.paint(f, env.palette(), out.mutable_data());
  return out;
}

Action decode(int64_t a, int grid) {
  Action act;
  if (!py::decode_action(a, grid, &act))
    throw std::invalid_argument("action " + std::to_string(a) + " is not in 0.." + std::to_string(4 + grid * grid) +
                                " (0 noop, 1-4 left/right/up/down, 5 + y*W + x click)");
  return act;
}

// One action id, as VecEnv takes them: a Python or NumPy integer. A float or a
// bool is refused, not truncated (2.9 would run action 2, True action 1), with
// the ValueError VecEnv.step raises.
int64_t action_id(const pb::object& given) {
  auto refuse = [](const std::string& what) {
    return std::invalid_argument("an action must be an integer (an action id), got " + what);
  };
  if (pb::isinstance<pb::bool_>(given)) throw refuse("a bool");
  if (pb::hasattr(given, "dtype")) {  // a NumPy scalar (or array)
    const pb::object dtype = given.attr("dtype");
    const char kind = dtype.attr("kind").cast<std::string>().at(0);
    if (kind != 'i' && kind != 'u') throw refuse("NumPy " + std::string(pb::str(dtype)));
    if (pb::hasattr(given, "ndim") && given.attr("ndim").cast<int>() != 0) throw refuse("an array");
  } else if (!PyLong_Check(given.ptr())) {
    throw refuse(std::string(pb::str(pb::type::of(given).attr("__name__"))));
  }
  const auto index = pb::reinterpret_steal<pb::object>(PyNumber_Index(given.ptr()));
  if (!index) throw pb::error_already_set();
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow) throw std::invalid_argument("action " + std::string(pb::str(given)) + " is out of range");
  return v;
}

class Env {
 public:
  Env(const std::string& text, const std::string& name, uint64_t seed, const std::string& engine,
      const std::optional<std::string>& trigger, uint32_t max_steps)
      : spec_(make_spec(text, name, engine, trigger)), seed_(seed), max_steps_(max_steps) {
    env_ = make_env(spec_, spec_.engine == "compiled");
    start();
    grid_ = env_->frame().size;
  }
  Env(const Env& o)
      : spec_(o.spec_),
        seed_(o.seed_),
        max_steps_(o.max_steps_),
        env_(o.env_->clone()),
        initial_(o.initial_ ? o.initial_->clone() : nullptr),
        grid_(o.grid_),
        steps_(o.steps_),
        started_(o.started_),
        done_(o.done_),
        last_obs_(o.last_obs_) {}

  pb::tuple reset(std::optional<uint64_t> seed, const pb::object&) {
    if (seed && *seed != seed_) {
      seed_ = *seed;
      initial_.reset();
    }
    if (spec_.engine == "auto" && on_interp() && py::is_ready(spec_.proto) && spec_.proto.get()->env) {
      env_ = make_env(spec_, false);  // the module is ready: move to the compiled engine
      initial_.reset();
    }
    if (initial_ && env_->copy_from(*initial_)) {
    } else if (initial_) {
      env_ = initial_->clone();
    } else {
      start();
    }
    steps_ = 0;
    started_ = true;
    done_ = false;
    last_obs_ = observe(*env_, colours_);
    return pb::make_tuple(last_obs_, pb::dict());
  }

  pb::tuple step(const pb::object& action) {
    if (!started_) throw std::runtime_error("call reset() before step()");
    if (done_) throw std::runtime_error("the episode has ended (terminated or truncated): call reset()");
    const Action a = decode(action_id(action), grid_);
    bool ok = false;
    {
      InterruptPollScope poll(&py::poll_python_signals);  // Ctrl-C ends a long interpreted step
      ok = env_->step(a);
    }
    if (!ok) {
      done_ = true;
      py::raise_if_interrupted();
      pb::dict info;
      info["error"] = env_->error();
      return pb::make_tuple(last_obs_, 0.0, true, false, info);
    }
    ++steps_;
    const bool truncated = max_steps_ && steps_ >= max_steps_;
    done_ = truncated;
    last_obs_ = observe(*env_, colours_);
    return pb::make_tuple(last_obs_, env_->triggered() ? 1.0 : 0.0, false, truncated, pb::dict());
  }

  int grid() const { return grid_; }
  std::string engine() const { return on_interp() ? "interp" : "compiled"; }
  uint64_t state_hash() const { return env_->state_hash(); }

 private:
  bool on_interp() const { return dynamic_cast<const InterpretedEnvironment*>(env_.get()) != nullptr; }
  void start() {
    if (!env_->reset(seed_)) throw std::runtime_error(env_->error());
    initial_ = env_->clone();
  }

  Spec spec_;
  uint64_t seed_;
  uint32_t max_steps_;
  std::unique_ptr<Environment> env_, initial_;
  int grid_ = 0;
  uint32_t steps_ = 0;
  bool started_ = false, done_ = false;
  pb::array_t<uint8_t> last_obs_;
  py::PaletteMap colours_;
};

// VecEnv takes one call at a time: step() and reset() release the GIL, so a
// second Python thread could otherwise enter while the slots are being stepped.
class OneCaller {
 public:
  explicit OneCaller(std::atomic<bool>& busy) : busy_(busy) {
    if (busy_.exchange(true))
      throw std::runtime_error(
          "this VecEnv is in use by another thread: a VecEnv takes one call at a time (give each thread its own)");
  }
  ~OneCaller() { busy_ = false; }
  OneCaller(const OneCaller&) = delete;
  OneCaller& operator=(const OneCaller&) = delete;

 private:
  std::atomic<bool>& busy_;
};

// Refuses, before allocating, a batch that cannot fit in this machine's memory
// (MemoryError): each slot holds an environment, its state and its frame, at
// least kSlotBytes; the allocator would otherwise fail deep inside, or the
// system would kill the process.
constexpr size_t kSlotBytes = 4096;
void check_batch_memory(size_t n) {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return;
  const double need = static_cast<double>(n) * kSlotBytes, have = static_cast<double>(pages) * page;
  if (need <= have) return;
  const std::string msg = "num_envs=" + std::to_string(n) + " needs at least " +
                          std::to_string(static_cast<long long>(need / (1 << 20))) + " MiB; this machine has " +
                          std::to_string(static_cast<long long>(have / (1 << 20))) + " MiB";
  PyErr_SetString(PyExc_MemoryError, msg.c_str());
  throw pb::error_already_set();
}

// The check of a batched call's Interrupt (vec_env.hpp): the calling thread,
// which released the GIL for the batch, takes it back for a moment to let
// Python run its signal handlers; a raised KeyboardInterrupt stays pending in
// the thread state until the call returns and raises it.
bool python_signal_pending() {
  pb::gil_scoped_acquire gil;
  return PyErr_CheckSignals() != 0;
}

// Runs batch(&interrupt) without the GIL, Ctrl-C ending it early; a pending
// KeyboardInterrupt is raised after it (and *interrupted set), in place of
// whatever the batch returned or threw.
template <class F>
void interruptible_batch(F&& batch, bool* interrupted) {
  py::Interrupt interrupt;
  interrupt.check = &python_signal_pending;
  try {
    pb::gil_scoped_release release;
    batch(&interrupt);
  } catch (...) {
    if (PyErr_Occurred()) *interrupted = true;
    py::raise_if_interrupted();
    throw;
  }
  if (PyErr_Occurred()) *interrupted = true;
  py::raise_if_interrupted();
}

struct EnvState {
  std::shared_ptr<const Environment> env;
  uint64_t episode;
  uint32_t steps;
  bool done;
  std::string error;
};

class VecEnv {
 public:
  VecEnv(const std::string& text, const std::string& name, size_t n, unsigned threads, uint64_t seed,
         const std::string& engine, const std::optional<std::string>& trigger, uint32_t max_steps)
      : spec_(make_spec(text, name, engine, trigger)), seed_(seed) {
    if (n == 0) throw std::invalid_argument("num_envs must be at least 1");
    check_batch_memory(n);
    std::unique_ptr<Environment> proto = make_env(spec_, true);
    {
      pb::gil_scoped_release release;
      set_ = std::make_unique<py::SlotSet>(*proto, n, seed, max_steps, threads);
    }
    const pb::ssize_t g = set_->grid(), N = static_cast<pb::ssize_t>(n);
    obs_ = pb::array_t<uint8_t>({N, g, g});
    rewards_ = pb::array_t<float>(N);
    terminated_ = pb::array_t<bool>(N);
    truncated_ = pb::array_t<bool>(N);
    buf_ = {obs_.mutable_data(), rewards_.mutable_data(), terminated_.mutable_data(), truncated_.mutable_data()};
    reset(std::nullopt, pb::none());
  }

  pb::tuple reset(std::optional<uint64_t> seed, const pb::object&) {
    OneCaller one(busy_);
    if (seed) seed_ = *seed;
    interrupted_ = false;
    interruptible_batch([&](py::Interrupt* in) { set_->reset_all(seed_, buf_, in); }, &interrupted_);
    return pb::make_tuple(obs_, errors());
  }

  // Actions are action ids: an array of integers (any integer dtype; a list of
  // ints becomes one). Floats and bools are refused rather than truncated.
  pb::tuple step(const pb::object& given) {
    OneCaller one(busy_);
    if (interrupted_)
      throw std::runtime_error("the last call to this VecEnv was interrupted (Ctrl-C) half way through the batch: "
                               "call reset");
    pb::array any = pb::array::ensure(given);
    if (!any) throw pb::error_already_set();
    const char kind = any.dtype().kind();
    if (kind != 'i' && kind != 'u')
      throw std::invalid_argument("actions must be integers (action ids), got an array of dtype " +
                                  std::string(pb::str(any.dtype())));
    auto actions = pb::array_t<int64_t, pb::array::c_style | pb::array::forcecast>::ensure(any);
    if (!actions) throw pb::error_already_set();
    if (actions.ndim() != 1 || static_cast<size_t>(actions.shape(0)) != set_->size())
      throw std::invalid_argument("actions must be a 1-D array of " + std::to_string(set_->size()) + " integers");
    const int64_t* a = actions.data();
    interruptible_batch([&](py::Interrupt* in) { set_->step(a, buf_, in); }, &interrupted_);
    return pb::make_tuple(obs_, rewards_, terminated_, truncated_, errors());
  }

  pb::list clone(const std::vector<int64_t>& ids) {
    OneCaller one(busy_);
    pb::list out;
    for (int64_t i : ids) {
      py::Slot& s = set_->slot(index(i));
      out.append(EnvState{std::shared_ptr<const Environment>(s.env->clone()), s.episode, s.steps, s.done, s.error});
    }
    return out;
  }

  void restore(const std::vector<int64_t>& ids, const std::vector<const EnvState*>& states) {
    OneCaller one(busy_);
    if (ids.size() != states.size()) throw std::invalid_argument("restore: ids and states differ in length");
    for (size_t k = 0; k < ids.size(); ++k) {
      const size_t i = index(ids[k]);
      py::Slot& s = set_->slot(i);
      if (!states[k]) throw std::invalid_argument("restore: a state is None");
      if (!s.env->copy_from(*states[k]->env)) s.env = states[k]->env->clone();
      s.episode = states[k]->episode;
      s.steps = states[k]->steps;
      s.done = states[k]->done;
      s.error = states[k]->error;
      set_->write_obs(i, buf_);
    }
  }

  pb::array_t<uint64_t> state_hash() {
    OneCaller one(busy_);
    pb::array_t<uint64_t> out(static_cast<pb::ssize_t>(set_->size()));
    for (size_t i = 0; i < set_->size(); ++i) out.mutable_data()[i] = set_->slot(i).env->state_hash();
    return out;
  }

  size_t size() const { return set_->size(); }
  int grid() const { return set_->grid(); }
  unsigned threads() const { return set_->threads(); }

 private:
  size_t index(int64_t i) const {
    if (i < 0 || static_cast<size_t>(i) >= set_->size())
      throw pb::index_error("environment index " + std::to_string(i) + " out of range");
    return static_cast<size_t>(i);
  }
  pb::dict errors() {
    pb::dict info;
    for (size_t i = 0; i < set_->size(); ++i)
      if (buf_.terminated[i] && !set_->slot(i).error.empty()) {
        if (!info.contains("errors")) info["errors"] = pb::dict();
        info["errors"][pb::int_(i)] = set_->slot(i).error;
      }
    return info;
  }

  Spec spec_;
  uint64_t seed_;
  std::unique_ptr<py::SlotSet> set_;
  pb::array_t<uint8_t> obs_;
  pb::array_t<float> rewards_;
  pb::array_t<bool> terminated_, truncated_;
  py::Buffers buf_;
  std::atomic<bool> busy_{false};  // a call is running (OneCaller)
  bool interrupted_ = false;        // Ctrl-C stopped the last step or reset half way; step() wants a reset
};

}  // namespace

void bind_envs(pb::module_& m) {
  pb::class_<Env>(m, "_Env", pb::dynamic_attr())
      .def(pb::init<const std::string&, const std::string&, uint64_t, const std::string&,
                    const std::optional<std::string>&, uint32_t>(),
           pb::arg("text"), pb::arg("name"), pb::arg("seed"), pb::arg("engine"), pb::arg("trigger"),
           pb::arg("max_episode_steps"))
      .def("reset", &Env::reset, pb::arg("seed") = pb::none(), pb::arg("options") = pb::none())
      .def("step", &Env::step, pb::arg("action"))
      .def("clone", [](const Env& e) { return Env(e); })
      .def("state_hash", &Env::state_hash)
      .def_property_readonly("grid_size", &Env::grid)
      .def_property_readonly("engine", &Env::engine);
  pb::class_<EnvState>(m, "EnvState", "One environment's state, from VecEnv.clone()")
      .def("state_hash", [](const EnvState& s) { return s.env->state_hash(); });
  pb::class_<VecEnv>(m, "_VecEnv", pb::dynamic_attr())
      .def(pb::init<const std::string&, const std::string&, size_t, unsigned, uint64_t, const std::string&,
                    const std::optional<std::string>&, uint32_t>(),
           pb::arg("text"), pb::arg("name"), pb::arg("num_envs"), pb::arg("num_threads"), pb::arg("seed"),
           pb::arg("engine"), pb::arg("trigger"), pb::arg("max_episode_steps"))
      .def("reset", &VecEnv::reset, pb::arg("seed") = pb::none(), pb::arg("options") = pb::none())
      .def("step", &VecEnv::step, pb::arg("actions"))
      .def("clone", &VecEnv::clone, pb::arg("ids"))
      .def("restore", &VecEnv::restore, pb::arg("ids"), pb::arg("states"))
      .def("state_hash", &VecEnv::state_hash)
      .def_property_readonly("num_envs", &VecEnv::size)
      .def_property_readonly("grid_size", &VecEnv::grid)
      .def_property_readonly("num_threads", &VecEnv::threads);
}

}  // namespace autumn::py_bind
