// session_state — get_state()/set_state() bytes of a Session.
//
// A state is the episode itself: a digest of the program (text, standard
// library, trigger), the seed and the host log (with the text of evaluated
// expressions and executed statements), plus, when the compiled track can
// snapshot, its snapshot and position so that loading does not replay the
// episode. Any engine can load any state: without a usable snapshot the log is
// replayed. Layout (little-endian, as written by this machine): "AUTC" u32
// version, u64 digest, u64 seed, u64 entries, entries, u8 has_snapshot, [u64
// position, u8 ahead, u8 has_input, input, u64 size, bytes].
#include <cstring>
#include <functional>

#include "compiler/emit/emit_module.hpp"
#include "python/src/session.hpp"
#include "runtime/snapshot_header.hpp"

namespace autumn::py {
namespace {

constexpr uint32_t kVersion = 1;

struct Writer {
  std::vector<uint8_t> out;
  template <class T>
  void put(T v) {
    uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    out.insert(out.end(), b, b + sizeof(T));
  }
  void text(const std::string& s) {
    put<uint64_t>(s.size());
    out.insert(out.end(), s.begin(), s.end());
  }
  void action(const Action& a) {
    put<uint8_t>(static_cast<uint8_t>(a.kind));
    put<int32_t>(a.x);
    put<int32_t>(a.y);
  }
};

struct Reader {
  const uint8_t* p;
  size_t n;
  template <class T>
  T get() {
    if (n < sizeof(T)) throw std::invalid_argument("set_state: truncated state");
    T v;
    std::memcpy(&v, p, sizeof(T));
    p += sizeof(T);
    n -= sizeof(T);
    return v;
  }
  std::string text() {
    uint64_t len = get<uint64_t>();
    if (len > n) throw std::invalid_argument("set_state: truncated state");
    std::string s(reinterpret_cast<const char*>(p), len);
    p += len;
    n -= len;
    return s;
  }
  Action action() {
    uint8_t k = get<uint8_t>();
    if (k > static_cast<uint8_t>(Action::Kind::Click)) throw std::invalid_argument("set_state: corrupt state");
    Action a;
    a.kind = static_cast<Action::Kind>(k);
    a.x = get<int32_t>();
    a.y = get<int32_t>();
    return a;
  }
};

}  // namespace

uint64_t session_program_hash(const Program& p) {
  std::optional<std::string> trigger;
  if (!p.trigger_text.empty()) trigger = p.trigger_text;
  return module_source_hash(p.file.text, trigger) ^ (std::hash<std::string>{}(p.stdlib.text) * 0x9e3779b97f4a7c15ULL);
}

std::vector<uint8_t> Session::save() const {
  check_alive();
  Writer w;
  w.out.insert(w.out.end(), {'A', 'U', 'T', 'C'});
  w.put(kVersion);
  w.put(session_program_hash(*program_));
  w.put(seed_);
  w.put<uint64_t>(log_.size());
  for (const HostOp& op : log_) {
    w.put<uint8_t>(op.kind);
    w.put<uint8_t>(op.effect);
    if (op.kind == HostOp::Press) w.action(op.input);
    if (op.kind == HostOp::Reseed) w.put(op.arg);
    if (op.kind == HostOp::Eval || op.kind == HostOp::Exec) w.text(snippets_->items.at(op.arg)->text);
  }
  std::vector<uint8_t> snap;
  const bool has = ce_ && ce_->save_state(snap);
  w.put<uint8_t>(has);
  if (has) {
    w.put<uint64_t>(ce_pos_);
    w.put<uint8_t>(ce_ahead_);
    w.put<uint8_t>(ce_input_.has_value());
    w.action(ce_input_.value_or(Action::noop()));
    w.put<uint64_t>(snap.size());
    w.out.insert(w.out.end(), snap.begin(), snap.end());
  }
  return w.out;
}

void Session::load(const uint8_t* data, size_t size) {
  Reader r{data, size};
  if (size < 4 || std::memcmp(data, "AUTC", 4) != 0) throw std::invalid_argument("set_state: not an autumnc state");
  r.p += 4;
  r.n -= 4;
  if (r.get<uint32_t>() != kVersion) throw std::invalid_argument("set_state: a state of another autumnc version");
  if (r.get<uint64_t>() != session_program_hash(*program_))
    throw std::invalid_argument("set_state: the state belongs to another program, standard library or trigger");
  const uint64_t seed = r.get<uint64_t>();
  HostLog log;
  auto snippets = std::make_shared<Snippets>();
  const uint64_t entries = r.get<uint64_t>();
  for (uint64_t i = 0; i < entries; ++i) {
    HostOp op;
    uint8_t kind = r.get<uint8_t>();
    if (kind > HostOp::Exec) throw std::invalid_argument("set_state: corrupt state");
    op.kind = static_cast<HostOp::Kind>(kind);
    op.effect = r.get<uint8_t>() != 0;
    if (op.kind == HostOp::Press) op.input = r.action();
    if (op.kind == HostOp::Reseed) op.arg = r.get<uint64_t>();
    if (op.kind == HostOp::Eval || op.kind == HostOp::Exec) {
      auto s = std::make_shared<Snippet>();
      s->text = r.text();
      parse_snippet(*s, op.kind == HostOp::Exec);
      op.arg = snippets->add(s);
    }
    log.push_back(op);
  }
  std::optional<CompiledSnapshot> snap;
  if (r.get<uint8_t>()) {
    snap.emplace();
    snap->pos = r.get<uint64_t>();
    snap->ahead = r.get<uint8_t>() != 0;
    const bool has_input = r.get<uint8_t>() != 0;
    Action a = r.action();
    if (has_input) snap->input = a;
    const uint64_t len = r.get<uint64_t>();
    if (len > r.n || snap->pos > log.size()) throw std::invalid_argument("set_state: corrupt state");
    snap->bytes.assign(r.p, r.p + len);
  }
  std::unique_ptr<Environment> loaded = snap ? load_snapshot(*snap) : nullptr;
  seed_ = seed;
  log_ = std::move(log);
  snippets_ = std::move(snippets);
  restore_tracks(snap ? &*snap : nullptr, std::move(loaded));
}

// The compiled track loaded from a snapshot, before anything of the session
// changes: null when it cannot take one (replayed instead). A snapshot of
// another build of the module (its header names another format or layout,
// snapshot_header.hpp) is replayed too; one that claims this module's layout
// and fails its checks is corrupt, an error (ValueError), not a silent replay.
std::unique_ptr<Environment> Session::load_snapshot(const CompiledSnapshot& snap) {
  if (mode_ == "interp" || !compilable_ || !is_ready(prototype_)) return nullptr;
  std::shared_ptr<const Prototype> p = prototype_.get();
  std::unique_ptr<Environment> env = p->env ? instantiate(*p) : nullptr;
  if (!env) return nullptr;
  // Another build's state, or a module that cannot tell: the caller replays the log.
  if (rt::from_another_build(*env, snap.bytes.data(), snap.bytes.size()).value_or(true)) return nullptr;
  if (env->load_state(snap.bytes.data(), snap.bytes.size())) return env;
  if (env->failed()) throw std::invalid_argument("set_state: corrupt state (" + env->error() + ")");
  return nullptr;
}

void Session::restore_tracks(const CompiledSnapshot* snap, std::unique_ptr<Environment> env) {
  failed_ = false;
  error_.clear();
  it_.reset();
  ce_.reset();
  spec_.reset();
  spec_at_ = SIZE_MAX;
  ce_dead_ = mode_ == "interp" || !compilable_;
  ce_pos_ = 0;
  ce_ahead_ = true;
  ce_input_.reset();
  if (!ce_dead_ && snap && env) {
    ce_ = std::move(env);
    ce_pos_ = snap->pos;
    ce_ahead_ = snap->ahead;
    ce_input_ = snap->input;
    sync_compiled();
    probe_pending();
    return;
  }
  attach_compiled_if_ready();  // replays the log from the start
  if (!ce_) interp();
}

}  // namespace autumn::py
