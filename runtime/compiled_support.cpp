// compiled_support — the parts of compiled_support.hpp that are the same for
// every program: error texts, snapshot headers, the state check's totals and
// the Environment adapter's bookkeeping and every member but the step
// (CompiledHost, CompiledProgramHost over a program's ProgramOps). They live here, once, in
// the runtime library every module links, so that a module's compile spends its
// time on the program's own code (docs/design.md, "Tests": a module compile was
// mostly this shared code, instantiated again per program).
//
// What stays in the header is what the hot loops call (occupancy, painter,
// hashing, the loop charge's fast path) and what depends on the program's types.
#include "runtime/compiled_support.hpp"

#include <tuple>

#include <mutex>

namespace autumn::rt {

std::string describe(const std::string& path, const ErrorSite& e, const std::string& msg, const Relocation* moved) {
  const char* file = e.in_program ? nullptr : e.source;
  int line = e.in_program ? e.program_line : e.line, col = e.in_program ? e.program_col : e.col;
  if (!file && moved) std::tie(line, col) = moved->at(line, col);
  std::string out = diagnostic_prefix(file ? file : path, line, col, "runtime error") + shown(e.prefix + msg);
  if (e.in_program && e.source && std::string(e.source) != "<internal>")
    out += diagnostic_inside(e.source, e.line, e.col);
  return out;
}

void Occupancy::sort_outside() const {
  std::sort(outside_.begin(), outside_.end());
  outside_.erase(std::unique(outside_.begin(), outside_.end()), outside_.end());
  sorted_ = true;
}

void fail_string_id(int32_t id) {
  fail("string id " + std::to_string(id) + " is not a string of this program (a corrupt state)");
}

void fail_at(int site, const std::string& msg) { throw LocatedError(site, msg); }
void fail_at(int site, const char* msg) { throw LocatedError(site, msg); }

void fail_list_length(int site, int64_t n, int64_t limit) { fail_at(site, limits::list_length_error(n, limit)); }

void fail_loop_budget(int site, int64_t limit) { fail_at(site, limits::loop_elements_error(limit)); }
// The interpreter's text: what specialised code charges is a part of what the
// interpreter counts (limits.hpp, cells), so past the budget both statements hold.
void fail_built_budget(int site, int64_t limit) { fail_at(site, limits::created_cells_error(limit)); }

Core::Core(const Core&) = default;
Core::Core(Core&&) noexcept = default;
Core& Core::operator=(const Core&) = default;
Core& Core::operator=(Core&&) noexcept = default;
Core::~Core() = default;

void fail_state_limit(const Core& c, const StateTally& s, bool objects) {
  if (objects) fail_at(s.site_objects, limits::objects_error(c.objects_limit, s.name_objects));
  fail_at(s.site_cells, limits::state_cells_error(c.cells_limit, s.name_cells));
}

void truncated_snapshot() { throw std::runtime_error("truncated state snapshot"); }

void corrupt_snapshot(const char* what) {
  throw std::runtime_error(std::string("corrupt state snapshot (") + what + ")");
}

// The header save_state writes (snapshot_header.hpp).
void check_snapshot_header(SnapshotReader& r, uint64_t layout) {
  uint32_t magic = 0, format = 0;
  uint64_t theirs = 0;
  static_assert(sizeof magic + sizeof format + sizeof theirs == kSnapshotHeaderBytes);
  if (static_cast<size_t>(r.end - r.p) < kSnapshotHeaderBytes)
    throw std::runtime_error("not a state snapshot of a compiled module (too short for its header)");
  r.raw(magic);
  if (magic != kSnapshotMagic) throw std::runtime_error("not a state snapshot of a compiled module (no AUTS header)");
  r.raw(format);
  if (format != kSnapshotFormat)
    throw std::runtime_error("a state snapshot of another autumnc version (snapshot format " + std::to_string(format) +
                             "; this one reads format " + std::to_string(kSnapshotFormat) + ")");
  r.raw(theirs);
  if (theirs != layout)
    throw std::runtime_error(
        "a state snapshot of another program, or of another build of this program's module (its layout differs)");
}

void save_core(SnapshotWriter& w, const Core& c) {
  w.raw(c.rng_at_render);  // load_state's render draws from here (Core::rng_at_render)
  save_value(w, c.click_x);
  save_value(w, c.click_y);
  save_value(w, c.have_prev);
  save_value(w, c.covered);
  save_value(w, c.triggered);
  w.raw(c.ids.next());
  w.raw(static_cast<uint32_t>(c.ids.remap().size()));
  for (const auto& [uid, id] : c.ids.remap()) {
    w.raw(uid);
    w.raw(id);
  }
  w.raw(static_cast<uint32_t>(c.rot.turns().size()));
  for (const auto& [group, turns] : c.rot.turns()) {
    w.raw(group);
    w.raw(turns);
  }
}

std::vector<std::pair<uint32_t, uint32_t>> load_sorted_pairs(SnapshotReader& r, const char* what) {
  uint32_t n = 0;
  r.raw(n);
  if (n > static_cast<size_t>(r.end - r.p) / 8) corrupt_snapshot(what);
  std::vector<std::pair<uint32_t, uint32_t>> out(n);
  for (size_t i = 0; i < out.size(); ++i) {
    r.raw(out[i].first);
    r.raw(out[i].second);
    if (i > 0 && out[i].first <= out[i - 1].first) corrupt_snapshot(what);
  }
  return out;
}

void load_core(SnapshotReader& r, Core& c, int on_clauses) {
  uint32_t rng = 0;
  r.raw(rng);
  c.rng.set_state(rng);
  c.rng_at_render = rng;
  c.clear_inputs();
  load_value(r, c.click_x);
  load_value(r, c.click_y);
  load_value(r, c.have_prev);
  load_value(r, c.covered);
  if (c.covered.size() != static_cast<size_t>(on_clauses)) corrupt_snapshot("on-clause count");
  for (uint8_t f : c.covered)
    if (f > 1) corrupt_snapshot("an on-clause flag is neither 0 nor 1");
  load_value(r, c.triggered);
  uint32_t next = 0;
  r.raw(next);
  auto remap = load_sorted_pairs(r, "identity table");
  c.ids.restore(next, std::move(remap));
  c.rot.restore(load_sorted_pairs(r, "rotation table"));
}

void save_value(SnapshotWriter& w, const GlobalOrder& o) {
  w.raw(static_cast<uint64_t>(o.map().bucket_count()));
  w.raw(static_cast<uint64_t>(o.map().next_resize()));
  w.raw(static_cast<uint32_t>(o.map().size()));
  for (int32_t k : o.keys()) {
    w.raw(k);
    w.raw(o.map().hash_of(k));
  }
}

void load_value(SnapshotReader& r, GlobalOrder& o) {
  uint64_t buckets = 0, resize = 0;
  uint32_t n = 0;
  r.raw(buckets);
  r.raw(resize);
  r.raw(n);
  if (n > static_cast<size_t>(r.end - r.p) / 12) corrupt_snapshot("global order");
  std::vector<std::pair<int, uint64_t>> keys(n);
  for (auto& [k, hash] : keys) {
    int32_t key = 0;
    r.raw(key);
    r.raw(hash);
    if (key < 0 || key >= kMaxOrderKey) corrupt_snapshot("a global's symbol out of range");
    k = key;
  }
  try {
    o.restore(buckets, resize, keys);
  } catch (const std::invalid_argument&) {
    corrupt_snapshot("global order");
  }
}

CompiledHost::~CompiledHost() = default;
CompiledHost::CompiledHost(const CompiledHost&) = default;

void CompiledHost::set_source_name(const std::string& path) { source_name_ = path; }

void CompiledHost::set_limits(const Limits& l) { limits_ = limits::normalised(l); }

void CompiledHost::copy_host(const CompiledHost& o) {
  frame_ = o.frame_;
  source_name_ = o.source_name_;
  relocation_ = o.relocation_;
  limits_ = o.limits_;
  painter_ = o.painter_;
  failed_ = o.failed_;
  error_ = o.error_;
}

// Rethrows what the caller's catch (...) holds, to tell the kinds apart here,
// once: a located error reads its site, anything else has no place.
void CompiledHost::fail_with_current(const ErrorSite* sites) {
  failed_ = true;
  try {
    throw;
  } catch (const LocatedError& e) {
    error_ = describe(source_name_, sites[e.site], e.what(), relocation_.get());
  } catch (const std::bad_alloc&) {
    error_ = diagnostic_prefix(source_name_, 0, 0, "runtime error") + "out of memory";
  } catch (const std::exception& e) {
    error_ = diagnostic_prefix(source_name_, 0, 0, "runtime error") + shown(e.what());
  } catch (...) {
    error_ = diagnostic_prefix(source_name_, 0, 0, "runtime error") + "unknown failure";
  }
}

namespace {

// The program's palette tables, made by its first environment.
std::shared_ptr<const PaletteTables> tables_of(const ProgramOps& ops) {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<const PaletteTables>& t = *ops.tables;
  if (!t) {
    auto fresh = std::make_shared<PaletteTables>();
    for (int i = 0; ops.colours[i] != nullptr; ++i) fresh->pal.push_back(fresh->palette.id(ops.colours[i]));
    t = std::move(fresh);
  }
  return t;
}

}  // namespace

CompiledProgramHost::CompiledProgramHost(const ProgramOps& ops, void* state, Core* core)
    : CompiledHost(ops.name), ops_(&ops), tables_(tables_of(ops)), state_(state), core_(core) {}
CompiledProgramHost::CompiledProgramHost(const CompiledProgramHost&) = default;
CompiledProgramHost::~CompiledProgramHost() = default;

bool CompiledProgramHost::reset(uint64_t seed) {
  ops_->clear(state_);
  Core& c = *core_;
  c.list_limit = limits_.list_length;
  c.objects_limit = limits_.objects;
  c.cells_limit = limits_.cells;
  c.visit_limit = limits_.calls;
  return guarded([&] {
    ops_->start(state_, seed);
    core_->begin_entry();
    painter_.bind(&frame_);
    core_->rng_at_render = core_->rng.state();
    ops_->render(state_, &painter_, tables_->pal);
  });
}

int CompiledProgramHost::covered_on_clause_count() const {
  int n = 0;
  for (uint8_t c : core_->covered) n += c;
  return n;
}

bool CompiledProgramHost::copy_from(const Environment& other) {
  // typeid, not dynamic_cast: this runs once per search successor. Equal
  // types are the same CompiledEnvironment<P>, so the same ProgramOps.
  if (typeid(other) != typeid(*this)) return false;
  auto* o = static_cast<const CompiledProgramHost*>(&other);
  if (o == this) return true;
  // Member by member, leaving tables_ alone: copying the shared_ptr would make
  // every search thread write the same reference count.
  ops_->assign(state_, o->state_);
  copy_host(*o);
  return true;
}

uint64_t CompiledProgramHost::state_hash() const { return failed_ ? 0 : ops_->hash(state_); }

bool CompiledProgramHost::save_state(std::vector<uint8_t>& out) const {
  if (failed_) return false;
  {
    SnapshotWriter w(out);
    w.raw(kSnapshotMagic);
    w.raw(kSnapshotFormat);
    w.raw(ops_->snapshot_layout);
    save_core(w, *core_);
    ops_->save(state_, w);
  }
  return true;
}

bool CompiledProgramHost::load_state(const uint8_t* data, size_t size) {
  return guarded([&] {
    SnapshotReader r{data, data + size};
    check_snapshot_header(r, ops_->snapshot_layout);
    load_core(r, *core_, ops_->on_clauses);
    ops_->load(state_, r);
    if (r.p != r.end) throw std::runtime_error("state snapshot has trailing bytes");
    painter_.bind(&frame_);
    core_->begin_entry();
    ops_->render(state_, &painter_, tables_->pal);
  });
}

int64_t CompiledProgramHost::random_draws() const { return failed_ ? -1 : static_cast<int64_t>(core_->rng.draws()); }

bool CompiledProgramHost::reseed_random(uint64_t seed) {
  if (failed_) return false;
  core_->rng.reseed(seed);
  return true;
}

// The generator keeps its script across reset() and copy_from() (rng.hpp).
bool CompiledProgramHost::render_json(std::string* out) const {
  if (failed_ || !painter_.recorded()) return false;
  std::vector<NamedCell> cells;
  cells.reserve(painter_.drawn().size());
  for (const Painter::Drawn& d : painter_.drawn())
    cells.push_back({ops_->render_names[d.global], d.position.x, d.position.y, ops_->string_text[d.colour]});
  *out = render_all_json(cells, frame_.size);
  return true;
}

bool CompiledProgramHost::set_draw_script(autumn_draw_script* script) {
  core_->rng.set_script(script);
  return true;
}

// Without a branch on the action's kind: a random action sequence (bench, a
// search's successors) mispredicted the switch this was on nearly every step,
// a third of particle_1's step (docs/design.md, "The light programs").
void CompiledProgramHost::latch(const Action& a) {
  Core& c = *core_;
  const Action::Kind k = a.kind;
  const bool click = k == Action::Kind::Click;
  c.left |= k == Action::Kind::Left;
  c.right |= k == Action::Kind::Right;
  c.up |= k == Action::Kind::Up;
  c.down |= k == Action::Kind::Down;
  c.click |= click;
  c.click_x = click ? a.x : c.click_x;
  c.click_y = click ? a.y : c.click_y;
}

}  // namespace autumn::rt
