/* Scene math: world transforms, the frame block's frustum rays (position
 * from linear depth, seed 000 eq 23-24), light data. No GL needed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <string.h>

#include "scene/scene.h"

/* Projects p with the frame's matrices, rebuilds it from uv and linear
 * depth / far the way shaders do, and returns the distance between the two. */
static float reconstruction_error(const lm_frame_data *f, const float p[3]) {
  vec4 world = {p[0], p[1], p[2], 1}, clip, view;
  glm_mat4_mulv((vec4 *)f->view_proj, world, clip);
  glm_mat4_mulv((vec4 *)f->view, world, view);
  float u = clip[0] / clip[3] * 0.5f + 0.5f, v = clip[1] / clip[3] * 0.5f + 0.5f;
  float depth01 = -view[2] / f->clip[1];
  float out[3];
  for (int i = 0; i < 3; i++)
    out[i] = f->camera_pos[i] + (f->frustum_o[i] + f->frustum_u[i] * u + f->frustum_v[i] * v) * depth01;
  return sqrtf((out[0] - p[0]) * (out[0] - p[0]) + (out[1] - p[1]) * (out[1] - p[1]) +
               (out[2] - p[2]) * (out[2] - p[2]));
}

static void positions_rebuild_from_linear_depth(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  lm_frame_data f;
  lm_scene_frame_data(s, 0, 256, 192, &f);
  static const float points[][3] = {{0, 1, 0}, {-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.5f}, {0.3f, 0.6f, 0.3f}};
  for (size_t i = 0; i < sizeof points / sizeof *points; i++)
    assert_true(reconstruction_error(&f, points[i]) < 1e-4f);
  assert_float_equal(f.camera_pos[2], 3.4f, 1e-5f);
  assert_float_equal(f.clip[2], 1.0f / f.clip[1], 1e-9f);
  /* A rotated camera, another aspect. */
  mat4 m;
  glm_translate_make(m, (vec3){1, 2, 3});
  glm_rotate_y(m, 0.7f, m);
  glm_rotate_x(m, -0.3f, m);
  memcpy(s->nodes[s->cameras[0].node].local, m, sizeof m);
  lm_scene_update(s);
  lm_scene_frame_data(s, 0, 100, 300, &f);
  float ahead[3] = {1 - sinf(0.7f) * 2, 2 - 0.6f, 3 - cosf(0.7f) * 2};
  assert_true(reconstruction_error(&f, ahead) < 1e-4f);
  lm_scene_destroy(s);
}

static void extreme_cameras_stay_finite(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  static const float cams[][3] = {{1e-4f, 1e-4f, 1e6f}, {3.2f, 0, 0}, {NAN, -1, INFINITY}, {0, 5, 5}};
  for (size_t i = 0; i < sizeof cams / sizeof *cams; i++) {
    s->cameras[0].fov_y = cams[i][0];
    s->cameras[0].znear = cams[i][1];
    s->cameras[0].zfar = cams[i][2];
    lm_frame_data f;
    lm_scene_frame_data(s, 0, 1, 1, &f);
    const float *all = (const float *)&f;
    for (size_t k = 0; k < offsetof(lm_frame_data, counts) / sizeof(float); k++)
      if (!isfinite(all[k])) fail_msg("camera %zu: value %zu is %g", i, k, all[k]);
    assert_true(f.clip[1] > f.clip[0] && f.clip[0] > 0);
  }
  lm_scene_destroy(s);
}

static void children_follow_their_parents(void **state) {
  (void)state;
  lm_scene *s = lm_scene_create("tree");
  mat4 a, b;
  glm_translate_make(a, (vec3){1, 0, 0});
  glm_rotate_z(a, GLM_PI_2f, a);
  glm_translate_make(b, (vec3){2, 0, 0});
  int root = lm_scene_add_node(s, "root", -1, (float *)a, -1, -1);
  int child = lm_scene_add_node(s, "child", root, (float *)b, -1, -1);
  lm_scene_add_node(s, "grandchild", child, (float *)b, -1, -1);
  lm_scene_update(s);
  /* root turns +x into +y: the child sits at (1, 2, 0), the grandchild at (1, 4, 0). */
  assert_float_equal(s->nodes[child].world[12], 1, 1e-5f);
  assert_float_equal(s->nodes[child].world[13], 2, 1e-5f);
  assert_float_equal(s->nodes[2].world[12], 1, 1e-5f);
  assert_float_equal(s->nodes[2].world[13], 4, 1e-5f);
  lm_scene_destroy(s);
}

/* The viewer flies a camera by world transform; a parented node gets the
 * local transform that puts it there, and its children follow. */
static void nodes_move_to_a_world_transform(void **state) {
  (void)state;
  lm_scene *s = lm_scene_create("fly");
  mat4 a, b, want;
  glm_translate_make(a, (vec3){1, 0, 0});
  glm_rotate_z(a, GLM_PI_2f, a);
  glm_translate_make(b, (vec3){2, 0, 0});
  int root = lm_scene_add_node(s, "root", -1, (float *)a, -1, -1);
  int cam = lm_scene_add_node(s, "camera", root, (float *)b, -1, -1);
  int child = lm_scene_add_node(s, "child", cam, (float *)b, -1, -1);
  lm_scene_update(s);
  glm_translate_make(want, (vec3){5, 6, 7});
  glm_rotate_y(want, 0.5f, want);
  lm_scene_node_set_world(s, cam, (float *)want);
  for (int i = 0; i < 16; i++) assert_float_equal(s->nodes[cam].world[i], ((float *)want)[i], 1e-5f);
  /* the child sits 2 along the camera's own +x */
  assert_float_equal(s->nodes[child].world[12], 5 + 2 * cosf(0.5f), 1e-5f);
  assert_float_equal(s->nodes[child].world[14], 7 - 2 * sinf(0.5f), 1e-5f);
  lm_scene_node_set_world(s, root, (float *)want); /* a root takes it as its local */
  assert_float_equal(s->nodes[root].local[12], 5, 0);
  lm_scene_node_set_world(s, 99, (float *)want);   /* no such node: nothing happens */
  lm_scene_destroy(s);
}

static void lights_take_position_and_direction_from_nodes(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  lm_light_data d[4];
  assert_int_equal(lm_scene_light_data(s, d, 4), 1);
  assert_float_equal(d[0].position[1], 1.85f, 1e-5f);
  assert_float_equal(d[0].direction[1], -1.0f, 1e-5f); /* shines down */
  assert_float_equal(d[0].color[3], 4.0f, 1e-6f);     /* radius */
  /* A node scaled to nothing still gives a unit direction. */
  memset(s->nodes[s->lights[0].node].local, 0, sizeof(float) * 12);
  lm_scene_update(s);
  lm_scene_light_data(s, d, 4);
  float len = sqrtf(d[0].direction[0] * d[0].direction[0] + d[0].direction[1] * d[0].direction[1] +
                    d[0].direction[2] * d[0].direction[2]);
  assert_float_equal(len, 1.0f, 1e-5f);
  lm_scene_destroy(s);
}

/* Scripts set a material's reflectivity per pass like any other parameter. */
static void reflectivity_is_a_material_parameter(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  lm_material_param ok = {"red", "reflectivity", 1, {0.5f}};
  assert_true(lm_scene_check_params(s, &ok, 1, &err));
  lm_material_param bad = {"red", "reflectivity", 3, {0.5f, 0, 0}};
  assert_false(lm_scene_check_params(s, &bad, 1, &err));
  assert_non_null(strstr(err.msg, "material 'red': parameter 'reflectivity' takes 1 number, not 3"));
  assert_float_equal(s->materials[lm_scene_find_material(s, "red")].reflectivity, 0, 0); /* built-ins: none */
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(positions_rebuild_from_linear_depth),
      cmocka_unit_test(reflectivity_is_a_material_parameter),
      cmocka_unit_test(extreme_cameras_stay_finite),
      cmocka_unit_test(children_follow_their_parents),
      cmocka_unit_test(nodes_move_to_a_world_transform),
      cmocka_unit_test(lights_take_position_and_direction_from_nodes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
