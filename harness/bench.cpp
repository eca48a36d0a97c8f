#include "harness/bench.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>

#include "harness/engine.hpp"
#include "harness/policy.hpp"
#include "harness/program_files.hpp"

namespace autumn {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Steps per second over the action sequence, replayed from `start` until at
// least kMinSeconds have passed (a fast engine runs 300 steps in microseconds,
// too short to time once). `step` is Environment::step or ::advance. The first
// replay's step count goes to `done_first` and its environment, at the end of
// the run, to `end_first` (what the clone cost is measured on). With a cap, the
// first replay also stops once it has run `cap` seconds (looked at every
// kCapStride steps, so the clock costs nothing measurable): `done_first` then
// says how far it got.
constexpr double kMinSeconds = 0.2;
constexpr size_t kCapStride = 16;
template <class Step>
double rate(const Environment& start, const std::vector<Action>& actions, Step step, size_t* done_first,
            std::unique_ptr<Environment>* end_first, double cap = 0) {
  size_t steps = 0;
  double elapsed = 0;
  for (int rep = 0; rep == 0 || elapsed < kMinSeconds; ++rep) {
    auto env = start.clone();
    auto t0 = Clock::now();
    size_t done = 0;
    for (const Action& a : actions) {
      if (!step(*env, a)) break;
      ++done;
      if (cap > 0 && done % kCapStride == 0 && seconds_since(t0) > cap) break;
    }
    elapsed += seconds_since(t0);
    steps += done;
    if (rep == 0 && done_first) *done_first = done;
    if (rep == 0 && end_first) *end_first = std::move(env);
    if (done == 0 || done < actions.size()) break;
  }
  return elapsed > 0 ? steps / elapsed : 0;
}

// The action sequence: the random policy on the probe engine's frames (every
// engine shows the same frames, so the fastest one probes: the compiled engine
// when it is asked for). A runtime error ends it there (`stopped` says so), and
// so does the time cap (`capped`).
std::vector<Action> probe_actions(Environment& env, size_t steps, uint64_t seed, double cap, std::string* stopped,
                                  std::string* capped) {
  std::vector<Action> actions;
  auto probe = env.clone();
  RandomPolicy policy(seed + 101);
  const auto t0 = Clock::now();
  for (size_t i = 0; i < steps; ++i) {
    Action a = policy.next(probe->frame());
    if (!probe->step(a)) {
      *stopped = "stopped after " + std::to_string(actions.size()) + " of " + std::to_string(steps) +
                 " steps: " + probe->error();
      break;
    }
    actions.push_back(a);
    if (cap > 0 && actions.size() % kCapStride == 0 && actions.size() < steps && seconds_since(t0) > cap) {
      *capped = "choosing the actions took over " + fmt::format("{:g}", cap) + " s: timed over the first " +
                std::to_string(actions.size()) + " of " + std::to_string(steps) + " steps";
      break;
    }
  }
  return actions;
}

std::unique_ptr<Environment> started(const std::string& engine, const std::shared_ptr<const Program>& program,
                                     uint64_t seed, std::string* why) {
  auto env = make_environment(engine, program, why);
  if (env && !env->reset(seed)) {
    *why = env->error();
    env.reset();
  }
  return env;
}

}  // namespace

BenchRow bench_program(const std::string& name, const std::shared_ptr<const Program>& program,
                       const std::vector<std::string>& engines, size_t steps, uint64_t seed, double time_cap) {
  BenchRow row;
  row.program = name;
  // One action sequence for all engines; a runtime error before `steps` ends it
  // there, and every engine's figures then say so (they cover the steps before it).
  std::vector<Action> actions;
  std::string stopped;
  bool probed = false;
  const bool compiled_asked = std::find(engines.begin(), engines.end(), "compiled") != engines.end();
  const std::string probe_engine = compiled_asked ? "compiled" : engines.empty() ? "" : engines.front();
  if (!probe_engine.empty()) {
    std::string why;
    if (auto env = started(probe_engine, program, seed, &why)) {
      actions = probe_actions(*env, steps, seed, time_cap, &stopped, &row.note);
      probed = true;
    }
  }
  // Each engine in turn. An engine whose first timed replay passes the cap ends
  // the sequence where it stopped, and every engine is timed again over that
  // prefix, so the figures and their ratio always cover the same steps. The
  // prefix is what one replay did within the cap: the timing again is not
  // capped (the same replay could pass it by a hair and shrink it once more).
  double cap = time_cap;
  for (size_t i = 0; i < engines.size(); ++i) {
    const std::string& engine = engines[i];
    EngineFigures f;
    std::string why;
    auto env = started(engine, program, seed, &why);
    if (!env) {
      f.error = why;
      row.engines.push_back(f);
      continue;
    }
    row.grid = env->frame().size;
    if (!probed) {
      actions = probe_actions(*env, steps, seed, time_cap, &stopped, &row.note);
      probed = true;
    }
    auto start_state = env->clone();
    size_t done = 0;
    // With render (the protocol), then without.
    f.steps_per_s =
        rate(*start_state, actions, [](Environment& e, const Action& a) { return e.step(a); }, &done, &env, cap);
    if (cap > 0 && done < actions.size() && !env->failed()) {
      row.note = engine + " took over " + fmt::format("{:g}", time_cap) + " s to replay the actions: timed over the first " +
                 std::to_string(done) + " of " + std::to_string(steps) + " steps";
      actions.resize(done);  // done >= kCapStride: the cap is looked at after that many steps
      stopped.clear();
      row.engines.clear();
      cap = 0;
      i = static_cast<size_t>(-1);  // again, from the first engine, over the prefix
      continue;
    }
    f.steps_per_s_no_render =
        rate(*start_state, actions, [](Environment& e, const Action& a) { return e.advance(a); }, nullptr, nullptr);
    f.steps = done;
    // Clone cost, on the final state of the protocol run (env is now its first replay's).
    const int clones = 200;
    auto t0 = Clock::now();
    for (int k = 0; k < clones; ++k) {
      auto c = env->clone();
      (void)c;
    }
    f.clone_ns = seconds_since(t0) * 1e9 / clones;
    f.ok = done == actions.size() && stopped.empty();
    f.error = done != actions.size() ? env->error() : stopped;
    row.engines.push_back(f);
  }
  return row;
}

nlohmann::json bench_row_json(const BenchRow& row) {
  static const char* const kEngines[] = {"interp", "compiled"};
  const EngineFigures& in = row.engines.at(0);
  const EngineFigures& co = row.engines.at(1);
  const double ratio = in.ok && co.ok && in.steps_per_s > 0 ? co.steps_per_s / in.steps_per_s : 0;
  nlohmann::json r = {{"program", row.program}, {"grid", row.grid}, {"steps", in.steps}, {"ratio", ratio}};
  if (!row.note.empty()) r["note"] = row.note;
  for (size_t i = 0; i < 2; ++i)
    r[kEngines[i]] = {{"ok", row.engines[i].ok},
                      {"steps_per_s", row.engines[i].steps_per_s},
                      {"steps_per_s_no_render", row.engines[i].steps_per_s_no_render},
                      {"clone_ns", row.engines[i].clone_ns},
                      {"error", row.engines[i].error}};
  return r;
}

nlohmann::json bench_error_row(const std::string& program, const std::string& why) {
  return {{"program", program}, {"error", why}};
}

bool bench_row_ok(const nlohmann::json& row) {
  return !row.contains("error") && row.at("interp").at("ok").get<bool>() && row.at("compiled").at("ok").get<bool>();
}

nlohmann::json bench_report(const nlohmann::json& rows) {
  std::vector<double> ratios, compiled_us;
  for (const auto& r : rows)
    if (bench_row_ok(r) && r.at("ratio").get<double>() > 0) {
      ratios.push_back(r.at("ratio").get<double>());
      compiled_us.push_back(1e6 / r.at("compiled").at("steps_per_s").get<double>());
    }
  return {{"rows", rows}, {"median_ratio", median(ratios)}, {"median_compiled_step_us", median(compiled_us)}};
}

std::string bench_table(const nlohmann::json& report) {
  std::string s = fmt::format("{:<32} {:>4} {:>6} {:>13} {:>13} {:>13} {:>13} {:>12} {:>12} {:>8}\n", "program", "grid",
                              "steps", "interp st/s", "compiled st/s", "interp bare/s", "comp bare/s", "interp cl ns",
                              "comp cl ns", "ratio x");
  size_t counted = 0;
  for (const auto& r : report.at("rows")) {
    if (r.contains("error")) {
      s += fmt::format("{:<32} error: {}\n", r.at("program").get<std::string>(), r.at("error").get<std::string>());
      continue;
    }
    const auto& in = r.at("interp");
    const auto& co = r.at("compiled");
    s += fmt::format("{:<32} {:>4} {:>6} {:>13.0f} {:>13.0f} {:>13.0f} {:>13.0f} {:>12.0f} {:>12.0f} {:>7.1f}x\n",
                     r.at("program").get<std::string>(), r.at("grid").get<int>(), r.at("steps").get<size_t>(),
                     in.at("steps_per_s").get<double>(), co.at("steps_per_s").get<double>(),
                     in.at("steps_per_s_no_render").get<double>(), co.at("steps_per_s_no_render").get<double>(),
                     in.at("clone_ns").get<double>(), co.at("clone_ns").get<double>(), r.at("ratio").get<double>());
    if (r.contains("note")) s += fmt::format("  {}\n", r.at("note").get<std::string>());
    for (const char* e : {"interp", "compiled"})
      if (!r.at(e).at("error").get<std::string>().empty())
        s += fmt::format("  {}: {}\n", e, r.at(e).at("error").get<std::string>());
    counted += bench_row_ok(r) && r.at("ratio").get<double>() > 0;
  }
  s += fmt::format("median over {} programs: compiled/interp {:.1f}x, compiled step {:.2f} us (render included)\n",
                   counted, report.at("median_ratio").get<double>(), report.at("median_compiled_step_us").get<double>());
  return s;
}

}  // namespace autumn
