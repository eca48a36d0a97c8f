#include "harness/trace_check.hpp"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "runtime/frame.hpp"
#include "runtime/limits.hpp"

namespace autumn {
namespace {

std::vector<std::string> split_words(const std::string& row) {
  std::vector<std::string> out;
  std::istringstream in(row);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// Describes the first difference between an expected frame and the environment's.
std::string first_difference(const std::vector<std::string>& expected, const Frame& got, const Palette& pal) {
  if (static_cast<int>(expected.size()) != got.size)
    return "grid size differs: expected " + std::to_string(expected.size()) + ", got " + std::to_string(got.size);
  for (int y = 0; y < got.size; ++y) {
    std::vector<std::string> want = split_words(expected[y]);
    if (static_cast<int>(want.size()) != got.size) return "row " + std::to_string(y) + " has the wrong width";
    for (int x = 0; x < got.size; ++x) {
      const std::string& have = pal.name(got.at(x, y));
      if (have != want[x])
        return "first differing cell (x=" + std::to_string(x) + ", y=" + std::to_string(y) + "): expected " +
               want[x] + ", got " + have;
    }
  }
  return "";
}

}  // namespace

std::string json_error_text(const std::exception& e) {
  std::string s = e.what();
  if (s.rfind("[json.exception.", 0) == 0)
    if (size_t close = s.find("] "); close != std::string::npos) s = s.substr(close + 2);
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

TraceFile load_trace_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open trace file");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not valid JSON (" + json_error_text(e) + ")");
  }
  return trace_file_from_json(j, path);
}

TraceFile trace_file_from_json(const nlohmann::json& j, const std::string& path) {
  TraceFile f;
  try {
    f.program = j.value("program", "");
    if (j.contains("grid_size")) {  // absent: not stated (0); present: a paintable size
      const auto& g = j["grid_size"];
      if (!g.is_number_integer() || g.get<int64_t>() < limits::kMinGridSize || g.get<int64_t>() > limits::kMaxGridSize)
        throw std::runtime_error("\"grid_size\" must be an integer from " + std::to_string(limits::kMinGridSize) +
                                 " to " + std::to_string(limits::kMaxGridSize) + ", got " + g.dump());
      f.grid_size = g.get<int>();
    }
    f.background = j.value("background", "");
    if (j.contains("triggering_condition") && j["triggering_condition"].is_string())
      f.triggering_condition = j["triggering_condition"].get<std::string>();
    if (!j.contains("traces") || !j["traces"].is_array()) throw std::runtime_error("missing \"traces\" array");
    if (j["traces"].empty()) throw std::runtime_error("the \"traces\" array is empty: nothing to check");
    for (const auto& t : j["traces"]) {
      Trace tr;
      // get<uint64_t>() would wrap a negative seed silently.
      if (!t.at("seed").is_number_unsigned())
        throw std::runtime_error("trace " + std::to_string(f.traces.size()) + ": \"seed\" must be a non-negative integer");
      tr.seed = t.at("seed").get<uint64_t>();
      for (const auto& a : t.at("actions")) {
        std::string why;
        auto act = parse_action(a.get<std::string>(), &why);
        if (!act) throw std::runtime_error("trace " + std::to_string(f.traces.size()) + ": " + why);
        tr.actions.push_back(*act);
      }
      for (const auto& fr : t.at("frames")) tr.frames.push_back(fr.get<std::vector<std::string>>());
      if (t.contains("trigger"))
        for (const auto& b : t["trigger"]) tr.trigger.push_back(b.get<bool>());
      if (tr.frames.size() != tr.actions.size() + 1)
        throw std::runtime_error("trace " + std::to_string(f.traces.size()) + " has " +
                                 std::to_string(tr.frames.size()) + " frames for " +
                                 std::to_string(tr.actions.size()) + " actions (expected actions+1)");
      f.traces.push_back(std::move(tr));
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": malformed trace file (" + json_error_text(e) + ")");
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return f;
}

CheckResult check_traces(Environment& env, const TraceFile& file) {
  CheckResult r;
  for (size_t ti = 0; ti < file.traces.size(); ++ti) {
    const Trace& t = file.traces[ti];
    ++r.traces;
    r.frames_total += t.frames.size();
    r.triggers_total += t.trigger.size();
    std::string where = "trace " + std::to_string(ti) + " (seed " + std::to_string(t.seed) + ")";
    if (!env.reset(t.seed)) {
      r.mismatches.push_back(where + ", start: the environment failed: " + env.error());
      continue;
    }
    std::string diff = first_difference(t.frames[0], env.frame(), env.palette());
    auto note_frames = [&](const std::string& at, const std::vector<std::string>& expected) {
      if (!r.first_frame_mismatch) r.first_frame_mismatch = FrameMismatch{at, expected, frame_rows(env.frame(), env.palette())};
    };
    if (!diff.empty()) {
      note_frames(where + ", frame 0 (after start)", t.frames[0]);
      r.mismatches.push_back(where + ", frame 0 (after start): " + diff);
      continue;
    }
    ++r.frames_matched;
    for (size_t i = 0; i < t.actions.size(); ++i) {
      std::string at = where + ", step " + std::to_string(i + 1) + " (" + format_action(t.actions[i]) + ")";
      if (!env.step(t.actions[i])) {
        r.mismatches.push_back(at + ": the environment failed: " + env.error());
        break;
      }
      diff = first_difference(t.frames[i + 1], env.frame(), env.palette());
      if (!diff.empty()) {
        note_frames(at, t.frames[i + 1]);
        r.mismatches.push_back(at + ": " + diff);
        break;
      }
      ++r.frames_matched;
      if (i < t.trigger.size()) {
        if (env.triggered() != t.trigger[i]) {
          r.mismatches.push_back(at + ": trigger expected " + (t.trigger[i] ? "true" : "false") + ", got " +
                                 (env.triggered() ? "true" : "false"));
          break;
        }
        ++r.triggers_matched;
      }
    }
  }
  return r;
}

}  // namespace autumn
