// autumn play — a program or task in the browser. The server and its page are the
// Python package's (python/autumnc/play.py, docs/play.md): this subcommand only
// replaces itself (exec) with `PYTHON -m autumnc.play ARGS...`, PYTHON being the
// interpreter the package was built for and PYTHONPATH gaining the build tree's
// python/ folder (both fixed by CMake, AUTUMN_PLAY_PYTHON / AUTUMN_PLAY_PYTHONPATH).
// Every argument after `play`, --help included, goes to the Python program, so
// the two spellings are one program with one --help and one set of messages.
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "harness/cli/commands.hpp"

#ifndef AUTUMN_PLAY_PYTHON
#define AUTUMN_PLAY_PYTHON "python3"
#endif
#ifndef AUTUMN_PLAY_PYTHONPATH
#define AUTUMN_PLAY_PYTHONPATH ""
#endif

namespace autumn::cli {
namespace {

void register_play(CLI::App* cmd) {
  cmd->prefix_command();  // the rest of the line, options too, is the Python program's
  cmd->set_help_flag();   // `autumn play --help` is answered by autumnc.play
  cmd->fallthrough(false);  // and so are options the top-level command would otherwise try
  cmd->footer("Runs " AUTUMN_PLAY_PYTHON " -m autumnc.play with the arguments given; `autumn play --help` lists them.");
}

int run_play(CLI::App* cmd) {
  const std::vector<std::string> args = cmd->remaining();
  std::string path = AUTUMN_PLAY_PYTHONPATH;
  if (const char* old = std::getenv("PYTHONPATH"); old && *old) path = path.empty() ? old : path + ":" + old;
  if (!path.empty()) setenv("PYTHONPATH", path.c_str(), 1);
  setenv("AUTUMN_PLAY_PROG", "autumn play", 1);
  std::vector<std::string> words = {AUTUMN_PLAY_PYTHON, "-m", "autumnc.play"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::cout.flush();
  execvp(argv[0], argv.data());
  std::cerr << "autumn play: cannot run " << AUTUMN_PLAY_PYTHON << ": " << std::strerror(errno)
            << " (the browser front end is the Python package autumnc; docs/play.md)\n";
  return kExitFailed;
}

}  // namespace

Subcommand add_play_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("play", "Play a program or task in the browser (a local web server; docs/play.md)");
  register_play(cmd);
  return {cmd, [cmd] { return run_play(cmd); }};
}

}  // namespace autumn::cli
