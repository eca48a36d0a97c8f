// test_support — where the tests find their data.
//
// The conformance corpus lives outside the repo, in ../shared next to the
// checkout; AUTUMN_SHARED_DIR overrides that. Tests that need it skip loudly
// when it is absent.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/limits.hpp"

namespace autumn::testing {

inline std::filesystem::path source_dir() { return AUTUMN_SOURCE_DIR; }

inline std::filesystem::path shared_dir() {
  if (const char* d = std::getenv("AUTUMN_SHARED_DIR")) return d;
  return source_dir() / ".." / "shared";
}

// Scratch folders: per process (ctest runs test processes side by side), under
// <tmp>/autumn_tests_<pid>, all removed when the test program ends.
inline std::filesystem::path scratch_root() {
  return std::filesystem::temp_directory_path() / ("autumn_tests_" + std::to_string(getpid()));
}
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(scratch_root(), ec);
  }
};
inline ::testing::Environment* const scratch_cleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

// A fresh, empty folder <suite>/<name> under scratch_root().
inline std::filesystem::path scratch_dir(const std::string& suite, const std::string& name) {
  const std::filesystem::path d = scratch_root() / suite / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

// Files in `dir` with extension `ext`, sorted by name.
inline std::vector<std::filesystem::path> files_in(const std::filesystem::path& dir, const std::string& ext) {
  std::vector<std::filesystem::path> out;
  if (!std::filesystem::is_directory(dir)) return out;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ext) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// The value of a "; key: value" header line, or "" when absent.
inline std::string header(const std::string& text, const std::string& key) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::string prefix = "; " + key + ":";
    if (line.rfind(prefix, 0) == 0) {
      std::string v = line.substr(prefix.size());
      size_t b = v.find_first_not_of(' ');
      return b == std::string::npos ? "" : v.substr(b);
    }
  }
  return "";
}

// The limits a program's random-policy episodes run under (the differential,
// copy and snapshot suites): its "; random-limits:" header, in the --limits
// syntax, or the defaults. For a program whose every step is costly only
// because it runs into a limit: tests/lowering/construct_own_class.au recurses
// to the call-depth limit at every step, a third of a second at the default
// 10,000 and a hundredth at 200, with the same frames. Its scripted actions
// (LoweringFile) still run at the defaults. A malformed header fails the test.
// The first form takes the program's text when the caller already holds it.
inline Limits random_limits(const std::string& text, const std::filesystem::path& program) {
  std::string why;
  const std::optional<Limits> l = limits::parse(header(text, "random-limits"), &why);
  if (!l) ADD_FAILURE() << program.string() << ": random-limits: " << why;
  return l.value_or(Limits{});
}
inline Limits random_limits(const std::filesystem::path& program) { return random_limits(read_text(program), program); }

// Names of the golden trace files (without .json), or the one name
// "MISSING_SHARED_CORPUS" so that suites can report themselves skipped.
inline std::vector<std::string> trace_names() {
  std::vector<std::string> names;
  for (const auto& p : files_in(shared_dir() / "conformance/traces", ".json")) names.push_back(p.stem().string());
  if (names.empty()) names.push_back("MISSING_SHARED_CORPUS");
  return names;
}

// The engines the two-engine suites check: both, unless AUTUMN_TEST_ENGINES
// names some (comma-separated; scripts/sanitize.sh sets "interp").
inline std::vector<std::string> test_engines() {
  std::vector<std::string> out;
  const char* env = std::getenv("AUTUMN_TEST_ENGINES");
  std::stringstream in(env && *env ? env : "interp,compiled");
  for (std::string e; std::getline(in, e, ',');) out.push_back(e);
  return out;
}

// How many episodes of each golden trace file the interpreter's conformance
// suite replays: all of them (eight per file), unless AUTUMN_TRACE_EPISODES=K
// asks for the first K. scripts/sanitize.sh sets 2: under the sanitizers every
// program runs, two seeds each, while the release run replays all eight on both
// engines. A value that is not a positive number is an error, not "all".
inline size_t trace_episodes(size_t available) {
  const char* env = std::getenv("AUTUMN_TRACE_EPISODES");
  if (!env || !*env) return available;
  char* end = nullptr;
  const long k = std::strtol(env, &end, 10);
  if (*end != 0 || k < 1) throw std::invalid_argument(std::string("AUTUMN_TRACE_EPISODES='") + env + "' is not a positive number");
  return std::min(available, static_cast<size_t>(k));
}

struct CliResult {
  int status;
  std::string out;  // stdout and stderr
};

// Runs the autumn binary built with the tests (or `binary`); `out` holds stdout and
// stderr, or with stdout_only stdout alone (for JSON output while notes go to stderr).
// `env`: variable assignments for the command ("AUTUMN_CACHE_DIR=/x").
inline CliResult run_cli(const std::string& args, bool stdout_only = false, const std::string& env = "",
                         const std::string& binary = AUTUMN_CLI) {
  std::string cmd = (env.empty() ? "" : env + " ") + binary + " " + args + (stdout_only ? " 2>/dev/null" : " 2>&1");
  CliResult r{0, ""};
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) r.out.append(buf.data(), n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace autumn::testing
