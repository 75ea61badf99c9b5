/* Light culling (engine/scene/lightgrid.c): no cluster leaves out a light
 * that reaches a point of it, checked on the CPU at points just inside each
 * light's range and cone; and the Cornell box lit by many lights whose ranges
 * end on its walls renders as it does with every light evaluated everywhere;
 * spots of unbounded reach are culled by their cones.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gl_test.h"

static uint32_t rng = 12345;
static float uniform01(void) {
  rng = rng * 1664525u + 1013904223u;
  return (float)(rng >> 8) / 16777216.0f;
}

/* The Cornell box (x -1..1, y 0..2, z -1..1) with `count` extra lights
 * inside, each range ending just past the nearest wall (0.2% to 2% beyond),
 * every third a spot aimed at a wall; no shadows, so that only light
 * evaluation differs. */
static lm_scene *box_with_lights(int count) {
  rng = 12345; /* the same lights in every test */
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  s->lights[0].casts_shadows = false;
  mat4 sun;
  glm_rotate_make(sun, glm_rad(-60.0f), (vec3){1, 0.3f, 0}); /* listed for every cluster */
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {0.2f, 0.2f, 0.3f},
                                    .power = 1, .node = lm_scene_add_node(s, "sun", -1, (float *)sun, -1, -1)});
  for (int i = 0; i < count; i++) {
    float p[3] = {-0.9f + 1.8f * uniform01(), 0.1f + 1.8f * uniform01(), -0.9f + 1.8f * uniform01()};
    float wall = fminf(fminf(1 - fabsf(p[0]), fminf(p[1], 2 - p[1])), 1 - fabsf(p[2]));
    mat4 m;
    glm_translate_make(m, p);
    glm_rotate_x(m, glm_rad(-90.0f + 60.0f * uniform01()), m); /* mostly down */
    char name[32];
    snprintf(name, sizeof name, "light_%d", i);
    int node = lm_scene_add_node(s, name, -1, (float *)m, -1, -1);
    float hue = uniform01();
    lm_scene_add_light(s, &(lm_light){.name = "", .type = i % 3 == 2 ? LM_LIGHT_SPOT : LM_LIGHT_POINT,
                                      .color = {0.5f + hue, 1.0f, 1.5f - hue}, .power = 20.0f,
                                      .radius = wall * (1.002f + 0.018f * uniform01()),
                                      .inner_cone = 0.3f, .outer_cone = 0.6f, .node = node});
  }
  lm_scene_update(s);
  return s;
}

/* Does light l's falloff and cone give anything at p? */
static bool reaches(const lm_light_data *l, const float p[3]) {
  float d[3] = {p[0] - l->position[0], p[1] - l->position[1], p[2] - l->position[2]};
  float dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(dist < lm_light_data_reach(l))) return false;
  if ((int)(l->position[3] + 0.5f) != LM_LIGHT_SPOT) return true;
  float along = d[0] * l->direction[0] + d[1] * l->direction[1] + d[2] * l->direction[2];
  return along > l->direction[3] * dist;
}

/* Points at 99.9% of each light's range (and anywhere inside), inside its
 * cone, that a pixel of camera `cam`'s view sees: each light must be in the
 * point's cluster. Returns how many points were checked. */
static long check_listed(lm_scene *s, int cam) {
  enum { W = 96, H = 72, MAX = 64 };
  lm_frame_data f;
  lm_scene_frame_data(s, cam, W, H, &f);
  lm_light_data lights[MAX];
  int n = lm_scene_light_data(s, lights, MAX);
  assert_int_equal(n, 42);
  lm_light_grid g = {0};
  lm_light_grid_build(&g, &f, lights, n, true);
  assert_true(g.tile_px > 0);
  /* The box's inverse-square light and the sun reach everywhere: in every cluster. */
  assert_int_equal(g.global, 2);
  for (int c = 0; c < g.tiles_x * g.tiles_y * g.slices; c++)
    assert_true(lm_light_grid_has(&g, c, 0) && lm_light_grid_has(&g, c, 1));
  /* Culling does something: a cluster lists a small share of the lights. */
  double mean = (double)g.listed / (g.tiles_x * g.tiles_y * g.slices);
  printf("camera %d: lights a cluster lists: %.2f on average of %d\n", cam, mean, n);
  assert_true(mean < n / 4.0);
  long checked = 0;
  for (int i = 0; i < n; i++) {
    float reach = lm_light_data_reach(&lights[i]);
    if (isinf(reach)) continue;
    for (int k = 0; k < 4000; k++) {
      /* A point at 99.9% of the range (most), or anywhere inside. */
      float u = 2 * uniform01() - 1, a = 2 * GLM_PIf * uniform01(), rr = sqrtf(fmaxf(0, 1 - u * u));
      float t = k % 4 ? 0.999f : uniform01();
      float p[3] = {lights[i].position[0] + reach * t * rr * cosf(a), lights[i].position[1] + reach * t * rr * sinf(a),
                    lights[i].position[2] + reach * t * u};
      if (!reaches(&lights[i], p)) continue;
      vec4 c, wp = {p[0], p[1], p[2], 1};
      glm_mat4_mulv((vec4 *)f.view_proj, wp, c);
      if (!(c[3] > 0)) continue;
      float x = (c[0] / c[3] * 0.5f + 0.5f) * W, y = (c[1] / c[3] * 0.5f + 0.5f) * H;
      if (x < 0 || y < 0 || x >= W || y >= H) continue; /* off screen: no pixel */
      int cluster = lm_light_grid_cluster(&g, x, y, c[3] / f.clip[1]);
      if (cluster < 0) continue;
      checked++;
      if (!lm_light_grid_has(&g, cluster, i))
        fail_msg("camera %d: light %d (reach %g) left out of cluster %d at (%g, %g, %g)", cam, i, reach, cluster, p[0],
                 p[1], p[2]);
    }
  }
  /* Off: no grid, every pixel evaluates every light. */
  lm_light_grid_build(&g, &f, lights, n, false);
  assert_int_equal(lm_light_grid_cluster(&g, 10, 10, 0.5f), -1);
  assert_int_equal(lm_light_grid_count(&g, -1, n), n);
  lm_light_grid_free(&g);
  return checked;
}

/* From the box's camera, and from inside the box among the lights (some
 * behind the eye, some reaching over the near plane). */
static void every_reaching_light_is_listed(void **state) {
  (void)state;
  lm_scene *s = box_with_lights(40);
  mat4 m;
  glm_translate_make(m, (vec3){0.1f, 1.0f, 0.2f});
  glm_rotate_y(m, glm_rad(30.0f), m);
  int node = lm_scene_add_node(s, "inside", -1, (float *)m, -1, -1);
  int inside = lm_scene_add_camera(s, &(lm_camera){.name = "inside", .fov_y = glm_rad(70.0f), .znear = 0.05f,
                                                   .zfar = 10.0f, .node = node});
  lm_scene_update(s);
  long outside_checked = check_listed(s, 0), inside_checked = check_listed(s, inside);
  printf("points checked in their clusters: %ld from the front, %ld from inside\n", outside_checked, inside_checked);
  assert_true(outside_checked > 20000 && inside_checked > 10000);
  lm_scene_destroy(s);
  /* A sun alone: nothing to cull, no grid. */
  lm_error err;
  s = lm_scene_builtin("field", &err);
  assert_non_null(s);
  lm_frame_data f;
  lm_scene_frame_data(s, 0, 96, 72, &f);
  lm_light_data sun[4];
  int n = lm_scene_light_data(s, sun, 4);
  lm_light_grid g = {0};
  lm_light_grid_build(&g, &f, sun, n, true);
  assert_int_equal(g.tile_px, 0);
  assert_int_equal(lm_light_grid_count(&g, lm_light_grid_cluster(&g, 5, 5, 0.5f), n), n);
  lm_light_grid_free(&g);
  lm_scene_destroy(s);
}

static void culled_frame_matches_every_light_evaluated(void **state) {
  (void)state;
  lm_scene *s = box_with_lights(40);
  const char *sets[] = {"ambient=0", NULL};
  gl_result on = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = 96, .height = 72});
  gl_result off = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = 96, .height = 72,
                                      .no_light_culling = true});
  lm_scene *plain = box_with_lights(0);
  gl_result one = gl_render(&(gl_run){.scene = plain, .tech = "dl", .sets = sets, .width = 96, .height = 72});
  assert_true(on.ok && off.ok && one.ok);
  const lm_light_grid *g = lm_renderer_light_grid(on.renderer);
  assert_true(g->tile_px > 0 && lm_renderer_light_grid(off.renderer)->tile_px == 0);
  double worst = 0, sum = 0, sum_one = 0;
  for (int i = 0; i < 3 * 96 * 72; i++) {
    /* The lit target is half float: sums in another order differ in its last bits. */
    double d = fabs(on.rgb[i] - off.rgb[i]) / fmax(off.rgb[i], 0.05);
    worst = fmax(worst, d);
    sum += off.rgb[i];
    sum_one += one.rgb[i];
  }
  printf("culled against unculled: largest relative difference %.2e; radiance %.3f, %.3f without the 40 lights\n",
         worst, sum, sum_one);
  assert_true(sum > 1.5 * sum_one); /* the added lights do light the box */
  assert_true(worst < 4e-3);
  gl_result_free(&on);
  gl_result_free(&off);
  gl_result_free(&one);
  lm_scene_destroy(s);
  lm_scene_destroy(plain);
}

/* Spots whose falloff has no range (1 / d^2) reach every distance but only
 * their cone: the grid lists them where the cone reaches (at points inside
 * it, near and far, in their clusters), not in every cluster, and the frame
 * is the one every light evaluated everywhere gives. */
static void spots_of_unbounded_reach_are_culled_by_their_cone(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  s->lights[0].casts_shadows = false;
  enum { SPOTS = 6, W = 96, H = 72 };
  for (int i = 0; i < SPOTS; i++) {
    mat4 m;
    glm_translate_make(m, (vec3){-0.8f + 0.32f * (float)i, 1.9f, -0.5f + 0.2f * (float)(i % 3)});
    glm_rotate_x(m, glm_rad(-90.0f + 10.0f * (float)(i % 3)), m); /* down, some tilted forward */
    char name[16];
    snprintf(name, sizeof name, "spot_%d", i);
    lm_scene_add_light(s, &(lm_light){.name = "", .type = LM_LIGHT_SPOT, .color = {1, 0.9f, 0.8f}, .power = 50.0f,
                                      .falloff = LM_FALLOFF_INVERSE_SQUARE, .inner_cone = 0.15f, .outer_cone = 0.25f,
                                      .node = lm_scene_add_node(s, name, -1, (float *)m, -1, -1)});
  }
  lm_scene_update(s);
  lm_frame_data f;
  lm_scene_frame_data(s, 0, W, H, &f);
  lm_light_data lights[8];
  int n = lm_scene_light_data(s, lights, 8);
  lm_light_grid g = {0};
  lm_light_grid_build(&g, &f, lights, n, true);
  assert_true(g.tile_px > 0 && isinf(lm_light_data_reach(&lights[1])));
  assert_int_equal(g.global, 1); /* the box's own light */
  double mean = (double)g.listed / (g.tiles_x * g.tiles_y * g.slices);
  printf("spots of unbounded reach: a cluster lists %.2f of %d on average\n", mean, SPOTS);
  assert_true(mean < SPOTS / 2.0);
  long checked = 0;
  for (int i = 1; i < n; i++)
    for (int k = 0; k < 4000; k++) {
      /* A point in the cone: along the axis up to 3 units, at most 0.99 of the cone's radius off it. */
      float t = 3.0f * uniform01(), a = 2 * GLM_PIf * uniform01(), off = 0.99f * sqrtf(uniform01()) * t * tanf(0.25f);
      vec3 d = {lights[i].direction[0], lights[i].direction[1], lights[i].direction[2]}, u, v;
      glm_vec3_crossn(d, fabsf(d[0]) < 0.9f ? (vec3){1, 0, 0} : (vec3){0, 1, 0}, u);
      glm_vec3_crossn(d, u, v);
      float p[3];
      for (int c = 0; c < 3; c++)
        p[c] = lights[i].position[c] + t * d[c] + off * (cosf(a) * u[c] + sinf(a) * v[c]);
      vec4 c, wp = {p[0], p[1], p[2], 1};
      glm_mat4_mulv((vec4 *)f.view_proj, wp, c);
      if (!(c[3] > 0)) continue;
      float x = (c[0] / c[3] * 0.5f + 0.5f) * W, y = (c[1] / c[3] * 0.5f + 0.5f) * H;
      int cluster = x < 0 || y < 0 || x >= W || y >= H ? -1 : lm_light_grid_cluster(&g, x, y, c[3] / f.clip[1]);
      if (cluster < 0) continue;
      checked++;
      if (!lm_light_grid_has(&g, cluster, i)) fail_msg("spot %d left out of cluster %d", i, cluster);
    }
  printf("points inside the cones checked in their clusters: %ld\n", checked);
  assert_true(checked > 5000);
  lm_light_grid_free(&g);
  const char *sets[] = {"ambient=0", "light_variants=0", NULL}; /* 7 lights: the general loop, not a variant */
  gl_result on = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = W, .height = H});
  gl_result off = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = W, .height = H,
                                      .no_light_culling = true});
  s->light_count = 1; /* the box alone: the spots must add light */
  gl_result box = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = W, .height = H});
  assert_true(on.ok && off.ok && box.ok);
  double worst = 0, sum = 0, sum_box = 0;
  for (int i = 0; i < 3 * W * H; i++) {
    worst = fmax(worst, fabs(on.rgb[i] - off.rgb[i]) / fmax(off.rgb[i], 0.05));
    sum += off.rgb[i], sum_box += box.rgb[i];
  }
  printf("culled against unculled: largest relative difference %.2e; radiance %.1f, %.1f without the spots\n",
         worst, sum, sum_box);
  assert_true(worst < 4e-3 && sum > 1.2 * sum_box);
  gl_result_free(&on);
  gl_result_free(&off);
  gl_result_free(&box);
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_reaching_light_is_listed),
      cmocka_unit_test(culled_frame_matches_every_light_evaluated),
      cmocka_unit_test(spots_of_unbounded_reach_are_culled_by_their_cone),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
