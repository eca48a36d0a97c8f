#include "harness/cli/cli_common.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <fstream>
#include <iostream>
#include <sstream>

#include "compiler/analyse/lint.hpp"
#include "harness/engine.hpp"

namespace autumn::cli {

bool& warnings_are_errors() {
  static bool on = false;
  return on;
}

std::shared_ptr<const Program> load_or_report(const std::string& path, const std::optional<std::string>& trigger,
                                              std::string* why) {
  try {
    auto p = load_program_file(path, trigger);
    for (const auto& w : p->warnings) std::cerr << w << "\n";
    if (warnings_are_errors() && !p->warnings.empty()) {
      const std::string e = warnings_as_errors(path, p->warnings.size());
      std::cerr << e << "\n";
      if (why) *why = e;
      return nullptr;
    }
    return p;
  } catch (const CompileError& e) {
    std::cerr << e.formatted() << "\n";
    if (why) *why = e.formatted();
    return nullptr;
  }
}

std::unique_ptr<Environment> make_env(const std::string& command, const std::string& engine,
                                      std::shared_ptr<const Program> program, FirstUse first_use) {
  std::string why;
  auto env = first_use == FirstUse::kWaitForModule ? make_environment(engine, std::move(program), &why)
                                                   : make_episode_environment(engine, std::move(program), &why);
  if (!env) std::cerr << "autumn " << command << ": " << why << "\n";
  else env->set_limits(episode_limits());
  return env;
}

namespace {
std::string& limits_spec() {
  static std::string spec;
  return spec;
}
Limits& limits_value() {
  static Limits limits;
  return limits;
}
}  // namespace

void add_limits_option(CLI::App* cmd) {
  const Limits d;
  cmd->add_option("--limits", limits_spec(),
                  fmt::format("Episode budget, KEY=N,...: call-depth (default {}), list-length ({}), objects ({}), "
                              "cells ({}), calls ({})",
                              d.call_depth, d.list_length, d.objects, d.cells, d.calls));
}

bool parse_limits_option() {
  if (limits_spec().empty()) return true;
  std::string why;
  auto parsed = limits::parse(limits_spec(), &why);
  if (!parsed) {
    std::cerr << "autumn: --limits: " << why << "\n";
    return false;
  }
  limits_value() = *parsed;
  return true;
}

const Limits& episode_limits() { return limits_value(); }

nlohmann::json episode_limits_json() {
  const Limits& l = limits_value();
  return {{"call_depth", l.call_depth}, {"list_length", l.list_length}, {"objects", l.objects}, {"cells", l.cells},
          {"calls", l.calls}};
}

namespace {

std::optional<std::string> read_action_file(const std::string& command, const std::string& file) {
  std::ifstream in(file);
  if (!in) {
    std::cerr << "autumn " << command << ": cannot open actions file '" << file << "'\n";
    return std::nullopt;
  }
  std::string text, line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    text += (text.empty() ? "" : ",") + line;
  }
  return text;
}

}  // namespace

std::optional<std::vector<Action>> read_actions(const std::string& command, const std::string& text,
                                                const std::string& file, int steps) {
  std::string action_text = text;
  if (!file.empty()) {
    auto t = read_action_file(command, file);
    if (!t) return std::nullopt;
    action_text = *t;
  }
  std::string why;
  auto actions = parse_action_list(action_text, &why);
  if (!actions) {
    std::cerr << "autumn " << command << ": " << why << "\n";
    return std::nullopt;
  }
  if (steps >= 0) {
    if (static_cast<size_t>(steps) < actions->size()) {
      std::cerr << "autumn " << command << ": " << actions->size() << " actions given but --steps is " << steps << "\n";
      return std::nullopt;
    }
    actions->resize(static_cast<size_t>(steps), Action::noop());
  }
  return actions;
}

void warn_clicks_outside(const std::string& command, const std::vector<Action>& actions, int grid) {
  for (size_t i = 0; i < actions.size(); ++i) {
    const Action& a = actions[i];
    if (a.kind == Action::Kind::Click && (a.x < 0 || a.y < 0 || a.x >= grid || a.y >= grid))
      std::cerr << "autumn " << command << ": warning: action " << i + 1 << " (" << format_action(a)
                << ") is outside the " << grid << "x" << grid << " grid (cells 0.." << grid - 1
                << "); the program still receives it\n";
  }
}

}  // namespace autumn::cli
