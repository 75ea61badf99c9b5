/* Scene math: world transforms, the frame block's frustum rays (position
 * from linear depth, seed 000 eq 23-24), light data. No GL needed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "image/image.h"
#include "scene/scene.h"
#include "scene/sky.h"

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

/* E(n) / pi from the sky's coefficients, as shaders/sky.glsl sums them. */
static void sky_at(const float sh[LM_SKY_SH], float x, float y, float z, float out[3]) {
  const float b[9] = {0.282094792f, 0.488602512f * y, 0.488602512f * z, 0.488602512f * x, 1.092548431f * x * y,
                      1.092548431f * y * z, 0.315391565f * (3 * z * z - 1), 1.092548431f * x * z,
                      0.546274215f * (x * x - y * y)};
  for (int k = 0; k < 3; k++) {
    out[k] = 0;
    for (int i = 0; i < 9; i++) out[k] += sh[k * 9 + i] * b[i];
  }
}

/* A uniform sky of radiance L gives every normal L (gi-scale.md: a plane of
 * albedo a under it sends a L); a sky bright at the zenith alone (L = y)
 * gives an upward normal 2/3, a sideways one 2 / (3 pi) and a downward one nothing, to the 3 bands'
 * accuracy; an equirectangular map of the same gradient gives the same
 * coefficients; a missing map or one holding NaN is refused by name. */
static void sky_harmonics_match_the_sky(void **state) {
  (void)state;
  float sh[LM_SKY_SH], e[3];
  lm_sky uniform = {{0.5f, 1.0f, 2.0f}, {0.5f, 1.0f, 2.0f}, 2.0f};
  lm_sky_sh_gradient(&uniform, sh);
  static const float normals[][3] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0, 0, -1}, {0.6f, 0.0f, 0.8f}};
  for (int i = 0; i < 5; i++) {
    sky_at(sh, normals[i][0], normals[i][1], normals[i][2], e);
    for (int k = 0; k < 3; k++) assert_float_equal(e[k], 2.0f * uniform.zenith[k], 2e-3f * uniform.zenith[k]);
  }
  lm_sky zenith = {{1, 1, 1}, {0, 0, 0}, 1.0f};
  lm_sky_sh_gradient(&zenith, sh);
  float up[3], down[3], side[3];
  sky_at(sh, 0, 1, 0, up);
  sky_at(sh, 0, -1, 0, down);
  sky_at(sh, 1, 0, 0, side);
  printf("zenith-only sky: up %.4f (exact 2/3), side %.4f (exact 2/(3 pi)), down %.4f (exact 0)\n", up[0], side[0], down[0]);
  assert_float_equal(up[0], 2.0f / 3.0f, 0.03f);
  assert_float_equal(side[0], 2.0f / (3.0f * GLM_PIf), 0.03f);
  assert_true(fabsf(down[0]) < 0.04f);
  /* The same gradient as a 128 x 64 map (rows from the zenith), with a blue tint. */
  enum { W = 128, H = 64 };
  static float texels[W * H * 3];
  for (int r = 0; r < H; r++)
    for (int c = 0; c < W; c++) {
      float y = cosf(GLM_PIf * ((float)r + 0.5f) / H), v = y > 0 ? y : 0;
      float *t = texels + ((size_t)r * W + (size_t)c) * 3;
      t[0] = t[1] = v, t[2] = 2 * v;
    }
  const char *path = "/tmp/limn-test-sky.exr";
  lm_error err;
  assert_true(lm_image_write(path, W, H, 3, true, texels, &err));
  float map[LM_SKY_SH];
  assert_true(lm_sky_sh_map(path, 1.0f, map, &err));
  for (int i = 0; i < 9; i++) {
    assert_float_equal(map[i], sh[i], 2e-3f);
    assert_float_equal(map[18 + i], 2 * sh[i], 4e-3f);
  }
  texels[5] = NAN;
  assert_true(lm_image_write(path, W, H, 3, true, texels, &err));
  assert_false(lm_sky_sh_map(path, 1.0f, map, &err));
  assert_non_null(strstr(err.msg, path));
  remove(path);
  assert_false(lm_sky_sh_map("/tmp/limn-no-such-sky.exr", 1.0f, map, &err));
  assert_non_null(strstr(err.msg, "limn-no-such-sky.exr"));
}

/* lm_box_outside_frustum (one plane test a side) says what transforming the
 * box's eight corners says: all of them beyond one clip plane. Boxes from
 * every side of a perspective and an orthographic view, those whose corners
 * come within 1e-3 of w of a plane left out (rounding may go either way there). */
static void boxes_outside_the_frustum_as_their_corners_say(void **state) {
  (void)state;
  mat4 proj[2], view, vp;
  glm_perspective(glm_rad(50), 4.0f / 3, 0.1f, 40, proj[0]);
  glm_ortho(-6, 6, -4, 4, -10, 30, proj[1]);
  glm_lookat((vec3){1, 2, 6}, (vec3){0, 0.5f, 0}, (vec3){0, 1, 0}, view);
  unsigned seed = 7;
  int checked = 0, outside = 0;
  for (int v = 0; v < 2; v++) {
    glm_mat4_mul(proj[v], view, vp);
    for (int i = 0; i < 4000; i++) {
      float lo[3], hi[3];
      for (int k = 0; k < 3; k++) {
        seed = seed * 1664525u + 1013904223u;
        float c = ((float)(seed >> 8) / 16777216.0f - 0.5f) * 24;
        seed = seed * 1664525u + 1013904223u;
        float e = (float)(seed >> 8) / 16777216.0f * 3;
        lo[k] = c - e, hi[k] = c + e;
      }
      int beyond[6] = {0};
      bool near = false;
      for (int c = 0; c < 8; c++) {
        vec4 p = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2], 1}, q;
        glm_mat4_mulv(vp, p, q);
        for (int k = 0; k < 3; k++) {
          beyond[2 * k] += q[3] + q[k] < 0, beyond[2 * k + 1] += q[3] - q[k] < 0;
          near |= fabsf(q[3] + q[k]) < 1e-3f || fabsf(q[3] - q[k]) < 1e-3f;
        }
      }
      if (near) continue;
      bool all = false;
      for (int k = 0; k < 6; k++) all |= beyond[k] == 8;
      assert_int_equal(lm_box_outside_frustum((float *)vp, lo, hi), all);
      checked++, outside += all;
    }
  }
  assert_true(checked > 7000 && outside > 1000 && outside < checked - 1000); /* both answers, often */
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
      cmocka_unit_test(sky_harmonics_match_the_sky),
      cmocka_unit_test(reflectivity_is_a_material_parameter),
      cmocka_unit_test(boxes_outside_the_frustum_as_their_corners_say),
      cmocka_unit_test(extreme_cameras_stay_finite),
      cmocka_unit_test(children_follow_their_parents),
      cmocka_unit_test(nodes_move_to_a_world_transform),
      cmocka_unit_test(lights_take_position_and_direction_from_nodes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
