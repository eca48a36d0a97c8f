// interp_track — the reference-exact interpreter following a host log.
//
// An InterpTrack is one interp::Interpreter started with the session's seed and
// advanced through the host log (host_log.hpp) up to pos(): Press sets an input,
// Step steps, Render is the host render_all() (its cells are kept, with the
// global each came from, for the JSON), Reseed reseeds, Eval/Exec re-run their
// snippets. A runtime error ends the track: failed() and error() tell, and
// nothing more is applied (as after an error in the reference, the state is not
// to be trusted). evaluate()/execute() are the live calls: they restore the
// state from a copy when the code fails, so a bad expression costs nothing.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "compiler/interpret/interpreter.hpp"
#include "python/src/host_log.hpp"
#include "runtime/frame.hpp"

namespace autumn::py {

struct DrawnCell {
  int x, y;
  Sym name;
  std::string colour;  // with its quotes, as the reference prints it
};

class InterpTrack {
 public:
  InterpTrack(std::shared_ptr<const Program> program, uint64_t seed);
  InterpTrack(const InterpTrack& other);

  bool failed() const { return failed_; }
  const std::string& error() const { return error_; }
  size_t pos() const { return pos_; }
  // Applies log[pos()..end) (stopping at a failure; the failing entry counts as applied).
  void catch_up(const HostLog& log, const Snippets& snippets);

  // Live calls at the end of the log (the caller then appends their entry).
  // They throw interp::RuntimeError (state restored) and set *changed when the
  // state hash moved.
  std::string evaluate(const Snippet& s, bool* changed);
  void execute(const Snippet& s);
  void skip() { ++pos_; }  // an entry the caller has just applied through evaluate/execute

  std::string render_json() const;  // the last host render, in the reference's format
  void paint(Frame& frame, Palette& palette) const;  // the same render painted as the harness does
  interp::Interpreter& interpreter() { return *it_; }
  int grid_size() const { return grid_size_; }

 private:
  void apply(const HostOp& op, const Snippets& snippets);
  void render();

  std::shared_ptr<const Program> program_;
  std::unique_ptr<interp::Interpreter> it_;
  size_t pos_ = 0;
  bool failed_ = false;
  std::string error_;
  std::vector<DrawnCell> cells_;
  int grid_size_ = 0;
  std::string background_;  // `background` at the last render, for paint()
};

}  // namespace autumn::py
