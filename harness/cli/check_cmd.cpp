// autumn check — replay golden traces and compare every frame and trigger value;
// --diff-png draws the first mismatching frame as expected | got | difference.
#include <fmt/core.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "harness/cli/commands.hpp"
#include "harness/engine.hpp"
#include "harness/render_images.hpp"
#include "harness/trace_check.hpp"

namespace autumn::cli {
namespace {

struct CheckOptions {
  std::string program;
  std::string traces;
  std::string engine = "interp";
  bool quiet = false;
  bool json = false;
  std::string diff_png;
  int scale = 16;
};

void register_check(CLI::App* cmd, CheckOptions& o) {
  cmd->add_option("PROGRAM", o.program, "Autumn program")->required()->check(CLI::ExistingFile);
  cmd->add_option("TRACES", o.traces, "Trace file (JSON)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--engine", o.engine, "Execution engine")->check(CLI::IsMember(engine_names()))->default_val("interp");
  cmd->add_flag("--quiet", o.quiet, "Only print the summary lines");
  cmd->add_flag("--json", o.json, "Print one JSON object instead of text");
  cmd->add_option("--diff-png", o.diff_png,
                  "On a mismatch, write FILE.png: the expected frame | the frame drawn | the differing cells (red)");
  cmd->add_option("--scale", o.scale, "--diff-png: pixels per cell side")->default_val(16)->check(CLI::Range(1, 256));
}

// Same size as the larger of the two; differing cells red, equal ones dark.
Picture difference(const Picture& a, const Picture& b) {
  Picture d;
  d.width = std::max(a.width, b.width);
  d.height = std::max(a.height, b.height);
  for (int y = 0; y < d.height; ++y)
    for (int x = 0; x < d.width; ++x) {
      const bool in_a = x < a.width && y < a.height, in_b = x < b.width && y < b.height;
      const bool same = in_a && in_b && a.at(x, y) == b.at(x, y);
      d.rgb.push_back(same ? 0x202020 : 0xff0000);
    }
  return d;
}

void write_diff_png(const CheckOptions& o, const FrameMismatch& m) {
  const Picture expected = picture_of_rows(m.expected), got = picture_of_rows(m.got);
  const DrawOptions d{o.scale, true};
  write_png(o.diff_png, tile({captioned(draw(expected, d), "expected"), captioned(draw(got, d), "got"),
                              captioned(draw(difference(expected, got), d), "differing cells (red)")},
                             3, 8));
  std::cerr << "autumn check: wrote " << o.diff_png << " (" << m.where << ": expected | got | differing cells)\n";
}

void print_result(const CheckOptions& o, const CheckResult& r) {
  if (o.json) {
    nlohmann::json j = {{"frames_matched", r.frames_matched}, {"frames", r.frames_total},
                        {"triggers_matched", r.triggers_matched}, {"triggers", r.triggers_total},
                        {"traces", r.traces}, {"mismatches", r.mismatches}, {"ok", r.ok()}};
    std::cout << j.dump() << "\n";
    return;
  }
  if (!o.quiet)
    for (const auto& m : r.mismatches) fmt::print("MISMATCH {}\n", m);
  if (r.triggers_total) fmt::print("matched {}/{} trigger values\n", r.triggers_matched, r.triggers_total);
  fmt::print("matched {}/{} frames in {} traces\n", r.frames_matched, r.frames_total, r.traces);
}

int run_check(const CheckOptions& o) {
  TraceFile file;
  try {
    file = load_trace_file(o.traces);
  } catch (const std::exception& e) {
    std::cerr << "autumn check: " << e.what() << "\n";
    return kExitFailed;
  }
  auto program = load_or_report(o.program, file.triggering_condition);
  if (!program) return kExitFailed;
  // --engine compiled checks the module's frames, never the interpreter's while it compiles.
  auto env = make_env("check", o.engine, program, FirstUse::kWaitForModule);
  if (!env) return kExitFailed;
  CheckResult r = check_traces(*env, file);
  print_result(o, r);
  if (!o.diff_png.empty() && r.first_frame_mismatch) {
    try {
      write_diff_png(o, *r.first_frame_mismatch);
    } catch (const std::exception& e) {
      std::cerr << "autumn check: " << e.what() << "\n";
      return kExitFailed;
    }
  }
  return r.ok() ? kExitOk : kExitFailed;
}

}  // namespace

Subcommand add_check_command(CLI::App& app) {
  auto o = std::make_shared<CheckOptions>();
  CLI::App* cmd = app.add_subcommand("check", "Replay golden traces and compare every frame");
  register_check(cmd, *o);
  add_limits_option(cmd);
  return {cmd, [o] { return run_check(*o); }};
}

}  // namespace autumn::cli
