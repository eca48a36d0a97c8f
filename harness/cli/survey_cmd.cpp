// autumn survey — run every program of a folder under a reproducible random
// policy and tabulate what happened (text table or --json).
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/engine.hpp"
#include "harness/policy.hpp"
#include "harness/program_files.hpp"

namespace autumn::cli {
namespace {

struct SurveyOptions {
  std::string dir;
  int steps = 100;
  uint64_t seed = 0;
  std::string engine = "interp";
  bool json = false;
};

void register_survey(CLI::App* cmd, SurveyOptions& o) {
  cmd->add_option("DIR", o.dir, "Folder of .au/.sexp programs")->required();
  cmd->add_option("--steps", o.steps, "Steps per program")->default_val(100)->check(int_count());
  cmd->add_option("--seed", o.seed, "Seed for the programs and the random policy")->default_val(0)->check(seed_number());
  cmd->add_option("--engine", o.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the table");
  cmd->footer(
      "Columns: program (file name); grid (GRID_SIZE); steps (random actions taken before the end or an error); "
      "frames (frames drawn, the first included); distinct (different frames among them); clauses (on-clauses "
      "whose condition held at least once / on-clauses of the program); time ms (wall clock of the episode); "
      "status (ok, error: a runtime error, its message below the table, load error, engine error).");
}

struct SurveyRow {
  std::string program;
  int grid = 0;
  size_t steps = 0, frames = 0, distinct = 0;
  int clauses = 0, covered = 0;
  double ms = 0;
  std::string status = "ok";  // ok | error | load error | engine error
  std::string error;
};

SurveyRow survey_program(const SurveyOptions& o, const std::filesystem::path& f) {
  SurveyRow row;
  row.program = f.stem().string();
  auto program = load_or_report(f.string(), std::nullopt);
  if (!program) {
    row.status = "load error";
    return row;
  }
  auto env = make_env("survey", o.engine, program);
  if (!env) {
    row.status = "engine error";
    return row;
  }
  auto t0 = std::chrono::steady_clock::now();
  bool ok = env->reset(o.seed);
  std::set<std::vector<uint16_t>> distinct;
  if (ok) row.grid = env->frame().size, row.frames = 1, distinct.insert(env->frame().cells);
  RandomPolicy policy(o.seed);
  for (int i = 0; ok && i < o.steps; ++i) {
    if (!(ok = env->step(policy.next(env->frame())))) break;
    ++row.steps, ++row.frames;
    distinct.insert(env->frame().cells);
  }
  row.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  row.distinct = distinct.size();
  row.clauses = env->on_clause_count();
  row.covered = env->covered_on_clause_count();
  if (!ok) row.status = "error", row.error = env->error();
  return row;
}

constexpr const char* kRowFormat = "{:<36} {:>5} {:>6} {:>7} {:>9} {:>9} {:>9}  {}\n";

void print_table(const std::vector<SurveyRow>& rows) {
  fmt::print(kRowFormat, "program", "grid", "steps", "frames", "distinct", "clauses", "time ms", "status");
  size_t steps = 0, frames = 0, failed = 0;
  for (const auto& r : rows) {
    const std::string clauses = r.status == "load error" || r.status == "engine error" ? "-" : fmt::format("{}/{}", r.covered, r.clauses);
    fmt::print(kRowFormat, r.program, r.grid ? std::to_string(r.grid) : "-", r.steps, r.frames, r.distinct, clauses,
               fmt::format("{:.1f}", r.ms), r.status);
    steps += r.steps, frames += r.frames, failed += r.status != "ok";
  }
  fmt::print("{} programs, {} steps, {} frames, {} failed\n", rows.size(), steps, frames, failed);
}

nlohmann::json rows_json(const std::vector<SurveyRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows)
    out.push_back({{"program", r.program}, {"grid", r.grid}, {"steps", r.steps}, {"frames", r.frames},
                   {"distinct_frames", r.distinct}, {"on_clauses", r.clauses}, {"on_clauses_covered", r.covered},
                   {"time_ms", r.ms}, {"status", r.status}, {"error", r.error}});
  return out;
}

int run_survey(const SurveyOptions& o) {
  if (!std::filesystem::is_directory(o.dir)) {
    std::cerr << "autumn survey: '" << o.dir << "' is not a directory\n";
    return kExitFailed;
  }
  auto files = program_files(o.dir);
  if (files.empty()) {
    std::cerr << "autumn survey: no .au or .sexp programs in '" << o.dir << "'\n";
    return kExitFailed;
  }
  std::vector<SurveyRow> rows;
  Progress progress("survey", files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    progress.item(i, files[i].stem().string());
    rows.push_back(survey_program(o, files[i]));
    if (!rows.back().error.empty()) std::cerr << "  " << rows.back().error << "\n";
  }
  progress.done();
  if (o.json) std::cout << nlohmann::json({{"programs", rows_json(rows)}, {"steps_per_program", o.steps}}).dump() << "\n";
  else print_table(rows);
  for (const auto& r : rows)
    if (r.status != "ok") return kExitFailed;
  return kExitOk;
}

}  // namespace

Subcommand add_survey_command(CLI::App& app) {
  auto o = std::make_shared<SurveyOptions>();
  CLI::App* cmd = app.add_subcommand("survey", "Run every program in a folder under a random policy and tabulate");
  register_survey(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [o] { return run_survey(*o); }};
}

}  // namespace autumn::cli
