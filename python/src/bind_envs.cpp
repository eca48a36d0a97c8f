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
#include <cstring>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "compiler/interpret/interpreted_env.hpp"
#include "python/src/bindings.hpp"
#include "python/src/interruptible.hpp"
#include "python/src/module_broker.hpp"
#include "runtime/snapshot_header.hpp"
#include "python/src/programs.hpp"
#include "python/src/session.hpp"
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

// One slot of a VecEnv, copied out by clone() (restore() copies it back). The
// program it belongs to goes with it: restore() refuses another program's
// state, and pickling carries the program's text.
struct EnvState {
  std::shared_ptr<const Environment> env;
  uint64_t episode;
  uint32_t steps;
  bool done;
  std::string error;
  std::shared_ptr<const Program> program;
  uint64_t digest;  // py::session_program_hash(*program)
};

// The bytes form of an EnvState (to_bytes / from_bytes / pickle). The compiled
// engine's snapshot (Environment::save_state, validated by load_state) behind
// a header that names the program the way Interpreter.get_state() does, so a
// state loads only into the program, standard library and trigger it came
// from. Layout (little-endian, as written by this machine): "AUTE" u32
// version, u64 program digest, u64 episode, u32 steps, u8 done, u64 length and
// the error text, u64 length and the snapshot; nothing after it.
constexpr uint32_t kStateVersion = 1;

pb::bytes state_bytes(const EnvState& s) {
  std::vector<uint8_t> snap;
  if (s.env->failed())
    throw std::invalid_argument("this state ended in a runtime error (" + s.env->error() +
                                "): it has nothing to continue, and no bytes form");
  if (!s.env->save_state(snap))
    throw std::invalid_argument(
        "this state's engine cannot save its state as bytes (only specialised compiled modules can: the "
        "interpreter and modules that embed it cannot); make the VecEnv with engine=\"compiled\"");
  std::string out = "AUTE";
  auto put = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
  put(kStateVersion);
  put(s.digest);
  put(s.episode);
  put(s.steps);
  put(static_cast<uint8_t>(s.done));
  put(static_cast<uint64_t>(s.error.size()));
  out += s.error;
  put(static_cast<uint64_t>(snap.size()));
  out.append(reinterpret_cast<const char*>(snap.data()), snap.size());
  return pb::bytes(out);
}

EnvState state_from_bytes(const std::string& text, const std::string& name, const std::optional<std::string>& trigger,
                          const pb::bytes& data) {
  const std::string_view b = data;
  size_t at = 0;
  auto bad = [](const std::string& why) { return std::invalid_argument("EnvState.from_bytes: " + why); };
  auto get = [&](auto& v) {
    if (b.size() - at < sizeof v) throw bad("truncated state");
    std::memcpy(&v, b.data() + at, sizeof v);
    at += sizeof v;
  };
  auto text_of = [&](uint64_t n) {
    if (b.size() - at < n) throw bad("truncated state");
    std::string t(b.substr(at, n));
    at += n;
    return t;
  };
  if (b.substr(0, 4) != "AUTE") throw bad("not the bytes of an autumnc EnvState (EnvState.to_bytes())");
  at = 4;
  uint32_t version = 0;
  get(version);
  if (version != kStateVersion) throw bad("a state of another autumnc version");
  EnvState s{};
  s.program = py::load(text, name, trigger.value_or(""), std::nullopt).program;
  s.digest = py::session_program_hash(*s.program);
  uint64_t digest = 0, len = 0;
  uint8_t done = 0;
  get(digest);
  if (digest != s.digest) throw bad("the state belongs to another program, standard library or trigger");
  get(s.episode);
  get(s.steps);
  get(done);
  s.done = done != 0;
  get(len);
  s.error = text_of(len);
  get(len);
  const std::string snap = text_of(len);
  if (at != b.size()) throw bad("corrupt state (bytes after the end)");
  std::shared_ptr<const py::Prototype> proto;
  {
    pb::gil_scoped_release release;  // may compile the program's module
    proto = py::request_compiled(s.program).get();
  }
  if (!proto->env) throw std::runtime_error("the compiled engine cannot serve " + name + ": " + proto->why);
  std::unique_ptr<Environment> env = py::instantiate(*proto);
  // Refused as another build's only when the module can tell; else load_state says what is wrong.
  if (rt::from_another_build(*env, reinterpret_cast<const uint8_t*>(snap.data()), snap.size()).value_or(false))
    throw bad("the state was saved by another build of this program's module (its snapshot names another layout "
              "or format), which this one cannot read; save it again with this autumnc");
  if (!env->load_state(reinterpret_cast<const uint8_t*>(snap.data()), snap.size()))
    throw bad(env->failed() ? "corrupt state (" + env->error() + ")"
                            : "this program's module cannot load snapshots (it embeds the interpreter)");
  s.env = std::move(env);
  return s;
}

class VecEnv {
 public:
  VecEnv(const std::string& text, const std::string& name, size_t n, unsigned threads, uint64_t seed,
         const std::string& engine, const std::optional<std::string>& trigger, uint32_t max_steps)
      : spec_(make_spec(text, name, engine, trigger)), digest_(py::session_program_hash(*spec_.loaded.program)), seed_(seed) {
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
      out.append(EnvState{std::shared_ptr<const Environment>(s.env->clone()), s.episode, s.steps, s.done, s.error,
                          spec_.loaded.program, digest_});
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
      if (states[k]->digest != digest_)
        throw std::invalid_argument("restore: state " + std::to_string(k) +
                                    " belongs to another program, standard library or trigger");
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
  uint64_t digest_;  // of the program: states of another are refused
  uint64_t seed_;
  std::unique_ptr<py::SlotSet> set_;
  pb::array_t<uint8_t> obs_;
  pb::array_t<float> rewards_;
  pb::array_t<bool> terminated_, truncated_;
  py::Buffers buf_;
  std::atomic<bool> busy_{false};  // a call is running (OneCaller)
  bool interrupted_ = false;        // Ctrl-C stopped the last step or reset half way; step() wants a reset
};

void bind_env(pb::module_& m) {
  // autumnc.Env and autumnc.VecEnv (autumnc/envs.py) subclass these and add the
  // spaces; their class docstrings explain actions, observations and rewards.
  pb::class_<Env>(m, "_Env", pb::dynamic_attr(), "The C++ side of autumnc.Env (construct autumnc.Env instead)")
      .def(pb::init<const std::string&, const std::string&, uint64_t, const std::string&,
                    const std::optional<std::string>&, uint32_t>(),
           pb::arg("text"), pb::arg("name"), pb::arg("seed"), pb::arg("engine"), pb::arg("trigger"),
           pb::arg("max_episode_steps"),
           "text: the program's text; name: its name in error messages; seed: the random seed of the first "
           "episode; engine: \"auto\", \"compiled\" or \"interp\"; trigger: a trigger-condition expression or "
           "None; max_episode_steps: steps before truncation (0: never)")
      .def(pb::init([](const Env& other) { return Env(other); }), pb::arg("other"),
           "A copy of other at the same point of the same episode (how autumnc.Env.clone makes an Env of "
           "the caller's class)")
      .def("reset", &Env::reset, pb::arg("seed") = pb::none(), pb::arg("options") = pb::none(),
           "Start an episode; returns (obs, info).\n\n"
           "seed: None keeps the current seed (the initial state saved at the last start is copied, not "
           "recomputed); a new seed restarts the program with it. options is accepted and ignored (Gymnasium's "
           "signature). In \"auto\" mode a reset is where the environment moves to the compiled engine once the "
           "program's module is ready. obs is a uint8 [H, W] array of colour ids (autumnc.colour_names()).")
      .def("step", &Env::step, pb::arg("action"),
           "One step; returns (obs, reward, terminated, truncated, info).\n\n"
           "action: an integer action id: 0 noop, 1 left, 2 right, 3 up, 4 down, 5 + y*W + x a click on cell "
           "(x, y); anything else (a float, a bool, an id out of range) raises ValueError. obs: uint8 [H, W] "
           "colour ids. reward: 1.0 when the trigger condition held after the step, else 0.0. terminated: the "
           "program met a runtime error (info[\"error\"] says which; obs is then the last good frame). "
           "truncated: max_episode_steps reached. After either, call reset().")
      .def("clone", [](const Env& e) { return Env(e); },
           "An independent copy of this environment, at the same point of the same episode: stepping either "
           "with the same actions gives the same observations")
      .def("state_hash", &Env::state_hash,
           "A 64-bit digest of the program's state: equal digests on one engine mean equal futures (the two "
           "engines hash differently)")
      .def_property_readonly("grid_size", &Env::grid, "W = H, the side of the grid in cells")
      .def_property_readonly("engine", &Env::engine, "The engine serving steps now: \"compiled\" or \"interp\"");
}

void bind_env_state(pb::module_& m) {
  pb::class_<EnvState>(m, "EnvState",
                       "One environment's state, copied out of a VecEnv by VecEnv.clone(ids) and put back (into the "
                       "same VecEnv or another of the same program) by VecEnv.restore(ids, states).\n\n"
                       "Immutable; restoring it does not consume it. It has a bytes form, to_bytes() and "
                       "EnvState.from_bytes(program, data), and pickles (the program's text travels with it): a "
                       "state restored from either continues exactly as the original would. Only the compiled "
                       "engine's specialised modules can save their state as bytes.")
      .def("state_hash", [](const EnvState& s) { return s.env->state_hash(); },
           "The state's 64-bit digest, as VecEnv.state_hash() gives it for the environment it came from")
      .def_property_readonly("episode", [](const EnvState& s) { return s.episode; },
                             "How many episodes the environment had finished (its seed is seed + i + episode*N)")
      .def_property_readonly("steps", [](const EnvState& s) { return s.steps; }, "Steps into the current episode")
      .def_property_readonly("done", [](const EnvState& s) { return s.done; },
                             "The episode had ended (the next VecEnv.step resets it)")
      .def("to_bytes", &state_bytes,
           "The state as bytes: the program's digest, the episode counters and the compiled engine's snapshot. "
           "EnvState.from_bytes(program, data) turns them back into a state of that program. Raises ValueError "
           "for a state that ended in a runtime error and for engines that cannot save their state (the "
           "interpreter, modules that embed it).")
      .def_static(
          "from_bytes",
          [](const pb::object& program, const pb::bytes& data, const std::optional<std::string>& trigger) {
            const auto tn = pb::module_::import("autumnc.envs").attr("_program_text")(program).cast<pb::tuple>();
            return state_from_bytes(tn[0].cast<std::string>(), tn[1].cast<std::string>(), trigger, data);
          },
          pb::arg("program"), pb::arg("data"), pb::arg("trigger") = pb::none(),
          "The state that to_bytes() gave, for the program it came from (a path, an autumnc.Program or the "
          "program's text, and the same trigger condition). Compiles the program's module if it is not cached. "
          "Raises ValueError for bytes that are not such a state: truncated or corrupt, of another autumnc "
          "version, or of another program, standard library or trigger.")
      .def(pb::pickle(
          [](const EnvState& s) {
            const std::string& t = s.program->trigger_text;
            return pb::make_tuple(s.program->file.text, s.program->file.name,
                                  t.empty() ? pb::object(pb::none()) : pb::object(pb::str(t)), state_bytes(s));
          },
          [](const pb::tuple& t) {
            if (t.size() != 4) throw std::invalid_argument("EnvState: not a pickled EnvState");
            return state_from_bytes(t[0].cast<std::string>(), t[1].cast<std::string>(),
                                    t[2].cast<std::optional<std::string>>(), t[3].cast<pb::bytes>());
          }));
}

void bind_vec_env(pb::module_& m) {
  pb::class_<VecEnv>(m, "_VecEnv", pb::dynamic_attr(), "The C++ side of autumnc.VecEnv (construct autumnc.VecEnv instead)")
      .def(pb::init<const std::string&, const std::string&, size_t, unsigned, uint64_t, const std::string&,
                    const std::optional<std::string>&, uint32_t>(),
           pb::arg("text"), pb::arg("name"), pb::arg("num_envs"), pb::arg("num_threads"), pb::arg("seed"),
           pb::arg("engine"), pb::arg("trigger"), pb::arg("max_episode_steps"),
           "text: the program's text; name: its name in error messages; num_envs: N; num_threads: worker "
           "threads (0: one per core); seed: environment i's first episode has seed + i; engine: \"auto\", "
           "\"compiled\" or \"interp\"; trigger: a trigger-condition expression or None; max_episode_steps: steps "
           "before truncation (0: never)")
      .def("reset", &VecEnv::reset, pb::arg("seed") = pb::none(), pb::arg("options") = pb::none(),
           "Start every environment afresh (episode counters back to 0); returns (obs [N, H, W] uint8, info).\n\n"
           "seed: None keeps the seed; environment i then starts with seed + i. options is ignored. info has "
           "\"errors\" {i: message} for environments whose start-up met a runtime error.")
      .def("step", &VecEnv::step, pb::arg("actions"),
           "Step all N environments in C++ threads (the GIL released); returns (obs [N, H, W] uint8, rewards [N] "
           "float32, terminated [N] bool, truncated [N] bool, info).\n\n"
           "actions: N integer action ids (a list or an array of any integer dtype; floats and bools raise "
           "ValueError): 0 noop, 1 left, 2 right, 3 up, 4 down, 5 + y*W + x a click on (x, y). The returned arrays "
           "are the same objects on every call, overwritten in place: copy what you keep. An environment whose "
           "episode ended is reset by its next step, which ignores its action; episode k of environment i has "
           "seed seed + i + k*N. info[\"errors\"] maps an environment index to its runtime error.")
      .def("clone", &VecEnv::clone, pb::arg("ids"),
           "Copies of the environments at the given indices, as a list of EnvState")
      .def("restore", &VecEnv::restore, pb::arg("ids"), pb::arg("states"),
           "Put states (from clone() of a VecEnv of the same program, or EnvState.from_bytes / pickle) into the "
           "environments at the given indices; their observations in the obs buffer are rewritten. A state of "
           "another program raises ValueError.")
      .def("state_hash", &VecEnv::state_hash, "The 64-bit state digest of each environment, as a uint64 [N] array")
      .def_property_readonly("num_envs", &VecEnv::size, "N, the number of environments")
      .def_property_readonly("grid_size", &VecEnv::grid, "W = H, the side of the grid in cells")
      .def_property_readonly("num_threads", &VecEnv::threads, "The worker threads stepping the environments");
}

}  // namespace

void bind_envs(pb::module_& m) {
  bind_env(m);
  bind_env_state(m);
  bind_vec_env(m);
}

}  // namespace autumn::py_bind
