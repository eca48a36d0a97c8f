// mfp — masked frame prediction: which choice fills the masked rectangle.
//
// Deterministic programs: one exact rollout replays the task's actions; if its
// frames agree with every observation's unmasked cells, its final frame cropped to
// the masked rectangle names the answer (reported as standing for all --rollouts).
//
// Stochastic programs (the task does not say its seed, as in the benchmark):
// two hypotheses. H0, the stated seed (the task's "seed", else the benchmark's 0),
// is replayed exactly and either contradicts an observation or predicts one frame
// with probability 1. H1, an unknown seed, is explored by sequential Monte Carlo
// (smc.hpp) with --rollouts samples, filtered observation by observation; the
// filter estimates the likelihood of the observations under H1. With equal prior
// odds, the answer is the choice of highest posterior probability
// P(H0|obs)[H0's choice] + P(H1|obs) share of H1's samples showing it.
// A task no hypothesis explains has no answer (choice -1).
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/agent/solve_common.hpp"

namespace autumn::agent {

struct MfpResult {
  int choice = -1;  // -1 when no surviving rollout matches any choice
  std::vector<uint64_t> counts;
  uint64_t rollouts = 0;
  uint64_t accepted = 0;   // rollouts consistent with every observation
  uint64_t unmatched = 0;  // accepted rollouts whose masked region is no choice
  bool deterministic = false;
  uint64_t env_steps = 0;  // resets + steps actually executed
  size_t peak_particles = 0;
  double seconds = 0;
  std::optional<int> expected;  // the answers file's correct_idx (or the task's "answer")
  // Stochastic programs only (smc = true).
  bool smc = false;
  bool stated_seed_consistent = false;  // H0 explains every observation
  std::optional<int> smc_died_at;       // observation no sample explained
  double smc_ess_min = 0;               // effective particles, minimum over steps
  uint64_t smc_retries = 0;             // steps that needed more children per sample
  double posterior_stated_seed = 0;     // P(H0 | observations)
  std::vector<double> probabilities;    // posterior probability of each choice
  // Seed inversion (seed_inversion.hpp): the seeds whose start-up draws are the
  // first frame's and whose exact episode explains every observation.
  bool inverted = false;                // the inversion ran to completion and some seed explains everything
  double pinned_bits = 0;               // what the first frame pinned
  uint64_t seeds_matching_draws = 0;    // seeds the enumeration returned
  uint64_t seeds_consistent = 0;        // of those, seeds whose whole episode agrees
};

// The answer rule, for posteriors and for rollout counts alike: the index of the
// largest weight, the first of equal ones; -1 when every weight is zero (no
// hypothesis shows any choice). Tests: AgentChoice.MostProbableFirstOnTies.
template <class W>
int most_probable_choice(const std::vector<W>& weights) {
  int best = -1;
  for (size_t c = 0; c < weights.size(); ++c)
    if (weights[c] > 0 && (best < 0 || weights[c] > weights[static_cast<size_t>(best)])) best = static_cast<int>(c);
  return best;
}

MfpResult solve_mfp(const Task& task, const SolveOptions& opts, ThreadPool& pool);
nlohmann::json mfp_json(const MfpResult& r);
std::string mfp_summary(const MfpResult& r);

}  // namespace autumn::agent
