#include "harness/engine.hpp"

#include "compiler/interpret/interpreted_env.hpp"
#include "harness/module_cache.hpp"

namespace autumn {

const std::vector<std::string>& engine_names() {
  static const std::vector<std::string> names = {"interp", "compiled"};
  return names;
}

std::unique_ptr<Environment> make_environment(const std::string& engine, std::shared_ptr<const Program> program,
                                              std::string* why) {
  if (engine == "interp") return std::make_unique<InterpretedEnvironment>(std::move(program));
  if (engine == "compiled") return make_compiled_environment(std::move(program), why);
  if (why) *why = "unknown engine '" + engine + "'";
  return nullptr;
}

std::unique_ptr<Environment> make_episode_environment(const std::string& engine, std::shared_ptr<const Program> program,
                                                      std::string* why) {
  if (engine == "compiled") return make_compiled_episode_environment(std::move(program), why);
  return make_environment(engine, std::move(program), why);
}

}  // namespace autumn
