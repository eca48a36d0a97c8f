// make_task — generate AutumnBench-format tasks for any program.
//
// mfp: a seeded random action sequence of --steps actions from reset(env seed);
// the final `masked_frames` frames hide one rectangle (chosen among random
// rectangles for how much its content changes); six choices, exactly one the true
// content. For a stochastic program the task must be fair to a solver that does
// not know the seed: for the best-ranked rectangles in turn (at most 32), a
// sequential Monte Carlo filter over an unknown seed (smc.hpp, posterior_samples
// samples, 1000 by default, at most
// 8 children per sample: a generator's check, not a solver)
// conditioned on the task's observations says which contents the observations
// allow; the first rectangle whose true content is at least half of that
// posterior is taken (else the one where it is most probable; else, when the
// filter explains nothing, the best-ranked one), and no distractor may be any
// content the posterior allows. Every distractor differs from the masked content of every rollout in a
// batch (`batch` interpreter seeds from rollout_seeds(), the same actions), so
// across that batch only the answer is consistent with the program. Distractors
// come from the same rectangle at earlier steps, shifted rectangles of the final
// frame, then recolourings of the answer. The answers file holds correct_idx.
//
// planning: the goal is the frame after a seeded random sequence of --steps
// actions that changes the frame; the mask is the bounding box of the changed
// cells grown by one cell. The answers file holds the reference_plan.
//
// Blind layout, as the benchmark keeps it: the prompt holds only what a solver
// may see (type, program, observations/choices or goal/mask); the environment
// seed, the answer and the generator's settings go to an answers file (see
// write_task), which only `autumn eval` reads.
//
// Colours: a frame colour missing from the colour table is an error unless
// extend_colours, which appends it (and the colour table is written next to the
// task). With an output file under a folder named prompts/, the program is copied
// into the sibling programs/ folder so the task resolves with solve's defaults.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/agent/task_file.hpp"
#include "harness/agent/thread_pool.hpp"

namespace autumn::agent {

struct MakeTaskOptions {
  std::string kind;  // mfp | planning
  fs::path program;
  uint64_t seed = 0;
  int steps = -1;    // default: mfp 20, planning 4
  fs::path out;      // empty: print to stdout
  uint64_t env_seed = 0;
  std::string engine = "interp";
  uint64_t batch = 200;
  uint64_t posterior_samples = 1000;  // mfp, stochastic programs: samples of the blind solver's posterior
  int masked_frames = 3;
  bool extend_colours = false;
  fs::path answers_out;  // empty: the default beside the task (write_task)
};

struct MadeTask {
  nlohmann::json task;     // the prompt
  nlohmann::json answers;  // seed, correct_idx / reference_plan, generator
  ColourTable colours;
  bool colours_extended = false;
  std::vector<std::string> warnings;  // "warning: ..." lines for the user (make-task prints them)
};

MadeTask make_task(const MakeTaskOptions& opts, ThreadPool& pool);
// Writes the task, its answers (opts.answers_out, else <root>/answers/<name>.json
// when the task is under prompts/, else <name>.answers.json beside it), the
// program copy and colour table (see above); returns notes.
std::vector<std::string> write_task(const MadeTask& made, const MakeTaskOptions& opts);
// JSON with grids (arrays of number arrays) kept one row per line.
std::string format_task_json(const nlohmann::json& j);

}  // namespace autumn::agent
