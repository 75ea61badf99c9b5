/* core: errors with location, logging, clocks, files, hashing, growable
 * arrays and a frame arena. Everything above builds on these. */
#ifndef LIMN_CORE_H
#define LIMN_CORE_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- errors ------------------------------------------------------------
 * Functions that can fail for a user's reason return false (or NULL) and
 * fill an lm_error with one line: "where: what". */
typedef struct lm_error {
  char msg[2048];
} lm_error;

void lm_error_set(lm_error *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* Puts "prefix: " in front of the message already there. */
void lm_error_prefix(lm_error *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* ---- logging ----------------------------------------------------------- */
typedef enum { LM_LOG_DEBUG, LM_LOG_INFO, LM_LOG_WARN, LM_LOG_ERROR, LM_LOG_QUIET } lm_log_level;
void lm_log_set_level(lm_log_level level);
lm_log_level lm_log_get_level(void);
void lm_log(lm_log_level level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
#define lm_debug(...) lm_log(LM_LOG_DEBUG, __VA_ARGS__)
#define lm_info(...) lm_log(LM_LOG_INFO, __VA_ARGS__)
#define lm_warn(...) lm_log(LM_LOG_WARN, __VA_ARGS__)

/* ---- clocks ------------------------------------------------------------ */
double lm_now_ms(void);     /* CLOCK_MONOTONIC, milliseconds */
double lm_cpu_ms(void);     /* this process's CPU time, milliseconds */
double lm_thread_cpu_ms(void); /* the calling thread's CPU time, milliseconds */
int lm_cpu_count(void);     /* cores this process may run on (its affinity mask), at least 1 */

/* ---- files ------------------------------------------------------------- */
/* Reads a whole file, NUL-terminated; *len (may be NULL) gets its size. */
char *lm_read_file(const char *path, size_t *len, lm_error *err);
bool lm_file_exists(const char *path);
/* Directory part of a path ("." when none), written into out. */
void lm_dirname(const char *path, char *out, size_t cap);
/* The engine's root (holds shaders/ and scripts/): $LIMN_ROOT or the source tree. */
const char *lm_root_dir(void);

/* ---- file watching (Linux inotify) ------------------------------------ */
/* Reports files that were written (closed after writing) or renamed into a
 * watched folder, so editors that save by rename are seen too. */
typedef struct lm_watch lm_watch;
lm_watch *lm_watch_create(lm_error *err);
void lm_watch_destroy(lm_watch *w);
/* Watches every file directly in `dir` (not its subfolders). */
bool lm_watch_dir(lm_watch *w, const char *dir, lm_error *err);
/* Never blocks: writes the next changed file's path ("<dir>/<name>", dir as
 * given to lm_watch_dir) and returns true, or returns false when none is pending. */
bool lm_watch_next(lm_watch *w, char *path, size_t cap);

/* ---- hashing (FNV-1a, 64 bit) ----------------------------------------- */
uint64_t lm_hash(const void *data, size_t len, uint64_t seed);
#define LM_HASH_SEED 0xcbf29ce484222325ull

/* ---- memory ------------------------------------------------------------ */
/* Alignment of a field in a header C and C++ both read. */
#ifdef __cplusplus
#define LM_ALIGNED(n) alignas(n)
#else
#define LM_ALIGNED(n) _Alignas(n)
#endif
/* Allocation that cannot fail quietly: aborts with a message when out of memory. */
void *lm_alloc(size_t size);
void *lm_realloc(void *p, size_t size);
char *lm_strdup(const char *s);

/* Growable array: LM_PUSH(items, count, cap) returns a pointer to a new zeroed slot. */
void *lm_grow(void *items, int *cap, int need, size_t elem);
#define LM_PUSH(items, count, cap)                                          \
  ((items) = lm_grow((items), &(cap), (count) + 1, sizeof *(items)),        \
   &(items)[(count)++])

/* Growable string buffer. */
typedef struct lm_buf {
  char *data;
  int len, cap;
} lm_buf;
void lm_buf_append(lm_buf *b, const char *s, int n); /* n < 0: strlen */
void lm_buf_printf(lm_buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void lm_buf_free(lm_buf *b);

/* Arena: many small allocations freed together (one frame's recording). */
typedef struct lm_arena_block lm_arena_block;
typedef struct lm_arena {
  lm_arena_block *head;
} lm_arena;
void *lm_arena_alloc(lm_arena *a, size_t size);
char *lm_arena_strdup(lm_arena *a, const char *s);
void lm_arena_reset(lm_arena *a); /* frees every block */

#ifdef __cplusplus
}
#endif
#endif
