// bind_interpreter — autumnc.interpreter_module.Interpreter, the drop-in for the
// reference's pybind11 class (Autumn.cpp tools/bindings_python.cpp).
//
// Same method names, argument names (keyword names only where the reference
// declares them: run_script's and click's; the rest are positional, as there),
// defaults, return strings and exceptions: run_script returns "Script executed
// successfully." or, for a standard library or trigger condition that does not
// parse, "Runtime Error: ..."; a program that does not parse raises ParseError
// and a runtime error raises AutumnRuntimeError (both RuntimeError subclasses,
// as the reference's exceptions reach Python as RuntimeError). The episode
// itself lives in a Session (session.hpp). Additions: clone/__deepcopy__,
// get_state/set_state, state_hash, render_grid/palette, engine.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "python/src/bindings.hpp"
#include "python/src/colours.hpp"
#include "python/src/interruptible.hpp"
#include "python/src/programs.hpp"
#include "python/src/session.hpp"

namespace pb = pybind11;

namespace autumn::py_bind {
namespace {

using autumn::py::Session;

class Interpreter {
 public:
  explicit Interpreter(std::string engine) : engine_(std::move(engine)) {
    if (engine_ != "auto" && engine_ != "compiled" && engine_ != "interp")
      throw std::invalid_argument("unknown engine '" + engine_ + "' (expected auto, compiled or interp)");
  }
  Interpreter(const Interpreter& o)
      : engine_(o.engine_),
        session_(o.session_ ? std::make_unique<Session>(*o.session_) : nullptr),
        seed_(o.seed_),
        verbose_(o.verbose_) {
    for (const auto& u : o.undo_) undo_.push_back(std::make_unique<Session>(*u));
  }

  std::string run_script(const std::string& script, const std::string& stdlib, const std::string& trigger,
                         uint64_t seed) {
    seed_ = static_cast<uint32_t>(seed);
    py::LoadedProgram loaded;
    try {
      loaded = py::load(script, "<script>", trigger, stdlib);
    } catch (const CompileError& e) {
      if (e.file() == "<stdlib>" || e.file() == "<trigger>") return "Runtime Error: " + e.formatted();
      throw;
    }
    session_.reset();
    undo_.clear();
    session_ = std::make_unique<Session>(loaded.program, seed, engine_, loaded.compilable);
    return "Script executed successfully.";
  }

  Session& s() {
    if (!session_) throw std::runtime_error("no script is running: call run_script first");
    return *session_;
  }
  std::string step() {
    py::interruptible([&] { s().step(); });  // Ctrl-C ends a long interpreted step
    return "Step executed.";
  }
  void press(const Action& a) { s().press(a); }
  void set_seed(uint64_t seed) {
    seed_ = static_cast<uint32_t>(seed);
    if (session_) session_->reseed(seed);
  }
  uint64_t get_seed() const {
    if (!seed_) throw std::runtime_error("get_random_seed: no random generator yet (call run_script or set_random_seed)");
    return *seed_;
  }
  std::string tmp_execute(const std::string& text) {
    auto saved = std::make_unique<Session>(s());
    std::string out = s().execute(text);
    undo_.push_back(std::move(saved));
    return out;
  }
  void restore(const std::string& script, const std::string& stdlib, const std::string& trigger) {
    py::LoadedProgram loaded = py::load(script, "<script>", trigger, stdlib);
    if (undo_.empty()) throw std::runtime_error("restore_environment: no tmp_execute_stmt to go back from");
    const Program& now = s().program();
    if (loaded.program->file.text != now.file.text || loaded.program->stdlib.text != now.stdlib.text ||
        loaded.program->trigger_text != now.trigger_text)
      throw std::runtime_error("restore_environment: autumnc restores the state only into the same program");
    session_ = std::move(undo_.back());
    undo_.pop_back();
    set_seed(0);  // the reference restarts the program, which seeds its generator with 0
  }
  pb::array_t<uint8_t> render_grid() {
    Frame frame;
    Palette palette;
    s().render_frame(frame, palette);
    pb::array_t<uint8_t> out({frame.size, frame.size});
    colours_.paint(frame, palette, out.mutable_data());
    return out;
  }
  pb::bytes get_state() {
    std::vector<uint8_t> b = s().save();
    return pb::bytes(reinterpret_cast<const char*>(b.data()), b.size());
  }
  void set_state(const pb::bytes& b) {
    std::string_view v = b;
    s().load(reinterpret_cast<const uint8_t*>(v.data()), v.size());
  }

  std::string engine_;
  std::unique_ptr<Session> session_;
  std::optional<uint32_t> seed_;
  bool verbose_ = false;
  std::vector<std::unique_ptr<Session>> undo_;
  py::PaletteMap colours_;
};

}  // namespace

void bind_interpreter(pb::module_& m) {
  pb::class_<Interpreter> c(m, "Interpreter", "Autumn Interpreter (autumnc; drop-in for Autumn.cpp's interpreter_module)");
  c.def(pb::init<std::string>(), pb::arg("engine") = "auto");
  c.def("step", &Interpreter::step, "Execute a step");
  c.def("click", [](Interpreter& i, int x, int y) { i.press(Action::click(x, y)); }, "Simulate a click at (x, y)",
        pb::arg("x"), pb::arg("y"));
  c.def("left", [](Interpreter& i) { i.press(Action{Action::Kind::Left}); }, "Push left");
  c.def("right", [](Interpreter& i) { i.press(Action{Action::Kind::Right}); }, "Push right");
  c.def("up", [](Interpreter& i) { i.press(Action{Action::Kind::Up}); }, "Push up");
  c.def("down", [](Interpreter& i) { i.press(Action{Action::Kind::Down}); }, "Push down");
  c.def("get_trigger_state", [](Interpreter& i) { return i.s().trigger_state(); }, "Get trigger state");
  c.def(
      "render_all", [](Interpreter& i) { return py::interruptible([&] { return i.s().render_all(); }); }, "Render all");
  c.def("get_environment_string", [](Interpreter& i) { return i.s().environment_string(); },
        "Get environment string");
  c.def("get_on_clause_count", [](Interpreter& i) { return i.s().on_clause_count(); }, "Get on clause count");
  c.def("get_covered_on_clause_count", [](Interpreter& i) { return i.s().covered_on_clause_count(); },
        "Get covered on clause count");
  c.def("evaluate_to_string", [](Interpreter& i, const std::string& e) { return i.s().evaluate(e); },
        "Evaluate to string");
  c.def("restore_environment", &Interpreter::restore, "Restore environment");
  c.def("tmp_execute_stmt", &Interpreter::tmp_execute, "Execute a statement");
  c.def("set_verbose", [](Interpreter& i, bool v) { i.verbose_ = v; }, "Set verbose");
  c.def("get_verbose", [](Interpreter& i) { return i.verbose_; }, "Get verbose");
  c.def("set_random_seed", &Interpreter::set_seed, "Set random seed");
  c.def("get_random_seed", &Interpreter::get_seed, "Get random seed");
  c.def("get_background", [](Interpreter& i) { return i.s().background(); }, "Get background");
  c.def("get_frame_rate", [](Interpreter& i) { return i.s().frame_rate(); }, "Get frame rate");
  c.def("run_script", &Interpreter::run_script, "Run a script", pb::arg("script"), pb::arg("stdlib"),
        pb::arg("triggeringCondition"), pb::arg("randomSeed") = 42);
  // --- additions
  c.def("clone", [](const Interpreter& i) { return Interpreter(i); }, "An independent copy with the same future");
  c.def("__copy__", [](const Interpreter& i) { return Interpreter(i); });
  c.def("__deepcopy__", [](const Interpreter& i, pb::dict) { return Interpreter(i); }, pb::arg("memo"));
  c.def("get_state", &Interpreter::get_state, "The episode as bytes (set_state restores it)");
  c.def("set_state", &Interpreter::set_state, pb::arg("state"), "Continue from a get_state() of the same program");
  c.def("state_hash", [](Interpreter& i) { return i.s().state_hash(); },
        "Digest of the state (equal on one engine means equal futures)");
  c.def("render_grid", &Interpreter::render_grid,
        "A host render like render_all(), as a uint8 [H, W] array of colour ids (see palette())");
  c.def("palette", [](const Interpreter&) { return py::colour_names(); }, "Colour names by id");
  c.def_property_readonly("engine", [](Interpreter& i) { return i.session_ ? i.session_->engine() : i.engine_; },
                          "The engine serving steps now: compiled or interp");
}

}  // namespace autumn::py_bind
