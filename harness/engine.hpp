// engine — builds an Environment for a loaded program by engine name.
//
// Engines: "interp" (the reference-exact interpreter) and "compiled" (a module
// emitted by autumnc: built in, cached, or compiled on demand; module_cache.hpp). Every harness command takes
// --engine and goes through here, so a new engine is one entry.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "runtime/environment.hpp"

namespace autumn {

const std::vector<std::string>& engine_names();
// Null (with *why set) when the engine is unknown or cannot serve this program.
std::unique_ptr<Environment> make_environment(const std::string& engine, std::shared_ptr<const Program> program,
                                              std::string* why);
// For one episode driven step by step (run, render, survey): as
// make_environment, but the compiled engine does not make the caller wait for a
// module that is not built yet (module_cache.hpp: make_compiled_episode_environment).
std::unique_ptr<Environment> make_episode_environment(const std::string& engine, std::shared_ptr<const Program> program,
                                                      std::string* why);

}  // namespace autumn
