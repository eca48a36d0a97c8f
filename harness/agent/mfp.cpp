#include "harness/agent/mfp.hpp"

#include <fmt/core.h>

#include "harness/agent/particles.hpp"

namespace autumn::agent {

namespace {
constexpr uint64_t kBatch = 4096;
}

MfpResult solve_mfp(const Task& task, const SolveOptions& opts, ThreadPool& pool) {
  if (task.type != TaskType::MaskedFramePrediction) throw TaskError(task.file.string() + ": not an MFP task");
  Stopwatch clock;
  MfpResult r;
  r.rollouts = std::max<uint64_t>(opts.rollouts, 1);
  r.counts.assign(task.choices.size(), 0);
  r.expected = task.answer;

  auto program = load_program_checked(task_program_path(task, opts, task.program));
  auto probe = make_env_checked(opts.engine, program);
  if (!probe->reset(0)) throw TaskError(probe->error());
  int size = probe->frame().size;
  int task_size = task.observations[0].grid.width;
  if (size != task_size)
    throw TaskError(fmt::format("{}: task grids are {}x{} but program '{}' has GRID_SIZE {}", task.file.filename().string(),
                                task_size, task_size, task.program, size));
  r.deterministic = probe->deterministic();

  // Particles are clones of the probe (building an engine's environment may be costly).
  auto make = [&] { return probe->clone(); };
  std::vector<uint64_t> seeds = rollout_seeds(opts.seed, r.rollouts, task.env_seed);
  for (uint64_t begin = 0; begin < seeds.size(); begin += kBatch) {
    std::vector<uint64_t> batch(seeds.begin() + begin, seeds.begin() + std::min<uint64_t>(seeds.size(), begin + kBatch));
    if (r.deterministic) batch = seeds;  // one rollout stands for all of them
    ParticleSet set(pool, task.colours);
    const Grid* obs = &task.observations[0].grid;
    FramePredicate keep = [&obs](const TaskFrame& f, int sz) { return consistent(f, sz, *obs); };
    set.start(make, batch, r.deterministic, keep);
    for (size_t t = 1; t < task.observations.size() && !set.empty(); ++t) {
      obs = &task.observations[t].grid;
      set.step(*task.observations[t].action, keep);
    }
    for (const Particle& p : set.particles()) {
      r.accepted += p.weight;
      Grid region = crop(p.frame, size, task.masked);
      bool matched = false;
      for (size_t c = 0; c < task.choices.size(); ++c)
        if (task.choices[c] == region) {
          r.counts[c] += p.weight;
          matched = true;
          break;  // choices are distinct in well-formed tasks; count the first
        }
      if (!matched) r.unmatched += p.weight;
    }
    r.env_steps += set.env_steps();
    r.peak_particles = std::max(r.peak_particles, set.peak());
    if (r.deterministic) break;
  }
  uint64_t best = 0;
  for (size_t c = 0; c < r.counts.size(); ++c)
    if (r.counts[c] > best) best = r.counts[c], r.choice = static_cast<int>(c);
  r.seconds = clock.seconds();
  return r;
}

nlohmann::json mfp_json(const MfpResult& r) {
  nlohmann::json j = {{"choice", r.choice < 0 ? nlohmann::json(nullptr) : nlohmann::json(r.choice)},
                      {"counts", r.counts},
                      {"rollouts", r.rollouts},
                      {"accepted", r.accepted},
                      {"unmatched", r.unmatched},
                      {"acceptance_rate", r.rollouts ? static_cast<double>(r.accepted) / r.rollouts : 0.0},
                      {"deterministic", r.deterministic},
                      {"env_steps", r.env_steps},
                      {"peak_particles", r.peak_particles},
                      {"seconds", r.seconds},
                      {"rollouts_per_second", per_second(static_cast<double>(r.rollouts), r.seconds)}};
  if (r.expected) {
    j["expected"] = *r.expected;
    j["correct"] = r.choice == *r.expected;
  }
  return j;
}

std::string mfp_summary(const MfpResult& r) {
  std::string s;
  if (r.choice >= 0)
    s += fmt::format("answer: choice {} ({} of {} accepted rollouts)\n", r.choice, r.counts[r.choice], r.accepted);
  else
    s += fmt::format("answer: none (no accepted rollout matches a choice)\n");
  s += "counts:";
  for (size_t c = 0; c < r.counts.size(); ++c) s += fmt::format(" [{}] {}", c, r.counts[c]);
  s += fmt::format("\nrollouts: {}, accepted {} ({:.2f}%), matching no choice {}{}\n", r.rollouts, r.accepted,
                   r.rollouts ? 100.0 * r.accepted / r.rollouts : 0.0, r.unmatched,
                   r.deterministic ? " (deterministic program: one rollout stands for all)" : "");
  s += fmt::format("work: {} environment steps, peak {} live particles\n", r.env_steps, r.peak_particles);
  s += fmt::format("time: {:.3f} s, {:.0f} rollouts/s\n", r.seconds, per_second(static_cast<double>(r.rollouts), r.seconds));
  if (r.expected)
    s += fmt::format("expected: choice {} — {}\n", *r.expected, r.choice == *r.expected ? "correct" : "wrong");
  return s;
}

}  // namespace autumn::agent
