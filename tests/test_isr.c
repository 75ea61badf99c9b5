/* Image-space radiosity (scripts/isr.lua) through pp.lua: the physical
 * mode's scale (a floor under a uniformly lit ceiling gets albedo times the
 * ceiling's radiance) and its independence of the scene's unit; on the
 * built-in Cornell box the seed mode's colour bleeding, ambient occlusion in
 * corners, coarse versus full size; finite results at extreme parameters,
 * option errors, and that the dl technique records no ISR pass. Needs a GL
 * context (llvmpipe will do).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#include <cglm/cglm.h>
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"

enum { W = 256, H = 192 };

/* Renders one frame of pp.lua with technique `tech` and "name=value" options
 * (NULL-terminated); r.ok false with the message in r.err. */
static gl_result render(const char *tech, const char *const *sets) {
  return gl_render(&(gl_run){.tech = tech, .sets = sets, .width = W, .height = H});
}

static gl_result render_ok(const char *tech, const char *const *sets) {
  gl_result r = render(tech, sets);
  if (!r.ok) fail_msg("%s: %s", tech, r.err.msg);
  return r;
}

/* Surfaces beside a coloured wall take its colour: ISR raises the ratio of
 * the wall's channel to the other wall's over direct light alone. The floor
 * by the red wall is brightly lit, so bleeding shifts its ratio by about
 * 1.5% (the seed's simple scenes gained 0.2-3.3%); the dimmer ceiling by the
 * green wall shifts by about 3.5%. */
static void indirect_light_bleeds_wall_colour(void **state) {
  (void)state;
  static const char *const seed[] = {"isr.mode=seed", NULL};
  gl_result dl = render_ok("dl", NULL), isr = render_ok("isr", seed);
  float d[3], i[3];
  gl_mean_around(&dl, -0.85f, 0.0f, 0.3f, 3, d); /* floor by the red wall */
  gl_mean_around(&isr, -0.85f, 0.0f, 0.3f, 3, i);
  double red_dl = (double)d[0] / d[1], red_isr = (double)i[0] / i[1];
  gl_mean_around(&dl, 0.85f, 2.0f, 0.3f, 3, d);  /* ceiling by the green wall */
  gl_mean_around(&isr, 0.85f, 2.0f, 0.3f, 3, i);
  double green_dl = (double)d[1] / d[0], green_isr = (double)i[1] / i[0];
  print_message("red/green on the floor by the red wall: dl %.4f isr %.4f\n"
                "green/red on the ceiling by the green wall: dl %.4f isr %.4f\n",
                red_dl, red_isr, green_dl, green_isr);
  assert_true(red_isr > red_dl * 1.01);
  assert_true(green_isr > green_dl * 1.02);
  gl_result_free(&dl);
  gl_result_free(&isr);
}

/* With k_ISR = 0 and k_SSAO = 1, eq 29 is direct light times accessibility,
 * so isr / dl is the accessibility A: lower in the edge where the back wall
 * meets the green wall than in the open middle of the back wall. */
static void occlusion_darkens_inside_corners(void **state) {
  (void)state;
  static const char *const sets[] = {"isr.mode=seed", "isr.seed.k_isr=0", "isr.seed.k_ssao=1", NULL};
  gl_result dl = render_ok("dl", NULL), ao = render_ok("isr", sets);
  float d[3], a[3];
  gl_mean_around(&dl, 0.9f, 1.0f, -1.0f, 3, d);
  gl_mean_around(&ao, 0.9f, 1.0f, -1.0f, 3, a);
  double corner = (double)a[1] / d[1];
  gl_mean_around(&dl, 0.3f, 1.3f, -1.0f, 3, d);
  gl_mean_around(&ao, 0.3f, 1.3f, -1.0f, 3, a);
  double open = (double)a[1] / d[1];
  print_message("accessibility: corner %.3f, open wall %.3f\n", corner, open);
  assert_true(open > 0.9 && open <= 1.0 + 1e-4); /* occlusion only darkens */
  assert_true(corner < open - 0.1);
  gl_result_free(&dl);
  gl_result_free(&ao);
}

/* The seed's mean error, sum(|dR| + |dG| + |dB|) / (3 w h), between the
 * coarse (factor 2) and the full-size ISR stays under 0.01 (linear), with
 * k_ISR = k_SSAO = 1 so that the ISR terms weigh all they can. */
static void coarse_and_full_size_agree(void **state) {
  (void)state;
  static const char *const full[] = {"isr.mode=seed", "isr.coarse=1", "isr.seed.k_isr=1", "isr.seed.k_ssao=1", NULL};
  static const char *const half[] = {"isr.mode=seed", "isr.coarse=2", "isr.seed.k_isr=1", "isr.seed.k_ssao=1", NULL};
  gl_result a = render_ok("isr", full), b = render_ok("isr", half);
  double sum = 0;
  for (int i = 0; i < W * H * 3; i++) sum += fabs(a.rgb[i] - b.rgb[i]);
  double mean_error = sum / (3.0 * W * H);
  print_message("mean error coarse 1 vs 2: %.5f\n", mean_error);
  assert_true(mean_error < 0.01);
  gl_result_free(&a);
  gl_result_free(&b);
}

/* Extremes of every option give finite, non-negative light before the output
 * stage (which would hide a NaN). */
static void extreme_parameters_stay_finite(void **state) {
  (void)state;
  static const char *const cases[][8] = {
      {"isr.samples=1", "isr.steps=1", "isr.thickness=0", NULL},
      {"isr.samples=256", "isr.steps=64", "isr.thickness=1", "isr.coarse=1", "isr.k=16", NULL},
      {"isr.samples=2", "isr.coarse=4", "isr.blur=0", "isr.bounces=4", "isr.k=0", NULL},
      {"isr.blur=32", "isr.bounces=1", "isr.view=indirect", NULL},
      {"isr.mode=seed", "isr.samples=256", "isr.seed.samples=1", "isr.seed.radius=1e-6", NULL},
      {"isr.mode=seed", "isr.seed.samples=256", "isr.seed.radius=1e6", "isr.coarse=1", NULL},
      {"isr.mode=seed", "isr.seed.samples=2", "isr.seed.radius=1e6", "isr.coarse=4", "isr.blur=0", NULL},
      {"isr.mode=seed", "isr.seed.k_isr=0", "isr.seed.k_ssao=0", "isr.blur=32", NULL},
      {"isr.mode=seed", "isr.seed.k_isr=1", "isr.seed.k_ssao=1", "isr.seed.sender=lit", "isr.seed.bounces=4", NULL},
      {"isr.mode=seed", "isr.seed.radius=1e-30", "isr.coarse=1", "isr.seed.sender=lit", "isr.seed.bounces=2", NULL},
  };
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    gl_result r = render("isr", cases[c]);
    if (!r.ok) fail_msg("case %zu: %s", c, r.err.msg);
    if (!gl_target_finite(&r, "lit")) fail_msg("case %zu (%s ...): a NaN, Inf or negative value", c, cases[c][0]);
    gl_result_free(&r);
  }
}

/* Out-of-range options stop the frame with the option's name. */
static void bad_options_name_themselves(void **state) {
  (void)state;
  static const gl_bad_option cases[] = {
      {"isr", "isr.samples=0", "isr.samples must be a whole number in 1..256 (got 0)"},
      {"isr", "isr.samples=2.5", "isr.samples must be"},
      {"isr", "isr.coarse=5", "isr.coarse must be one of 0, 1, 2, 3, 4"},
      {"isr", "isr.seed.radius=0", "isr.seed.radius must be a positive"},
      {"isr", "isr.seed.k_ssao=-1", "isr.seed.k_ssao must be a finite number in 0..1"},
      {"isr", "isr.seed.sender=sun", "isr.seed.sender must be one of albedo, lit (got sun)"},
      {"isr", "isr.seed.bounces=0", "isr.seed.bounces must be"},
      {"isr", "isr.bounces=5", "isr.bounces must be"},
      {"isr", "isr.mode=fast", "isr.mode must be one of physical, seed (got fast)"},
      {"isr", "isr.steps=0", "isr.steps must be a whole number in 1..64 (got 0)"},
      {"isr", "isr.thickness=2", "isr.thickness must be a finite number in 0..1 (got 2)"},
      {"isr", "isr.k=-1", "isr.k must be a finite number in 0..16 (got -1)"},
      {"isr", "ambient=-1", "ambient must be a finite number in 0..1e+06 (got -1)"},
      {"isr", "isr.temporal.frames=0", "isr.temporal.frames must be"},
      {"isr", "isr.temporal.turn=never", "isr.temporal.turn must be one of always, moving (got never)"},
      {"isr", "isr.temporal.narrow=2", "isr.temporal.narrow must be a finite number in 0..1 (got 2)"},
  };
  gl_assert_bad_options(cases, sizeof cases / sizeof *cases, "pp.lua:");
}

/* Two planes a gap g apart, wide and deep, seen from between them along the
 * gap: a floor (albedo 0.5) under a ceiling (0.8) that a parallel light from
 * below lights uniformly (radiance 0.8; the floor faces away from the light
 * and has none). Far ahead (distance >> g) every ray from the floor meets
 * the ceiling, so gi-scale.md's uniform emitter applies: L_ind = a L =
 * 0.5 * 0.8 = 0.4, and the ceiling gets its direct 0.8 plus that sent back
 * (the second bounce): 0.8 + 0.8 * 0.4 = 1.12. `unit` scales every length
 * (a scene in other units). */
static lm_scene *gap_scene(float unit) {
  lm_scene *s = lm_scene_create("gap");
  int floor_m = lm_scene_add_material(s, &(lm_material){"floor", {0.5f, 0.5f, 0.5f}, 0.5f, 1, 1, 0, 1, 0, 0});
  int ceiling_m = lm_scene_add_material(s, &(lm_material){"ceiling", {0.8f, 0.8f, 0.8f}, 0.8f, 1, 1, 0, 1, 0, 0});
  const float w = 200 * unit, g = 1 * unit, z0 = 10 * unit, z1 = -400 * unit;
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  const float floor_v[4 * 8] = {-w, 0, z0, 0, 1, 0, 0, 0, w, 0, z0, 0, 1, 0, 1, 0,
                                w, 0, z1, 0, 1, 0, 1, 1, -w, 0, z1, 0, 1, 0, 0, 1};
  const float ceiling_v[4 * 8] = {-w, g, z1, 0, -1, 0, 0, 0, w, g, z1, 0, -1, 0, 1, 0,
                                  w, g, z0, 0, -1, 0, 1, 1, -w, g, z0, 0, -1, 0, 0, 1};
  mat4 id = GLM_MAT4_IDENTITY_INIT, m;
  lm_scene_add_node(s, "floor", -1, (float *)id, lm_scene_add_mesh(s, "floor", floor_v, 4, idx, 6), floor_m);
  lm_scene_add_node(s, "ceiling", -1, (float *)id, lm_scene_add_mesh(s, "ceiling", ceiling_v, 4, idx, 6),
                    ceiling_m);
  glm_rotate_make(m, glm_rad(90.0f), (vec3){1, 0, 0}); /* -Z of the node points up */
  int sun = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "up", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                     .node = sun});
  glm_translate_make(m, (vec3){0, 0.5f * g, 0});
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "along", .fov_y = glm_rad(45.0f), .znear = 0.05f * unit,
                                      .zfar = 600 * unit, .node = cam});
  lm_scene_update(s);
  return s;
}

enum { GAP_W = 160, GAP_H = 120 };

static gl_result render_gap(lm_scene *s, const char *const *sets) {
  gl_result r = gl_render(&(gl_run){.scene = s, .tech = "isr", .sets = sets, .width = GAP_W, .height = GAP_H});
  if (!r.ok) fail_msg("%s", r.err.msg);
  return r;
}

/* The floor 5 to 20 gaps ahead (rows 4 to 14 below the horizon at 160x120,
 * the middle half of the columns) and the ceiling above it, within 10%: the
 * screen misses the few rays that meet the ceiling behind the camera.
 * Measured 0.379 and 1.084. */
static void a_uniformly_lit_ceiling_gives_albedo_times_radiance(void **state) {
  (void)state;
  static const char *const sets[] = {"ambient=0", NULL};
  lm_scene *s = gap_scene(1.0f);
  gl_result r = render_gap(s, sets);
  float floor_rgb[3], ceiling_rgb[3];
  gl_region(&r, GAP_W / 4, GAP_H / 2 + 4, 3 * GAP_W / 4, GAP_H / 2 + 14, floor_rgb);
  gl_region(&r, GAP_W / 4, GAP_H / 2 - 14, 3 * GAP_W / 4, GAP_H / 2 - 4, ceiling_rgb);
  print_message("floor %.4f (expected 0.4), ceiling %.4f (expected 1.12)\n", gl_luminance(floor_rgb),
                gl_luminance(ceiling_rgb));
  assert_true(fabsf(gl_luminance(floor_rgb) - 0.4f) < 0.04f);
  assert_true(fabsf(gl_luminance(ceiling_rgb) - 1.12f) < 0.112f);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* The same scene in millimetres and in kilometres gives the same image: no
 * default of the physical mode is a world length. */
static void the_unit_of_the_scene_does_not_matter(void **state) {
  (void)state;
  static const char *const sets[] = {"ambient=0", NULL};
  lm_scene *mm = gap_scene(1000.0f), *km = gap_scene(0.001f);
  gl_result a = render_gap(mm, sets), b = render_gap(km, sets);
  double sum = 0;
  for (int i = 0; i < GAP_W * GAP_H * 3; i++) sum += fabs(a.rgb[i] - b.rgb[i]);
  double mean_error = sum / (3.0 * GAP_W * GAP_H);
  print_message("millimetres against kilometres: mean error %.6f\n", mean_error);
  assert_true(mean_error < 1e-3);
  gl_result_free(&a);
  gl_result_free(&b);
  lm_scene_destroy(mm);
  lm_scene_destroy(km);
}

/* Open ground far from the posts of the built-in field (the bottom rows of
 * the view): ISR changes it by less than 2% against direct light alone. */
static void an_open_floor_keeps_its_direct_light(void **state) {
  (void)state;
  lm_error err;
  lm_scene *field = lm_scene_builtin("field", &err);
  assert_non_null(field);
  gl_result dl = gl_render(&(gl_run){.scene = field, .tech = "dl", .width = W, .height = H});
  gl_result isr = gl_render(&(gl_run){.scene = field, .tech = "isr", .width = W, .height = H});
  assert_true(dl.ok && isr.ok);
  float a[3], b[3];
  gl_region(&dl, 16, 164, 240, 191, a);
  gl_region(&isr, 16, 164, 240, 191, b);
  float ratio = gl_luminance(b) / gl_luminance(a);
  print_message("open ground, isr / dl: %.4f\n", ratio);
  assert_true(ratio > 0.98f && ratio < 1.02f);
  gl_result_free(&dl);
  gl_result_free(&isr);
  lm_scene_destroy(field);
}

/* The later bounces sum over the senders the first march recorded
 * (isr_bounce.frag) instead of marching the same rays again: the indirect
 * light is the marched one, for 2 and 4 bounces, 12 rays (3 hit targets) and
 * 24 (6, the most beside E and the grid's depth); 28 rays do not fit and
 * march every bounce. */
static void later_bounces_from_the_recorded_senders_are_the_marched_ones(void **state) {
  (void)state;
  static const char *const cases[][2] = {{"isr.bounces=2", "isr.samples=12"}, {"isr.bounces=4", "isr.samples=12"},
                                         {"isr.bounces=2", "isr.samples=24"}};
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    const char *const reused[] = {"isr.view=indirect", cases[c][0], cases[c][1], NULL};
    const char *const marched[] = {"isr.view=indirect", cases[c][0], cases[c][1], "isr.reuse=false", NULL};
    gl_result a = render_ok("isr", reused), b = render_ok("isr", marched);
    assert_true(lm_graph_find_target(lm_renderer_graph(a.renderer), "isr.hits1") >= 0);
    assert_int_equal(lm_graph_find_target(lm_renderer_graph(b.renderer), "isr.hits1"), -1);
    double sum = 0, worst = 0, level = 0;
    for (int i = 0; i < W * H * 3; i++) {
      double d = fabs(a.rgb[i] - b.rgb[i]);
      sum += d, worst = fmax(worst, d), level += b.rgb[i];
    }
    print_message("%s, %s: mean difference %.2g (indirect light's mean %.3f), largest %.2g\n", cases[c][0],
                  cases[c][1], sum / (3.0 * W * H), level / (3.0 * W * H), worst);
    assert_true(sum / (3.0 * W * H) < 1e-5 && worst < 1e-3);
    gl_result_free(&a);
    gl_result_free(&b);
  }
  static const char *const many[] = {"isr.samples=28", NULL};
  gl_result r = render_ok("isr", many);
  lm_graph *g = lm_renderer_graph(r.renderer);
  assert_int_equal(lm_graph_find_target(g, "isr.hits1"), -1);
  gl_result_free(&r);
}

/* Temporal reuse (isr.temporal) on a still camera over the Cornell box's
 * indirect light, its passes running on (isr.temporal.skip=false: a frame
 * after 36 still ones would otherwise keep the last result whole; and
 * isr.temporal.turn = always: the default keeps a still view's pattern): the
 * change from one frame to the next falls from frame 3 to frame 40 by more
 * than 5x and ends below 1e-3 of the image's mean, and
 * the result lies nearer a frame of 64 rays a texel than one frame of the
 * default 4 does. Each way of taking the later bounces (the recorded
 * senders, marching again, one bounce) accumulates and stays finite; the
 * seed mode refuses it by name. */
static void still_frames_with_temporal_reuse_converge(void **state) {
  (void)state;
  static const char *const on[] = {"isr.view=indirect", "isr.temporal.enabled=true", "isr.temporal.skip=false",
                                   "isr.temporal.turn=always", NULL};
  static const char *const off[] = {"isr.view=indirect", NULL};
  static const char *const ref[] = {"isr.view=indirect", "isr.samples=64", NULL};
  gl_convergence c = gl_temporal_convergence((gl_run){.tech = "isr", .width = W, .height = H}, on, off, ref, 40,
                                             "isr temporal (reference: 64 rays)");
  assert_true(c.mean > 0.01 && c.late < 1e-3 * c.mean && c.late * 5 < c.early);
  assert_true(c.e_acc < c.e_one);

  static const char *const ways[][2] = {{"isr.bounces=1", NULL}, {"isr.reuse=false", NULL}, {"isr.bounces=3", NULL}};
  for (size_t i = 0; i < sizeof ways / sizeof *ways; i++) {
    const char *const sets[] = {"isr.temporal.enabled=true", ways[i][0], NULL};
    gl_result w = gl_render(&(gl_run){.tech = "isr", .sets = sets, .width = W, .height = H, .frames = 3});
    if (!w.ok) fail_msg("%s: %s", ways[i][0], w.err.msg);
    assert_true(gl_all_finite(&w));
    assert_true(lm_graph_find_target(lm_renderer_graph(w.renderer), "temporal.isr2.value0") >= 0);
    gl_result_free(&w);
  }
  static const char *const seed[] = {"isr.mode=seed", "isr.temporal.enabled=true", NULL};
  gl_result bad = render("isr", seed);
  assert_false(bad.ok);
  assert_non_null(strstr(bad.err.msg, "isr.temporal is for isr.mode \"physical\""));
  gl_result_free(&bad);
}

/* With the default isr.temporal.turn ("moving"), a still view keeps reuse
 * off's pattern, so temporal reuse neither flickers nor lags there: over
 * still frames, a light's colour halved (a world change the history must
 * not lag) and a box moved, each frame is reuse off's to 1e-6 of the
 * image's mean, so its flicker (the change from one frame to the next) is
 * reuse off's. With the pattern turning on a still view (turn = always) the
 * still frames change by their noise (docs/motion.md: the door sequence). */
static void a_still_view_with_temporal_reuse_is_reuse_off(void **state) {
  (void)state;
  static const char *const off[] = {NULL};
  static const char *const on[] = {"isr.temporal.enabled=true", NULL};
  static const char *const turning[] = {"isr.temporal.enabled=true", "isr.temporal.turn=always", NULL};
  const char *const *sets[] = {off, on, turning};
  lm_scene *s[3];
  gl_result r[3];
  double change[3] = {0, 0, 0}, worst = 0, mean = 0;
  float *before[3];
  for (int k = 0; k < 3; k++) {
    lm_error err;
    s[k] = lm_scene_builtin("cornell", &err);
    assert_non_null(s[k]);
    r[k] = gl_render(&(gl_run){.scene = s[k], .tech = "isr+esm", .sets = sets[k][0] ? sets[k] : NULL, .width = W,
                               .height = H, .frames = 2});
    assert_true(r[k].ok);
    before[k] = malloc(sizeof(float) * W * H * 3);
  }
  for (int f = 0; f < 8; f++) {
    for (int k = 0; k < 3; k++) {
      memcpy(before[k], r[k].rgb, sizeof(float) * W * H * 3);
      if (f == 3) s[k]->lights[0].color[0] *= 0.5f;
      if (f == 5) {
        s[k]->nodes[lm_scene_find_node(s[k], "tall_box")].local[12] += 0.05f;
        lm_scene_update(s[k]);
      }
      assert_true(gl_render_again(&r[k]));
      change[k] += gl_mean_abs_diff(r[k].rgb, before[k], W * H * 3);
    }
    float all[3];
    gl_region(&r[0], 0, 0, W - 1, H - 1, all);
    mean = (all[0] + all[1] + all[2]) / 3.0;
    worst = fmax(worst, gl_mean_abs_diff(r[1].rgb, r[0].rgb, W * H * 3) / mean);
  }
  print_message("over 8 frames: change off %.4g, on %.4g, turning %.4g; on against off at most %.2g of the mean\n",
                change[0], change[1], change[2], worst);
  assert_true(worst < 1e-6);
  assert_true(change[1] <= change[0] * (1 + 1e-6) && change[2] > change[0]);
  for (int k = 0; k < 3; k++) {
    free(before[k]);
    gl_result_free(&r[k]);
    lm_scene_destroy(s[k]);
  }
}

/* A still world settles: after <gi>.temporal.frames (8 here) frames with
 * the same scene, camera and settings, every pixel has converged, and a
 * frame keeps the last result (temporal.kept: ISR's and RSM's final E and
 * grid depth, SSDO's composite) and runs none of the technique's GI passes
 * (isr+rsm+esm's RSM gather among them), only what composites them: its
 * image is the last frame's, bit for bit, and lies within 1% of the image's
 * mean of the one the passes give when they run on (<gi>.temporal.skip =
 * false: there a refreshed tile whose fresh samples' noise drops the
 * confidence starts again; measured 0-0.5%). Moving the camera, a light or a
 * node runs them again; they stop again 8 frames later. */
static void a_settled_still_frame_skips_the_gi_passes(void **state) {
  (void)state;
  static const struct {
    const char *tech, *gi, *gather, *blur, *composite;
  } cases[] = {{"isr+esm", "isr", "isr.transport", "isr.blur", "isr.light"},
               {"isr+rsm+esm", "isr", "isr.transport", "isr.blur", "isr.light"},
               {"rsm+esm", "rsm", "rsm.gather", "rsm.blur", "direct"},
               {"ssdo", "ssdo", "ssdo.physical", "ssdo.blur", NULL}};
  for (size_t t = 0; t < sizeof cases / sizeof *cases; t++) {
    lm_error err;
    lm_scene *s = lm_scene_builtin("cornell", &err);
    assert_non_null(s);
    char enabled[64], frames[64], skip[64];
    snprintf(enabled, sizeof enabled, "%s.temporal.enabled=true", cases[t].gi);
    snprintf(frames, sizeof frames, "%s.temporal.frames=8", cases[t].gi);
    snprintf(skip, sizeof skip, "%s.temporal.skip=false", cases[t].gi);
    const char *const on[] = {enabled, frames, NULL};
    const char *const run[] = {enabled, frames, skip, NULL};
    const char *tech = cases[t].tech;
    gl_result r = gl_render(&(gl_run){.scene = s, .tech = tech, .sets = on, .width = W, .height = H, .frames = 8});
    gl_result u = gl_render(&(gl_run){.scene = s, .tech = tech, .sets = run, .width = W, .height = H, .frames = 12});
    if (!r.ok) fail_msg("%s: %s", tech, r.err.msg);
    assert_true(u.ok);
    assert_true(gl_has_pass(&r, cases[t].gather)); /* frame 8: 7 still frames before it */
    float *last = malloc(sizeof(float) * W * H * 3);
    memcpy(last, r.rgb, sizeof(float) * W * H * 3);
    for (int f = 9; f <= 12; f++) assert_true(gl_render_again(&r));
    double d = gl_mean_abs_diff(r.rgb, u.rgb, W * H * 3), same = gl_mean_abs_diff(r.rgb, last, W * H * 3);
    float all[3];
    gl_region(&u, 0, 0, W - 1, H - 1, all);
    double mean = (all[0] + all[1] + all[2]) / 3.0;
    print_message("%s, frame 12: %s %s, blur %s; %.3g from frame 8, %.2f%% of the mean from the frame the passes "
                  "give\n", tech, cases[t].gather, gl_has_pass(&r, cases[t].gather) ? "run" : "skipped",
                  gl_has_pass(&r, cases[t].blur) ? "run" : "skipped", same, 100 * d / mean);
    free(last);
    assert_false(gl_has_pass(&r, cases[t].gather) || gl_has_pass(&r, cases[t].blur));
    assert_true(gl_has_pass(&u, cases[t].gather));
    if (cases[t].composite) assert_true(gl_has_pass(&r, cases[t].composite));
    assert_true(same == 0.0 && d < 0.01 * mean);
    /* A camera move, then a light's colour, then a node under the still camera: the passes run again. */
    s->cameras[0].znear *= 1.01f;
    assert_true(gl_render_again(&r) && gl_has_pass(&r, cases[t].gather));
    for (int f = 0; f < 8; f++) assert_true(gl_render_again(&r));
    assert_false(gl_has_pass(&r, cases[t].gather));
    s->lights[0].color[0] *= 0.5f;
    assert_true(gl_render_again(&r) && gl_has_pass(&r, cases[t].gather));
    /* Settled again, then a node moves under the still camera: again. */
    for (int f = 0; f < 8; f++) assert_true(gl_render_again(&r));
    assert_false(gl_has_pass(&r, cases[t].gather));
    int box = lm_scene_find_node(s, "tall_box");
    assert_true(box >= 0);
    s->nodes[box].local[12] += 0.01f;
    lm_scene_update(s);
    assert_true(gl_render_again(&r) && gl_has_pass(&r, cases[t].gather) && gl_has_pass(&r, cases[t].blur));
    s->nodes[box].local[12] -= 0.01f;
    lm_scene_update(s);
    assert_true(gl_all_finite(&r));
    gl_result_free(&r);
    gl_result_free(&u);
    lm_scene_destroy(s);
  }
}

/* isr.coarse 0 (the default) gathers over a grid at least 128 texels wide:
 * coarse 2 up to 511 pixels wide, 4 from 512 (the same 128 x 96 grid at
 * 256 x 192 and 512 x 384); below 256 pixels wide, 3; a coarse factor
 * given is kept. */
static void the_auto_coarse_grid_keeps_its_size_relative_to_the_view(void **state) {
  (void)state;
  static const struct { int w, h; const char *set; int grid_w; } cases[] = {
      {160, 120, NULL, 53},  {255, 192, NULL, 85},  {256, 192, NULL, 128}, {510, 384, NULL, 255},
      {512, 384, NULL, 128}, {1024, 768, NULL, 256}, {512, 384, "isr.coarse=2", 256}};
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    const char *const sets[] = {cases[i].set, NULL};
    gl_result r = gl_render(&(gl_run){.tech = "isr", .sets = cases[i].set ? sets : NULL, .width = cases[i].w,
                                      .height = cases[i].h});
    assert_true(r.ok);
    lm_graph *g = lm_renderer_graph(r.renderer);
    lm_graph_target_info t = lm_graph_target(g, lm_graph_find_target(g, "isr.e1"));
    printf("%dx%d %s: coarse grid %dx%d\n", cases[i].w, cases[i].h, cases[i].set ? cases[i].set : "", t.width,
           t.height);
    assert_int_equal(t.width, cases[i].grid_w);
    gl_result_free(&r);
  }
}

static void dl_records_no_isr_pass(void **state) {
  (void)state;
  gl_result dl = render_ok("dl", NULL), isr = render_ok("isr", NULL);
  assert_false(gl_has_pass(&dl, "isr."));
  assert_true(gl_has_pass(&isr, "isr."));
  assert_int_equal(gl_culled(&isr, ""), 0); /* every ISR pass reaches the output */
  gl_result_free(&dl);
  gl_result_free(&isr);
}

/* coarse.glsl's QUAD_SHARED (the composite's upsampling where the coarse
 * factor is a multiple of 4 that divides the output): each pixel of a 2 x 2
 * quad reads one of the four coarse texels and takes the others from its
 * neighbours, against every pixel reading all four (and gathering the
 * depths and coverage). Test shaders (in the scratch root) fill a coarse E
 * of values over 2^-6 .. 2^6, depths with holes (0: nothing drawn) and
 * edges, a coverage, and full-size depths; then the upsampling runs with
 * and without QUAD_SHARED, with the coverage from the depth (Z_MASK) and
 * from coarse_mat. */
static const char coarse_fill_frag[] =
    "layout(location = 0) out vec4 e;\n"
    "layout(location = 1) out float z;\n"
    "layout(location = 2) out vec4 m;\n"
    "float hash(ivec2 p, int k) { return fract(float(p.x * (37 + 14 * k) + p.y * (101 + 22 * k)) / 997.0); }\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "  e = exp2(12.0 * vec4(hash(p, 0), hash(p, 1), hash(p, 2), hash(p, 3)) - 6.0);\n"
    "  z = hash(p, 4) < 0.1 ? 0.0 : 0.05 + 0.9 * hash(p, 5) * hash(p, 5);\n"
    "  m = vec4(0.0, 0.0, 0.0, hash(p, 6));\n"
    "}\n";
static const char full_depth_frag[] =
    "out float z;\n"
    "void main() { z = 0.05 + 0.9 * fract(float(int(gl_FragCoord.x) * 13 + int(gl_FragCoord.y) * 7) / 251.0); }\n";
static const char upsample_frag[] =
    "#include \"coarse.glsl\"\n"
    "in vec2 uv;\n"
    "uniform sampler2D z;\n"
    "out vec4 o;\n"
    "void main() { o = coarse_upsample(uv, texelFetch(z, ivec2(gl_FragCoord.xy), 0).r); }\n";
static const char upsampled_frag[] = /* reads the four results, so that none is culled */
    "uniform sampler2D a, b, c, d;\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "  o = texelFetch(a, p, 0) + texelFetch(b, p, 0) + texelFetch(c, p, 0) + texelFetch(d, p, 0);\n"
    "}\n";
static const char upsample_lua[] =
    "Techniques = { 'upsample' }\n"
    "Options = {}\n"
    "function OnRender()\n"
    "  local e, z, m = target{ 'e', format = 'rgba16f', scale = 1 / 4 }, target{ 'cz', format = 'r32f', scale = 1 / 4 },\n"
    "                  target{ 'm', format = 'rgba8', scale = 1 / 4 }\n"
    "  pass{ 'fill', shader = 'test_coarse_fill.frag', out = { e, z, m } }\n"
    "  local full = pass{ 'depth', shader = 'test_full_depth.frag', out = target{ 'z', format = 'r32f' } }\n"
    "  local up = {}\n"
    "  for _, mask in ipairs({ true, false }) do\n"
    "    for _, shared in ipairs({ true, false }) do\n"
    "      local name = (shared and 'shared' or 'own') .. (mask and '_z' or '_mat')\n"
    "      up[#up + 1] = pass{ name, shader = 'test_upsample.frag', defines = { QUAD_SHARED = shared, Z_MASK = mask },\n"
    "                          inputs = { coarse = e, coarse_dpt = z, coarse_mat = not mask and m or nil, z = full },\n"
    "                          out = target{ name, format = 'rgba32f' } }\n"
    "    end\n"
    "  end\n"
    "  present(pass{ 'read', shader = 'test_upsampled.frag', inputs = { a = up[1], b = up[2], c = up[3], d = up[4] },\n"
    "                out = target{ 'read', format = 'rgba32f' } }, 'display')\n"
    "end\n";

static void a_quad_shares_its_coarse_reads_as_each_pixel_reads_them(void **state) {
  (void)state;
  assert_true(gl_write_file("shaders/test_coarse_fill.frag", coarse_fill_frag));
  assert_true(gl_write_file("shaders/test_full_depth.frag", full_depth_frag));
  assert_true(gl_write_file("shaders/test_upsample.frag", upsample_frag));
  assert_true(gl_write_file("shaders/test_upsampled.frag", upsampled_frag));
  assert_true(gl_write_file("upsample.lua", upsample_lua));
  gl_result r = gl_render(&(gl_run){.script = "upsample.lua", .width = W, .height = H, .keep_targets = true});
  if (!r.ok) fail_msg("%s", r.err.msg);
  static const char *const pairs[][2] = {{"shared_z", "own_z"}, {"shared_mat", "own_mat"}};
  for (int k = 0; k < 2; k++) {
    int w = 0, h = 0, w2 = 0, h2 = 0;
    float *a = gl_read_target(&r, pairs[k][0], &w, &h), *b = gl_read_target(&r, pairs[k][1], &w2, &h2);
    assert_non_null(a);
    assert_non_null(b);
    assert_true(w == W && h == H && w2 == W && h2 == H);
    double worst = 0, lo = 1e30, hi = 0;
    int exact = 0;
    for (int i = 0; i < W * H * 4; i++) {
      exact += a[i] == b[i];
      worst = fmax(worst, fabs(a[i] - b[i]) / fmax(fabs(b[i]), 1e-30));
      lo = fmin(lo, b[i]), hi = fmax(hi, b[i]);
    }
    printf("%s against %s: %d of %d values the same bit for bit, the largest relative difference %g; "
           "values %g .. %g\n", pairs[k][0], pairs[k][1], exact, W * H * 4, worst, lo, hi);
    /* Where two depths' difference is not exact, a float's rounding, which the depth weight's 1 / EPS_Z
     * raises 100 times: under a fifth of a half float's step (2^-11) */
    assert_true(worst <= 1e-4);
    assert_true(exact >= W * H * 4 * 9 / 10); /* most differences are exact */
    assert_true(lo < 0.1 && hi > 10);         /* the coarse values were read: they span 2^-6 .. 2^6 */
    free(a);
    free(b);
  }
  gl_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_uniformly_lit_ceiling_gives_albedo_times_radiance),
      cmocka_unit_test(the_unit_of_the_scene_does_not_matter),
      cmocka_unit_test(indirect_light_bleeds_wall_colour),
      cmocka_unit_test(occlusion_darkens_inside_corners),
      cmocka_unit_test(coarse_and_full_size_agree),
      cmocka_unit_test(a_quad_shares_its_coarse_reads_as_each_pixel_reads_them),
      cmocka_unit_test(extreme_parameters_stay_finite),
      cmocka_unit_test(bad_options_name_themselves),
      cmocka_unit_test(an_open_floor_keeps_its_direct_light),
      cmocka_unit_test(dl_records_no_isr_pass),
      cmocka_unit_test(later_bounces_from_the_recorded_senders_are_the_marched_ones),
      cmocka_unit_test(the_auto_coarse_grid_keeps_its_size_relative_to_the_view),
      cmocka_unit_test(still_frames_with_temporal_reuse_converge),
      cmocka_unit_test(a_settled_still_frame_skips_the_gi_passes),
      cmocka_unit_test(a_still_view_with_temporal_reuse_is_reuse_off),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
