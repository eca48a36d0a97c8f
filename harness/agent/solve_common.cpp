#include "harness/agent/solve_common.hpp"

#include <algorithm>
#include <stdexcept>

#include "harness/agent/click_model.hpp"
#include "harness/module_cache.hpp"

namespace autumn::agent {

const std::vector<std::string>& search_names() {
  static const std::vector<std::string> names = {"auto", "bfs", "best-first", "beam", "fill", "local", "skeleton", "paper"};
  return names;
}

const std::vector<std::string>& policy_names() {
  static const std::vector<std::string> names = {"novelty", "random"};
  return names;
}

const std::vector<std::string>& cost_names() {
  static const std::vector<std::string> names = {"steps", "moves"};
  return names;
}

const std::vector<std::string>& protocol_names() {
  static const std::vector<std::string> names = {"default", "paper"};
  return names;
}

std::string unknown_name(const std::string& option, const std::string& value, const std::vector<std::string>& names) {
  if (std::find(names.begin(), names.end(), value) != names.end()) return "";
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return "unknown " + option + " '" + value + "' (" + list + ")";
}

SolveOptions protocol_options(const std::string& protocol) {
  if (std::string why = unknown_name("protocol", protocol, protocol_names()); !why.empty())
    throw std::invalid_argument(why);
  SolveOptions o;
  o.engine = "compiled";
  o.time_limit = 120;
  if (protocol == "paper") {
    o.rollouts = 10000;
    o.seed_inversion = false;
    o.policy = "random";
    o.search = "paper";
    o.depth = 10;
  }
  return o;
}

nlohmann::json solve_options_json(const SolveOptions& o) {
  return {{"engine", o.engine},       {"rollouts", o.rollouts}, {"seed_inversion", o.seed_inversion},
          {"policy", o.policy},       {"search", o.search},     {"depth", o.depth},
          {"seed", o.seed},           {"max_steps", o.max_steps}, {"nodes", o.nodes},
          {"cost", o.cost},           {"max_plan", o.max_plan}, {"keep_states", o.keep_states},
          {"time_limit", o.time_limit}};
}

SolveOptions solve_options_from_json(const nlohmann::json& j, SolveOptions o) {
  o.engine = j.value("engine", o.engine);
  o.rollouts = j.value("rollouts", o.rollouts);
  o.seed = j.value("seed", o.seed);
  o.seed_inversion = j.value("seed_inversion", o.seed_inversion);
  o.max_steps = j.value("max_steps", o.max_steps);
  o.policy = j.value("policy", o.policy);
  o.depth = j.value("depth", o.depth);
  o.nodes = j.value("nodes", o.nodes);
  o.search = j.value("search", o.search);
  o.cost = j.value("cost", o.cost);
  o.max_plan = j.value("max_plan", o.max_plan);
  o.keep_states = j.value("keep_states", o.keep_states);
  o.time_limit = j.value("time_limit", o.time_limit);
  auto folder = [&](const char* key) -> std::optional<std::string> {
    if (!j.contains(key) || !j.at(key).is_string() || j.at(key).get<std::string>().empty()) return std::nullopt;
    return j.at(key).get<std::string>();
  };
  if (auto p = folder("programs")) o.programs_dir = *p;
  if (auto a = folder("answers")) o.answers = *a;
  return o;
}

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
