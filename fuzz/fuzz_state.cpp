// fuzz_state — libFuzzer target: load_state() of every built-in module
// (generated/, one per program of programs/) on bytes it must not trust.
//
// Input: byte 0 picks the module, byte 1 the number of steps (0-7) taken from
// reset before a valid snapshot is saved, byte 2 the mutation. Even: the rest is
// a list of edits (u16 offset, xor byte) applied to the valid snapshot. Odd: the
// snapshot is cut to a u16 length (bytes 3-4) and the rest of the input is
// appended (truncations, trailing and arbitrary bytes). The mutated bytes must
// load or fail with a reason; a loaded state must step without a crash, save,
// and load again from its own bytes. The interpreter engine declines snapshots
// (its Python states are a host log: tests/python/test_envs.py); crashes and
// sanitizer reports are the findings.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <vector>

#include "harness/module_cache.hpp"
#include "runtime/module_env.hpp"

namespace {

using autumn::Action;

const autumn_module_v1* module_at(uint8_t pick) {
  static const autumn::BuiltinModules b = autumn::builtin_modules();
  return b.count ? b.entries[pick % b.count]() : nullptr;
}

Action action_of(int k, int grid) {
  if (k % 3 == 2) return Action::click((5 * k) % grid, (3 * k + 1) % grid);
  return Action{static_cast<Action::Kind>(k % 5)};
}

// The valid snapshot after `steps` steps from reset(1), cached per input pair.
const std::vector<uint8_t>& valid_snapshot(const autumn_module_v1* t, int steps) {
  static std::map<std::pair<const autumn_module_v1*, int>, std::vector<uint8_t>> cache;
  auto [it, fresh] = cache.try_emplace({t, steps});
  if (!fresh) return it->second;
  autumn::ModuleEnvironment env(t, nullptr);
  if (!env.reset(1)) std::abort();  // built-in programs start
  for (int k = 0; k < steps; ++k) env.step(action_of(k, env.frame().size));
  if (!env.failed() && !env.save_state(it->second)) std::abort();
  return it->second;
}

std::vector<uint8_t> mutated(const std::vector<uint8_t>& good, const uint8_t* d, size_t n) {
  std::vector<uint8_t> out = good;
  if (n == 0 || good.empty()) return out;
  if ((d[0] & 1) == 0) {
    for (size_t i = 1; i + 3 <= n; i += 3) out[(d[i] | d[i + 1] << 8) % out.size()] ^= d[i + 2];
    return out;
  }
  const size_t keep = n >= 3 ? static_cast<size_t>(d[1] | d[2] << 8) % (good.size() + 1) : good.size();
  out.resize(keep);
  if (n > 3) out.insert(out.end(), d + 3, d + n);
  return out;
}

// A loaded state steps, saves and reloads from its own bytes.
void exercise(autumn::ModuleEnvironment& env) {
  const int grid = env.frame().size;
  for (int k = 0; k < 6 && env.step(action_of(k, grid > 0 ? grid : 1)); ++k) {
  }
  if (env.failed()) return;
  std::vector<uint8_t> again;
  if (!env.save_state(again) || !env.load_state(again.data(), again.size())) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 3) return 0;
  const autumn_module_v1* t = module_at(data[0]);
  if (!t) return 0;
  const std::vector<uint8_t>& good = valid_snapshot(t, data[1] & 7);
  if (good.empty()) return 0;
  const std::vector<uint8_t> bytes = mutated(good, data + 2, size - 2);
  autumn::ModuleEnvironment env(t, nullptr);
  if (!env.reset(1)) std::abort();
  if (env.load_state(bytes.data(), bytes.size())) exercise(env);
  else if (env.error().empty()) std::abort();  // a refusal says why
  return 0;
}
