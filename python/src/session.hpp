// session — one episode driven the way the reference's Python Interpreter is.
//
// The session records every host call in a log (host_log.hpp) and keeps up to
// two engines behind it, each at its own position in the log:
//  * the compiled track, a compiled Environment, which can follow the log as
//    long as each step has at most one input and each step is followed by either
//    no render or one (any number when the program never draws a random number,
//    as renders are then idempotent); a pending step is run ahead on a copy so
//    that errors surface at step() and the copy is kept when a render follows;
//  * the interpreter track (interp_track.hpp), exact for any log, brought up to
//    date only when something needs it: evaluate_to_string, get_background, ...,
//    the render_all() JSON when the compiled track cannot give it (a module that
//    embeds the interpreter), or when the log leaves what the compiled track can
//    follow (then it serves alone). Both tracks write render_all() with
//    render_all_json (runtime/frame.hpp): cells per global, out-of-grid ones included.
// Both are exact, so which one answers never shows in the results; only speed
// and state_hash() values (engine-specific) differ. In "auto" mode a program
// whose module is still compiling runs on the interpreter, and the compiled
// track joins by replaying the log once the module is ready.
//
// Errors: a runtime error ends the episode; the call that met it and every
// later call that needs the state throw SessionError with the message.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "python/src/host_log.hpp"
#include "python/src/interp_track.hpp"
#include "python/src/module_broker.hpp"

namespace autumn::py {

struct SessionError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The digest of a program, its standard library and its trigger that saved
// states carry (Session::save, and EnvState's bytes in bind_envs.cpp): a state
// loads only into the program it was saved from.
uint64_t session_program_hash(const Program& p);

// The compiled track's part of a saved state (session_state.cpp).
struct CompiledSnapshot {
  uint64_t pos = 0;
  bool ahead = false;
  std::optional<Action> input;
  std::vector<uint8_t> bytes;
};

class Session {
 public:
  // engine: "auto", "compiled" (waits for the module; throws if none) or "interp".
  // compilable: false when the program uses a non-bundled standard library.
  Session(std::shared_ptr<const Program> program, uint64_t seed, const std::string& engine, bool compilable);
  Session(const Session& other);
  Session& operator=(Session&&) = default;

  void press(const Action& a);
  void step();
  std::string render_all();
  // A host render like render_all(), painted into the frame (for render_grid()).
  void render_frame(Frame& frame, Palette& palette);
  bool trigger_state();
  int on_clause_count();
  int covered_on_clause_count();
  std::string background();
  int frame_rate();
  void reseed(uint64_t seed);
  std::string evaluate(const std::string& text);
  std::string execute(const std::string& text);
  std::string environment_string();
  uint64_t state_hash();
  std::vector<uint8_t> save() const;
  void load(const uint8_t* data, size_t size);
  std::string engine() const;  // the engine serving steps now: "compiled" or "interp"
  const Program& program() const { return *program_; }

 private:
  void append(HostOp op);
  void attach_compiled_if_ready();
  void sync_compiled();
  bool step_compiled(size_t at);
  void kill_compiled();
  void probe_pending();
  const Environment* compiled_now();
  InterpTrack& interp();
  void check_interp(InterpTrack& t);
  void fail(const std::string& message);
  void parse_snippet(Snippet& s, bool statement) const;
  std::unique_ptr<Environment> load_snapshot(const CompiledSnapshot& snapshot);
  void restore_tracks(const CompiledSnapshot* snapshot, std::unique_ptr<Environment> loaded);
  void check_alive() const;

  std::shared_ptr<const Program> program_;
  uint64_t seed_;
  bool compilable_;
  std::string mode_;
  PrototypeFuture prototype_;
  HostLog log_;
  std::shared_ptr<Snippets> snippets_ = std::make_shared<Snippets>();
  bool failed_ = false;
  std::string error_;

  // compiled track
  std::unique_ptr<Environment> ce_;
  bool ce_dead_ = false;
  size_t ce_pos_ = 0;
  bool ce_ahead_ = true;               // it rendered once more than the log says (reset renders twice)
  std::optional<Action> ce_input_;     // inputs pressed since its last step
  std::unique_ptr<Environment> spec_;  // ce_ after the pending step at log_[spec_at_] and a render
  size_t spec_at_ = SIZE_MAX;

  // interpreter track
  std::unique_ptr<InterpTrack> it_;
};

}  // namespace autumn::py
