/* libFuzzer target: the capture-job reader and the camera-list parser. The
 * input is split at its first NUL into a job file and a camera list; the job
 * may name "scene.gltf" (a small valid scene) and "scene.cams" (the list). */
#include "fuzz_files.h"
#include "job.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  static bool ready;
  const char *dir = fuzz_dir("job");
  if (!ready) {
    ready = true;
    lm_log_set_level(LM_LOG_QUIET);
    lm_error err;
    size_t n;
    char *scene = lm_read_file(LIMN_SOURCE_ROOT "/tests/fuzz/corpus/fuzz_gltf/triangle.gltf", &n, &err);
    if (!scene) abort();
    fuzz_write(dir, "scene.gltf", scene, n);
    free(scene);
  }
  const unsigned char *cams;
  size_t cams_len, job_len = fuzz_split(data, size, &cams, &cams_len);
  fuzz_write(dir, "scene.cams", cams, cams_len);
  char path[160];
  snprintf(path, sizeof path, "%s", fuzz_write(dir, "job.lua", data, job_len));
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
