#include "harness/agent/mfp.hpp"

#include <fmt/core.h>

#include <cmath>

#include "harness/agent/draw_search.hpp"
#include "harness/agent/particles.hpp"
#include "harness/agent/seed_inversion.hpp"
#include "harness/agent/smc.hpp"

namespace autumn::agent {

namespace {

// The choice the frame's masked region equals (the first: choices are distinct
// in well-formed tasks), or -1.
int choice_shown(const Task& task, int size, const TaskFrame& frame) {
  Grid region = crop(frame, size, task.masked);
  for (size_t c = 0; c < task.choices.size(); ++c)
    if (task.choices[c] == region) return static_cast<int>(c);
  return -1;
}

// Adds `weight` to the choice the frame shows (or to unmatched).
void tally(const Task& task, int size, const TaskFrame& frame, uint64_t weight, MfpResult& r) {
  r.accepted += weight;
  int c = choice_shown(task, size, frame);
  (c >= 0 ? r.counts[c] : r.unmatched) += weight;
}

// One seed replayed exactly (the stated-seed hypothesis: the task's seed, the
// benchmark's 0 when it states none). The index of the choice it shows, -1 for
// none, or nullopt when the episode contradicts an observation.
std::optional<int> seed_choice(const Task& task, const Environment& probe, int size, uint64_t seed, MfpResult& r) {
  auto env = probe.clone();
  bool ok = env->reset(seed);
  ++r.env_steps;
  for (size_t t = 0; ok && t < task.observations.size(); ++t) {
    if (t > 0) ok = env->step(*task.observations[t].action), ++r.env_steps;
    ok = ok && consistent(task_frame(env->frame(), env->palette(), task.colours), size, task.observations[t].grid);
  }
  if (!ok) return std::nullopt;
  return choice_shown(task, size, task_frame(env->frame(), env->palette(), task.colours));
}

// The posterior over the two hypotheses, equal prior odds: H0, the stated seed
// (it shows choice *h0 with probability 1, or contradicts the observations:
// nullopt), and H1, an unknown seed of likelihood `w1`, whose choices are
// distributed as r.counts over r.accepted samples; then the posterior over the
// choices and the answer, the most probable one (the first on ties).
void decide(std::optional<int> h0, double w1, MfpResult& r) {
  const double w0 = h0 ? 1.0 : 0.0;
  if (w0 + w1 <= 0) return;
  r.posterior_stated_seed = w0 / (w0 + w1);
  std::vector<double> p(r.counts.size(), 0.0);
  if (h0 && *h0 >= 0) p[*h0] += r.posterior_stated_seed;
  for (size_t c = 0; c < p.size(); ++c)
    if (r.accepted) p[c] += (1 - r.posterior_stated_seed) * static_cast<double>(r.counts[c]) / static_cast<double>(r.accepted);
  r.probabilities = p;
  r.choice = most_probable_choice(p);
}

// Seed inversion: when the observations pin enough of the episode's draws
// (seed_inversion.hpp), the world is one of few seeds, each replayed exactly.
// Their likelihood: |consistent seeds| / 2^32 under a uniform prior over seeds.
// False when it cannot decide (more than kMaxSeeds seeds give the pinned draws,
// or none of them explains every observation: the draws were explained by
// values the world did not draw, e.g. two sparks' directions swapped).
constexpr size_t kMaxSeeds = 256;
bool solve_by_inversion(const Task& task, const SolveOptions& opts, ThreadPool& pool, const Environment& probe,
                        int size, std::optional<int> h0, MfpResult& r) {
  auto ex = explain_episode_draws(probe, task.colours, task.observations, opts.seed);
  if (!ex) return false;
  r.env_steps += ex->env_steps;
  SeedInversion inv = invert_start_draws(pool, *ex, kMaxSeeds);
  r.pinned_bits = inv.pinned_bits;
  r.seeds_matching_draws = inv.seeds.size();
  if (!inv.complete || inv.seeds.empty()) return false;
  for (uint32_t seed : inv.seeds) {
    std::optional<int> c = seed_choice(task, probe, size, seed, r);
    if (!c) continue;
    ++r.seeds_consistent;
    r.accepted += 1;
    (*c >= 0 ? r.counts[*c] : r.unmatched) += 1;
  }
  if (r.seeds_consistent == 0) return false;
  r.inverted = true;
  decide(h0, static_cast<double>(r.seeds_consistent) / 4294967296.0, r);
  return true;
}

// Stochastic programs: the stated-seed hypothesis H0 and sequential Monte Carlo
// over an unknown seed H1 (smc.hpp), equal prior odds. H0 predicts its frame with
// probability 1; H1's likelihood is the filter's estimate. The answer is the
// choice of highest posterior probability.
void solve_stochastic(const Task& task, const SolveOptions& opts, ThreadPool& pool, const Environment& probe, int size,
                      MfpResult& r) {
  std::optional<int> h0 = seed_choice(task, probe, size, task.env_seed, r);
  r.stated_seed_consistent = h0.has_value();
  r.smc = true;
  if (opts.seed_inversion && solve_by_inversion(task, opts, pool, probe, size, h0, r)) return;
  SmcSet smc(pool, task.colours, r.rollouts, opts.seed);
  const Grid* obs = &task.observations[0].grid;
  FramePredicate keep = [&obs](const TaskFrame& f, int sz) { return consistent(f, sz, *obs); };
  bool alive = smc.start(probe, keep, obs);
  for (size_t t = 1; alive && t < task.observations.size(); ++t) {
    obs = &task.observations[t].grid;
    alive = smc.step(*task.observations[t].action, keep, obs);
    if (!alive) r.smc_died_at = static_cast<int>(t);
  }
  if (!alive && !r.smc_died_at) r.smc_died_at = 0;
  r.smc = true;
  r.smc_ess_min = smc.ess_min();
  r.smc_retries = smc.retries();
  r.env_steps += smc.env_steps();
  r.peak_particles = smc.peak();
  if (alive)
    for (const SmcSample& s : smc.samples()) tally(task, size, s.frame, s.count, r);
  decide(h0, alive ? std::exp(smc.log_likelihood()) : 0.0, r);
}

}  // namespace

MfpResult solve_mfp(const Task& task, const SolveOptions& opts, ThreadPool& pool) {
  if (task.type != TaskType::MaskedFramePrediction) throw TaskError(task.file.string() + ": not an MFP task");
  Stopwatch clock;
  MfpResult r;
  r.rollouts = std::max<uint64_t>(opts.rollouts, 1);
  r.counts.assign(task.choices.size(), 0);
  r.expected = task.answer;
  if (opts.answers)  // for the report only; the solver never looks at it
    if (Answers a = load_answers(*opts.answers); a.correct_idx) r.expected = a.correct_idx;

  auto program = load_program_checked(task_program_path(task, opts, task.program));
  auto probe = make_env_checked(opts.engine, program);
  if (!probe->reset(0)) throw TaskError(probe->error());
  int size = probe->frame().size;
  int task_size = task.observations[0].grid.width;
  if (size != task_size)
    throw TaskError(fmt::format("{}: task grids are {}x{} but program '{}' has GRID_SIZE {}", task.file.filename().string(),
                                task_size, task_size, task.program, size));
  r.deterministic = probe->deterministic();

  if (r.deterministic) {
    // One rollout stands for all of them (particles.hpp): the seed is never read.
    ParticleSet set(pool, task.colours);
    const Grid* obs = &task.observations[0].grid;
    FramePredicate keep = [&obs](const TaskFrame& f, int sz) { return consistent(f, sz, *obs); };
    set.start([&] { return probe->clone(); }, rollout_seeds(opts.seed, r.rollouts, task.env_seed), true, keep);
    for (size_t t = 1; t < task.observations.size() && !set.empty(); ++t) {
      obs = &task.observations[t].grid;
      set.step(*task.observations[t].action, keep);
    }
    for (const Particle& p : set.particles()) tally(task, size, p.frame, p.weight, r);
    r.env_steps += set.env_steps();
    r.peak_particles = set.peak();
    r.choice = most_probable_choice(r.counts);
    r.seconds = clock.seconds();
    return r;
  }
  solve_stochastic(task, opts, pool, *probe, size, r);
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
  if (r.smc)
    j["smc"] = {{"stated_seed_consistent", r.stated_seed_consistent},
                {"died_at", r.smc_died_at ? nlohmann::json(*r.smc_died_at) : nlohmann::json(nullptr)},
                {"ess_min", r.smc_ess_min},
                {"retries", r.smc_retries},
                {"posterior_stated_seed", r.posterior_stated_seed},
                {"probabilities", r.probabilities},
                {"seed_inversion",
                 {{"used", r.inverted},
                  {"pinned_bits", r.pinned_bits},
                  {"seeds_matching_draws", r.seeds_matching_draws},
                  {"seeds_consistent", r.seeds_consistent}}}};
  if (r.expected) {
    j["expected"] = *r.expected;
    j["correct"] = r.choice == *r.expected;
  }
  return j;
}

std::string mfp_summary(const MfpResult& r) {
  std::string s;
  if (r.choice >= 0 && r.smc)
    s += fmt::format("answer: choice {} (posterior probability {:.3f})\n", r.choice, r.probabilities[r.choice]);
  else if (r.choice >= 0)
    s += fmt::format("answer: choice {} ({} of {} accepted rollouts)\n", r.choice, r.counts[r.choice], r.accepted);
  else
    s += fmt::format("answer: none (no accepted rollout matches a choice)\n");
  s += "counts:";
  for (size_t c = 0; c < r.counts.size(); ++c) s += fmt::format(" [{}] {}", c, r.counts[c]);
  s += fmt::format("\nrollouts: {}, accepted {} ({:.2f}%), matching no choice {}{}\n", r.rollouts, r.accepted,
                   r.rollouts ? 100.0 * r.accepted / r.rollouts : 0.0, r.unmatched,
                   r.deterministic ? " (deterministic program: one rollout stands for all)" : "");
  if (r.inverted) {
    s += fmt::format("stochastic program: stated seed {}; the observations pin {:.0f} bits of the episode's draws: "
                     "{} seed(s) of 2^32 give them, {} explain every observation\n",
                     r.stated_seed_consistent ? "explains the observations" : "contradicted", r.pinned_bits,
                     r.seeds_matching_draws, r.seeds_consistent);
  } else if (r.smc) {
    s += fmt::format("stochastic program: stated seed {}; sequential Monte Carlo {}, effective particles >= {:.1f}\n",
                     r.stated_seed_consistent ? "explains the observations" : "contradicted",
                     r.smc_died_at ? fmt::format("explains no sample at observation {}", *r.smc_died_at)
                                   : std::string("kept samples to the end"),
                     r.smc_ess_min);
  }
  if (r.smc && !r.probabilities.empty()) {
    s += fmt::format("posterior: stated seed {:.3f}; choices", r.posterior_stated_seed);
    for (size_t c = 0; c < r.probabilities.size(); ++c) s += fmt::format(" [{}] {:.3f}", c, r.probabilities[c]);
    s += "\n";
  }
  s += fmt::format("work: {} environment steps, peak {} live particles\n", r.env_steps, r.peak_particles);
  s += fmt::format("time: {:.3f} s, {:.0f} rollouts/s\n", r.seconds, per_second(static_cast<double>(r.rollouts), r.seconds));
  if (r.expected)
    s += fmt::format("expected: choice {} — {}\n", *r.expected, r.choice == *r.expected ? "correct" : "wrong");
  return s;
}

}  // namespace autumn::agent
