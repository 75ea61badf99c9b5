#define _GNU_SOURCE /* sched_getaffinity */
#include "core/core.h"

#include <errno.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

void lm_error_set(lm_error *err, const char *fmt, ...) {
  if (!err) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->msg, sizeof err->msg, fmt, ap);
  va_end(ap);
}

void lm_error_prefix(lm_error *err, const char *fmt, ...) {
  if (!err) return;
  char prefix[512], old[sizeof err->msg];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(prefix, sizeof prefix, fmt, ap);
  va_end(ap);
  memcpy(old, err->msg, sizeof old);
  snprintf(err->msg, sizeof err->msg, "%s: %s", prefix, old);
}

static lm_log_level log_level = LM_LOG_INFO;

void lm_log_set_level(lm_log_level level) { log_level = level; }
lm_log_level lm_log_get_level(void) { return log_level; }

void lm_log(lm_log_level level, const char *fmt, ...) {
  static const char *tag[] = {"debug: ", "", "warning: ", "error: "};
  if (level < log_level) return;
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "limn: %s", tag[level]);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}

static double clock_ms(clockid_t id) {
  struct timespec ts;
  clock_gettime(id, &ts);
  return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}
double lm_now_ms(void) { return clock_ms(CLOCK_MONOTONIC); }
double lm_cpu_ms(void) { return clock_ms(CLOCK_PROCESS_CPUTIME_ID); }
double lm_thread_cpu_ms(void) { return clock_ms(CLOCK_THREAD_CPUTIME_ID); }

int lm_cpu_count(void) {
  /* The affinity mask, not the machine's online count: a Slurm task, a
   * container or taskset may give this process fewer cores than exist. */
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? (int)n : 1;
}

char *lm_read_file(const char *path, size_t *len, lm_error *err) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    lm_error_set(err, "%s: cannot open: %s", path, strerror(errno));
    return NULL;
  }
  lm_buf b = {0};
  char chunk[65536];
  size_t n;
  while ((n = fread(chunk, 1, sizeof chunk, f)) > 0) lm_buf_append(&b, chunk, (int)n);
  bool failed = ferror(f);
  fclose(f);
  if (failed) {
    lm_error_set(err, "%s: read error", path);
    lm_buf_free(&b);
    return NULL;
  }
  if (!b.data) lm_buf_append(&b, "", 0);
  if (len) *len = (size_t)b.len;
  return b.data;
}

bool lm_file_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

void lm_dirname(const char *path, char *out, size_t cap) {
  const char *slash = strrchr(path, '/');
  if (!slash) {
    snprintf(out, cap, ".");
  } else if (slash == path) {
    snprintf(out, cap, "/");
  } else {
    snprintf(out, cap, "%.*s", (int)(slash - path), path);
  }
}

const char *lm_root_dir(void) {
  const char *env = getenv("LIMN_ROOT");
  return env && *env ? env : LIMN_SOURCE_ROOT;
}

uint64_t lm_hash(const void *data, size_t len, uint64_t seed) {
  const unsigned char *p = data;
  uint64_t h = seed;
  for (size_t i = 0; i < len; i++) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

static void *check(void *p, size_t size) {
  if (!p && size) {
    fprintf(stderr, "limn: out of memory (asked for %zu bytes)\n", size);
    abort();
  }
  return p;
}
void *lm_alloc(size_t size) { return check(calloc(1, size ? size : 1), size); }
void *lm_realloc(void *p, size_t size) { return check(realloc(p, size ? size : 1), size); }
char *lm_strdup(const char *s) {
  size_t n = strlen(s) + 1;
  return memcpy(lm_alloc(n), s, n);
}

void *lm_grow(void *items, int *cap, int need, size_t elem) {
  if (need <= *cap) return items;
  int old = *cap, n = old ? old * 2 : 8;
  while (n < need) n *= 2;
  items = lm_realloc(items, (size_t)n * elem);
  memset((char *)items + (size_t)old * elem, 0, (size_t)(n - old) * elem);
  *cap = n;
  return items;
}

void lm_buf_append(lm_buf *b, const char *s, int n) {
  if (n < 0) n = (int)strlen(s);
  b->data = lm_grow(b->data, &b->cap, b->len + n + 1, 1);
  memcpy(b->data + b->len, s, (size_t)n);
  b->len += n;
  b->data[b->len] = '\0';
}

void lm_buf_printf(lm_buf *b, const char *fmt, ...) {
  va_list ap, ap2;
  va_start(ap, fmt);
  va_copy(ap2, ap);
  int n = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  b->data = lm_grow(b->data, &b->cap, b->len + n + 1, 1);
  vsnprintf(b->data + b->len, (size_t)n + 1, fmt, ap2);
  va_end(ap2);
  b->len += n;
}

void lm_buf_free(lm_buf *b) {
  free(b->data);
  *b = (lm_buf){0};
}

struct lm_arena_block {
  lm_arena_block *next;
  size_t used, cap;
  _Alignas(16) unsigned char data[];
};

void *lm_arena_alloc(lm_arena *a, size_t size) {
  size = (size + 15) & ~(size_t)15;
  lm_arena_block *b = a->head;
  if (!b || b->used + size > b->cap) {
    size_t cap = size > 16384 ? size : 16384;
    b = lm_alloc(sizeof *b + cap);
    b->cap = cap;
    b->next = a->head;
    a->head = b;
  }
  void *p = b->data + b->used;
  b->used += size;
  memset(p, 0, size);
  return p;
}

char *lm_arena_strdup(lm_arena *a, const char *s) {
  size_t n = strlen(s) + 1;
  return memcpy(lm_arena_alloc(a, n), s, n);
}

void lm_arena_reset(lm_arena *a) {
  while (a->head) {
    lm_arena_block *next = a->head->next;
    free(a->head);
    a->head = next;
  }
}
