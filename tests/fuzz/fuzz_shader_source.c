/* libFuzzer target: the GLSL #include preprocessor and the log mapper. The
 * input is split at the first NUL into a main file and an included file. */
#include "fuzz_files.h"
#include "gfx/gfx.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  const char *dir = fuzz_dir("glsl");
  const unsigned char *inc;
  size_t inc_len, main_len = fuzz_split(data, size, &inc, &inc_len);
  fuzz_write(dir, "inc.glsl", inc, inc_len);
  char path[160];
  snprintf(path, sizeof path, "%s", fuzz_write(dir, "main.frag", data, main_len));
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
