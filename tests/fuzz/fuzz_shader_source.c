/* libFuzzer target: the GLSL #include preprocessor and the log mapper. The
 * input is split at the first NUL into a main file and an included file. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gfx/gfx.h"

static char dir[64];

static void write_file(const char *name, const unsigned char *data, size_t n) {
  char path[128];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f) abort();
  fwrite(data, 1, n, f);
  fclose(f);
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  if (!dir[0]) {
    snprintf(dir, sizeof dir, "/tmp/limn-fuzz-glsl-XXXXXX");
    if (!mkdtemp(dir)) abort();
  }
  const unsigned char *nul = memchr(data, 0, size);
  size_t main_len = nul ? (size_t)(nul - data) : size;
  write_file("main.frag", data, main_len);
  write_file("inc.glsl", nul ? nul + 1 : data, nul ? size - main_len - 1 : 0);
  char path[128];
  snprintf(path, sizeof path, "%s/main.frag", dir);
  lm_shader_source src;
  lm_error err;
  if (lm_shader_source_load(&src, path, dir, "A=1;B", &err)) {
    /* Feed the same bytes as a compiler log. */
    char *log = malloc(size + 1);
    memcpy(log, data, size);
    log[size] = '\0';
    lm_buf out = {0};
    lm_shader_map_log(&src, log, &out);
    lm_buf_free(&out);
    free(log);
    lm_shader_source_free(&src);
  }
  return 0;
}
