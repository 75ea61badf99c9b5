/* libFuzzer target: the glTF loader (.gltf JSON and .glb binary; the loader
 * tells them apart by content). */
#include "fuzz_files.h"
#include "scene/gltf.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size) {
  const char *path = fuzz_write(fuzz_dir("gltf"), "scene.glb", data, size);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (s) {
    float lo[3], hi[3];
    lm_scene_bounds(s, lo, hi);
    lm_scene_destroy(s);
  }
  return 0;
}
