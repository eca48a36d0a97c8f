// fuzz_interp — libFuzzer target: the interpreter, from program bytes and an
// action sequence.
//
// Input layout: PROGRAM ACTIONS N, where the last byte N gives the number of
// action bytes (N % 17) just before it; the rest is the program text. Each
// action byte is one host step (b % 6: noop, left, right, up, down, click; a
// click takes its x and y from the byte's high bits). The episode runs under
// small limits so that every input finishes quickly; halfway it is cloned and
// snapshotted (save_state, then load_state into a fresh environment), and the
// clone and the restored copy must continue exactly as the original (frames,
// trigger, hash, success and error text). A runtime error must be one located line.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "compiler/analyse/program.hpp"
#include "compiler/interpret/interpreted_env.hpp"

namespace {

using autumn::Action;

autumn::Limits fuzz_limits() {
  autumn::Limits l;
  l.call_depth = 250;  // see docs/design.md (Fuzzing): ASan makes each rethrow cost the depth of the stack
  l.list_length = 10'000;
  l.objects = 2'000;
  l.cells = 100'000;
  l.calls = 20'000;
  return l;
}

Action action_of(uint8_t b) {
  switch (b % 6) {
    case 0: return Action::noop();
    case 1: return Action{Action::Kind::Left, 0, 0};
    case 2: return Action{Action::Kind::Right, 0, 0};
    case 3: return Action{Action::Kind::Up, 0, 0};
    case 4: return Action{Action::Kind::Down, 0, 0};
    default: return Action::click((b >> 3) & 7, (b >> 5) & 7);
  }
}

void same_or_abort(const autumn::Environment& a, const autumn::Environment& b) {
  if (a.failed() != b.failed() || a.error() != b.error()) std::abort();
  if (a.failed()) return;
  if (a.frame().cells != b.frame().cells || a.frame().size != b.frame().size) std::abort();
  if (a.triggered() != b.triggered() || a.state_hash() != b.state_hash()) std::abort();
}

void check_error_text(const autumn::Environment& env) {
  const std::string& e = env.error();
  if (e.find('\n') != std::string::npos) std::abort();
  if (e.rfind("fuzz.au:", 0) != 0 && e.rfind("<stdlib>:", 0) != 0 && e.rfind("<trigger>:", 0) != 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const size_t n = std::min<size_t>(data[size - 1] % 17, size - 1);
  const std::string text(reinterpret_cast<const char*>(data), size - 1 - n);
  std::vector<Action> actions;
  for (size_t i = size - 1 - n; i < size - 1; ++i) actions.push_back(action_of(data[i]));
  std::shared_ptr<const autumn::Program> program;
  try {
    program = autumn::load_program(autumn::SourceFile{"fuzz.au", text});
  } catch (const autumn::CompileError&) {
    return 0;
  }
  autumn::InterpretedEnvironment env(program);
  env.set_limits(fuzz_limits());
  bool ok = env.reset(data[0]);
  std::unique_ptr<autumn::Environment> copy;
  std::unique_ptr<autumn::InterpretedEnvironment> restored;
  for (size_t i = 0; ok && i < actions.size(); ++i) {
    if (i == actions.size() / 2) {
      copy = env.clone();
      std::vector<uint8_t> snapshot;
      if (env.save_state(snapshot)) {
        restored = std::make_unique<autumn::InterpretedEnvironment>(program);
        restored->set_limits(fuzz_limits());
        if (!restored->reset(data[0]) || !restored->load_state(snapshot.data(), snapshot.size())) std::abort();
        same_or_abort(env, *restored);
      }
    }
    ok = env.step(actions[i]);
    for (autumn::Environment* other : {copy.get(), static_cast<autumn::Environment*>(restored.get())})
      if (other) {
        other->step(actions[i]);
        same_or_abort(env, *other);
      }
  }
  if (!ok) check_error_text(env);
  (void)env.state_hash();
  return 0;
}
