/* gltf_pose: prints the world matrix of every node of a glTF file posed at
 * the given times, and its cameras, as JSON (tools/blender_motion_check.sh
 * compares it with what Blender evaluates for the same export).
 *   gltf_pose FILE.glb [--animation NAME|INDEX|all] SECONDS...
 * Matrices are column-major, in the file's (glTF, y-up) space. Its JSON is
 * printed as limn bench --json prints its own, so they read alike. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf.h"
#include "tools.h"

int main(int argc, char **argv) {
  const char *spec = "all";
  int first = 2;
  if (argc > 3 && strcmp(argv[2], "--animation") == 0) {
    spec = argv[3];
    first = 4;
  }
  if (argc <= first || argv[1][0] == '-') {
    fprintf(stderr, "usage: gltf_pose FILE.glb [--animation NAME|INDEX|all] SECONDS...\n");
    return 2;
  }
  double *times = calloc((size_t)(argc - first), sizeof *times);
  int time_count = 0;
  for (int i = first; i < argc; i++) {
    char *end;
    times[time_count] = strtod(argv[i], &end);
    if (end == argv[i] || *end) {
      fprintf(stderr, "gltf_pose: argument %d: '%s' is not a time in seconds\n", i, argv[i]);
      free(times);
      return 2;
    }
    time_count++;
  }
  lm_error err = {0};
  lm_scene *s = lm_scene_load_gltf(argv[1], &err);
  if (!s) {
    fprintf(stderr, "gltf_pose: %s\n", err.msg);
    free(times);
    return 1;
  }
  int anim = lm_scene_animated(s) ? lm_scene_find_animation(s, spec, &err) : LM_ANIM_NONE;
  if (anim == -3) {
    fprintf(stderr, "gltf_pose: %s\n", err.msg);
    lm_scene_destroy(s);
    free(times);
    return 1;
  }
  printf("{\"cameras\": [");
  for (int c = 0; c < s->camera_count; c++) {
    const lm_camera *cam = &s->cameras[c];
    printf("%s{\"name\": ", c ? ", " : "");
    limn_json_string(cam->name);
    printf(", \"node\": ");
    limn_json_string(s->nodes[cam->node].name);
    printf(", \"fov_y\": %.9g, \"aspect\": %.9g, \"znear\": %.9g, \"zfar\": %.9g}", cam->fov_y, cam->aspect,
           cam->znear, cam->zfar);
  }
  printf("],\n \"times\": [");
  for (int t = 0; t < time_count; t++) printf("%s%.9g", t ? ", " : "", times[t]);
  printf("],\n \"nodes\": {");
  for (int n = 0; n < s->node_count; n++) {
    printf("%s\n  ", n ? "," : "");
    limn_json_string(s->nodes[n].name);
    printf(": [");
    for (int t = 0; t < time_count; t++) {
      lm_scene_set_time(s, anim, times[t]);
      printf("%s[", t ? ", " : "");
      for (int k = 0; k < 16; k++) printf("%s%.9g", k ? ", " : "", s->nodes[n].world[k]);
      printf("]");
    }
    printf("]");
  }
  printf("}}\n");
  lm_scene_destroy(s);
  free(times);
  return 0;
}
