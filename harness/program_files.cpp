#include "harness/program_files.hpp"

#include <algorithm>

namespace autumn {

std::vector<std::filesystem::path> program_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".au" || e.path().extension() == ".sexp") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::filesystem::path> expand_programs(const std::vector<std::string>& args) {
  std::vector<std::filesystem::path> out;
  for (const auto& a : args) {
    if (std::filesystem::is_directory(a)) {
      for (const auto& f : program_files(a)) out.push_back(f);
    } else {
      out.push_back(a);
    }
  }
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

}  // namespace autumn
