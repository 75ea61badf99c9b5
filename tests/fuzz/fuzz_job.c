/* libFuzzer target: the capture-job reader, the camera-list parser and
 * camera paths (a posed view must be finite). The input is split at its
 * first NUL into a job file and a camera list; the job may name "scene.gltf"
 * (a small valid scene) and "scene.cams" (the list). */
#include "fuzz_files.h"
#include "job.h"

#include <math.h>

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
    if (job_views(j, true, &views, &count, &err)) { /* outputs expanded too */
      for (int i = 0; i < count && i < 64; i++) { /* a path's or turntable's camera posed: finite */
        job_pose(j, &views[i]);
        const lm_scene *s = j->scenes[views[i].scene].scene;
        const lm_camera *c = &s->cameras[views[i].camera];
        for (int k = 0; k < 16; k++)
          if (!isfinite(s->nodes[c->node].world[k])) abort();
        if (!(c->fov_y > 0 && c->znear > 0 && c->zfar > c->znear)) abort();
      }
      free(views);
    }
    job_free_scenes(j);
  }
  free(j);
  return 0;
}
