// solve_pictures — `autumn solve --render DIR`: what the solver found, as pictures
// (harness/render_images.hpp, the benchmark's colours).
//
// planning: <task>_plan.gif, the plan replayed from the task's start (one frame a
// step), and <task>_plan.png: the frames as a strip, then the goal with the
// cells outside the mask in slate grey (how MARAProtocol draws masked cells).
// MFP: <task>_answer.png: the last observation (masked cells slate grey) beside
// the same frame with the chosen choice filled in; <task>_observations.gif, the
// observed trajectory. Change detection: <task>_detection.gif, the changed
// program's episode under the actions the solver took. Returns the files written;
// throws std::runtime_error when one cannot be.
#pragma once
#include <string>
#include <vector>

#include "harness/agent/change_detection.hpp"
#include "harness/agent/mfp.hpp"
#include "harness/agent/planning.hpp"

namespace autumn::agent {

std::vector<std::string> render_plan(const Task& task, const SolveOptions& opts, const PlanResult& r, const fs::path& dir);
std::vector<std::string> render_mfp(const Task& task, const MfpResult& r, const fs::path& dir);
std::vector<std::string> render_cd(const Task& task, const SolveOptions& opts, const CdResult& r, const fs::path& dir);

}  // namespace autumn::agent
