#include "harness/agent/agent_commands.hpp"

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <iostream>
#include <thread>

#include "compiler/read/output.hpp"
#include "harness/agent/bench_agent.hpp"
#include "harness/agent/change_detection.hpp"
#include "harness/agent/eval.hpp"
#include "harness/agent/eval_shards.hpp"
#include "harness/agent/make_cd.hpp"
#include "harness/agent/make_task.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"
#include "harness/agent/random_baseline.hpp"
#include "harness/agent/solve_pictures.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/engine.hpp"
#include "harness/module_cache.hpp"
#include "harness/program_files.hpp"
#include "harness/progress.hpp"

namespace autumn::agent {

namespace {

struct State {
  CLI::App* solve = nullptr;
  CLI::App* make = nullptr;
  CLI::App* eval = nullptr;
  CLI::App* bench = nullptr;
  SolveOptions solve_opts;
  std::string task_file, programs_dir, answers_file, render_dir;
  unsigned threads = 0;
  bool json = false;
  MakeTaskOptions make_opts;
  std::string make_program, make_out;
  std::string eval_dir;
  SolveOptions eval_opts;
  unsigned eval_threads = 0;
  bool eval_json = false;
  std::string eval_json_out;  // also write the JSON object here (the table still prints)
  std::string eval_shard;     // K/N: this slice of the folder's tasks (eval_shards.hpp)
  std::vector<std::string> eval_merge;  // shard JSON files to put back together
  std::vector<std::string> bench_paths;
  BenchAgentOptions bench_opts;
  bool bench_json = false;
  std::string solve_protocol = "default", eval_protocol = "default";
  // baseline random
  CLI::App* random = nullptr;
  std::vector<std::string> random_paths;
  RandomOptions random_opts;
  unsigned random_threads = 0;
  bool random_json = false;
  std::string random_json_out;
};

State& state() {
  static State s;
  return s;
}

void add_search_options(CLI::App* cmd, SolveOptions& o, unsigned& threads) {
  cmd->add_option("--engine", o.engine, "Execution engine (interp: the tree-walking interpreter, for comparison)")
      ->check(CLI::IsMember(engine_names()))
      ->default_val("compiled");
  cmd->add_option("--rollouts", o.rollouts, "MFP rollouts; particles for stochastic change detection")
      ->default_val(10000)
      ->check(cli::big_count(1));
  cmd->add_option("--threads", threads, "Worker threads (0: all cores)")->default_val(0)->check(cli::thread_count());
  cmd->add_flag("!--no-seed-inversion", o.seed_inversion,
                "MFP on stochastic programs: skip recovering the world's seed from the observed draws and "
                "use the sequential Monte Carlo filter alone");
  cmd->add_option("--seed", o.seed, "Seed of the agent's own randomness (rollout seeds, policy)")
      ->default_val(0)
      ->check(cli::seed_number());
  cmd->add_option("--max-steps", o.max_steps, "Change detection: episode length cap")
      ->default_val(200)
      ->check(cli::int_count());
  cmd->add_option("--policy", o.policy, "Change detection exploration policy")
      ->check(CLI::IsMember({"novelty", "random"}))
      ->default_val("novelty");
  cmd->add_option("--depth", o.depth, "Planning: BFS cost limit (layers)")->default_val(12)->check(cli::int_count());
  cmd->add_option("--nodes", o.nodes, "Planning: node budget (successor states generated)")->default_val(30000000)->check(cli::big_count(1));
  cmd->add_option("--search", o.search,
                  "Planning: bfs (proven cheapest), best-first, beam, fill (arrows first, then clicks into their "
                  "waiting steps), local (edits of whole plans), skeleton (local search over the moves alone, then "
                  "clicks into its steps), paper (the paper's BFS over 10 actions), or auto (bfs, focused bfs, bfs by moves, fill, beam, local, skeleton, "
                  "best-first)")
      ->check(CLI::IsMember({"auto", "bfs", "best-first", "beam", "fill", "local", "skeleton", "paper"}))
      ->default_val("auto");
  cmd->add_option("--cost", o.cost, "Planning: what a plan costs: steps (every action) or moves (noop is free)")
      ->check(CLI::IsMember({"steps", "moves"}))
      ->default_val("steps");
  cmd->add_option("--max-plan", o.max_plan, "Planning: plan length limit (steps)")
      ->default_val(200)
      ->check(cli::int_count(1));
  cmd->add_option("--keep-states", o.keep_states,
                  "Planning: search environments kept in memory when the engine cannot snapshot states "
                  "(the others are replayed from the start when needed)")
      ->default_val(10000)
      ->check(cli::big_count());
  cmd->add_option("--time-limit", o.time_limit,
                  "Planning: seconds for the whole search before giving up (0: no limit). Focused BFS stages "
                  "get an eighth of the time left each, so slow engines reach best-first; a search the limit "
                  "cuts short may depend on machine speed and --threads")
      ->default_val(120)
      ->check(cli::number_at_least(0, "NONNEGATIVE"));
}

// --protocol paper: the AutumnBench paper's simulator agent (docs/agent.md,
// "The paper's protocol"): 10,000 samples (MFP rollouts, change-detection
// particles) without seed inversion, the random exploration policy, and planning
// by plain BFS over ten actions to depth 10. An option given on the command line
// keeps its value.
void add_protocol_option(CLI::App* cmd, std::string& protocol) {
  cmd->add_option("--protocol", protocol,
                  "default: the agent as built; paper: the AutumnBench paper's simulator agent (10,000 samples "
                  "without seed inversion, random exploration, BFS over 10 actions to depth 10); options given "
                  "explicitly still apply")
      ->check(CLI::IsMember({"default", "paper"}))
      ->default_val("default");
}

void apply_protocol(const CLI::App* cmd, const std::string& protocol, SolveOptions& o) {
  if (protocol != "paper") return;
  auto given = [&](const char* flag) { return cmd->count(flag) > 0; };
  if (!given("--rollouts")) o.rollouts = 10000;
  if (!given("--no-seed-inversion")) o.seed_inversion = false;
  if (!given("--policy")) o.policy = "random";
  if (!given("--search")) o.search = "paper";
  if (!given("--depth")) o.depth = 10;
}

int fail(const std::string& cmd, const std::string& why) {
  std::string line = why;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::cerr << "autumn " << cmd << ": " << line << "\n";
  return 1;
}

// Clicks outside the task's grid reach the program but land on no cell: say so.
void warn_clicks_outside(const Task& task) {
  const int grid = task.type == TaskType::MaskedFramePrediction ? task.observations[0].grid.width
                   : task.type == TaskType::Planning           ? task.goal.width
                                                                : 0;
  std::vector<Action> actions = task.reference_plan;
  for (const Observation& o : task.observations)
    if (o.action) actions.push_back(*o.action);
  for (const Action& a : actions)
    if (grid > 0 && a.kind == Action::Kind::Click && (a.x < 0 || a.y < 0 || a.x >= grid || a.y >= grid))
      std::cerr << "autumn solve: warning: " << task.file.filename().string() << ": " << format_action(a)
                << " is outside the " << grid << "x" << grid << " grid; the program still receives it\n";
}

int run_solve(State& s) {
  try {
    SolveOptions o = s.solve_opts;
    apply_protocol(s.solve, s.solve_protocol, o);
    if (!s.programs_dir.empty()) o.programs_dir = s.programs_dir;
    if (!s.answers_file.empty()) o.answers = s.answers_file;
    Task task = load_task(s.task_file);
    warn_clicks_outside(task);
    ThreadPool pool(s.threads);
    nlohmann::json out = {{"task", s.task_file}, {"type", type_name(task.type)}, {"program", task.program}};
    out["compile_seconds"] = prepare_modules(task, o);
    std::string text;
    bool answered = false;
    std::vector<std::string> pictures;
    Heartbeat heartbeat("autumn solve: " + task.name);
    switch (task.type) {
      case TaskType::MaskedFramePrediction: {
        MfpResult r = solve_mfp(task, o, pool);
        out["result"] = mfp_json(r);
        text = mfp_summary(r);
        answered = r.choice >= 0;
        if (!s.render_dir.empty()) pictures = render_mfp(task, r, s.render_dir);
        break;
      }
      case TaskType::ChangeDetection: {
        out["wrong_program"] = task.wrong_program;
        CdResult r = solve_cd(task, o, pool);
        out["result"] = cd_json(r);
        text = cd_summary(r);
        answered = r.detected.has_value();
        if (!s.render_dir.empty()) pictures = render_cd(task, o, r, s.render_dir);
        break;
      }
      case TaskType::Planning: {
        PlanResult r = solve_planning(task, o, pool);
        out["result"] = planning_json(r);
        text = planning_summary(r);
        answered = r.found;
        if (!s.render_dir.empty()) pictures = render_plan(task, o, r, s.render_dir);
        break;
      }
    }
    for (const std::string& p : pictures) std::cerr << "autumn solve: wrote " << p << "\n";
    out["threads"] = pool.size();
    if (s.json) {
      std::cout << out.dump() << "\n";
    } else {
      fmt::print("task: {} ({}, program {}, {} threads)\n{}", s.task_file, type_name(task.type), task.program,
                 pool.size(), text);
    }
    if (!answered) std::cerr << "autumn solve: no answer found (exit status 1)\n";
    return answered ? 0 : 1;
  } catch (const std::exception& e) {
    return fail("solve", e.what());
  }
}

int run_make(State& s) {
  try {
    MakeTaskOptions o = s.make_opts;
    o.program = s.make_program;
    if (!s.make_out.empty()) o.out = s.make_out;
    if (o.kind == "cd") {
      if (o.out.empty()) return fail("make-task", "cd needs --out DIR/prompts/NAME_cd.json");
      for (const auto& note : write_cd(make_cd(o), o)) std::cerr << note << "\n";
      return 0;
    }
    ThreadPool pool(0);
    MadeTask made = make_task(o, pool);
    for (const auto& w : made.warnings) std::cerr << "autumn make-task: " << w << "\n";
    for (const auto& note : write_task(made, o)) std::cerr << note << "\n";
    return 0;
  } catch (const std::exception& e) {
    return fail("make-task", e.what());
  }
}

// A progress bar on stderr: redrawn in place on a terminal, a line per item
// otherwise (logs).
std::function<void(size_t, size_t, const std::string&)> progress_bar() {
  const bool tty = isatty(2);
  return [tty](size_t i, size_t n, const std::string& name) {
    const int width = 30;
    int filled = n ? static_cast<int>(width * i / n) : width;
    std::string bar = std::string(filled, '#') + std::string(width - filled, '-');
    if (tty) {
      std::cerr << "\r\033[K[" << bar << "] " << i << "/" << n << (name.empty() ? "" : " " + name)
                << (i == n ? "\n" : "") << std::flush;
    } else if (i < n) {
      std::cerr << "[" << bar << "] " << i + 1 << "/" << n << " " << name << "\n";
    }
  };
}

// A file that exists and may be written, or a new one in a folder that may be.
bool can_write(const fs::path& p) {
  std::error_code ec;
  if (fs::exists(p, ec)) return !fs::is_directory(p, ec) && access(p.c_str(), W_OK) == 0;
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  return fs::is_directory(dir, ec) && access(dir.c_str(), W_OK) == 0;
}

// Prints a report (the table, or JSON), writes --json-out; the exit status of
// its rows: 1 when a task failed (an error) or got no answer (no plan), as solve.
int finish_eval(State& s, const nlohmann::json& report, const std::vector<EvalRow>& rows) {
  if (s.eval_json) std::cout << report.dump() << "\n";
  else fmt::print("{}\n{}", eval_table(rows), eval_type_table(rows));
  if (!s.eval_json_out.empty()) {
    if (std::string why = write_file(s.eval_json_out, report.dump(1) + "\n"); !why.empty()) return fail("eval", why);
  }
  const auto errors = std::count_if(rows.begin(), rows.end(), [](const EvalRow& r) { return !r.error.empty(); });
  const auto unanswered =
      std::count_if(rows.begin(), rows.end(), [](const EvalRow& r) { return r.error.empty() && !r.answered; });
  if (unanswered) std::cerr << "autumn eval: " << unanswered << " task" << (unanswered == 1 ? "" : "s") << " got no answer\n";
  return errors || unanswered ? 1 : 0;
}

int run_eval_merge(State& s) {
  std::vector<nlohmann::json> reports;
  for (const std::string& f : s.eval_merge) {
    std::ifstream in(f);
    try {
      reports.push_back(nlohmann::json::parse(in));
    } catch (const nlohmann::json::exception& e) {
      return fail("eval", f + ": not JSON (" + e.what() + ")");
    }
  }
  std::vector<EvalRow> rows;
  try {
    const nlohmann::json merged = merge_shard_reports(reports, s.eval_merge, rows);
    return finish_eval(s, merged, rows);
  } catch (const nlohmann::json::exception& e) {
    return fail("eval", std::string("a shard's rows are not eval's: ") + e.what());
  }
}

int run_eval_cmd(State& s) {
  try {
    if (!s.eval_merge.empty()) {
      if (!s.eval_json_out.empty() && !can_write(s.eval_json_out)) return fail("eval", "cannot write " + s.eval_json_out);
      return run_eval_merge(s);
    }
    if (s.eval_dir.empty()) return fail("eval", "a folder of tasks is required (DIR), or --merge SHARD.json ...");
    const Shard shard = s.eval_shard.empty() ? Shard{} : parse_shard(s.eval_shard);
    // Checked before the (long) run, so a bad path fails at once; written after,
    // so a file inside DIR is never scanned half-made (an eval JSON is not a task).
    if (!s.eval_json_out.empty() && !can_write(s.eval_json_out))
      return fail("eval", "cannot write " + s.eval_json_out);
    ThreadPool pool(s.eval_threads);
    SolveOptions o = s.eval_opts;
    apply_protocol(s.eval, s.eval_protocol, o);
    const std::vector<fs::path> all = find_tasks(s.eval_dir);
    std::vector<EvalRow> rows = run_eval_files(s.eval_dir, select_shard(all, shard), o, pool, progress_bar());
    nlohmann::json report = eval_json(rows);
    report["agent"] = eval_agent_json(s.eval_protocol, o);
    report["task_set"] = {s.eval_dir};
    if (!s.eval_shard.empty()) report["shard"] = {{"index", shard.index}, {"count", shard.count}, {"tasks", all.size()}};
    return finish_eval(s, report, rows);
  } catch (const std::exception& e) {
    return fail("eval", e.what());
  }
}

int run_random_baseline_cmd(State& s) {
  try {
    if (!s.random_json_out.empty() && !can_write(s.random_json_out))
      return fail("baseline random", "cannot write " + s.random_json_out);
    ThreadPool pool(s.random_threads);
    const std::vector<RandomRow> rows = run_random_baseline(s.random_paths, s.random_opts, pool, progress_bar());
    if (rows.empty()) return fail("baseline random", "no task files in the paths given");
    const nlohmann::json report = random_report_json(rows, s.random_opts, s.random_paths);
    if (s.random_json) std::cout << report.dump() << "\n";
    else fmt::print("{}", random_table(rows));
    if (!s.random_json_out.empty()) {
      if (std::string why = write_file(s.random_json_out, report.dump(1) + "\n"); !why.empty())
        return fail("baseline random", why);
    }
    const auto errors = std::count_if(rows.begin(), rows.end(), [](const RandomRow& r) { return !r.error.empty(); });
    if (errors) std::cerr << "autumn baseline random: " << errors << " task" << (errors == 1 ? "" : "s") << " failed\n";
    return errors ? 1 : 0;
  } catch (const std::exception& e) {
    return fail("baseline random", e.what());
  }
}

int run_bench_agent(State& s) {
  try {
    for (const std::string& p : s.bench_paths)
      if (fs::is_directory(p) && program_files(p).empty()) return fail("bench-agent", "no .sexp or .au programs in " + p);
    const std::vector<fs::path> programs = expand_programs(s.bench_paths);
    for (const std::string& p : s.bench_paths)
      if (!fs::is_directory(p)) s.bench_opts.named.push_back(p);  // never filtered out by --grid
    if (s.bench_opts.threads == 0) s.bench_opts.threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<BenchAgentRow> rows = bench_agent(programs, s.bench_opts, progress_bar());
    if (rows.empty()) return fail("bench-agent", fmt::format("no program has GRID_SIZE {} (use --grid 0)", s.bench_opts.grid));
    if (s.bench_json) std::cout << bench_agent_json(rows, s.bench_opts).dump() << "\n";
    else fmt::print("{}", bench_agent_table(rows, s.bench_opts));
    return 0;
  } catch (const std::exception& e) {
    return fail("bench-agent", e.what());
  }
}

}  // namespace

void add_agent_commands(CLI::App& app) {
  State& s = state();

  s.solve = app.add_subcommand("solve", "Solve an AutumnBench task (MFP, change detection or planning)");
  s.solve->add_option("TASK", s.task_file, "Task file (JSON)")->required()->check(CLI::ExistingFile);
  s.solve->add_option("--programs", s.programs_dir, "Folder of the task's programs (default: programs/ beside the task's folder)")
      ->check(CLI::ExistingDirectory);
  s.solve->add_option("--answers", s.answers_file, "Answers file, read only to report and score: MFP correct_idx, change detection's condition and world seed")
      ->check(CLI::ExistingFile);
  s.solve->add_flag("--json", s.json, "Print one JSON object");
  s.solve->add_option("--render", s.render_dir,
                      "Write pictures of the answer into DIR: the plan (GIF and PNG), the chosen MFP answer, "
                      "the change-detection episode");
  add_search_options(s.solve, s.solve_opts, s.threads);
  add_protocol_option(s.solve, s.solve_protocol);

  s.make = app.add_subcommand("make-task", "Generate an MFP, planning or change-detection task for a program");
  s.make->add_option("KIND", s.make_opts.kind, "mfp, planning or cd")
      ->required()
      ->check(CLI::IsMember({"mfp", "planning", "cd"}));
  s.make->add_option("PROGRAM", s.make_program, "Autumn program (.au or .sexp)")->required()->check(CLI::ExistingFile);
  s.make->add_option("--seed", s.make_opts.seed, "Seed of the generator (actions, mask, distractors)")
      ->default_val(0)
      ->check(cli::seed_number());
  s.make->add_option("--steps", s.make_opts.steps, "Actions in the task (default: mfp 20, planning 4); cd: the clock value K "
                                                 "the change starts at (default: seeded in 6..20)")
      ->check(cli::int_count(1));
  s.make->add_option("--out", s.make_out, "Output task file (default: stdout); under prompts/ the program is copied "
                                          "to the sibling programs/ and the answers go to the sibling answers/ "
                                          "(cd: required, and the changed program goes to programs/ too)");
  s.make->add_option("--answers", s.make_opts.answers_out,
                     "Answers file (seed, correct_idx / reference_plan) (default: answers/TASK.json beside prompts/, "
                     "else TASK.answers.json beside the task)");
  s.make->add_option("--env-seed", s.make_opts.env_seed, "Interpreter seed of the environment")
      ->default_val(0)
      ->check(cli::seed_number());
  s.make->add_option("--batch", s.make_opts.batch, "MFP: rollouts whose outcomes no distractor may equal")
      ->default_val(200)
      ->check(cli::big_count(1));
  s.make->add_option("--posterior-samples", s.make_opts.posterior_samples,
                     "MFP, stochastic programs: samples of the blind solver's posterior that choose the rectangle")
      ->default_val(1000)
      ->check(cli::big_count(1));
  s.make->add_option("--masked-frames", s.make_opts.masked_frames, "MFP: final frames that hide the rectangle")
      ->default_val(3)
      ->check(cli::int_count(1));
  s.make->add_flag("--extend-colours", s.make_opts.extend_colours,
                   "Append colours missing from the colour table (and write the table next to the task)");
  s.make->add_option("--engine", s.make_opts.engine, "Execution engine")
      ->check(CLI::IsMember(engine_names()))
      ->default_val("compiled");

  s.eval = app.add_subcommand("eval", "Solve every task in a folder (recursively) and tabulate the scores");
  CLI::Option* dir = s.eval->add_option("DIR", s.eval_dir, "Folder of tasks (not with --merge)")->check(CLI::ExistingDirectory);
  s.eval->add_flag("--json", s.eval_json, "Print one JSON object");
  s.eval->add_option("--json-out", s.eval_json_out, "Also write that JSON object to FILE (the table still prints)")
      ->type_name("FILE");
  add_search_options(s.eval, s.eval_opts, s.eval_threads);
  add_protocol_option(s.eval, s.eval_protocol);
  s.eval->footer(
      "Columns: task (its file, relative to DIR); type (mfp, cd, planning); score (MFP and planning: 1 for a "
      "right answer or a plan that reaches the goal, else 0; change detection: the benchmark's score of when "
      "the change was detected, 0 to 1; - when there is no answers file to score against; error when the "
      "solver failed); time s (solve time, module compiles not counted: the summary "
      "line gives them); throughput and unit (rollouts/s for MFP, steps/s for change detection, nodes/s for "
      "planning: measured work per second of that solve, - when nothing was measured); detail (what was "
      "answered, or why not). The second table gives the mean score per task type.");
  s.eval->add_option("--shard", s.eval_shard,
                     "Solve only slice K of N of the folder's tasks (those whose index in path order is K-1 modulo N), "
                     "for a batch scheduler's array job; its JSON says which slice (docs/scale.md)")
      ->type_name("K/N")
      ->needs(dir);
  s.eval->add_option("--merge", s.eval_merge,
                     "Put the N shards' JSON files (--json-out of each --shard run) back together: the table and JSON "
                     "one run of the whole folder prints")
      ->type_name("SHARD.json ...")
      ->excludes(dir)
      ->check(CLI::ExistingFile);

  CLI::App* baseline = app.add_subcommand("baseline", "Reference agents the paper compares against (baseline random)");
  baseline->require_subcommand(1);
  RandomOptions& ro = s.random_opts;
  s.random = baseline->add_subcommand(
      "random", "The paper's memoryless random agent: success probability and mean steps per task, by rollouts");
  s.random->add_option("TASKS", s.random_paths, "Task files, or folders of them (searched recursively)")
      ->required()
      ->check(CLI::ExistingPath);
  s.random->add_option("--rollouts", ro.rollouts, "Episodes per task")->default_val(50)->check(cli::big_count(1));
  s.random->add_option("--timeout", ro.timeout, "Steps per episode")->default_val(1000)->check(cli::int_count(1));
  s.random->add_option("--seed", ro.seed, "Seed of the policy (episode r draws from (seed, r))")
      ->default_val(0)
      ->check(cli::seed_number());
  s.random->add_option("--engine", ro.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("compiled");
  s.random->add_option("--programs", ro.programs_dir, "Folder of the tasks' programs (default: programs/ beside each task's folder)")
      ->check(CLI::ExistingDirectory);
  s.random->add_option("--threads", s.random_threads, "Worker threads (0: all cores)")->default_val(0)->check(cli::thread_count());
  s.random->add_flag("--json", s.random_json, "Print one JSON object (the shape scripts/compare-agents.py reads)");
  s.random->footer(
      "Columns: task; type; score (+- se) (MFP: the chance of picking the right choice at random; change "
      "detection: the probability that the trigger condition fires within --timeout steps; planning: the "
      "probability of reaching the goal; se: the binomial standard error over --rollouts episodes); successes "
      "(episodes that succeeded); mean steps (steps to success, over the successful episodes; - without any); "
      "seconds (wall clock of the task's episodes).");
  s.random->add_option("--json-out", s.random_json_out, "Also write that JSON object to FILE (the table still prints)")
      ->type_name("FILE");

  BenchAgentOptions& b = s.bench_opts;
  s.bench = app.add_subcommand("bench-agent",
                               "Throughput of the simulator agent: a 10,000-rollout MFP query and BFS expansion per program");
  s.bench->add_option("PROGRAMS", s.bench_paths, "Programs, or folders of programs")->required()->check(CLI::ExistingPath);
  s.bench->add_option("--engine", b.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("compiled");
  s.bench->add_option("--threads", b.threads, "Threads of the MFP query and the parallel BFS run (0: all cores)")
      ->default_val(2)
      ->check(cli::thread_count());
  s.bench->add_option("--rollouts", b.rollouts, "MFP rollouts")->default_val(10000)->check(cli::big_count(1));
  s.bench->add_option("--mfp-steps", b.mfp_steps, "Actions in the MFP trajectory")->default_val(70)->check(cli::int_count(1));
  s.bench->add_option("--seed", b.seed, "Seed of the generated MFP task and of the rollouts")
      ->default_val(1)
      ->check(cli::seed_number());
  s.bench->add_option("--bfs-nodes", b.bfs_nodes, "BFS: successors to generate per run")
      ->default_val(1000000)
      ->check(cli::big_count(1));
  s.bench->add_option("--bfs-depth", b.bfs_depth, "BFS: depth limit")->default_val(12)->check(cli::int_count(1));
  s.bench->add_option("--seconds", b.seconds, "BFS: time limit per run")
      ->default_val(10)
      ->check(cli::number_at_least(0.001, "POSITIVE"));
  s.bench->add_option("--grid", b.grid,
                      "Only programs with this GRID_SIZE (0: all) among those found in folders; files named here "
                      "always run")
      ->default_val(16)
      ->check(cli::int_count());
  s.bench->add_option("--only", b.only, "Run only one measurement")->check(CLI::IsMember({"mfp", "bfs"}));
  s.bench->footer(
      "Columns: program; grid (GRID_SIZE); code (specialised or embedded module, or the engine when not "
      "compiled); mfp s (seconds of one --rollouts MFP query on --threads threads); rollout/s (rollouts per "
      "second of that query); ok (whether it chose the right answer); actions (the BFS's action set size); "
      "depth (BFS levels completed; * the search space ran out: left out of the medians); bfs nodes "
      "(successors generated on one thread); bfs/s 1t (successors per second on one thread); bfs/s Nt (on "
      "--threads threads); per thread (bfs/s Nt / N). - where a measurement did not run.");
  s.bench->add_flag("--json", s.bench_json, "Print one JSON object");
}

int run_agent_command(const CLI::App& app) {
  (void)app;
  State& s = state();
  if (s.solve && s.solve->parsed()) return run_solve(s);
  if (s.make && s.make->parsed()) return run_make(s);
  if (s.eval && s.eval->parsed()) return run_eval_cmd(s);
  if (s.bench && s.bench->parsed()) return run_bench_agent(s);
  if (s.random && s.random->parsed()) return run_random_baseline_cmd(s);
  return -1;
}

}  // namespace autumn::agent
