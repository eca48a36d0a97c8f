// fuzz_task — libFuzzer target: the task loader and the trace loader.
//
// The input is written to a file (the loaders read files, and their messages
// name them) and loaded as an AutumnBench task and as a golden-trace file. Bad
// input must be a TaskError / std::runtime_error with a one-line message naming
// the file; any other exception escaping is a crash here, as it would be in
// the CLI.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "harness/agent/task_file.hpp"
#include "harness/trace_check.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path& scratch() {
  static const fs::path p = fs::temp_directory_path() / ("autumn_fuzz_task_" + std::to_string(getpid()) + ".json");
  return p;
}

void check_message(const std::string& msg, const std::string& name) {
  if (msg.find('\n') != std::string::npos || msg.find(name) == std::string::npos) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(scratch(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    (void)autumn::agent::load_task(scratch());
  } catch (const autumn::agent::TaskError& e) {
    check_message(e.what(), scratch().filename().string());
  }
  (void)autumn::agent::meant_as_task(scratch());
  try {
    (void)autumn::load_trace_file(scratch().string());
  } catch (const std::runtime_error& e) {
    check_message(e.what(), scratch().string());
  }
  return 0;
}
