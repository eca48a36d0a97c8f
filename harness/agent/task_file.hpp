// task_file — AutumnBench task files, their colour table, and frame <-> grid glue.
//
// A task file is one JSON object with a "type" of masked_frame_prediction,
// change_detection or planning (see ../shared/tasks/README.md). Grids are row-major
// grid[y][x] of integer colour ids from the benchmark's color_dict.yaml; id 0
// (transparent) marks a masked cell. load_task validates everything that can be
// checked without running the program (shapes, colour ids, actions, choice sizes)
// and throws TaskError with a one-line "FILE: what" message; checks that need the
// program (grid size against GRID_SIZE, unknown program names) happen when a
// solver loads it, with the same error type.
//
// Frames from an Environment carry palette ids private to that environment;
// task_frame() turns them into colour-table ids by exact colour name. Names that
// are not in the table get ids >= table_size(), interned on first sight (thread
// safe), so they never match a task grid but two frames still compare correctly.
//
// Extensions to the released format (all optional): "answer" (index of the
// correct MFP choice; "correct_idx" is accepted too), "seed" (the environment's
// interpreter seed; default 0, the benchmark's), "reference_plan" (planning: the
// action list that generated the goal). Tasks made by `autumn make-task` carry
// none of them: like the benchmark, they keep what the solver must not see in an
// answers file beside the prompts (Answers below), which only scoring reads.
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "runtime/action.hpp"
#include "runtime/environment.hpp"

namespace autumn::agent {

namespace fs = std::filesystem;

// A task error is one line, whatever the file holds: the CLI prints it as its
// one-line reason. Text taken from the file (a task type, an action name) is
// shown through runtime/diagnostic's shown(), with a newline as "\n".
std::string one_line(std::string_view message);
struct TaskError : std::runtime_error {
  explicit TaskError(const std::string& message) : std::runtime_error(one_line(message)) {}
};

class ColourTable {
 public:
  ColourTable();  // the AutumnBench color_dict.yaml (ids 0..39), built in
  // "ID: name" lines; '#' comments and blank lines are skipped, names are trimmed.
  static ColourTable from_yaml(std::string_view text, const std::string& where);
  static ColourTable load(const fs::path& yaml);
  // color_dict.yaml in the task file's folder or the folder above it (the
  // AutumnBench layout keeps it next to prompts/), else the built-in table.
  static ColourTable for_task(const fs::path& task_file);

  int table_size() const;                   // ids 0..table_size()-1 belong to the table
  bool in_table(int id) const;              // a named table id
  int find(std::string_view name) const;    // table id by exact name, -1 if absent
  std::string name(int id) const;           // table or interned name ("?" if unknown)
  int frame_id(std::string_view name) const;  // table id, or an interned id >= table_size()
  int add(const std::string& name);         // appends a name to the table, returns its id
  std::string to_yaml() const;
  const fs::path& source() const;           // empty for the built-in table

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

using TaskFrame = std::vector<int16_t>;  // colour ids (ColourTable::frame_id), row-major
TaskFrame task_frame(const Frame& f, const Palette& p, const ColourTable& colours);
// Palette id -> colour-table id (ColourTable::frame_id), what task_frame maps through.
std::vector<int16_t> colour_ids(const Palette& p, const ColourTable& colours);
uint64_t frame_digest(const TaskFrame& f);  // FNV-1a over the ids

// task_frame for the hot loops (rollouts, search): the palette-id map is kept and
// rebuilt only when the palette's contents change (Palette::version; compiled
// copies share one palette), and frames are written into a reused buffer. One
// instance per thread, always used with the same colour table.
class FrameColours {
 public:
  const std::vector<int16_t>& ids(const Palette& p, const ColourTable& colours) {
    if (p.version() != version_) {
      version_ = p.version();
      ids_ = colour_ids(p, colours);
    }
    return ids_;
  }
  // out = task_frame(f, p, colours), without allocating once out has grown.
  void map(const Frame& f, const Palette& p, const ColourTable& colours, TaskFrame& out) {
    const std::vector<int16_t>& m = ids(p, colours);
    out.resize(f.cells.size());
    for (size_t i = 0; i < f.cells.size(); ++i) out[i] = m[f.cells[i]];
  }

 private:
  uint64_t version_ = 0;  // Palette versions start at 1
  std::vector<int16_t> ids_;
};

struct Grid {
  int width = 0, height = 0;
  std::vector<int16_t> cells;  // row-major
  int16_t at(int x, int y) const { return cells[static_cast<size_t>(y) * width + x]; }
  bool operator==(const Grid&) const = default;
  nlohmann::json to_json() const;
};

struct Rect {
  int x = 0, y = 0, w = 0, h = 0;
};

// Cells of a full frame inside `r` (frame is size x size).
Grid crop(const TaskFrame& frame, int size, const Rect& r);
// True when every unmasked (non-zero) cell of `obs` equals the frame's.
bool consistent(const TaskFrame& frame, int size, const Grid& obs);

enum class TaskType { MaskedFramePrediction, ChangeDetection, Planning };
const char* type_name(TaskType t);   // the JSON spelling
const char* short_name(TaskType t);  // mfp, cd, planning

struct Observation {
  std::optional<Action> action;  // absent for the initial frame
  Grid grid;
};

struct Task {
  fs::path file;
  std::string name;  // file stem
  TaskType type = TaskType::MaskedFramePrediction;
  std::string program, wrong_program;
  uint64_t env_seed = 0;
  ColourTable colours;
  // masked_frame_prediction
  std::vector<Observation> observations;
  std::vector<Grid> choices;
  Rect masked;  // bounding box of the masked cells of the final observation
  std::optional<int> answer;
  // planning
  Grid goal, mask;
  std::vector<Action> reference_plan;
};

Task parse_task(const nlohmann::json& j, const fs::path& file, ColourTable colours);
Task load_task(const fs::path& file);  // colours from ColourTable::for_task
// A .json file that is a task or was meant as one: a JSON object with a
// "type", or a file that is not valid JSON (eval reports those in their row
// rather than skip them). Answers files and colour tables have no "type".
bool meant_as_task(const fs::path& file);

nlohmann::json action_to_json(const Action& a);
Action action_from_json(const nlohmann::json& j, const std::string& where);

// The folder a task's program names resolve in: <task folder>/../programs.
fs::path default_programs_dir(const fs::path& task_file);
// NAME.sexp or NAME.au in `dir`; NAME_wrong also as NAME_change_detection_wrong_program.
fs::path resolve_program(const fs::path& dir, const std::string& name);
// Loads a program; a CompileError becomes a TaskError carrying its formatted text.
std::shared_ptr<const Program> load_program_checked(const fs::path& path,
                                                    const std::optional<std::string>& trigger = std::nullopt);
// The same for program text held in memory; `name` is what messages call it.
std::shared_ptr<const Program> load_program_checked_text(const std::string& text, const std::string& name,
                                                         const std::optional<std::string>& trigger = std::nullopt);
std::unique_ptr<Environment> make_env_checked(const std::string& engine, std::shared_ptr<const Program> program);

// The "condition" of a change-detection answers file.
std::string load_trigger_condition(const fs::path& answers_file);

// An answers file: what a task's generator knows and its solver must never read.
// Every field is optional; the benchmark's own (ice_change_detection.json) has
// only "condition".
struct Answers {
  fs::path file;
  std::optional<uint64_t> seed;         // the environment's interpreter seed
  std::optional<int> correct_idx;       // mfp: the index of the true choice
  std::vector<Action> reference_plan;   // planning: the actions that made the goal
  std::optional<std::string> condition; // cd: the trigger condition of the change
  std::optional<int> t_star;            // cd: the first state on which it holds
};
Answers load_answers(const fs::path& file);
// The answers of a task, first found of: <task folder>/../answers/<task name>.json,
// <task folder>/../answers/<program>_change_detection.json (change detection, the
// benchmark's name), <task folder>/<task name>.answers.json.
std::optional<fs::path> find_answers(const Task& task);

}  // namespace autumn::agent
