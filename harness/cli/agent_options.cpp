#include "harness/cli/agent_options.hpp"

#include <unistd.h>

#include <algorithm>
#include <iostream>

#include "harness/cli/number_options.hpp"
#include "harness/engine.hpp"

namespace autumn::cli {

void add_search_options(CLI::App* cmd, agent::SolveOptions& o, unsigned& threads) {
  const agent::SolveOptions d = agent::protocol_options("default");  // the defaults, decided in solve_common
  cmd->add_option("--engine", o.engine, "Execution engine (interp: the tree-walking interpreter, for comparison)")
      ->check(CLI::IsMember(engine_names()))
      ->default_val(d.engine);
  cmd->add_option("--rollouts", o.rollouts, "MFP rollouts; particles for stochastic change detection")
      ->default_val(d.rollouts)
      ->check(cli::big_count(1));
  cmd->add_option("--threads", threads, "Worker threads (0: all cores)")->default_val(0)->check(cli::thread_count());
  cmd->add_flag("!--no-seed-inversion", o.seed_inversion,
                "MFP on stochastic programs: skip recovering the world's seed from the observed draws and "
                "use the sequential Monte Carlo filter alone");
  cmd->add_option("--seed", o.seed, "Seed of the agent's own randomness (rollout seeds, policy)")
      ->default_val(d.seed)
      ->check(cli::seed_number());
  cmd->add_option("--max-steps", o.max_steps, "Change detection: episode length cap")
      ->default_val(d.max_steps)
      ->check(cli::int_count());
  cmd->add_option("--policy", o.policy, "Change detection exploration policy")
      ->check(CLI::IsMember(agent::policy_names()))
      ->default_val(d.policy);
  cmd->add_option("--depth", o.depth, "Planning: BFS cost limit (layers)")->default_val(d.depth)->check(cli::int_count());
  cmd->add_option("--nodes", o.nodes, "Planning: node budget (successor states generated)")
      ->default_val(d.nodes)
      ->check(cli::big_count(1));
  cmd->add_option("--search", o.search,
                  "Planning: bfs (proven cheapest), best-first, beam, fill (arrows first, then clicks into their "
                  "waiting steps), local (edits of whole plans), skeleton (local search over the moves alone, then "
                  "clicks into its steps), paper (the paper's BFS over 10 actions), or auto (bfs, focused bfs, bfs "
                  "by moves, fill, beam, local, skeleton, best-first)")
      ->check(CLI::IsMember(agent::search_names()))
      ->default_val(d.search);
  cmd->add_option("--cost", o.cost, "Planning: what a plan costs: steps (every action) or moves (noop is free)")
      ->check(CLI::IsMember(agent::cost_names()))
      ->default_val(d.cost);
  cmd->add_option("--max-plan", o.max_plan, "Planning: plan length limit (steps)")
      ->default_val(d.max_plan)
      ->check(cli::int_count(1));
  cmd->add_option("--keep-states", o.keep_states,
                  "Planning: search environments kept in memory when the engine cannot snapshot states "
                  "(the others are replayed from the start when needed)")
      ->default_val(d.keep_states)
      ->check(cli::big_count());
  cmd->add_option("--time-limit", o.time_limit,
                  "Planning: seconds for the whole search before giving up (0: no limit). Focused BFS stages "
                  "get an eighth of the time left each, so slow engines reach best-first; a search the limit "
                  "cuts short may depend on machine speed and --threads")
      ->default_val(d.time_limit)
      ->check(cli::number_at_least(0, "NONNEGATIVE"));
}

// --protocol paper: the AutumnBench paper's simulator agent (docs/agent.md,
// "The paper's protocol"): 10,000 samples (MFP rollouts, change-detection
// particles) without seed inversion, the random exploration policy, and planning
// by plain BFS over ten actions to depth 10. An option given on the command line
// keeps its value.
void add_protocol_option(CLI::App* cmd, std::string& protocol) {
  cmd->add_option("--protocol", protocol,
                  "default: the agent as built; paper: the AutumnBench paper's simulator agent (10,000 samples "
                  "without seed inversion, random exploration, BFS over 10 actions to depth 10); options given "
                  "explicitly still apply")
      ->check(CLI::IsMember(agent::protocol_names()))
      ->default_val("default");
}

void apply_protocol(const CLI::App* cmd, const std::string& protocol, agent::SolveOptions& o) {
  if (protocol == "default") return;  // the options' own defaults are the default protocol's
  const agent::SolveOptions p = agent::protocol_options(protocol);
  auto given = [&](const char* flag) { return cmd->count(flag) > 0; };
  if (!given("--rollouts")) o.rollouts = p.rollouts;
  if (!given("--no-seed-inversion")) o.seed_inversion = p.seed_inversion;
  if (!given("--policy")) o.policy = p.policy;
  if (!given("--search")) o.search = p.search;
  if (!given("--depth")) o.depth = p.depth;
}

int command_failed(const std::string& cmd, const std::string& why) {
  std::string line = why;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::cerr << "autumn " << cmd << ": " << line << "\n";
  return 1;
}

// A progress bar on stderr: redrawn in place on a terminal, a line per item
// otherwise (logs).
std::function<void(size_t, size_t, const std::string&)> progress_bar() {
  const bool tty = isatty(2);
  return [tty](size_t i, size_t n, const std::string& name) {
    const int width = 30;
    int filled = n ? static_cast<int>(width * i / n) : width;
    std::string bar = std::string(filled, '#') + std::string(width - filled, '-');
    if (tty) {
      std::cerr << "\r\033[K[" << bar << "] " << i << "/" << n << (name.empty() ? "" : " " + name)
                << (i == n ? "\n" : "") << std::flush;
    } else if (i < n) {
      std::cerr << "[" << bar << "] " << i + 1 << "/" << n << " " << name << "\n";
    }
  };
}

// A file that exists and may be written, or a new one in a folder that may be.
bool can_write(const std::filesystem::path& p) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(p, ec)) return !fs::is_directory(p, ec) && access(p.c_str(), W_OK) == 0;
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  return fs::is_directory(dir, ec) && access(dir.c_str(), W_OK) == 0;
}

}  // namespace autumn::cli
