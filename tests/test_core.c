#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/core.h"

static void buf_appends_and_formats(void **state) {
  (void)state;
  lm_buf b = {0};
  lm_buf_append(&b, "abc", -1);
  lm_buf_append(&b, "defgh", 2);
  lm_buf_printf(&b, "-%d-%s", 42, "x");
  assert_string_equal(b.data, "abcde-42-x");
  assert_int_equal(b.len, 10);
  for (int i = 0; i < 1000; i++) lm_buf_append(&b, "0123456789", 10);
  assert_int_equal(b.len, 10010);
  assert_int_equal((int)strlen(b.data), 10010);
  lm_buf_free(&b);
  assert_null(b.data);
}

static void grow_zeroes_new_slots(void **state) {
  (void)state;
  int *items = NULL, count = 0, cap = 0;
  for (int i = 0; i < 100; i++) assert_int_equal(*LM_PUSH(items, count, cap), 0), items[i] = i;
  assert_int_equal(count, 100);
  assert_true(cap >= 100);
  for (int i = 0; i < 100; i++) assert_int_equal(items[i], i);
  free(items);
}

static void arena_allocations_are_zeroed_and_aligned(void **state) {
  (void)state;
  lm_arena a = {0};
  for (int i = 1; i < 2000; i++) {
    unsigned char *p = lm_arena_alloc(&a, (size_t)i);
    assert_int_equal((uintptr_t)p % 16, 0);
    for (int k = 0; k < i; k++) assert_int_equal(p[k], 0);
    memset(p, 0xab, (size_t)i);
  }
  char *s = lm_arena_strdup(&a, "hello");
  assert_string_equal(s, "hello");
  lm_arena_reset(&a);
  assert_null(a.head);
}

static void hash_is_fnv1a(void **state) {
  (void)state;
  /* Published FNV-1a 64 test vectors. */
  assert_true(lm_hash("", 0, LM_HASH_SEED) == 0xcbf29ce484222325ull);
  assert_true(lm_hash("a", 1, LM_HASH_SEED) == 0xaf63dc4c8601ec8cull);
  assert_true(lm_hash("foobar", 6, LM_HASH_SEED) == 0x85944171f73967e8ull);
}

static void errors_prefix(void **state) {
  (void)state;
  lm_error e;
  lm_error_set(&e, "reads target '%s'", "x");
  lm_error_prefix(&e, "%s:%d", "pp.lua", 12);
  assert_string_equal(e.msg, "pp.lua:12: reads target 'x'");
}

static void files_read_and_dirname(void **state) {
  (void)state;
  lm_error err;
  assert_null(lm_read_file("/nonexistent/file", NULL, &err));
  assert_non_null(strstr(err.msg, "/nonexistent/file"));
  size_t len = 0;
  char *text = lm_read_file(LIMN_TEST_DIR "/test_core.c", &len, &err);
  assert_non_null(text);
  assert_true(len > 100 && strlen(text) == len);
  free(text);
  char dir[64];
  lm_dirname("a/b/c.lua", dir, sizeof dir);
  assert_string_equal(dir, "a/b");
  lm_dirname("c.lua", dir, sizeof dir);
  assert_string_equal(dir, ".");
  lm_dirname("/c.lua", dir, sizeof dir);
  assert_string_equal(dir, "/");
}

/* A write and a rename-over (how editors save) are both reported, once each. */
static void watch_sees_writes_and_renames(void **state) {
  (void)state;
  char dir[] = "/tmp/limn-watch-XXXXXX", path[512], got[600];
  assert_non_null(mkdtemp(dir));
  lm_error err;
  lm_watch *w = lm_watch_create(&err);
  assert_non_null(w);
  assert_false(lm_watch_dir(w, "/nonexistent/dir", &err));
  assert_non_null(strstr(err.msg, "/nonexistent/dir"));
  assert_true(lm_watch_dir(w, dir, &err));
  assert_false(lm_watch_next(w, got, sizeof got));
  snprintf(path, sizeof path, "%s/a.lua", dir);
  FILE *f = fopen(path, "w");
  fputs("x = 1\n", f);
  fclose(f);
  assert_true(lm_watch_next(w, got, sizeof got));
  assert_string_equal(got, path);
  assert_false(lm_watch_next(w, got, sizeof got));
  char tmp[520], b[520];
  snprintf(tmp, sizeof tmp, "%s/.b.tmp", dir);
  snprintf(b, sizeof b, "%s/b.glsl", dir);
  f = fopen(tmp, "w");
  fclose(f);
  assert_true(lm_watch_next(w, got, sizeof got)); /* the temporary file's write */
  assert_int_equal(rename(tmp, b), 0);
  assert_true(lm_watch_next(w, got, sizeof got));
  assert_string_equal(got, b);
  assert_false(lm_watch_next(w, got, sizeof got));
  lm_watch_destroy(w);
  unlink(path);
  unlink(b);
  rmdir(dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(buf_appends_and_formats),
      cmocka_unit_test(grow_zeroes_new_slots),
      cmocka_unit_test(arena_allocations_are_zeroed_and_aligned),
      cmocka_unit_test(hash_is_fnv1a),
      cmocka_unit_test(errors_prefix),
      cmocka_unit_test(files_read_and_dirname),
      cmocka_unit_test(watch_sees_writes_and_renames),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
