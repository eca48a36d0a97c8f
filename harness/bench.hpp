// bench — interpreter versus compiled engine, one program at a time.
//
// For each engine: steps/s under the benchmark protocol (render after every
// step), steps/s without the render (advance), and the mean cost of clone().
// The same reproducible action sequence drives every engine.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compiler/analyse/program.hpp"

namespace autumn {

struct EngineFigures {
  bool ok = false;
  std::string error;
  size_t steps = 0;
  double steps_per_s = 0;          // with render
  double steps_per_s_no_render = 0;
  double clone_ns = 0;
};

struct BenchRow {
  std::string program;
  int grid = 0;
  std::vector<EngineFigures> engines;  // in the order asked
  std::string note;  // why fewer than the steps asked were timed (the time cap), or empty
};

// The actions are chosen on the compiled engine's frames when it is among
// `engines` (the same frames as the interpreter's, and far sooner). `time_cap`
// (seconds, 0: none) bounds an engine's first timed replay and the choosing of
// the actions: past it, every engine is timed over the steps done by then, and
// the row's note says so (a program whose state grows step after step can take
// the interpreter minutes a replay).
constexpr double kDefaultBenchTimeCap = 60;
BenchRow bench_program(const std::string& name, const std::shared_ptr<const Program>& program,
                       const std::vector<std::string>& engines, size_t steps, uint64_t seed,
                       double time_cap = kDefaultBenchTimeCap);

// The interpreter-vs-compiled comparison (engines {"interp", "compiled"}), as
// `autumn bench` reports it and autumnc.distributed.bench collects it: a row's
// JSON ({"program", "grid", "steps", "ratio", "interp": {...}, "compiled":
// {...}}, and "note" when the time cap shortened it); a program that could not be loaded as a row with "error"; the report
// of all rows ({"rows", "median_ratio", "median_compiled_step_us"}) and its table.
nlohmann::json bench_row_json(const BenchRow& row);
nlohmann::json bench_error_row(const std::string& program, const std::string& why);
nlohmann::json bench_report(const nlohmann::json& rows);
std::string bench_table(const nlohmann::json& report);
bool bench_row_ok(const nlohmann::json& row);

}  // namespace autumn
