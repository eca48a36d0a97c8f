// autumn survey — run every program of a folder under a reproducible random
// policy and tabulate what happened (text table or --json). --shard K/N runs a
// slice of the folder's programs (name order), --merge puts the slices' JSON
// back together (shard_options.hpp): every program's episode starts from
// --seed, whatever its place in the folder, so its row is the whole run's.
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "harness/cli/agent_options.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/number_options.hpp"
#include "harness/cli/shard_options.hpp"
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
  ShardOptions shards;  // --shard, --merge, --json-out
};

void register_survey(CLI::App* cmd, SurveyOptions& o) {
  CLI::Option* dir = cmd->add_option("DIR", o.dir, "Folder of .au/.sexp programs; not with --merge");
  cmd->add_option("--steps", o.steps, "Steps per program")->default_val(100)->check(int_count());
  cmd->add_option("--seed", o.seed, "Seed for the programs and the random policy")->default_val(0)->check(seed_number());
  cmd->add_option("--engine", o.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of the table");
  cmd->footer(
      "Columns: program (file name); grid (GRID_SIZE); steps (random actions taken before the end or an error); "
      "frames (frames drawn, the first included); distinct (different frames among them); clauses (on-clauses "
      "whose condition held at least once / on-clauses of the program); time ms (wall clock of the episode); "
      "status (ok, error: a runtime error, its message below the table, load error, engine error).");
  add_shard_options(cmd, o.shards, dir, "folder's programs", "name order");
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

SurveyRow row_from_json(const nlohmann::json& j) {
  SurveyRow r;
  r.program = j.at("program").get<std::string>();
  r.grid = j.at("grid").get<int>();
  r.steps = j.at("steps").get<size_t>();
  r.frames = j.at("frames").get<size_t>();
  r.distinct = j.at("distinct_frames").get<size_t>();
  r.clauses = j.at("on_clauses").get<int>();
  r.covered = j.at("on_clauses_covered").get<int>();
  r.ms = j.at("time_ms").get<double>();
  r.status = j.at("status").get<std::string>();
  r.error = j.at("error").get<std::string>();
  return r;
}

ShardFormat survey_shard_format() {
  return {"survey", "programs", "programs", {"steps_per_program", "seed", "engine", "program_set", "limits"}};
}

// Prints the report (the table, or JSON) and writes --json-out; 1 when a program failed.
int finish_survey(const SurveyOptions& o, const nlohmann::json& report, const std::vector<SurveyRow>& rows) {
  if (o.json) std::cout << report.dump() << "\n";
  else print_table(rows);
  if (std::string why = write_json_out(o.shards, report); !why.empty()) return command_failed("survey", why);
  for (const auto& r : rows)
    if (r.status != "ok") return kExitFailed;
  return kExitOk;
}

int run_survey_merge(const SurveyOptions& o) {
  const MergedShards m = merge_shard_files(o.shards, survey_shard_format());
  std::vector<SurveyRow> rows;
  try {
    for (const auto& p : m.rows) rows.push_back(row_from_json(p));
  } catch (const nlohmann::json::exception& e) {
    return command_failed("survey", std::string("a shard's rows are not survey's: ") + e.what());
  }
  for (const auto& r : rows)  // as the run prints them
    if (!r.error.empty()) std::cerr << "  " << r.error << "\n";
  nlohmann::json report = m.settings;
  report["programs"] = m.rows;
  return finish_survey(o, report, rows);
}

int run_survey_folder(const SurveyOptions& o) {
  if (!std::filesystem::is_directory(o.dir)) {
    std::cerr << "autumn survey: '" << o.dir << "' is not a directory\n";
    return kExitFailed;
  }
  const auto all = program_files(o.dir);
  if (all.empty()) {
    std::cerr << "autumn survey: no .au or .sexp programs in '" << o.dir << "'\n";
    return kExitFailed;
  }
  const Shard shard = chosen_shard(o.shards);
  const auto files = select_shard(all, shard);
  std::vector<SurveyRow> rows;
  Progress progress("survey", files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    progress.item(i, files[i].stem().string());
    rows.push_back(survey_program(o, files[i]));
    if (!rows.back().error.empty()) std::cerr << "  " << rows.back().error << "\n";
  }
  progress.done();
  nlohmann::json report = {{"programs", rows_json(rows)},
                           {"steps_per_program", o.steps},
                           {"seed", o.seed},
                           {"engine", o.engine},
                           {"program_set", {o.dir}},
                           {"limits", episode_limits_json()}};
  if (!o.shards.shard.empty()) report["shard"] = shard_json(shard, "programs", all.size());
  return finish_survey(o, report, rows);
}

int run_survey(const CLI::App* cmd, const SurveyOptions& o) {
  if (int status = check_shard_options("survey", cmd, o.shards, !o.dir.empty())) return status;
  try {
    return o.shards.merging() ? run_survey_merge(o) : run_survey_folder(o);
  } catch (const std::exception& e) {
    return command_failed("survey", e.what());
  }
}

}  // namespace

Subcommand add_survey_command(CLI::App& app) {
  auto o = std::make_shared<SurveyOptions>();
  CLI::App* cmd = app.add_subcommand("survey", "Run every program in a folder under a random policy and tabulate");
  register_survey(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [cmd, o] { return run_survey(cmd, *o); }};
}

}  // namespace autumn::cli
