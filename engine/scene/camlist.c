/* Camera lists: the views a capture job renders, one per line, kept beside
 * a scene file (data/scenes/<name>.cams):
 *     # comment
 *     name  eye_x eye_y eye_z  target_x target_y target_z  fov_y_degrees [near far]
 * Each line becomes a camera (and its node) of the scene. */
#include "scene/scene.h"

#include <cglm/cglm.h>
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Centre and radius of the bounds of every mesh node (world space). */
static void scene_sphere(const lm_scene *s, vec3 centre, float *radius) {
  vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0 || n->mesh >= s->mesh_count) continue;
    const lm_scene_mesh *m = &s->meshes[n->mesh];
    for (int c = 0; c < 8; c++) {
      float p[3] = {m->bounds[c & 1][0], m->bounds[(c >> 1) & 1][1], m->bounds[(c >> 2) & 1][2]};
      for (int r = 0; r < 3; r++) {
        float w = n->world[r] * p[0] + n->world[4 + r] * p[1] + n->world[8 + r] * p[2] + n->world[12 + r];
        lo[r] = fminf(lo[r], w), hi[r] = fmaxf(hi[r], w);
      }
    }
  }
  if (!(lo[0] <= hi[0])) {
    glm_vec3_zero(centre);
    *radius = 1;
    return;
  }
  glm_vec3_center(lo, hi, centre);
  *radius = 0.5f * glm_vec3_distance(lo, hi);
  if (!(*radius > 0)) *radius = glm_vec3_norm(centre) > 0 ? 1e-3f * glm_vec3_norm(centre) : 1; /* one point */
}

void lm_camera_look_at(const float eye[3], const float target[3], float world[16]) {
  vec3 f, up = {0, 1, 0}, r, u;
  glm_vec3_sub((float *)target, (float *)eye, f);
  if (!(glm_vec3_norm(f) > 0)) glm_vec3_copy((vec3){0, 0, -1}, f);
  glm_vec3_normalize(f);
  /* The world's up while the view has any level part: its right is then level and turns with its
   * heading, up to the vertical (switching up at |f.y| 0.999 rolled a view from the -z side 180
   * degrees, a path or orbit near the vertical flipping between two frames). Straight down or up:
   * -z or +z, the limit of a view from the +z side. */
  if (!(f[0] * f[0] + f[2] * f[2] > 1e-12f)) up[1] = 0, up[2] = f[1] < 0 ? -1 : 1;
  glm_vec3_crossn(f, up, r);
  glm_vec3_cross(r, f, u);
  float m[16] = {r[0], r[1], r[2], 0, u[0], u[1], u[2], 0, -f[0], -f[1], -f[2], 0, eye[0], eye[1], eye[2], 1};
  memcpy(world, m, sizeof m);
}

int lm_scene_add_camera_list(lm_scene *s, const char *path, int *count, lm_error *err) {
  *count = 0;
  size_t len;
  char *text = lm_read_file(path, &len, err);
  if (!text) return -1;
  if (strlen(text) != len) {
    lm_error_set(err, "%s: not a text file (it holds a NUL byte)", path);
    free(text);
    return -1;
  }
  vec3 centre;
  float radius;
  scene_sphere(s, centre, &radius);
  int first = s->camera_count, line_no = 0;
  bool ok = true;
  for (char *line = text, *next; line && ok; line = next) {
    next = strchr(line, '\n');
    if (next) *next++ = '\0';
    line_no++;
    char *hash = strchr(line, '#');
    if (hash) *hash = '\0';
    char *tok[12];
    int n = 0;
    for (char *t = strtok(line, " \t\r"); t; t = strtok(NULL, " \t\r")) {
      if (n == 12) break;
      tok[n++] = t;
    }
    if (n == 0) continue;
    if (n != 8 && n != 10) {
      lm_error_set(err, "%s:%d: %d field%s; a view is: name eye_x eye_y eye_z target_x target_y target_z "
                   "fov_y_degrees [near far]", path, line_no, n, n == 1 ? "" : "s");
      ok = false;
      break;
    }
    if (strlen(tok[0]) >= LM_NAME_MAX) {
      lm_error_set(err, "%s:%d: view name '%.20s...' is longer than %d characters", path, line_no, tok[0],
                   LM_NAME_MAX - 1);
      ok = false;
      break;
    }
    float v[9] = {0};
    static const char *const field[] = {"eye_x", "eye_y", "eye_z", "target_x", "target_y", "target_z",
                                        "fov_y_degrees", "near", "far"};
    for (int i = 1; i < n && ok; i++) {
      char *end;
      double x = strtod(tok[i], &end);
      if (end == tok[i] || *end || !isfinite(x) || fabs(x) > 1e9) {
        lm_error_set(err, "%s:%d: view '%s': %s '%s' is not a number within +-1e9", path, line_no, tok[0],
                     field[i - 1], tok[i]);
        ok = false;
      }
      v[i - 1] = (float)x;
    }
    if (!ok) break;
    vec3 eye = {v[0], v[1], v[2]}, target = {v[3], v[4], v[5]};
    if (!(glm_vec3_distance(eye, target) > 1e-6f * fmaxf(glm_vec3_norm(eye), glm_vec3_norm(target)))) {
      lm_error_set(err, "%s:%d: view '%s': the eye is at the target", path, line_no, tok[0]);
      ok = false;
    } else if (!(v[6] > 0.1f && v[6] < 179.0f)) {
      lm_error_set(err, "%s:%d: view '%s': fov_y_degrees %g is outside (0.1, 179)", path, line_no, tok[0], v[6]);
      ok = false;
    } else if (n == 10 && !(v[7] > 0 && v[8] > v[7] * 1.001f)) {
      lm_error_set(err, "%s:%d: view '%s': want 0 < near < far, not %g and %g", path, line_no, tok[0], v[7], v[8]);
      ok = false;
    }
    if (!ok) break;
    float world[16];
    lm_camera_look_at(eye, target, world);
    lm_camera c = {.fov_y = glm_rad(v[6]), .znear = v[7], .zfar = v[8]};
    if (n == 8) { /* far enough for the whole scene, near a small part of that (any unit: */
      c.zfar = 1.5f * (glm_vec3_distance(eye, centre) + radius); /* reversed float depth */
      c.znear = c.zfar * 1e-4f;                                  /* holds any ratio) */
    }
    snprintf(c.name, sizeof c.name, "%s", tok[0]);
    c.node = lm_scene_add_node(s, c.name, -1, world, -1, -1);
    memcpy(s->nodes[c.node].world, world, sizeof world);
    lm_scene_add_camera(s, &c);
  }
  free(text);
  if (ok && s->camera_count == first) {
    lm_error_set(err, "%s: no views (each line: name eye_x eye_y eye_z target_x target_y target_z fov_y_degrees)", path);
    ok = false;
  }
  if (!ok) { /* leave the scene as it was */
    s->node_count -= s->camera_count - first;
    s->camera_count = first;
    return -1;
  }
  *count = s->camera_count - first;
  return first;
}
