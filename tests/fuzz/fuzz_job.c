/* libFuzzer target: the capture-job reader and the camera-list parser. The
 * input is split at its first NUL into a job file and a camera list; the job
 * may name "scene.gltf" (a small valid scene) and "scene.cams" (the list). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "job.h"

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
    snprintf(dir, sizeof dir, "/tmp/limn-fuzz-job-XXXXXX");
    if (!mkdtemp(dir)) abort();
    lm_log_set_level(LM_LOG_QUIET);
    lm_error err;
    size_t n;
    char *scene = lm_read_file(LIMN_SOURCE_ROOT "/tests/fuzz/corpus/fuzz_gltf/triangle.gltf", &n, &err);
    if (!scene) abort();
    write_file("scene.gltf", (const unsigned char *)scene, n);
    free(scene);
  }
  const unsigned char *nul = memchr(data, 0, size);
  size_t job_len = nul ? (size_t)(nul - data) : size;
  write_file("job.lua", data, job_len);
  write_file("scene.cams", nul ? nul + 1 : data, nul ? size - job_len - 1 : 0);
  char path[128];
  snprintf(path, sizeof path, "%s/job.lua", dir);
  job *j = lm_alloc(sizeof *j);
  lm_error err;
  if (job_read(j, path, &err)) {
    job_view *views = NULL;
    int count = 0;
    if (job_views(j, true, &views, &count, &err)) free(views); /* outputs expanded too */
    job_free_scenes(j);
  }
  free(j);
  return 0;
}
