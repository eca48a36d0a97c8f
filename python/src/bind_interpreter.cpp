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

using InterpreterClass = pb::class_<Interpreter>;

// The reference's stepping and input methods.
void bind_steps(InterpreterClass& c) {
  c.def(pb::init<std::string>(), pb::arg("engine") = "auto");
  c.def("step", &Interpreter::step,
        "Advance the program one time step, with the input given since the last step (if any); returns "
        "\"Step executed.\". A runtime error raises AutumnRuntimeError and ends the episode.");
  c.def("click", [](Interpreter& i, int x, int y) { i.press(Action::click(x, y)); },
        "Give a click on cell (x, y) (x the column, y the row, from the top left) as the next step's input",
        pb::arg("x"), pb::arg("y"));
  c.def("left", [](Interpreter& i) { i.press(Action{Action::Kind::Left}); },
        "Give the left arrow key as the next step's input");
  c.def("right", [](Interpreter& i) { i.press(Action{Action::Kind::Right}); },
        "Give the right arrow key as the next step's input");
  c.def("up", [](Interpreter& i) { i.press(Action{Action::Kind::Up}); },
        "Give the up arrow key as the next step's input");
  c.def("down", [](Interpreter& i) { i.press(Action{Action::Kind::Down}); },
        "Give the down arrow key as the next step's input");
}

// The reference's reads of the state, and its loading and seeding.
void bind_reads(InterpreterClass& c) {
  c.def("get_trigger_state", [](Interpreter& i) { return i.s().trigger_state(); },
        "Whether the run_script trigger condition held after the last step (False before the first, and "
        "without a trigger)");
  c.def(
      "render_all", [](Interpreter& i) { return py::interruptible([&] { return i.s().render_all(); }); },
      "Render the grid as the reference's JSON text: the cells to draw per global, with positions and colours "
      "(out-of-grid cells included). The host's render: call it once after each step, as MARAProtocol does.");
  c.def("get_environment_string", [](Interpreter& i) { return i.s().environment_string(); },
        "The program's globals and their values as JSON text, in the reference's layout and order");
  c.def("get_on_clause_count", [](Interpreter& i) { return i.s().on_clause_count(); },
        "How many on-clauses the program has");
  c.def("get_covered_on_clause_count", [](Interpreter& i) { return i.s().covered_on_clause_count(); },
        "How many of the program's on-clauses have fired so far in this episode");
  c.def("evaluate_to_string", [](Interpreter& i, const std::string& e) { return i.s().evaluate(e); },
        "Evaluate an Autumn expression (text) in the current state and return its value printed; the state "
        "is left as it was. Only names the program or the standard library mentions can be used.");
  c.def("restore_environment", &Interpreter::restore,
        "restore_environment(script, stdlib, triggeringCondition): go back to the state before the last "
        "tmp_execute_stmt, for the same program only, and reseed the random generator with 0 (as the "
        "reference's restart does)");
  c.def("tmp_execute_stmt", &Interpreter::tmp_execute,
        "Execute an Autumn statement (text, e.g. an assignment) in the current state, remembering the state "
        "before it for restore_environment(); returns the globals afterwards (get_environment_string()). A "
        "statement that fails raises RuntimeError.");
  c.def("set_verbose", [](Interpreter& i, bool v) { i.verbose_ = v; },
        "Store the verbose flag (autumnc prints nothing more either way)");
  c.def("get_verbose", [](Interpreter& i) { return i.verbose_; }, "The verbose flag set_verbose stored");
  c.def("set_random_seed", &Interpreter::set_seed,
        "Reseed the program's random generator: later random draws follow the new seed");
  c.def("get_random_seed", &Interpreter::get_seed,
        "The seed last given to run_script or set_random_seed (RuntimeError before any)");
  c.def("get_background", [](Interpreter& i) { return i.s().background(); },
        "The program's background colour name (its `background` global; \"black\" when it sets none)");
  c.def("get_frame_rate", [](Interpreter& i) { return i.s().frame_rate(); },
        "The program's FRAME_RATE, the steps per second it is meant to be shown at (16 when it sets none)");
  c.def("run_script", &Interpreter::run_script,
        "Load a program and start its episode; returns \"Script executed successfully.\".\n\n"
        "script: the program's text; stdlib: the standard library's text (\"\" reads "
        "./autumnstdlib/stdlib.sexp as the reference does, or the bundled library, autumnc.stdlib(), when that "
        "file is missing; the compiled engine serves only programs on the bundled library); "
        "triggeringCondition: an Autumn expression that get_trigger_state() reports after each step (\"\" for "
        "none); randomSeed: the random generator's seed. A standard library or trigger that does not parse is "
        "returned as \"Runtime Error: ...\"; a program that does not parse raises ParseError; a runtime error "
        "at start-up raises AutumnRuntimeError. A second call starts afresh.",
        pb::arg("script"), pb::arg("stdlib"), pb::arg("triggeringCondition"), pb::arg("randomSeed") = 42);
}

// autumnc's additions: copies, saved states, hashes, the grid render.
void bind_additions(InterpreterClass& c) {
  c.def("clone", [](const Interpreter& i) { return Interpreter(i); },
        "An independent copy at the same point of the same episode, with the same future");
  c.def("__copy__", [](const Interpreter& i) { return Interpreter(i); }, "clone()");
  c.def("__deepcopy__", [](const Interpreter& i, pb::dict) { return Interpreter(i); }, pb::arg("memo"), "clone()");
  c.def("get_state", &Interpreter::get_state,
        "The episode as bytes (the program's digest, seed and call log, plus the compiled snapshot when there "
        "is one); set_state() of an Interpreter running the same program continues from it");
  c.def("set_state", &Interpreter::set_state, pb::arg("state"),
        "Continue from get_state() bytes of the same program (standard library and trigger included). Bytes "
        "that are not such a state raise ValueError and leave the interpreter as it was.");
  c.def("state_hash", [](Interpreter& i) { return i.s().state_hash(); },
        "A 64-bit digest of the state: equal digests on one engine mean equal futures (the engines hash "
        "differently)");
  c.def("render_grid", &Interpreter::render_grid,
        "A host render like render_all(), as a uint8 [H, W] array of colour ids (names: palette()); on the "
        "compiled engine, much faster than the JSON");
  c.def("palette", [](const Interpreter&) { return py::colour_names(); },
        "Colour names by id, the ids of render_grid() (autumnc.colour_names())");
  c.def_property_readonly("engine", [](Interpreter& i) { return i.session_ ? i.session_->engine() : i.engine_; },
                          "The engine serving steps now: \"compiled\" or \"interp\" (before run_script, the "
                          "engine asked for)");
}

}  // namespace

void bind_interpreter(pb::module_& m) {
  // The reference's names, argument names and defaults (tests/python/test_interpreter.py
  // checks every signature); only the docstrings are autumnc's.
  pb::class_<Interpreter> c(
      m, "Interpreter",
      "Autumn Interpreter: a drop-in for Autumn.cpp's pybind11 interpreter_module.Interpreter, on autumnc's "
      "engines.\n\n"
      "Same methods, argument names, defaults, return strings and exceptions as the reference. Typical use: "
      "run_script(program_text, stdlib_text, trigger_text, seed); then per step at most one input (left(), "
      "right(), up(), down(), click(x, y)), step(), and a render (render_all() JSON, or render_grid() as an "
      "array). Errors: a program that does not parse raises ParseError, a runtime error AutumnRuntimeError "
      "(both RuntimeError); after a runtime error the episode has ended.\n\n"
      "engine: \"auto\" (the interpreter serves while the program's module compiles in the background, the "
      "compiled engine once it is ready), \"compiled\" (waits for the module) or \"interp\". Results are the "
      "same on every engine; the engine property says which serves now. Additions to the reference: clone() "
      "and copy.deepcopy, get_state()/set_state(bytes), state_hash(), render_grid(), palette().");
  bind_steps(c);
  bind_reads(c);
  bind_additions(c);
}

}  // namespace autumn::py_bind
