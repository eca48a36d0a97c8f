// module_export — the C ABI table of module_export.hpp: each entry unwraps the
// handle and calls the Environment's method. Compiled once here, in the runtime
// library every module links, rather than in each module.
#include "runtime/module_export.hpp"

namespace autumn {
namespace {

Environment& env(autumn_env* h) { return *reinterpret_cast<ExportedEnv*>(h)->env; }
const Environment& env(const autumn_env* h) { return *reinterpret_cast<const ExportedEnv*>(h)->env; }

Action action(int kind, int x, int y) {
  Action a;
  a.kind = static_cast<Action::Kind>(kind);
  a.x = x;
  a.y = y;
  return a;
}

}  // namespace

autumn_env* export_env(std::unique_ptr<Environment> e) {
  return reinterpret_cast<autumn_env*>(new ExportedEnv{std::move(e)});
}

autumn_module_v1 module_table(const char* name, uint64_t source_hash, autumn_env* (*create)()) {
  autumn_module_v1 t{};
  t.abi_version = AUTUMN_MODULE_ABI_VERSION;
  t.program_name = name;
  t.source_hash = source_hash;
  t.create = create;
  t.destroy = [](autumn_env* h) { delete reinterpret_cast<ExportedEnv*>(h); };
  t.reset = [](autumn_env* h, uint64_t seed) { return env(h).reset(seed) ? 1 : 0; };
  t.step = [](autumn_env* h, int kind, int x, int y) { return env(h).step(action(kind, x, y)) ? 1 : 0; };
  t.advance = [](autumn_env* h, int kind, int x, int y) { return env(h).advance(action(kind, x, y)) ? 1 : 0; };
  t.grid_size = [](const autumn_env* h) { return env(h).frame().size; };
  t.cells = [](const autumn_env* h) { return env(h).frame().cells.data(); };
  t.palette_size = [](const autumn_env* h) { return static_cast<int>(env(h).palette().size()); };
  t.palette_name = [](const autumn_env* h, int id) { return env(h).palette().name(static_cast<uint16_t>(id)).c_str(); };
  t.triggered = [](const autumn_env* h) { return env(h).triggered() ? 1 : 0; };
  t.on_clause_count = [](const autumn_env* h) { return env(h).on_clause_count(); };
  t.covered_on_clause_count = [](const autumn_env* h) { return env(h).covered_on_clause_count(); };
  t.error = [](const autumn_env* h) { return env(h).error().c_str(); };
  t.clone = [](const autumn_env* h) { return export_env(env(h).clone()); };
  t.state_hash = [](const autumn_env* h) { return env(h).state_hash(); };
  t.deterministic = [](const autumn_env* h) { return env(h).deterministic() ? 1 : 0; };
  t.copy_from = [](autumn_env* dst, const autumn_env* src) {
    if (!env(dst).copy_from(env(src))) reinterpret_cast<ExportedEnv*>(dst)->env = env(src).clone();
  };
  t.save_state = [](const autumn_env* h, const uint8_t** data) -> uint64_t {
    const auto* e = reinterpret_cast<const ExportedEnv*>(h);
    e->snapshot.clear();
    if (!e->env->save_state(e->snapshot)) return 0;
    *data = e->snapshot.data();
    return e->snapshot.size();
  };
  t.load_state = [](autumn_env* h, const uint8_t* data, uint64_t size) {
    // 0 (not supported) unless the load itself ended the episode: an environment
    // without snapshots changes nothing, failed or not.
    const std::string before = env(h).error();
    if (env(h).load_state(data, static_cast<size_t>(size))) return 1;
    return env(h).failed() && env(h).error() != before ? -1 : 0;
  };
  t.random_draws = [](const autumn_env* h) { return env(h).random_draws(); };
  t.reseed_random = [](autumn_env* h, uint64_t seed) { return env(h).reseed_random(seed) ? 1 : 0; };
  t.set_source_name = [](autumn_env* h, const char* path) { env(h).set_source_name(path); };
  t.set_limits = [](autumn_env* h, const autumn_limits* l) {
    env(h).set_limits(Limits{l->call_depth, l->list_length, l->objects, l->cells, l->calls});
  };
  t.set_draw_script = [](autumn_env* h, autumn_draw_script* s) { return env(h).set_draw_script(s) ? 1 : 0; };
  t.record_render = [](autumn_env* h, int on) { return env(h).record_render(on != 0) ? 1 : 0; };
  t.render_json = [](autumn_env* h) -> const char* {
    auto* e = reinterpret_cast<ExportedEnv*>(h);
    return e->env->render_json(&e->json) ? e->json.c_str() : nullptr;
  };
  t.set_relocation = [](autumn_env* h, const int32_t* moves, uint64_t count) {
    auto r = std::make_shared<Relocation>();
    for (uint64_t i = 0; i < count; ++i)
      r->moves.push_back({moves[4 * i], moves[4 * i + 1], moves[4 * i + 2], moves[4 * i + 3]});
    env(h).set_relocation(count ? std::move(r) : nullptr);
  };
  return t;
}

}  // namespace autumn
