/* The built-in scenes, made in code so that a capture and the tests need no file. */
#include "scene/scene.h"

#include <cglm/cglm.h>
#include <stdio.h>
#include <string.h>

/* A quad p0 p1 p2 p3, counter-clockwise seen from the side it faces. */
static int quad_mesh(lm_scene *s, const char *name, const float p[4][3]) {
  vec3 e1, e2, n;
  glm_vec3_sub((float *)p[1], (float *)p[0], e1);
  glm_vec3_sub((float *)p[3], (float *)p[0], e2);
  glm_vec3_crossn(e1, e2, n);
  static const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  float v[4 * 8];
  for (int i = 0; i < 4; i++) {
    float *o = v + i * 8;
    memcpy(o, p[i], 12);
    memcpy(o + 3, n, 12);
    memcpy(o + 6, uv[i], 8);
  }
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  return lm_scene_add_mesh(s, name, v, 4, idx, 6);
}

int lm_scene_add_cube(lm_scene *s, const char *name, float half) {
  float v[24 * 8];
  uint32_t idx[36];
  for (int face = 0; face < 6; face++) {
    int axis = face / 2;
    float sign = face % 2 ? -1.0f : 1.0f;
    vec3 n = {0, 0, 0}, a = {0, 0, 0}, b = {0, 0, 0};
    n[axis] = sign;
    a[(axis + 1) % 3] = 1;
    b[(axis + 2) % 3] = 1;
    if (sign < 0) glm_vec3_negate(a); /* keep counter-clockwise winding outside */
    static const float corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int c = 0; c < 4; c++) {
      float *o = v + (face * 4 + c) * 8;
      for (int k = 0; k < 3; k++) o[k] = half * (n[k] + a[k] * corner[c][0] + b[k] * corner[c][1]);
      memcpy(o + 3, n, 12);
      o[6] = corner[c][0] * 0.5f + 0.5f;
      o[7] = corner[c][1] * 0.5f + 0.5f;
    }
    static const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++) idx[face * 6 + k] = (uint32_t)(face * 4) + q[k];
  }
  return lm_scene_add_mesh(s, name, v, 24, idx, 36);
}

static void trs(vec3 t, float yaw_deg, vec3 scale, mat4 out) {
  glm_mat4_identity(out);
  glm_translate(out, t);
  glm_rotate_y(out, glm_rad(yaw_deg), out);
  glm_scale(out, scale);
}

/* The classic box: interior x in [-1, 1], y in [0, 2], z in [-1, 1], open
 * toward +z; red wall at -x, green at +x, a point light under the ceiling
 * with inverse-square falloff, so that limn export-pov matches it exactly
 * and the box has a POV-Ray reference (the seed's window falloff, eq 16,
 * stays with lm_light.falloff for glTF lights; the power keeps the image's
 * mean about where the seed's light had it).
 * pov: the same box with a brighter ceiling light and two more lights, a dim
 * parallel light through the open side and a spot (no falloff) on the tall
 * box, so that every light model the export claims is exercised
 * (test_pov_faithful); it stays apart so that the box itself keeps the
 * seed's one light, which the tests' images and shadow maps assume.
 * mirror: the pov box with its left wall a perfect mirror (black, no
 * diffuse or specular, reflectivity 1): ray-traced reflections against
 * POV-Ray's reflection of the same finish. */
static lm_scene *cornell(bool pov, bool mirror) {
  lm_scene *s = lm_scene_create(mirror ? "cornell_mirror" : pov ? "cornell_pov" : "cornell");
  lm_material white = {"white", {0.73f, 0.73f, 0.73f}, 0.73f, 1.0f, 1.0f, 0.0f, 1.0f, 0, 0};
  lm_material red = {"red", {0.63f, 0.065f, 0.05f}, 0.63f, 1.0f, 1.0f, 0.0f, 1.0f, 0, 0};
  lm_material green = {"green", {0.14f, 0.45f, 0.091f}, 0.45f, 1.0f, 1.0f, 0.0f, 1.0f, 0, 0};
  lm_material box = {"box", {0.73f, 0.73f, 0.73f}, 0.73f, 1.0f, 1.0f, 0.15f, 24.0f, 0, 0};
  int m_white = lm_scene_add_material(s, &white), m_red = lm_scene_add_material(s, &red);
  int m_green = lm_scene_add_material(s, &green), m_box = lm_scene_add_material(s, &box);
  if (mirror)
    m_red = lm_scene_add_material(s, &(lm_material){.name = "mirror", .ka = 1, .shininess = 1, .reflectivity = 1});

  const struct {
    const char *name;
    float p[4][3];
    int material;
  } walls[] = {
      {"floor", {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}}, m_white},
      {"ceiling", {{-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}}, m_white},
      {"back", {{-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}}, m_white},
      {"left", {{-1, 0, 1}, {-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}}, m_red},
      {"right", {{1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1}}, m_green},
  };
  mat4 id = GLM_MAT4_IDENTITY_INIT;
  for (size_t i = 0; i < sizeof walls / sizeof *walls; i++)
    lm_scene_add_node(s, walls[i].name, -1, (float *)id, quad_mesh(s, walls[i].name, walls[i].p),
                      walls[i].material);

  int cube = lm_scene_add_cube(s, "cube", 0.5f);
  mat4 m;
  trs((vec3){0.35f, 0.3f, 0.3f}, -17.0f, (vec3){0.6f, 0.6f, 0.6f}, m);
  lm_scene_add_node(s, "short_box", -1, (float *)m, cube, m_box);
  trs((vec3){-0.35f, 0.6f, -0.35f}, 17.0f, (vec3){0.6f, 1.2f, 0.6f}, m);
  lm_scene_add_node(s, "tall_box", -1, (float *)m, cube, m_box);

  glm_translate_make(m, (vec3){0.0f, 1.85f, 0.0f});
  glm_rotate_x(m, glm_rad(-90.0f), m); /* shine down (-Z of the node) */
  int light_node = lm_scene_add_node(s, "light", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "ceiling_light", .type = LM_LIGHT_POINT,
                                     .color = {1.0f, 0.95f, 0.85f}, .power = pov ? 2.4f : 1.4f,
                                     .radius = 4.0f, .inner_cone = glm_rad(30), .outer_cone = glm_rad(45),
                                     .falloff = LM_FALLOFF_INVERSE_SQUARE,
                                     .casts_shadows = true, .node = light_node});
  if (pov) {
    /* Parallel light from the open side, above and to the right, shining down into the box. */
    glm_mat4_identity(m);
    glm_rotate_y(m, glm_rad(20.0f), m);
    glm_rotate_x(m, glm_rad(-35.0f), m);
    int sun = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1);
    lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL,
                                       .color = {0.6f, 0.7f, 1.0f}, .power = 0.25f,
                                       .casts_shadows = true, .node = sun});
    /* Spot from the front right corner onto the tall box. */
    glm_lookat((vec3){0.8f, 1.7f, 0.9f}, (vec3){-0.35f, 0.8f, -0.35f}, (vec3){0, 1, 0}, m);
    glm_mat4_inv(m, m); /* lookat gives the view; the node holds its inverse */
    int spot = lm_scene_add_node(s, "spot", -1, (float *)m, -1, -1);
    lm_scene_add_light(s, &(lm_light){.name = "spot", .type = LM_LIGHT_SPOT, .color = {1.0f, 0.9f, 0.6f},
                                       .power = 0.5f, .inner_cone = glm_rad(8), .outer_cone = glm_rad(16),
                                       .falloff = LM_FALLOFF_NONE, .casts_shadows = true, .node = spot});
  }

  glm_translate_make(m, (vec3){0.0f, 1.0f, 3.4f});
  int cam_node = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "front", .fov_y = glm_rad(45.0f), .znear = 0.1f, .zfar = 20.0f,
                                      .node = cam_node});
  lm_scene_update(s);
  return s;
}

/* An open field for directional light and cascaded shadows: a 200 x 200
 * ground, rows of posts reaching far from the camera, a low sun. */
static lm_scene *field(void) {
  lm_scene *s = lm_scene_create("field");
  lm_material ground = {"ground", {0.45f, 0.5f, 0.35f}, 0.45f, 1.0f, 1.0f, 0.0f, 1.0f, 0, 0};
  lm_material post = {"post", {0.7f, 0.6f, 0.5f}, 0.6f, 1.0f, 1.0f, 0.1f, 16.0f, 0, 0};
  int m_ground = lm_scene_add_material(s, &ground), m_post = lm_scene_add_material(s, &post);
  const float g[4][3] = {{-100, 0, 100}, {100, 0, 100}, {100, 0, -100}, {-100, 0, -100}};
  mat4 id = GLM_MAT4_IDENTITY_INIT, m;
  lm_scene_add_node(s, "ground", -1, (float *)id, quad_mesh(s, "ground", g), m_ground);
  int cube = lm_scene_add_cube(s, "cube", 0.5f);
  for (int row = 0; row < 12; row++) {
    for (int col = -2; col <= 2; col++) {
      char name[32];
      snprintf(name, sizeof name, "post_%d_%d", row, col + 2);
      trs((vec3){col * 4.0f, 1.0f, 2.0f - row * 6.0f}, 10.0f * col, (vec3){0.6f, 2.0f, 0.6f}, m);
      lm_scene_add_node(s, name, -1, (float *)m, cube, m_post);
    }
  }
  glm_mat4_identity(m);
  glm_rotate_y(m, glm_rad(35.0f), m);
  glm_rotate_x(m, glm_rad(-40.0f), m); /* -Z points down and away */
  int sun = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1.0f, 0.95f, 0.9f},
                                     .power = 1.0f, .casts_shadows = true, .node = sun});
  glm_translate_make(m, (vec3){0.0f, 2.5f, 8.0f});
  glm_rotate_x(m, glm_rad(-8.0f), m);
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "front", .fov_y = glm_rad(50.0f), .znear = 0.1f,
                                      .zfar = 150.0f, .node = cam});
  lm_scene_update(s);
  return s;
}

const char *lm_scene_builtin_list(void) { return "cornell, cornell_pov, cornell_mirror, field"; }

lm_scene *lm_scene_builtin(const char *name, lm_error *err) {
  if (!strcmp(name, "cornell")) return cornell(false, false);
  if (!strcmp(name, "cornell_pov")) return cornell(true, false);
  if (!strcmp(name, "cornell_mirror")) return cornell(true, true);
  if (!strcmp(name, "field")) return field();
  lm_error_set(err, "unknown scene '%s' (built in: %s)", name, lm_scene_builtin_list());
  return NULL;
}
