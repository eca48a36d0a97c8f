// bench_agent — throughput figures of the simulator agent (`autumn bench-agent`).
//
// For each program, two measurements on generated queries:
//   mfp: a masked-frame-prediction task over a random trajectory of `mfp_steps`
//        actions (make_task, generator seed `seed`), solved with `rollouts`
//        rollouts on `threads` threads; time and rollouts/s, and whether the
//        answer was right.
//   bfs: breadth-first search from reset(0) towards a goal no frame can show, so
//        the search runs until `bfs_nodes` successors, `bfs_depth` layers or
//        `seconds` — pure expansion throughput. Run on one thread (the per-thread
//        figure) and on `threads` threads (the scaling); each `bfs_repeat` times,
//        the fastest run kept (a busy machine slows a run, nothing speeds one).
//        Beside them, the machine's own scaling (machine_scaling): on a virtual
//        machine the second core is shared with other tenants, and the BFS's
//        scaling reads against what a loop that shares nothing got.
// Nothing here is timed by a test: the figures are printed for people to read.
#pragma once
#include <nlohmann/json.hpp>
#include <functional>
#include <string>
#include <vector>

#include "harness/agent/task_file.hpp"

namespace autumn::agent {

struct BenchAgentOptions {
  std::string engine = "compiled";
  unsigned threads = 2;
  uint64_t rollouts = 10000;
  int mfp_steps = 70;
  uint64_t seed = 1;
  uint64_t bfs_nodes = 1000000;
  int bfs_depth = 12;
  double seconds = 10;  // per BFS run
  int bfs_repeat = 1;   // BFS runs per measurement; the fastest is kept
  int grid = 16;        // only programs with this GRID_SIZE (0: all), among those found in folders
  std::vector<fs::path> named;  // files named on the command line: they run whatever their grid
  std::string only;     // "mfp" or "bfs": run just that measurement
};

struct BenchAgentRow {
  std::string program;
  int grid = 0;
  bool specialised = false;
  std::string error;  // set when a measurement could not run
  bool deterministic = false;
  // mfp
  bool mfp_ran = false, mfp_correct = false;
  double mfp_seconds = 0, mfp_rollouts_per_s = 0;
  // bfs
  uint64_t bfs_nodes_1 = 0, bfs_nodes_n = 0;
  size_t bfs_actions = 0;
  int bfs_depth_done = 0;
  bool bfs_small = false;  // the space ran out (all seen, or < a tenth of the budget): a rate of little meaning
  double bfs_seconds_1 = 0, bfs_seconds_n = 0;  // search time alone
  // What the machine's own `threads` threads gave against one beside this
  // program's BFS runs: an arithmetic loop (nothing shared, no memory) timed
  // alone and on every thread at once, the fastest of bfs_repeat turns each.
  // 0: not measured (one thread, or no BFS run).
  double machine_scaling = 0;
};

// `progress(i, n, name)` before program i (and once with i == n at the end).
// A program left out by `grid` has no row; `skipped` (when given) gets its
// index in `programs`. A row depends on its program and the options only.
std::vector<BenchAgentRow> bench_agent(const std::vector<fs::path>& programs, const BenchAgentOptions& opts,
                                       const std::function<void(size_t, size_t, const std::string&)>& progress,
                                       std::vector<size_t>* skipped = nullptr);
std::string bench_agent_table(const std::vector<BenchAgentRow>& rows, const BenchAgentOptions& opts);
// The options (those that change a row: engine, threads, rollouts, mfp_steps,
// seed, bfs_nodes, bfs_depth, bfs_repeat, seconds, grid, only) and "programs": the rows.
nlohmann::json bench_agent_json(const std::vector<BenchAgentRow>& rows, const BenchAgentOptions& opts);
// The inverse of a row of bench_agent_json's "programs" (for --merge).
BenchAgentRow bench_agent_row_from_json(const nlohmann::json& program);
// The options bench_agent_json records, back (for --merge's table; `named` is not recorded).
BenchAgentOptions bench_agent_options_from_json(const nlohmann::json& report);

}  // namespace autumn::agent
