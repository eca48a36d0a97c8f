// bind_agent — the simulator agent and program tools, as the CLI runs them.
//
// Each function builds the same JSON object as the corresponding `autumn`
// command prints with --json (solve; baseline random; run; make-task writes the task
// itself) and
// returns it as text, which autumnc/agent.py turns into a dict. The GIL is
// released while they work. compile() has no CLI twin: it reports what the
// compiled engine made of a program (module found or built, specialised or the
// embedded interpreter, how long it took).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <filesystem>

#include "harness/agent/change_detection.hpp"
#include "harness/agent/make_cd.hpp"
#include "harness/agent/make_task.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"
#include "harness/agent/random_baseline.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/engine.hpp"
#include "harness/trace_check.hpp"
#include "python/src/bindings.hpp"
#include "python/src/module_broker.hpp"

namespace pb = pybind11;

namespace autumn::py_bind {
namespace {

using namespace autumn::agent;

std::string solve(const std::string& task_file, const SolveOptions& o, unsigned threads) {
  Task task = load_task(task_file);
  ThreadPool pool(threads);
  nlohmann::json out = {{"task", task_file}, {"type", type_name(task.type)}, {"program", task.program}};
  switch (task.type) {
    case TaskType::MaskedFramePrediction: out["result"] = mfp_json(solve_mfp(task, o, pool)); break;
    case TaskType::ChangeDetection:
      out["wrong_program"] = task.wrong_program;
      out["result"] = cd_json(solve_cd(task, o, pool));
      break;
    case TaskType::Planning: out["result"] = planning_json(solve_planning(task, o, pool)); break;
  }
  out["threads"] = pool.size();
  return out.dump();
}

std::string make(const MakeTaskOptions& o) {
  if (o.kind == "cd") {  // as `autumn make-task cd`: the changed program is written beside the prompt
    if (o.out.empty())
      throw std::invalid_argument("a cd task needs out= (a path under prompts/: the changed program goes to the "
                                  "sibling programs/, the answers to answers/)");
    MadeCd made = make_cd(o);
    write_cd(made, o);
    return nlohmann::json{{"task", made.prompt}, {"answers", made.answers}, {"change", made.change}}.dump();
  }
  ThreadPool pool(0);
  MadeTask made = make_task(o, pool);
  if (!o.out.empty() || !o.answers_out.empty()) write_task(made, o);
  return nlohmann::json{{"task", made.task}, {"answers", made.answers}}.dump();
}

std::unique_ptr<Environment> engine_env(const std::string& engine, std::shared_ptr<const Program> p) {
  std::string why;
  auto env = make_environment(engine, std::move(p), &why);
  if (!env) throw std::runtime_error(why);
  return env;
}

std::string run(const std::string& path, uint64_t seed, const std::vector<std::string>& action_texts,
                const std::optional<std::string>& trigger, const std::string& engine) {
  std::vector<Action> actions;
  for (const auto& t : action_texts) {
    std::string why;
    auto a = parse_action(t, &why);
    if (!a) throw std::invalid_argument(why);
    actions.push_back(*a);
  }
  auto env = engine_env(engine, load_program_file(path, trigger));
  nlohmann::json frames = nlohmann::json::array(), triggers = nlohmann::json::array(),
                 done = nlohmann::json::array();
  bool ok = env->reset(seed);
  if (ok) frames.push_back(frame_rows(env->frame(), env->palette()));
  for (size_t i = 0; ok && i < actions.size(); ++i) {
    if (!(ok = env->step(actions[i]))) break;
    done.push_back(format_action(actions[i]));
    frames.push_back(frame_rows(env->frame(), env->palette()));
    if (trigger) triggers.push_back(env->triggered());
  }
  nlohmann::json trace = {{"seed", seed}, {"actions", done}, {"frames", frames}};
  if (trigger) trace["trigger"] = triggers;
  nlohmann::json out = {{"program", std::filesystem::path(path).stem().string()},
                        {"grid_size", env->frame().size},
                        {"traces", nlohmann::json::array({trace})}};
  if (trigger) out["triggering_condition"] = *trigger;
  if (!ok) out["error"] = env->error();
  return out.dump();
}

std::string check(const std::string& path, const std::string& traces, const std::string& engine) {
  TraceFile file = load_trace_file(traces);
  std::optional<std::string> trigger = file.triggering_condition;
  auto env = engine_env(engine, load_program_file(path, trigger));
  CheckResult r = check_traces(*env, file);
  return nlohmann::json({{"traces", r.traces},
                         {"frames_total", r.frames_total},
                         {"frames_matched", r.frames_matched},
                         {"triggers_total", r.triggers_total},
                         {"triggers_matched", r.triggers_matched},
                         {"mismatches", r.mismatches},
                         {"ok", r.ok()}})
      .dump();
}

std::string compile(const std::string& path, const std::optional<std::string>& trigger) {
  auto program = load_program_file(path, trigger);
  std::shared_ptr<const py::Prototype> p = py::request_compiled(program).get();
  nlohmann::json out = {{"program", path}, {"warnings", program->warnings}, {"ok", p->env != nullptr}};
  if (p->env) {
    out["kind"] = p->specialised ? "specialised" : "embedded";
    out["grid_size"] = p->env->frame().size;
  } else {
    out["error"] = p->why;
  }
  out["seconds"] = p->seconds;
  return out.dump();
}

}  // namespace

void bind_agent(pb::module_& m) {
  // The agent's options under a protocol, by name (JSON text), and the names
  // of the protocols: the one set of defaults autumnc.solve and
  // autumnc.distributed present (harness/agent/solve_common.hpp).
  m.def("_solve_defaults", [](const std::string& protocol) { return solve_options_json(protocol_options(protocol)).dump(); });
  m.def("_protocol_names", [] { return protocol_names(); });
  m.def(
      "_solve",
      [](const std::string& task, const std::string& engine, uint64_t rollouts, unsigned threads, uint64_t seed,
         int max_steps, const std::string& policy, int depth, uint64_t nodes, const std::string& search,
         int max_plan, double time_limit, const std::string& programs, const std::string& answers,
         bool seed_inversion) {
        SolveOptions o;
        o.seed_inversion = seed_inversion;
        o.engine = engine;
        o.rollouts = rollouts;
        o.seed = seed;
        o.max_steps = max_steps;
        o.policy = policy;
        o.depth = depth;
        o.nodes = nodes;
        o.search = search;
        o.max_plan = max_plan;
        o.time_limit = time_limit;
        if (!programs.empty()) o.programs_dir = programs;
        if (!answers.empty()) o.answers = answers;
        pb::gil_scoped_release release;
        return solve(task, o, threads);
      });
  m.def("_baseline_random", [](const std::vector<std::string>& paths, const std::string& engine, uint64_t rollouts,
                               int timeout, uint64_t seed, unsigned threads, const std::string& programs) {
    if (paths.empty()) throw std::invalid_argument("no task files or folders given");
    if (rollouts < 1) throw std::invalid_argument("rollouts must be at least 1");
    if (timeout < 1) throw std::invalid_argument("timeout must be at least 1 step");
    for (const std::string& p : paths)
      if (!std::filesystem::exists(p)) throw std::invalid_argument("no task file or folder at '" + p + "'");
    RandomOptions o;
    o.engine = engine;
    o.rollouts = rollouts;
    o.timeout = timeout;
    o.seed = seed;
    if (!programs.empty()) o.programs_dir = programs;
    pb::gil_scoped_release release;
    ThreadPool pool(threads);
    return random_report_json(run_random_baseline(paths, o, pool), o, paths).dump();
  });
  m.def("_make_task", [](const std::string& kind, const std::string& program, uint64_t seed, int steps,
                         const std::string& out, uint64_t env_seed, const std::string& engine, uint64_t batch,
                         int masked_frames, bool extend_colours, const std::string& answers) {
    MakeTaskOptions o;
    o.kind = kind;
    o.program = program;
    o.seed = seed;
    o.steps = steps;
    o.out = out;
    o.env_seed = env_seed;
    o.engine = engine;
    o.batch = batch;
    o.masked_frames = masked_frames;
    o.extend_colours = extend_colours;
    o.answers_out = answers;
    if (kind != "mfp" && kind != "planning" && kind != "cd")
      throw std::invalid_argument("kind must be 'mfp', 'planning' or 'cd'");
    pb::gil_scoped_release release;
    return make(o);
  });
  m.def("_run", [](const std::string& path, uint64_t seed, const std::vector<std::string>& actions,
                   const std::optional<std::string>& trigger, const std::string& engine) {
    pb::gil_scoped_release release;
    return run(path, seed, actions, trigger, engine);
  });
  m.def("_check", [](const std::string& path, const std::string& traces, const std::string& engine) {
    pb::gil_scoped_release release;
    return check(path, traces, engine);
  });
  m.def("_compile", [](const std::string& path, const std::optional<std::string>& trigger) {
    pb::gil_scoped_release release;
    return compile(path, trigger);
  });
}

}  // namespace autumn::py_bind
