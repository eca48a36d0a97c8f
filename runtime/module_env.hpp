// module_env — an Environment backed by a compiled module's C ABI table.
//
// Owns one module environment handle. Frames are copied out of the module after
// each reset/step and colour names mirrored into a host-side Palette, so callers
// see an ordinary Environment. The host palette holds only the names frames have
// shown (colours, not every string of the program); it is shared between clones
// and copied only when one of them meets a colour the others have not named yet.
#pragma once
#include <functional>
#include <memory>
#include <string>

#include "runtime/environment.hpp"
#include "runtime/module_abi.h"

namespace autumn {

class ModuleEnvironment : public Environment {
 public:
  // `keepalive` holds whatever keeps the table's code loaded (a dlopen handle).
  ModuleEnvironment(const autumn_module_v1* table, std::shared_ptr<void> keepalive);
  ~ModuleEnvironment() override;
  void set_source_name(const std::string& path) override;
  void set_limits(const Limits& limits) override;
  // A module can serve a text that differs from the one it was built from only
  // in layout and comments (harness/module_key.hpp): the module moves its
  // program locations by `r` when it makes a message.
  void set_relocation(std::shared_ptr<const Relocation> r) override;
  ModuleEnvironment(const ModuleEnvironment&) = delete;
  ModuleEnvironment& operator=(const ModuleEnvironment&) = delete;

  bool reset(uint64_t seed) override;
  bool step(const Action& action) override;
  bool advance(const Action& action) override;
  const Frame& frame() const override {
    pull();
    return frame_;
  }
  int frame_side() const override;
  uint16_t frame_cell(size_t i) const override;
  const Palette& cell_palette() const override { return *palette_; }  // remap_'s ids are named in it
  const Palette& palette() const override {
    pull();
    return *palette_;
  }
  bool triggered() const override;
  int on_clause_count() const override;
  int covered_on_clause_count() const override;
  bool failed() const override { return failed_; }
  const std::string& error() const override { return error_; }
  std::unique_ptr<Environment> clone() const override;
  bool copy_from(const Environment& other) override;
  bool save_state(std::vector<uint8_t>& out) const override;
  bool load_state(const uint8_t* data, size_t size) override;
  uint64_t state_hash() const override;
  bool deterministic() const override;
  int64_t random_draws() const override;
  bool reseed_random(uint64_t seed) override;
  bool set_draw_script(autumn_draw_script* script) override;
  bool record_render(bool on) override;
  bool render_json(std::string* out) const override;

 private:
  ModuleEnvironment(const autumn_module_v1* table, std::shared_ptr<void> keepalive, autumn_env* handle);
  bool sync(int ok);
  void pull() const;  // copies the module's frame on first use after a step
  void name_colour(uint16_t module_id) const;
  static constexpr uint16_t kUnnamed = 0xffff;
  std::string module_error() const;

  const autumn_module_v1* table_;
  std::shared_ptr<void> keepalive_;
  autumn_env* handle_;
  mutable std::shared_ptr<Palette> palette_;  // copy-on-write between clones
  mutable std::vector<uint16_t> remap_;  // module palette id -> host palette id (kUnnamed: not yet shown)
  mutable bool remap_identity_ = true;   // remap_[i] == i for all i: frames below remap_.size() copy as they are
  mutable Frame frame_;
  mutable bool stale_ = true;
  bool failed_ = true;
  std::string error_ = "not started";
};

}  // namespace autumn
