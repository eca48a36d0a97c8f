#include "runtime/module_env.hpp"

#include <algorithm>
#include <typeinfo>

namespace autumn {

ModuleEnvironment::ModuleEnvironment(const autumn_module_v1* table, std::shared_ptr<void> keepalive)
    : ModuleEnvironment(table, std::move(keepalive), table->create()) {}

ModuleEnvironment::ModuleEnvironment(const autumn_module_v1* table, std::shared_ptr<void> keepalive,
                                     autumn_env* handle)
    : table_(table), keepalive_(std::move(keepalive)), handle_(handle), palette_(std::make_shared<Palette>()) {}

ModuleEnvironment::~ModuleEnvironment() {
  if (handle_) table_->destroy(handle_);
}

std::string ModuleEnvironment::module_error() const { return table_->error(handle_); }

void ModuleEnvironment::set_relocation(std::shared_ptr<const Relocation> r) {
  std::vector<int32_t> flat;
  if (r)
    for (const Relocation::Move& m : r->moves) flat.insert(flat.end(), {m.from_line, m.from_col, m.to_line, m.to_col});
  table_->set_relocation(handle_, flat.data(), flat.size() / 4);
}

bool ModuleEnvironment::sync(int ok) {
  failed_ = !ok;
  if (failed_) {
    error_ = module_error();
    return false;
  }
  if (!error_.empty()) error_.clear();
  stale_ = true;
  return true;
}

void ModuleEnvironment::pull() const {
  if (!stale_ || failed_) return;
  stale_ = false;
  frame_.size = table_->grid_size(handle_);
  const uint16_t* cells = table_->cells(handle_);
  const size_t count = static_cast<size_t>(frame_.size) * frame_.size;
  frame_.cells.resize(count);
  if (remap_identity_ && !remap_.empty()) {  // every id below remap_.size() named in order
    const uint16_t limit = static_cast<uint16_t>(remap_.size());
    size_t i = 0;
    for (; i < count && cells[i] < limit; ++i) frame_.cells[i] = cells[i];
    if (i == count) return;
  }
  for (size_t i = 0; i < count; ++i) {
    const uint16_t m = cells[i];
    if (m >= remap_.size() || remap_[m] == kUnnamed) name_colour(m);
    frame_.cells[i] = remap_[m];
  }
}

// Read from the module's frame while frame_ is stale. A colour not yet named
// pulls the whole frame instead, so that colours are named in the order pull()
// names them (row-major) however the cells are read.
int ModuleEnvironment::frame_side() const { return stale_ && !failed_ ? table_->grid_size(handle_) : frame_.size; }

uint16_t ModuleEnvironment::frame_cell(size_t i) const {
  if (stale_ && !failed_) {
    const uint16_t m = table_->cells(handle_)[i];
    if (m < remap_.size() && remap_[m] != kUnnamed) return remap_[m];
    pull();
  }
  return frame_.cells[i];
}

// A module's palette names every string of the program (a specialised module
// interns them all at start, "origin" and "left" included); the host palette
// takes a name only when a frame shows it, so that it holds colours only, as the
// interpreter's does.
void ModuleEnvironment::name_colour(uint16_t module_id) const {
  if (module_id >= remap_.size()) remap_.resize(module_id + 1, kUnnamed);
  if (palette_.use_count() > 1) palette_ = std::make_shared<Palette>(*palette_);
  remap_[module_id] = palette_->id(table_->palette_name(handle_, module_id));
  bool identity = true;
  for (size_t i = 0; i < remap_.size() && identity; ++i) identity = remap_[i] == i;
  remap_identity_ = identity;
}

bool ModuleEnvironment::reset(uint64_t seed) { return sync(table_->reset(handle_, seed)); }

bool ModuleEnvironment::step(const Action& a) {
  if (failed_) return false;
  return sync(table_->step(handle_, static_cast<int>(a.kind), a.x, a.y));
}

bool ModuleEnvironment::advance(const Action& a) {
  if (failed_) return false;
  failed_ = !table_->advance(handle_, static_cast<int>(a.kind), a.x, a.y);
  if (failed_) error_ = module_error();
  return !failed_;
}

bool ModuleEnvironment::triggered() const { return table_->triggered(handle_) != 0; }
int ModuleEnvironment::on_clause_count() const { return table_->on_clause_count(handle_); }
int ModuleEnvironment::covered_on_clause_count() const { return table_->covered_on_clause_count(handle_); }
uint64_t ModuleEnvironment::state_hash() const { return table_->state_hash(handle_); }
bool ModuleEnvironment::deterministic() const { return table_->deterministic(handle_) != 0; }
int64_t ModuleEnvironment::random_draws() const { return failed_ ? -1 : table_->random_draws(handle_); }
bool ModuleEnvironment::reseed_random(uint64_t seed) { return !failed_ && table_->reseed_random(handle_, seed) != 0; }
bool ModuleEnvironment::record_render(bool on) { return table_->record_render(handle_, on ? 1 : 0) != 0; }

bool ModuleEnvironment::render_json(std::string* out) const {
  if (failed_) return false;
  const char* json = table_->render_json(handle_);
  if (!json) return false;
  *out = json;
  return true;
}

bool ModuleEnvironment::set_draw_script(autumn_draw_script* script) {
  return table_->set_draw_script(handle_, script) != 0;
}
void ModuleEnvironment::set_source_name(const std::string& path) { table_->set_source_name(handle_, path.c_str()); }
void ModuleEnvironment::set_limits(const Limits& l) {
  const autumn_limits c{l.call_depth, l.list_length, l.objects, l.cells, l.calls};
  table_->set_limits(handle_, &c);
}

std::unique_ptr<Environment> ModuleEnvironment::clone() const {
  auto copy = std::unique_ptr<ModuleEnvironment>(
      new ModuleEnvironment(table_, keepalive_, table_->clone(handle_)));
  copy->palette_ = palette_;
  copy->remap_ = remap_;
  copy->remap_identity_ = remap_identity_;
  copy->frame_ = frame_;
  copy->stale_ = stale_;
  copy->failed_ = failed_;
  copy->error_ = error_;
  return copy;
}

bool ModuleEnvironment::copy_from(const Environment& other) {
  if (typeid(other) != typeid(ModuleEnvironment)) return false;  // not dynamic_cast: once per search successor
  auto* o = static_cast<const ModuleEnvironment*>(&other);
  if (o->table_ != table_) return false;
  if (o == this) return true;
  table_->copy_from(handle_, o->handle_);
  // Module palette ids may depend on the history (an embedded interpreter names
  // colours as it meets them), so the mapping comes along; the frame is pulled
  // again on demand. Comparing first keeps the shared count untouched in the
  // usual case, where every copy descends from one root.
  if (palette_ != o->palette_) palette_ = o->palette_;
  if (remap_ != o->remap_) {
    remap_ = o->remap_;
    remap_identity_ = o->remap_identity_;
  }
  stale_ = true;
  failed_ = o->failed_;
  error_ = o->error_;
  return true;
}

bool ModuleEnvironment::save_state(std::vector<uint8_t>& out) const {
  if (failed_) return false;
  const uint8_t* data = nullptr;
  const uint64_t n = table_->save_state(handle_, &data);
  if (n == 0) return false;
  out.insert(out.end(), data, data + n);
  return true;
}

bool ModuleEnvironment::load_state(const uint8_t* data, size_t size) {
  const int ok = table_->load_state(handle_, data, size);
  if (ok == 0) return false;
  return sync(ok > 0 ? 1 : 0);
}

}  // namespace autumn
