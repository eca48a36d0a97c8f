// program_files — which programs a command line names, and small figures helpers
// shared by the commands that run many programs (survey, bench, difftest,
// bench-agent).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace autumn {

// The .au and .sexp files of a folder, sorted by name.
std::vector<std::filesystem::path> program_files(const std::filesystem::path& dir);
// Programs named on a command line: files, or folders of .au/.sexp files.
std::vector<std::filesystem::path> expand_programs(const std::vector<std::string>& args);
// The median of `v` (0 when empty).
double median(std::vector<double> v);

}  // namespace autumn
