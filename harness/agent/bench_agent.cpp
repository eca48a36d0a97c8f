#include "harness/agent/bench_agent.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <system_error>
#include <thread>

#include "compiler/lower/lower.hpp"
#include "harness/agent/make_task.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"
#include "harness/agent/solve_common.hpp"
#include "harness/program_files.hpp"

namespace autumn::agent {

namespace {

// A planning task whose goal no frame shows: every cell masked, every goal cell
// a colour id outside any table.
Task unreachable_goal(const fs::path& program, int size, const ColourTable& colours) {
  Task t;
  t.file = program;
  t.name = program.stem().string() + "_bench";
  t.type = TaskType::Planning;
  t.program = program.stem().string();
  t.colours = colours;
  t.goal.width = t.goal.height = size;
  t.goal.cells.assign(static_cast<size_t>(size) * size, int16_t{32000});
  t.mask.width = t.mask.height = size;
  t.mask.cells.assign(static_cast<size_t>(size) * size, int16_t{1});
  return t;
}

std::string rate(double per_s) {
  if (per_s >= 1e6) return fmt::format("{:.2f}M", per_s / 1e6);
  if (per_s >= 1e3) return fmt::format("{:.0f}k", per_s / 1e3);
  return fmt::format("{:.0f}", per_s);
}

double bfs_rate(uint64_t nodes, double seconds) { return per_second(static_cast<double>(nodes), seconds); }

// `threads` times one thread's time over all `threads` threads' time, each
// thread running the same arithmetic loop (four independent chains, about 30 ms
// alone): N on a machine whose N cores are all this process's, less where
// another tenant takes part of one. The fastest of `repeat` turns of each,
// alternating, as the BFS runs are measured (fastest_bfs). Plain threads, not
// the pool: its parallel_for lets one thread run every index, and each loop
// here must have a thread of its own. 0 when a thread cannot be started (the
// figure is then not measured; the BFS's row stands).
double machine_scaling(unsigned threads, int repeat) {
  if (threads < 2) return 0;
  const auto loop = [] {
    uint64_t a = 1, b = 2, c = 3, d = 4;
    for (uint64_t i = 0; i < 40'000'000; ++i) {
      a += i, b += i * 3, c += i * 5, d += i * 7;
      asm volatile("" : "+r"(a), "+r"(b), "+r"(c), "+r"(d));  // kept, and not vectorised
    }
    return a + b + c + d;
  };
  const auto seconds = [&](unsigned n) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> others;
    try {
      for (unsigned i = 1; i < n; ++i) others.emplace_back(loop);
    } catch (...) {  // the ones started are joined (a joinable thread's destructor ends the process)
      for (auto& t : others) t.join();
      throw;
    }
    loop();
    for (auto& t : others) t.join();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  double one = 1e300, all = 1e300;
  try {
    for (int i = 0; i < std::max(1, repeat); ++i) {
      one = std::min(one, seconds(1));
      all = std::min(all, seconds(threads));
    }
  } catch (const std::system_error&) {
    return 0;
  }
  return threads * one / all;
}

// The fastest of `repeat` runs of each BFS measurement, on one thread and on
// the pool. The runs alternate (one, pool, one, pool, ...): a busy spell of the
// machine then slows runs of both, not every run of one of them.
std::pair<PlanResult, PlanResult> fastest_bfs(const Task& goal, const SolveOptions& so, ThreadPool& one,
                                              ThreadPool& many, int repeat) {
  auto keep_faster = [](PlanResult& best, PlanResult r) {
    if (bfs_rate(r.nodes, r.search_seconds) > bfs_rate(best.nodes, best.search_seconds)) best = std::move(r);
  };
  PlanResult best1 = solve_planning(goal, so, one);
  PlanResult bestn = solve_planning(goal, so, many);
  for (int i = 1; i < repeat; ++i) {
    keep_faster(best1, solve_planning(goal, so, one));
    keep_faster(bestn, solve_planning(goal, so, many));
  }
  return {std::move(best1), std::move(bestn)};
}

}  // namespace

std::vector<BenchAgentRow> bench_agent(const std::vector<fs::path>& programs, const BenchAgentOptions& opts,
                                       const std::function<void(size_t, size_t, const std::string&)>& progress,
                                       std::vector<size_t>* skipped) {
  ThreadPool one(1), many(opts.threads);
  std::vector<BenchAgentRow> rows;
  for (size_t i = 0; i < programs.size(); ++i) {
    const fs::path& path = programs[i];
    progress(i, programs.size(), path.stem().string());
    BenchAgentRow row;
    row.program = path.stem().string();
    try {
      auto program = load_program_checked(path);
      auto env = make_env_checked(opts.engine, program);
      if (!env->reset(0)) throw TaskError("reset failed: " + env->error());
      row.grid = env->frame().size;
      if (opts.grid > 0 && row.grid != opts.grid &&
          std::find(opts.named.begin(), opts.named.end(), path) == opts.named.end()) {
        if (skipped) skipped->push_back(i);
        continue;
      }
      row.deterministic = env->deterministic();
      row.specialised = opts.engine == "compiled" && lower_program(*program, "bench").ok;

      SolveOptions so;
      so.engine = opts.engine;
      so.programs_dir = path.parent_path();
      so.seed = opts.seed;
      so.rollouts = opts.rollouts;
      ColourTable colours;
      if (opts.only != "bfs") try {
        MakeTaskOptions mo;
        mo.kind = "mfp";
        mo.program = path;
        mo.seed = opts.seed;
        mo.steps = opts.mfp_steps;
        mo.engine = opts.engine;
        mo.extend_colours = true;
        MadeTask made = make_task(mo, many);
        colours = made.colours;
        Task task = parse_task(made.task, path, made.colours);
        MfpResult r = solve_mfp(task, so, many);
        row.mfp_ran = true;
        row.mfp_correct = r.choice == made.answers.at("correct_idx").get<int>();
        row.mfp_seconds = r.seconds;
        row.mfp_rollouts_per_s = per_second(static_cast<double>(r.rollouts), r.seconds);
      } catch (const std::exception& e) {
        row.error = std::string("mfp: ") + e.what();
      }

      if (opts.only == "mfp") {
        rows.push_back(std::move(row));
        continue;
      }
      so.search = "bfs";
      so.depth = opts.bfs_depth;
      so.nodes = opts.bfs_nodes;
      so.time_limit = opts.seconds;
      Task goal = unreachable_goal(path, row.grid, colours);
      // The planner's search model (click-reset) is built before the clock
      // starts, as solve and eval build it: its first compile took the time
      // limit of a run and left it a fraction of its successors.
      prepare_modules(goal, so);
      auto [r1, rn] = fastest_bfs(goal, so, one, many, opts.bfs_repeat);
      row.bfs_actions = r1.actions;
      row.bfs_depth_done = r1.bfs_depth_done;
      row.bfs_nodes_1 = r1.nodes;
      row.bfs_small = r1.exhausted || (r1.nodes < opts.bfs_nodes / 10 && !r1.timed_out);
      row.bfs_seconds_1 = r1.search_seconds;
      row.bfs_nodes_n = rn.nodes;
      row.bfs_seconds_n = rn.search_seconds;
      row.machine_scaling = machine_scaling(opts.threads, opts.bfs_repeat);
    } catch (const std::exception& e) {
      if (!row.error.empty()) row.error += "; ";
      row.error += e.what();
    }
    rows.push_back(std::move(row));
  }
  progress(programs.size(), programs.size(), "");
  return rows;
}

std::string bench_agent_table(const std::vector<BenchAgentRow>& rows, const BenchAgentOptions& o) {
  std::string s = fmt::format("{:<34} {:>4} {:<11} {:>8} {:>10} {:>4}  {:>7} {:>6} {:>9} {:>10} {:>10} {:>10}\n",
                              "program", "grid", "code", "mfp s", "rollout/s", "ok", "actions", "depth", "bfs nodes",
                              "bfs/s 1t", fmt::format("bfs/s {}t", o.threads), "per thread");
  std::vector<double> mfp_s, spec_rate, emb_rate, spec_rate_n, emb_rate_n, spec_scaling, machine;
  size_t mfp_ok = 0, mfp_ran = 0, fast = 0, fast_n = 0, small = 0, scaled = 0;
  // The scaling asked of N threads: 0.9 N times one thread's rate (1.8x on two).
  const double scaling_bar = 0.9 * std::max(1u, o.threads);
  std::string slowest;
  double slowest_s = -1;
  for (const auto& r : rows) {
    const std::string code = o.engine != "compiled" ? o.engine : r.specialised ? "specialised" : "embedded";
    const double r1 = bfs_rate(r.bfs_nodes_1, r.bfs_seconds_1), rn = bfs_rate(r.bfs_nodes_n, r.bfs_seconds_n);
    s += fmt::format("{:<34} {:>4} {:<11} {:>8} {:>10} {:>4}  {:>7} {:>6} {:>9} {:>10} {:>10} {:>10}\n", r.program,
                     r.grid, code, r.mfp_ran ? fmt::format("{:.3f}", r.mfp_seconds) : "-",
                     r.mfp_ran ? rate(r.mfp_rollouts_per_s) : "-", r.mfp_ran ? (r.mfp_correct ? "yes" : "NO") : "-",
                     r.bfs_actions, fmt::format("{}{}", r.bfs_depth_done, r.bfs_small ? "*" : ""),
                     rate(static_cast<double>(r.bfs_nodes_1)), rate(r1), rate(rn), rate(rn / std::max(1u, o.threads)));
    if (!r.error.empty()) s += "    error: " + r.error + "\n";
    if (r.mfp_ran) {
      ++mfp_ran;
      mfp_ok += r.mfp_correct;
      mfp_s.push_back(r.mfp_seconds);
      if (r.mfp_seconds > slowest_s) slowest_s = r.mfp_seconds, slowest = r.program;
    }
    if (r.bfs_nodes_1 == 0) continue;
    if (r.machine_scaling > 0) machine.push_back(r.machine_scaling);
    if (r.bfs_small) {
      ++small;
      continue;
    }
    const bool spec = r.specialised || o.engine != "compiled";
    (spec ? spec_rate : emb_rate).push_back(r1);
    (spec ? spec_rate_n : emb_rate_n).push_back(rn / std::max(1u, o.threads));
    if (spec && r1 >= 1e6) ++fast;
    if (spec && rn / std::max(1u, o.threads) >= 1e6) ++fast_n;
    if (spec && r1 > 0) {
      spec_scaling.push_back(rn / r1);
      if (rn / r1 >= scaling_bar) ++scaled;
    }
  }
  s += "\n";
  if (o.only != "bfs")  // each measurement's summary only where it ran
    s += fmt::format("mfp ({} steps x {} rollouts, {} threads, {}): {}/{} answered correctly; median {:.3f} s, "
                     "slowest {:.3f} s ({})\n",
                     o.mfp_steps, o.rollouts, o.threads, o.engine, mfp_ok, mfp_ran, median(mfp_s),
                     std::max(0.0, slowest_s), slowest.empty() ? "-" : slowest);
  if (o.only == "mfp") return s;
  const std::string which = o.engine == "compiled" ? "specialised programs" : o.engine;
  s += fmt::format("bfs successors per second on one thread ({}): median {}{}; {} of {} at least 1M/s\n", which,
                   rate(median(spec_rate)),
                   emb_rate.empty() ? "" : fmt::format(" (embedded programs: median {})", rate(median(emb_rate))),
                   fast, spec_rate.size());
  s += fmt::format("bfs successors per second per thread on {} threads ({}): median {}{}; {} of {} at least 1M/s\n",
                   o.threads, which, rate(median(spec_rate_n)),
                   emb_rate_n.empty() ? "" : fmt::format(" (embedded programs: median {})", rate(median(emb_rate_n))),
                   fast_n, spec_rate_n.size());
  if (o.threads > 1)
    s += fmt::format("bfs on {} threads against one ({}): median {:.2f}x; {} of {} at least {:.1f}x{}\n", o.threads,
                     which, median(spec_scaling), scaled, spec_scaling.size(), scaling_bar,
                     o.bfs_repeat > 1 ? fmt::format(" (fastest of {} runs each)", o.bfs_repeat) : "");
  if (!machine.empty())
    s += fmt::format("the machine's own {} threads against one, beside those runs (a loop that shares nothing): "
                     "median {:.2f}x, lowest {:.2f}x\n",
                     o.threads, median(machine), *std::min_element(machine.begin(), machine.end()));
  if (small)
    s += fmt::format("* the search space ran out (every reachable state seen, or fewer than a tenth of the node budget "
                     "within the depth limit): {} program{} left out of the medians\n",
                     small, small == 1 ? "" : "s");
  return s;
}

nlohmann::json bench_agent_json(const std::vector<BenchAgentRow>& rows, const BenchAgentOptions& o) {
  nlohmann::json out = {{"engine", o.engine},       {"threads", o.threads},     {"rollouts", o.rollouts},
                        {"mfp_steps", o.mfp_steps}, {"bfs_nodes", o.bfs_nodes}, {"bfs_depth", o.bfs_depth},
                        {"seed", o.seed},           {"seconds", o.seconds},     {"grid", o.grid},
                        {"bfs_repeat", o.bfs_repeat},
                        {"only", o.only.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.only)},
                        {"programs", nlohmann::json::array()}};
  for (const auto& r : rows) {
    nlohmann::json j = {{"program", r.program},
                        {"grid", r.grid},
                        {"specialised", r.specialised},
                        {"deterministic", r.deterministic},
                        {"bfs_actions", r.bfs_actions},
                        {"bfs_depth_done", r.bfs_depth_done},
                        {"bfs_small_space", r.bfs_small},
                        {"bfs_nodes_1_thread", r.bfs_nodes_1},
                        {"bfs_seconds_1_thread", r.bfs_seconds_1},
                        {"bfs_nodes_per_s_1_thread", bfs_rate(r.bfs_nodes_1, r.bfs_seconds_1)},
                        {"bfs_nodes_n_threads", r.bfs_nodes_n},
                        {"bfs_seconds_n_threads", r.bfs_seconds_n},
                        {"bfs_nodes_per_s_n_threads", bfs_rate(r.bfs_nodes_n, r.bfs_seconds_n)}};
    if (r.machine_scaling > 0) j["machine_scaling_n_threads"] = r.machine_scaling;
    if (r.mfp_ran) {
      j["mfp_seconds"] = r.mfp_seconds;
      j["mfp_rollouts_per_s"] = r.mfp_rollouts_per_s;
      j["mfp_correct"] = r.mfp_correct;
    }
    if (!r.error.empty()) j["error"] = r.error;
    out["programs"].push_back(j);
  }
  return out;
}

BenchAgentRow bench_agent_row_from_json(const nlohmann::json& j) {
  BenchAgentRow r;
  r.program = j.at("program").get<std::string>();
  r.grid = j.at("grid").get<int>();
  r.specialised = j.at("specialised").get<bool>();
  r.deterministic = j.at("deterministic").get<bool>();
  r.bfs_actions = j.at("bfs_actions").get<size_t>();
  r.bfs_depth_done = j.at("bfs_depth_done").get<int>();
  r.bfs_small = j.at("bfs_small_space").get<bool>();
  r.bfs_nodes_1 = j.at("bfs_nodes_1_thread").get<uint64_t>();
  r.bfs_seconds_1 = j.at("bfs_seconds_1_thread").get<double>();
  r.bfs_nodes_n = j.at("bfs_nodes_n_threads").get<uint64_t>();
  r.bfs_seconds_n = j.at("bfs_seconds_n_threads").get<double>();
  r.machine_scaling = j.value("machine_scaling_n_threads", 0.0);
  r.mfp_ran = j.contains("mfp_seconds");
  if (r.mfp_ran) {
    r.mfp_seconds = j.at("mfp_seconds").get<double>();
    r.mfp_rollouts_per_s = j.at("mfp_rollouts_per_s").get<double>();
    r.mfp_correct = j.at("mfp_correct").get<bool>();
  }
  r.error = j.value("error", "");
  return r;
}

BenchAgentOptions bench_agent_options_from_json(const nlohmann::json& j) {
  BenchAgentOptions o;
  o.engine = j.at("engine").get<std::string>();
  o.threads = j.at("threads").get<unsigned>();
  o.rollouts = j.at("rollouts").get<uint64_t>();
  o.mfp_steps = j.at("mfp_steps").get<int>();
  o.bfs_nodes = j.at("bfs_nodes").get<uint64_t>();
  o.bfs_depth = j.at("bfs_depth").get<int>();
  o.seed = j.at("seed").get<uint64_t>();
  o.seconds = j.at("seconds").get<double>();
  o.grid = j.at("grid").get<int>();
  o.bfs_repeat = j.value("bfs_repeat", 1);  // absent from reports written before --repeat
  if (!j.at("only").is_null()) o.only = j.at("only").get<std::string>();
  return o;
}

}  // namespace autumn::agent
