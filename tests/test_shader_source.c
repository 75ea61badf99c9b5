/* #include expansion and compiler-log mapping back to file:line (no GL).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gfx/gfx.h"

static char dir[256];

static void write_file(const char *name, const char *text) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static int setup(void **state) {
  (void)state;
  snprintf(dir, sizeof dir, "/tmp/limn-shader-XXXXXX");
  if (!mkdtemp(dir)) return -1;
  setenv("LIMN_ROOT", dir, 1); /* messages show paths relative to the root */
  char sub[512];
  snprintf(sub, sizeof sub, "%s/lib", dir);
  mkdir(sub, 0755);
  write_file("main.frag", "#version 330\n#include \"a.glsl\"\nvoid main() {}\n  #  include <lib/b.glsl>\nint z;\n");
  write_file("a.glsl", "float a;\n#include \"lib/b.glsl\"\nfloat a2;\n");
  write_file("lib/b.glsl", "float b;\n#include \"../a.glsl\"\n"); /* a cycle: included once */
  write_file("missing.frag", "float x;\n\n#include \"nope.glsl\"\n");
  write_file("malformed.frag", "#include nope.glsl\n");
  write_file("skipped.frag", "#ifdef NOPE\n#include \"a.glsl\"\n#endif\nfloat after;\n");
  return 0;
}

static int teardown(void **state) {
  (void)state;
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  return system(cmd);
}

/* The text of source string `file`, line `line`, found by following #line. */
static void assert_maps(const lm_shader_source *src, const char *needle, int file, int line) {
  const char *text = src->text.data;
  const char *hit = strstr(text, needle);
  assert_non_null(hit);
  int cur_file = -1, cur_line = 0;
  for (const char *p = text; p < hit;) {
    const char *nl = strchr(p, '\n');
    int f, l;
    if (sscanf(p, "#line %d %d", &l, &f) == 2) {
      cur_line = l;
      cur_file = f;
    } else {
      cur_line++;
    }
    p = nl + 1;
  }
  assert_int_equal(cur_file, file);
  assert_int_equal(cur_line, line);
}

static void includes_expand_once_with_line_directives(void **state) {
  (void)state;
  char path[512];
  snprintf(path, sizeof path, "%s/main.frag", dir);
  lm_shader_source src;
  lm_error err;
  assert_true(lm_shader_source_load(&src, path, dir, "FOO=2;BAR", &err));
  assert_true(strncmp(src.text.data, "#version 450 core\n#define FOO 2\n#define BAR\n", 44) == 0);
  assert_int_equal(src.file_count, 3);
  assert_non_null(strstr(src.files[1], "a.glsl"));
  assert_non_null(strstr(src.files[2], "b.glsl"));
  assert_maps(&src, "float a;", 1, 1);
  assert_maps(&src, "float b;", 2, 1);
  assert_maps(&src, "float a2;", 1, 3);
  assert_maps(&src, "void main", 0, 3);
  assert_maps(&src, "int z;", 0, 5);
  assert_null(strstr(src.text.data, "#version 330"));
  lm_shader_source_free(&src);
}

/* An #include in a group the preprocessor skips still adds its lines, and
 * the #line after it is skipped with them: the line after the group's end
 * sets the line again, so what follows maps to its own line. */
static void includes_in_skipped_groups_keep_lines(void **state) {
  (void)state;
  char path[512];
  snprintf(path, sizeof path, "%s/skipped.frag", dir);
  lm_shader_source src;
  lm_error err;
  assert_true(lm_shader_source_load(&src, path, dir, NULL, &err));
  assert_non_null(strstr(src.text.data, "#endif\n#line 4 0\nfloat after;"));
  lm_shader_source_free(&src);
}

static void missing_includes_name_file_and_line(void **state) {
  (void)state;
  char path[512];
  lm_shader_source src;
  lm_error err;
  snprintf(path, sizeof path, "%s/missing.frag", dir);
  assert_false(lm_shader_source_load(&src, path, dir, NULL, &err));
  assert_non_null(strstr(err.msg, "missing.frag:3: #include \"nope.glsl\": no such file"));
  snprintf(path, sizeof path, "%s/malformed.frag", dir);
  assert_false(lm_shader_source_load(&src, path, dir, NULL, &err));
  assert_non_null(strstr(err.msg, "malformed.frag:1: malformed #include"));
  snprintf(path, sizeof path, "%s/main.frag", dir);
  assert_false(lm_shader_source_load(&src, path, dir, "9BAD=1", &err));
  assert_non_null(strstr(err.msg, "'9BAD' is not a GLSL identifier"));
}

static void compiler_logs_map_to_files(void **state) {
  (void)state;
  char path[512];
  snprintf(path, sizeof path, "%s/main.frag", dir);
  lm_shader_source src;
  lm_error err;
  assert_true(lm_shader_source_load(&src, path, dir, NULL, &err));
  lm_buf out = {0};
  lm_shader_map_log(&src, "0:3(12): error: syntax error\n2:1(1): warning: unused\n", &out);
  assert_string_equal(out.data, "main.frag:3: error: syntax error\nlib/b.glsl:1: warning: unused\n");
  lm_buf_free(&out);
  lm_shader_map_log(&src, "1(3) : error C0000: syntax error, unexpected '}'\nnot a location\n", &out);
  assert_string_equal(out.data, "a.glsl:3: error C0000: syntax error, unexpected '}'\nnot a location\n");
  lm_buf_free(&out);
  lm_shader_map_log(&src, "7:3(1): error: beyond the file table\n", &out);
  assert_string_equal(out.data, "7:3(1): error: beyond the file table\n");
  lm_buf_free(&out);
  lm_shader_source_free(&src);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(includes_expand_once_with_line_directives),
      cmocka_unit_test(includes_in_skipped_groups_keep_lines),
      cmocka_unit_test(missing_includes_name_file_and_line),
      cmocka_unit_test(compiler_logs_map_to_files),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
