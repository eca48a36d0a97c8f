/* module_abi.h — the versioned C ABI of a compiled Autumn environment module.
 *
 * A module built as a shared library exports one symbol, autumn_module_v1_entry,
 * returning a table of functions. Everything crosses the boundary as plain C:
 * opaque environment handles, integers, and strings/arrays owned by the module
 * that stay valid until the next call on the same handle. A module built into
 * the autumn binary exposes the same table under a per-module name instead.
 *
 * Bump AUTUMN_MODULE_ABI_VERSION for any change to the table; the loader refuses
 * a module whose abi_version differs.
 */
#ifndef AUTUMN_MODULE_ABI_H
#define AUTUMN_MODULE_ABI_H
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AUTUMN_MODULE_ABI_VERSION 8u

typedef struct autumn_env autumn_env; /* opaque */

/* v5: an episode's resource limits (runtime/limits.hpp: struct Limits, same order). */
typedef struct autumn_limits {
  int64_t call_depth, list_length, objects, cells, calls;
} autumn_limits;

/* v6: a draw script (runtime/rng.hpp): inference at the level of random numbers.
 * While a script is set on an environment, its k-th random draw (k = drawn, then
 * drawn is incremented) returns forced[k] % bound when k < forced_count and
 * forced[k] >= 0, and records its bound in bounds[k] when k < capacity. The
 * caller owns the script and keeps it alive while it is set. */
typedef struct autumn_draw_script {
  const int64_t* forced;
  uint64_t forced_count;
  uint64_t* bounds;
  uint64_t capacity;
  uint64_t drawn;
} autumn_draw_script;

/* Action kinds, as in runtime/action.hpp. */
enum { AUTUMN_NOOP = 0, AUTUMN_LEFT = 1, AUTUMN_RIGHT = 2, AUTUMN_UP = 3, AUTUMN_DOWN = 4, AUTUMN_CLICK = 5 };

typedef struct autumn_module_v1 {
  uint32_t abi_version;
  const char* program_name;
  uint64_t source_hash;  /* hash of the program text the module was built from */
  autumn_env* (*create)(void);
  void (*destroy)(autumn_env*);
  int (*reset)(autumn_env*, uint64_t seed);                 /* 1 ok, 0 the episode failed */
  int (*step)(autumn_env*, int kind, int x, int y);          /* 1 ok, 0 the episode failed */
  int (*advance)(autumn_env*, int kind, int x, int y);       /* step without the host render */
  int (*grid_size)(const autumn_env*);
  const uint16_t* (*cells)(const autumn_env*);               /* grid_size^2 palette ids, row-major */
  int (*palette_size)(const autumn_env*);
  const char* (*palette_name)(const autumn_env*, int id);
  int (*triggered)(const autumn_env*);
  int (*on_clause_count)(const autumn_env*);
  int (*covered_on_clause_count)(const autumn_env*);
  const char* (*error)(const autumn_env*);                   /* "" unless failed */
  autumn_env* (*clone)(const autumn_env*);
  uint64_t (*state_hash)(const autumn_env*);
  int (*deterministic)(const autumn_env*);
  /* v2: makes dst an exact copy of src (both from this table), reusing dst's buffers. */
  void (*copy_from)(autumn_env* dst, const autumn_env* src);
  /* v2: snapshots. save_state points *data at an encoding of the state (owned by
   * the module, valid until the next call on the handle) and returns its size; 0
   * when the environment cannot encode its state. load_state: 1 restored, 0 not
   * supported, -1 corrupt snapshot (the episode has failed; see error). */
  uint64_t (*save_state)(const autumn_env*, const uint8_t** data);
  int (*load_state)(autumn_env*, const uint8_t* data, uint64_t size);
  /* v3: seed groups (runtime/environment.hpp). random_draws: random numbers drawn
   * so far, -1 unsupported; reseed_random: 1 done, 0 unsupported or failed. */
  int64_t (*random_draws)(const autumn_env*);
  int (*reseed_random)(autumn_env*, uint64_t seed);
  /* v4: the program's path, named in runtime error messages (the module only knows
   * the text it was built from; one module serves every path with that text). */
  void (*set_source_name)(autumn_env*, const char* path);
  /* v5: the limits of the episodes from the next reset on (copied). */
  void (*set_limits)(autumn_env*, const autumn_limits* limits);
  /* v6: sets (or, with NULL, clears) the draw script; 1 done, 0 unsupported. */
  int (*set_draw_script)(autumn_env*, autumn_draw_script* script);
  /* v7: the reference's render_all() JSON (runtime/frame.hpp). record_render(1)
   * keeps the elements of every later host render (0 stops); 1 done, 0
   * unsupported. render_json: the JSON of the last host render while recording,
   * owned by the module until the next call on the handle; NULL when there is none. */
  int (*record_render)(autumn_env*, int on);
  const char* (*render_json)(autumn_env*);
  /* v8: where the program's locations moved (runtime/diagnostic.hpp, Relocation):
   * `count` moves of four ints (from line, from col, to line, to col), sorted by
   * their first two; copied. Error messages name the moved locations. */
  void (*set_relocation)(autumn_env*, const int32_t* moves, uint64_t count);
} autumn_module_v1;

typedef const autumn_module_v1* (*autumn_module_entry_fn)(void);

#ifdef __cplusplus
}
#endif
#endif
