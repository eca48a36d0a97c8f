// output — the write side of the tools: every file and stream they produce goes
// through here, so a full disk or a closed pipe is an error with the path and the
// reason, never an empty or half file left as if the command had succeeded.
//
// A file is written whole or not at all: on any failure the partial file is
// removed. Standard output is checked once, at the end of main (finish_stdout):
// the C library reports a failed write only when the buffer is flushed.
#pragma once
#include <filesystem>
#include <string>

namespace autumn {

// Writes `text` to `path` (created or truncated). "" on success, else
// "cannot write PATH: REASON" (the OS's reason: "No space left on device").
std::string write_file(const std::filesystem::path& path, const std::string& text);

// Flushes standard output and reports a failure on stderr as
// "TOOL: cannot write the standard output: REASON". Returns `status`, or 1 when
// the output failed and `status` was 0: call it as `return finish_stdout("autumn", rc);`.
int finish_stdout(const char* tool, int status);

}  // namespace autumn
