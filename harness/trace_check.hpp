// trace_check — replay golden traces against an environment, frame by frame.
//
// Trace files are the conformance corpus format (../shared/conformance/README.md):
//   {"program", "grid_size", "background", ["triggering_condition"],
//    "traces": [{"seed", "actions": [...], "frames": [F0, F1, ...], ["trigger": [...]]}]}
// Frame F0 follows reset; F(i+1) follows action i. trigger[i] pairs with F(i+1).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "runtime/action.hpp"
#include "runtime/environment.hpp"

namespace autumn {

struct Trace {
  uint64_t seed = 0;
  std::vector<Action> actions;
  std::vector<std::vector<std::string>> frames;  // rows
  std::vector<bool> trigger;                     // empty when absent
};

struct TraceFile {
  std::string program;
  int grid_size = 0;
  std::string background;
  std::optional<std::string> triggering_condition;
  std::vector<Trace> traces;
};

// Throws std::runtime_error with a one-line reason for unreadable or malformed files.
// A JSON library exception's message without its "[json.exception.x.N] " tag,
// on one line, for "file: ..." messages.
std::string json_error_text(const std::exception& e);

TraceFile load_trace_file(const std::string& path);
// The same checks on a file already parsed (`path` names it in messages).
TraceFile trace_file_from_json(const nlohmann::json& j, const std::string& path);

// The first frame that differed: what the trace expected and what the engine drew.
struct FrameMismatch {
  std::string where;  // "trace 0 (seed 3), step 5 (left)"
  std::vector<std::string> expected, got;  // rows
};

struct CheckResult {
  size_t frames_total = 0;
  size_t frames_matched = 0;
  size_t triggers_total = 0;
  size_t triggers_matched = 0;
  size_t traces = 0;
  std::vector<std::string> mismatches;  // one readable report per failing trace
  std::optional<FrameMismatch> first_frame_mismatch;
  bool ok() const { return frames_matched == frames_total && triggers_matched == triggers_total; }
};

// Replays every trace on a fresh episode of `env`. A trace stops at its first
// mismatch; its remaining frames count as unmatched.
CheckResult check_traces(Environment& env, const TraceFile& file);

}  // namespace autumn
