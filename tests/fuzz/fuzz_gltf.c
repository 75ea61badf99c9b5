/* libFuzzer target: the glTF loader (.gltf JSON and .glb binary; the loader
 * tells them apart by content). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "scene/gltf.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  static char path[64];
  if (!path[0]) {
    char dir[] = "/tmp/limn-fuzz-gltf-XXXXXX";
    if (!mkdtemp(dir)) abort();
    snprintf(path, sizeof path, "%s/scene.glb", dir);
  }
  FILE *f = fopen(path, "wb");
  if (!f) abort();
  fwrite(data, 1, size, f);
  fclose(f);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (s) {
    float lo[3], hi[3];
    lm_scene_bounds(s, lo, hi);
    lm_scene_destroy(s);
  }
  return 0;
}
