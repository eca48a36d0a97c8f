#include "harness/agent/solve_common.hpp"

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

}  // namespace autumn::agent
