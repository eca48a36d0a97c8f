// bind_distributed — the pieces autumnc.distributed runs on its client and its
// workers, so that a distributed evaluation is the CLI's, task by task.
//
// Evaluation: _find_tasks lists a folder's tasks in `autumn eval`'s order;
// _eval_task is eval_task() on one of them (one unit of work on a worker),
// returning its row as eval's JSON prints it; _eval_report turns the rows back
// into EvalRows (eval_row_from_json, as `autumn eval --merge` does) and returns
// the report and the table `autumn eval` prints, so neither is re-implemented
// in Python. Options travel as a JSON object with solve()'s names.
//
// Modules shipped by digest: _task_module_programs names the programs whose
// modules a task needs (task_module_programs: its program, a change-detection
// task's changed program with the trigger, a planning task's click-reset model);
// _module_package builds one on the client and returns its cache entry (bytes,
// manifest, built-from text); on a worker, _module_at_hand says whether it is
// already there, and _install_module files a shipped one through the module
// store's checks (harness/module_cache.hpp). Programs are named by their text
// and trigger: a click-reset model has no file. _colour_id maps a worker's
// observation ids (colours beyond the AutumnBench table are numbered per
// process) into this process's. The GIL is released while they work.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <filesystem>

#include "harness/agent/eval.hpp"
#include "harness/agent/eval_shards.hpp"
#include "harness/agent/thread_pool.hpp"
#include "harness/bench.hpp"
#include "harness/module_cache.hpp"
#include "python/src/colours.hpp"
#include "python/src/bindings.hpp"

namespace pb = pybind11;

namespace autumn::py_bind {
namespace {

using namespace autumn::agent;
using Trigger = std::optional<std::string>;

// solve()'s option names (python/autumnc/distributed.py, _OPTION_DEFAULTS) to
// SolveOptions. autumnc.distributed sends every name; one left out keeps
// SolveOptions' own default, so no default is stated twice here.
SolveOptions options_from_json(const std::string& text) {
  return solve_options_from_json(nlohmann::json::parse(text), SolveOptions{});
}

std::shared_ptr<const Program> program_of(const std::string& text, const std::string& name, const Trigger& trigger) {
  return load_program_checked_text(text, name, trigger);
}

// A task set's units: the tasks, one task's eval row, the report, the modules a task needs.
void bind_eval_units(pb::module_& m) {
  m.def("_find_tasks", [](const std::string& dir) {
    pb::gil_scoped_release release;
    std::vector<std::string> out;
    for (const auto& f : find_tasks(dir)) out.push_back(f.string());
    return out;
  });
  m.def("_eval_task", [](const std::string& file, const std::string& root, const std::string& options,
                         unsigned threads) {
    SolveOptions o = options_from_json(options);
    pb::gil_scoped_release release;
    ThreadPool pool(threads);
    return eval_json({eval_task(file, root, o, pool)}).at("tasks").at(0).dump();
  });
  // (report JSON text, the table `autumn eval` prints) of rows in eval's JSON.
  m.def("_eval_report", [](const std::vector<std::string>& rows_json, const std::string& protocol,
                           const std::string& options, const std::vector<std::string>& task_set) {
    SolveOptions o = options_from_json(options);
    pb::gil_scoped_release release;
    std::vector<EvalRow> rows;
    for (const std::string& r : rows_json) rows.push_back(eval_row_from_json(nlohmann::json::parse(r)));
    nlohmann::json report = eval_json(rows);
    report["agent"] = eval_agent_json(protocol, o);
    report["task_set"] = task_set;
    return std::make_pair(report.dump(), eval_table(rows) + "\n" + eval_type_table(rows));
  });
  // [(name, text, trigger)] of the modules a task needs; `find` looks up the
  // task's answers file as eval does (the changed program's trigger).
  m.def("_task_module_programs", [](const std::string& file, const std::string& options, bool find) {
    SolveOptions o = options_from_json(options);
    pb::gil_scoped_release release;
    Task task = load_task(file);
    if (find && !o.answers) o.answers = find_answers(task);
    std::vector<std::tuple<std::string, std::string, Trigger>> out;
    for (const auto& p : task_module_programs(task, o))
      out.emplace_back(p->file.name, p->file.text,
                       p->trigger_text.empty() ? Trigger() : Trigger(p->trigger_text));
    return out;
  });
}

// Modules shipped by digest: packaged where they are built, installed through the store's checks.
void bind_module_shipping(pb::module_& m) {
  // None for a module built into the package; else {"key", "so" (bytes),
  // "manifest", "built_from"}. Builds the module when needed.
  m.def("_module_package", [](const std::string& text, const std::string& name, const Trigger& trigger) -> pb::object {
    ModulePackage pkg;
    std::string why;
    bool ok;
    {
      pb::gil_scoped_release release;
      ok = package_module(program_of(text, name, trigger), &pkg, &why);
    }
    if (!ok) throw std::runtime_error(name + ": " + why);
    if (pkg.builtin) return pb::none();
    pb::dict d;
    d["key"] = pkg.key;
    d["so"] = pb::bytes(pkg.so);
    d["manifest"] = pkg.manifest;
    d["built_from"] = pkg.built_from;
    return d;
  });
  m.def("_module_at_hand", [](const std::string& text, const std::string& name, const Trigger& trigger) {
    pb::gil_scoped_release release;
    return module_at_hand(program_of(text, name, trigger));
  });
  // "" when installed, else why it was refused.
  m.def("_install_module", [](const std::string& text, const std::string& name, const Trigger& trigger,
                              const pb::bytes& so, const std::string& manifest, const std::string& built_from) {
    std::string bytes = so;
    pb::gil_scoped_release release;
    return install_module(program_of(text, name, trigger), bytes, manifest, built_from);
  });
  m.def("_compiling_forbidden", [] { return compiling_forbidden(); });
  // This process's observation id of a colour (given the next free id when new):
  // a worker's ids beyond the AutumnBench table are its own, so rollouts map
  // them into the client's through the names.
  m.def("_colour_id", [](const std::string& name) { return py::colour_id(name); });
}

// `autumn bench`, one program per unit.
void bind_bench_units(pb::module_& m) {
  // One program's `autumn bench` row (JSON text): interpreter and compiled
  // engine over `steps` random actions; a program that does not load, a row
  // with its "error".
  m.def("_bench_program", [](const std::string& text, const std::string& name, size_t steps, uint64_t seed) {
    pb::gil_scoped_release release;
    const std::string stem = std::filesystem::path(name).stem().string();
    std::shared_ptr<const Program> p;
    try {
      p = program_of(text, name, std::nullopt);
    } catch (const std::exception& e) {
      return bench_error_row(stem, e.what()).dump();
    }
    return bench_row_json(bench_program(stem, p, {"interp", "compiled"}, steps, seed)).dump();
  });
  // (report JSON text, table text) of rows as _bench_program gives them.
  m.def("_bench_report", [](const std::vector<std::string>& rows_json) {
    nlohmann::json rows = nlohmann::json::array();
    for (const std::string& r : rows_json) rows.push_back(nlohmann::json::parse(r));
    const nlohmann::json report = bench_report(rows);
    return std::make_pair(report.dump(), bench_table(report));
  });
}

}  // namespace

void bind_distributed(pb::module_& m) {
  bind_eval_units(m);
  bind_module_shipping(m);
  bind_bench_units(m);
}

}  // namespace autumn::py_bind
