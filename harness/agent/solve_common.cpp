#include "harness/agent/solve_common.hpp"

#include "harness/agent/click_model.hpp"
#include "harness/module_cache.hpp"

namespace autumn::agent {

fs::path task_program_path(const Task& task, const SolveOptions& opts, const std::string& name) {
  fs::path dir = opts.programs_dir.empty() ? default_programs_dir(task.file) : opts.programs_dir;
  return resolve_program(dir, name);
}

Action random_action(std::mt19937_64& rng, int grid, int arrows) {
  int r = static_cast<int>(rng() % 10);
  if (r < 2) return Action::noop();
  if (r < 2 + arrows) return Action{static_cast<Action::Kind>(1 + rng() % 4)};
  return Action::click(static_cast<int>(rng() % grid), static_cast<int>(rng() % grid));
}

std::vector<std::shared_ptr<const Program>> task_module_programs(const Task& task, const SolveOptions& o) {
  std::vector<std::pair<std::string, std::optional<std::string>>> names = {{task.program, std::nullopt}};
  if (task.type == TaskType::ChangeDetection)
    names.emplace_back(task.wrong_program,
                       o.answers ? std::optional<std::string>(load_trigger_condition(*o.answers)) : std::nullopt);
  std::vector<std::shared_ptr<const Program>> out;
  for (const auto& [name, trigger] : names) {
    const fs::path path = task_program_path(task, o, name);
    const auto program = load_program_checked(path, trigger);
    out.push_back(program);
    // The planner's search model, when it may use one: its module too.
    if (task.type != TaskType::Planning || trigger) continue;
    std::string not_used;
    if (auto text = click_reset_model_text(*program, analyse_inputs(*program), &not_used))
      out.push_back(load_program_checked_text(*text, path.string() + " (click-reset model)"));
  }
  return out;
}

double prepare_modules(const Task& task, const SolveOptions& o) {
  if (o.engine != "compiled") return 0;
  double total = 0;
  for (const auto& program : task_module_programs(task, o)) {
    double seconds = 0;
    std::string why;  // a module that cannot be built fails the solver, which says why
    prepare_compiled_module(program, &seconds, &why);
    total += seconds;
  }
  return total;
}

}  // namespace autumn::agent
