#include "python/src/interp_track.hpp"

#include <cstdio>

namespace autumn::py {

InterpTrack::InterpTrack(std::shared_ptr<const Program> program, uint64_t seed)
    : program_(std::move(program)), it_(std::make_unique<interp::Interpreter>(program_)) {
  try {
    it_->start(seed);
  } catch (const interp::RuntimeError& e) {
    failed_ = true;
    error_ = it_->describe(e);
  }
}

InterpTrack::InterpTrack(const InterpTrack& o)
    : program_(o.program_),
      it_(o.it_->clone()),
      pos_(o.pos_),
      failed_(o.failed_),
      error_(o.error_),
      cells_(o.cells_),
      grid_size_(o.grid_size_),
      background_(o.background_) {}

void InterpTrack::catch_up(const HostLog& log, const Snippets& snippets) {
  while (!failed_ && pos_ < log.size()) {
    const HostOp& op = log[pos_++];
    try {
      apply(op, snippets);
    } catch (const interp::RuntimeError& e) {
      failed_ = true;
      error_ = it_->describe(e);
    } catch (const std::exception& e) {
      failed_ = true;
      error_ = program_->file.name + ": runtime error: " + e.what();
    }
  }
}

void InterpTrack::apply(const HostOp& op, const Snippets& snippets) {
  switch (op.kind) {
    case HostOp::Press: it_->press(op.input); return;
    case HostOp::Step: it_->step(Action::noop()); return;
    case HostOp::Render: render(); return;
    case HostOp::Reseed: it_->rng().reseed(op.arg); return;
    case HostOp::Eval: it_->evaluate_to_string(*snippets.items.at(op.arg)->expr); return;
    case HostOp::Exec: it_->execute_statement(*snippets.items.at(op.arg)->stmt); return;
  }
}

void InterpTrack::render() {
  std::vector<interp::RenderedCell> cells;
  grid_size_ = it_->render(&cells);
  cells_.clear();
  cells_.reserve(cells.size());
  for (const auto& c : cells) cells_.push_back(DrawnCell{c.x, c.y, c.name, *c.color});
  background_ = it_->background();
}

std::string InterpTrack::evaluate(const Snippet& s, bool* changed) {
  auto backup = it_->clone();
  const uint64_t before = it_->state_hash();
  try {
    std::string out = it_->evaluate_to_string(*s.expr);
    *changed = it_->state_hash() != before;
    return out;
  } catch (...) {
    it_ = std::move(backup);
    throw;
  }
}

void InterpTrack::execute(const Snippet& s) {
  auto backup = it_->clone();
  try {
    it_->execute_statement(*s.stmt);
  } catch (...) {
    it_ = std::move(backup);
    throw;
  }
}

// The reference's renderAll format (runtime/frame.hpp, render_all_json).
std::string InterpTrack::render_json() const {
  std::vector<NamedCell> cells;
  cells.reserve(cells_.size());
  for (const DrawnCell& c : cells_) cells.push_back({program_->name(c.name), c.x, c.y, c.colour});
  return render_all_json(cells, grid_size_);
}

void InterpTrack::paint(Frame& frame, Palette& palette) const {
  const int size = grid_size_;
  frame.size = size;
  frame.cells.assign(static_cast<size_t>(size) * size, palette.id(lower_ascii(background_)));
  for (const auto& c : cells_) {
    if (c.x < 0 || c.y < 0 || c.x >= size || c.y >= size) continue;
    const std::string& q = c.colour;
    std::string_view name = q.size() >= 2 ? std::string_view(q).substr(1, q.size() - 2) : std::string_view(q);
    frame.cells[static_cast<size_t>(c.y) * size + c.x] = palette.id(lower_ascii(name));
  }
}

}  // namespace autumn::py
