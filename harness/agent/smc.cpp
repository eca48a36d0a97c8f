// smc — see smc.hpp for the algorithm; this file keeps to its mechanics:
// proposing children in chunks, merging survivors, systematic resampling.
#include "harness/agent/smc.hpp"

#include <algorithm>
#include <cmath>

namespace autumn::agent {

namespace {
constexpr size_t kChunk = 2048;           // children alive at once while proposing
constexpr uint64_t kRetries[] = {1, 8, 64};  // children per sample, tried in turn
constexpr int kDrawSearchStarts = 8;         // descents when no start-up agrees (draw_search.hpp)

struct Child {
  std::unique_ptr<Environment> env;
  uint64_t seed = 0;
  uint64_t count = 0;  // population share it stands for (times the step's multiplier)
  bool alive = false;
  bool drew = true;
  TaskFrame frame;
};
}  // namespace

SmcSet::SmcSet(ThreadPool& pool, const ColourTable& colours, uint64_t n, uint64_t seed, uint64_t max_growth)
    : pool_(pool),
      colours_(colours),
      n_(std::max<uint64_t>(n, 1)),
      max_growth_(max_growth),
      rng_(seed ^ 0x5e3c0a11d1f7b2a9ull) {}

std::unique_ptr<SmcSet> SmcSet::fork() const {
  auto copy = std::make_unique<SmcSet>(pool_, colours_, n_, 0, max_growth_);
  copy->rng_ = rng_;
  for (const SmcSample& s : samples_) copy->samples_.push_back({s.env->clone(), s.count, s.hash, s.frame});
  copy->log_likelihood_ = log_likelihood_;
  copy->ess_min_ = ess_min_;
  copy->env_steps_ = env_steps_;
  copy->retries_ = retries_;
  copy->peak_ = peak_;
  return copy;
}

bool SmcSet::start(const Environment& model, const FramePredicate& keep, const Grid* first) {
  Op op = [](Environment& e, uint64_t seed) { return e.reset(seed); };
  uint64_t proposed = 0;
  for (uint64_t mult : kRetries) {
    if (mult > max_growth_) break;
    if (propagate({{&model, n_}}, op, keep, mult, /*from_reset=*/true)) return true;
    proposed += proposed_;
    ++retries_;
  }
  if (!first) return false;
  return adopt_found(search_start_draws(pool_, model, colours_, *first, rng_(), kDrawSearchStarts, draw_search_),
                     keep, proposed);
}

// The population becomes `states` (those `keep` accepts), split evenly; the
// observation's likelihood is bounded by 1 / (2 x proposed), as nothing of
// `proposed` children agreed.
bool SmcSet::adopt_found(std::vector<std::unique_ptr<Environment>> states, const FramePredicate& keep,
                         uint64_t proposed) {
  std::erase_if(states, [&](const std::unique_ptr<Environment>& e) {
    return !keep(task_frame(e->frame(), e->palette(), colours_), e->frame().size);
  });
  if (states.empty()) return false;
  samples_.clear();
  const uint64_t k = states.size();
  for (uint64_t i = 0; i < k; ++i) {
    TaskFrame frame = task_frame(states[i]->frame(), states[i]->palette(), colours_);
    uint64_t hash = states[i]->state_hash();
    samples_.push_back({std::move(states[i]), n_ / k + (i < n_ % k ? 1 : 0), hash, std::move(frame)});
  }
  std::erase_if(samples_, [](const SmcSample& s) { return s.count == 0; });
  peak_ = std::max(peak_, samples_.size());
  log_likelihood_ -= std::log(2.0 * static_cast<double>(std::max<uint64_t>(proposed, 1)));
  const double ess = static_cast<double>(samples_.size());
  ess_min_ = ess_min_ < 0 ? ess : std::min(ess_min_, ess);
  return true;
}

bool SmcSet::step(const Action& action, const FramePredicate& keep, const Grid* obs) {
  Op op = [&action](Environment& e, uint64_t seed) { return e.reseed_random(seed) && e.step(action); };
  std::vector<Parent> parents;
  for (const SmcSample& s : samples_) parents.push_back({s.env.get(), s.count});
  uint64_t proposed = 0;
  for (uint64_t mult : kRetries) {
    if (mult > max_growth_) break;
    if (propagate(parents, op, keep, mult, /*from_reset=*/false)) return true;
    proposed += proposed_;
    ++retries_;
  }
  if (!obs) return false;
  // The heaviest samples (at most kDrawSearchStarts, ties in population order)
  // are the parents of the draw search.
  std::vector<size_t> order(samples_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return samples_[a].count > samples_[b].count; });
  order.resize(std::min<size_t>(order.size(), kDrawSearchStarts));
  std::vector<const Environment*> chosen;
  for (size_t i : order) chosen.push_back(samples_[i].env.get());
  return adopt_found(search_step_draws(pool_, chosen, action, colours_, *obs, rng_(), draw_search_), keep, proposed);
}

// Proposes parents[i].children * mult children of every parent, keeps those
// `keep` accepts, and on success replaces the population by their resampling.
bool SmcSet::propagate(const std::vector<Parent>& parents, const Op& op, const FramePredicate& keep, uint64_t mult,
                       bool from_reset) {
  next_.clear();
  index_.clear();
  uint64_t proposed = 0, accepted = 0;
  auto judge = [&](Child& c) {
    // A reset starts the count afresh: it drew when the count is not zero.
    int64_t before = from_reset ? 0 : c.env->random_draws();
    c.alive = op(*c.env, c.seed);
    c.drew = before < 0 || c.env->random_draws() != before;
    if (!c.alive) return;
    c.frame = task_frame(c.env->frame(), c.env->palette(), colours_);
    c.alive = keep(c.frame, c.env->frame().size);
  };
  // First child of every parent; a parent whose step drew nothing is done.
  std::vector<uint64_t> rest(parents.size(), 0);
  for (size_t begin = 0; begin < parents.size(); begin += kChunk) {
    size_t end = std::min(parents.size(), begin + kChunk);
    std::vector<Child> chunk(end - begin);
    for (size_t i = begin; i < end; ++i) chunk[i - begin] = {copy_of(*parents[i].env), rng_(), 1};
    pool_.parallel_for(chunk.size(), [&](size_t k) { judge(chunk[k]); });
    env_steps_ += chunk.size();
    for (size_t i = begin; i < end; ++i) {
      Child& c = chunk[i - begin];
      uint64_t total = parents[i].children * mult;
      if (!c.drew) c.count = total;
      else rest[i] = total - 1;
      proposed += c.count;
      if (c.alive) accepted += c.count, adopt(std::move(c.env), std::move(c.frame), c.count);
      else give_spare(std::move(c.env));
    }
  }
  // The other children of parents that drew, in parent order.
  std::vector<Child> chunk;
  auto flush = [&] {
    pool_.parallel_for(chunk.size(), [&](size_t k) { judge(chunk[k]); });
    env_steps_ += chunk.size();
    for (Child& c : chunk) {
      proposed += 1;
      if (c.alive) accepted += 1, adopt(std::move(c.env), std::move(c.frame), 1);
      else give_spare(std::move(c.env));
    }
    chunk.clear();
  };
  for (size_t i = 0; i < parents.size(); ++i)
    for (uint64_t k = 0; k < rest[i]; ++k) {
      chunk.push_back({copy_of(*parents[i].env), rng_(), 1});
      if (chunk.size() == kChunk) flush();
    }
  flush();
  proposed_ = proposed;
  if (accepted == 0) return false;
  double rate = static_cast<double>(accepted) / static_cast<double>(proposed);
  log_likelihood_ += std::log(rate);
  double ess = rate * static_cast<double>(n_);
  ess_min_ = ess_min_ < 0 ? ess : std::min(ess_min_, ess);
  resample();
  return true;
}

// A copy of `parent` for a child: a spare environment made one (copy_from), or a
// clone. On the calling thread, as every clone and destruction here: an engine's
// environments may share storage with the one they were cloned from.
std::unique_ptr<Environment> SmcSet::copy_of(const Environment& parent) {
  if (!spare_.empty()) {
    std::unique_ptr<Environment> e = std::move(spare_.back());
    spare_.pop_back();
    if (e->copy_from(parent)) return e;
  }
  return parent.clone();
}

// At most a population and a chunk of spares are kept, and none of an engine
// that cannot copy into an environment (a copy onto itself says so: the default
// copy_from refuses every source), whose spares would only hold memory.
void SmcSet::give_spare(std::unique_ptr<Environment> env) {
  if (!env || !reuse_ || spare_.size() >= n_ + kChunk) return;
  if (spare_.empty() && !env->copy_from(*env)) {
    reuse_ = false;
    return;
  }
  spare_.push_back(std::move(env));
}

void SmcSet::adopt(std::unique_ptr<Environment> env, TaskFrame frame, uint64_t count) {
  uint64_t hash = env->state_hash();
  std::vector<size_t>& same = index_[hash];
  for (size_t k : same)
    if (next_[k].frame == frame) {
      next_[k].count += count;
      give_spare(std::move(env));
      return;
    }
  same.push_back(next_.size());
  next_.push_back({std::move(env), count, hash, std::move(frame)});
  peak_ = std::max(peak_, next_.size());
}

// Systematic resampling of next_ (weights = counts) to n_ samples: one uniform
// offset, n_ evenly spaced positions over the cumulative weights.
void SmcSet::resample() {
  uint64_t total = 0;
  for (const SmcSample& s : next_) total += s.count;
  const double stride = static_cast<double>(total) / static_cast<double>(n_);
  double pos = std::uniform_real_distribution<double>(0.0, 1.0)(rng_) * stride;
  double cumulative = 0;
  for (SmcSample& s : samples_) give_spare(std::move(s.env));  // the parents: their children are made
  samples_.clear();
  for (SmcSample& s : next_) {
    cumulative += static_cast<double>(s.count);
    uint64_t take = 0;
    while (pos < cumulative) ++take, pos += stride;
    if (take == 0) {
      give_spare(std::move(s.env));
      continue;
    }
    s.count = take;
    samples_.push_back(std::move(s));
  }
  // Rounding can leave the total a sample short or long: the last state absorbs it.
  uint64_t sum = 0;
  for (const SmcSample& s : samples_) sum += s.count;
  if (sum != n_ && !samples_.empty()) {
    SmcSample& last = samples_.back();
    last.count = sum > n_ ? last.count - std::min(last.count - 1, sum - n_) : last.count + (n_ - sum);
  }
  next_.clear();
  index_.clear();
}

}  // namespace autumn::agent
