/* Light propagation volumes (scripts/lpv.lua, shaders/lpv_*.{vert,frag})
 * through pp.lua: a sunlit red wall tints the white wall beside it, on the
 * scale of the RSM gather; propagation never adds energy; a sub-cell camera
 * move leaves the volumes where they were; cells follow the box the camera
 * sees (lpv.fit) or a cap; a frame that reads no LPV records
 * none of its passes; any unit gives the same image; extremes stay finite;
 * bad options name themselves. Needs a GL context (llvmpipe will do).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <cglm/cglm.h>
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

enum { W = 96, H = 72 };

/* A red wall (0.8, 0.1, 0.1) at x = -1 facing +x and a white wall (0.8) at
 * z = -1 facing +z, both 1.5 high, over [-1, 1]; a grey floor under them.
 * The sun (or a spot light at (1, 1.2, 0.5)) shines along -x and down onto
 * the red wall: the white wall, parallel to the light, gets none. The camera
 * at (0, 0.75, 2) looks along -z at the white wall, the red wall to its left. */
static lm_scene *corner_scene(lm_light_type type) {
  lm_scene *s = lm_scene_create("corner");
  int red = gl_material(s, "red", 0.8f, 0.1f, 0.1f), white = gl_material(s, "white", 0.8f, 0.8f, 0.8f);
  int grey = gl_material(s, "grey", 0.3f, 0.3f, 0.3f);
  gl_quad(s, "red", red, (const float[4][3]){{-1, 0, 1}, {-1, 0, -1}, {-1, 1.5f, -1}, {-1, 1.5f, 1}},
          (const float[3]){1, 0, 0});
  gl_quad(s, "white", white, (const float[4][3]){{-1, 0, -1}, {1, 0, -1}, {1, 1.5f, -1}, {-1, 1.5f, -1}},
          (const float[3]){0, 0, 1});
  gl_quad(s, "floor", grey, (const float[4][3]){{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}},
          (const float[3]){0, 1, 0});
  mat4 m;
  if (type == LM_LIGHT_DIRECTIONAL) {
    glm_rotate_make(m, glm_rad(90.0f), (vec3){0, 1, 0}); /* -Z of the node along -x */
    glm_rotate(m, glm_rad(-15.0f), (vec3){1, 0, 0});    /* and down */
  } else {
    glm_translate_make(m, (vec3){1, 1.2f, 0.5f});
    glm_rotate(m, glm_rad(90.0f), (vec3){0, 1, 0});
    glm_rotate(m, glm_rad(-20.0f), (vec3){1, 0, 0});
  }
  int light = lm_scene_add_node(s, "light", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "light", .type = type, .color = {1, 1, 1},
                                     .power = type == LM_LIGHT_DIRECTIONAL ? 1.0f : 3.0f,
                                     .inner_cone = glm_rad(50.0f), .outer_cone = glm_rad(60.0f),
                                     .falloff = LM_FALLOFF_INVERSE_SQUARE, .casts_shadows = true, .node = light});
  glm_translate_make(m, (vec3){0, 0.75f, 2});
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "front", .fov_y = glm_rad(60.0f), .znear = 0.01f, .zfar = 100,
                                      .node = cam});
  lm_scene_update(s);
  return s;
}

static gl_result render_ok(lm_scene *s, const char *tech, const char *const *sets, int w, int h) {
  return gl_render_ok(&(gl_run){.scene = s, .tech = tech, .sets = sets, .width = w, .height = h});
}

/* Mean linear RGB of the white wall between x0 and x1 (world), at heights
 * 0.45 .. 1.05, for the corner scene's camera. */
static void white_wall(const gl_result *r, float x0, float x1, float out[3]) {
  float half_w = 3 * tanf(glm_rad(30.0f)) * r->width / r->height, half_h = 3 * tanf(glm_rad(30.0f));
  int c0 = (int)((x0 / half_w + 1) * 0.5f * r->width), c1 = (int)((x1 / half_w + 1) * 0.5f * r->width);
  int r0 = (int)((1 - 0.3f / half_h) * 0.5f * r->height), r1 = (int)((1 + 0.3f / half_h) * 0.5f * r->height);
  gl_region(r, c0, r0, c1, r1, out);
}

/* The sunlit red wall lights the white wall red, most near the corner;
 * dl+esm leaves the white wall black. The LPV's light there is within a
 * factor 2 of the RSM gather's (which holds to the integral within 3%,
 * test_rsm). */
static void a_lit_coloured_wall_tints_a_neighbouring_white_one(void **state) {
  (void)state;
  static const char *const sets[] = {"ambient=0", NULL};
  lm_scene *s = corner_scene(LM_LIGHT_DIRECTIONAL);
  gl_result lpv = render_ok(s, "lpv+esm", sets, W, H), dl = render_ok(s, "dl+esm", sets, W, H),
            rsm = render_ok(s, "rsm+esm", sets, W, H);
  float near[3], far[3], dark[3], ref[3];
  white_wall(&lpv, -0.9f, -0.5f, near);
  white_wall(&lpv, 0.5f, 0.9f, far);
  white_wall(&dl, -0.9f, -0.5f, dark);
  white_wall(&rsm, -0.9f, -0.5f, ref);
  print_message("white wall near the red one: lpv %.4f %.4f %.4f, rsm %.4f %.4f %.4f, dl %.5f; far: lpv %.4f\n",
                near[0], near[1], near[2], ref[0], ref[1], ref[2], dark[0], far[0]);
  assert_true(dark[0] < 1e-4f);
  assert_true(near[0] > 0.005f && near[0] > 3 * near[1] && near[0] > 3 * near[2]);
  assert_true(near[0] > 1.5f * far[0]);
  assert_true(near[0] > 0.5f * ref[0] && near[0] < 2 * ref[0]);
  gl_result_free(&lpv);
  gl_result_free(&dl);
  gl_result_free(&rsm);
  lm_scene_destroy(s);
}

/* The power 4 pi A summed over the cells of each colour channel's volume. */
static void volume_power(gl_result *r, const char *prefix, int step, double out[3]) {
  for (int ch = 0; ch < 3; ch++) {
    char name[64];
    snprintf(name, sizeof name, "%s%c%d", prefix, "rgb"[ch], step);
    int w, h;
    float *px = gl_read_target(r, name, &w, &h);
    if (!px) fail_msg("no target %s", name);
    double sum = 0;
    for (int i = 0; i < w * h; i++) {
      if (!isfinite(px[4 * i]) || px[4 * i] < 0) fail_msg("%s: texel %d holds %g", name, i, px[4 * i]);
      sum += px[4 * i];
    }
    out[ch] = 4 * GLM_PI * sum;
    free(px);
  }
}

/* Each step's wave holds at most the power of the last one, in every
 * channel (nothing is made; blocking and the grids' borders take some), and
 * after 12 steps less than after 1. The waves are read as stored, scaled by
 * what each cell may send (lpv_propagate.frag), which lies between a wave's
 * power and the next one's, so the stored sequence falling is the waves'.
 * Step `steps` of steps + 1: the last step stores the sum of all in place of
 * its wave. */
static void energy_does_not_grow_with_propagation_steps(void **state) {
  (void)state;
  lm_scene *s = corner_scene(LM_LIGHT_DIRECTIONAL);
  double last[3] = {0}, first[3] = {0};
  for (int steps = 1; steps <= 12; steps++) {
    char set[32];
    snprintf(set, sizeof set, "lpv.steps=%d", steps + 1);
    const char *const sets[] = {"ambient=0", set, NULL};
    gl_result r = render_ok(s, "lpv+esm", sets, 48, 36);
    double p[3];
    volume_power(&r, "lpv.wave_", steps, p);
    if (steps == 1) memcpy(first, p, sizeof p);
    print_message("steps %2d: wave power %.5g %.5g %.5g\n", steps, p[0], p[1], p[2]);
    for (int ch = 0; ch < 3 && steps > 1; ch++)
      if (p[ch] > last[ch] * (1 + 1e-5)) fail_msg("step %d, channel %d: %.9g after %.9g", steps, ch, p[ch], last[ch]);
    assert_true(p[0] > 0);
    memcpy(last, p, sizeof p);
    gl_result_free(&r);
  }
  for (int ch = 0; ch < 3; ch++) assert_true(last[ch] < first[ch]);
  lm_scene_destroy(s);
}

/* Mean absolute difference of the first cascades' volumes, n^3 cells each (a
 * grid that follows the camera: cascade c's block of n slices from column
 * c n^2, lpv.glsl), b's cells shifted by the whole cells that match best (a
 * grid that moves whole cells leaves its light where it was), over cells two
 * from the borders, relative to a's mean magnitude; per cascade, the worst.
 * Grids that stay put (n = 0): the volumes texel by texel. */
static double aligned_difference(const float *a, const float *b, int w, int h, int n, int cascades) {
  if (n == 0) {
    double diff = 0, mag = 0;
    for (int i = 0; i < 4 * w * h; i++) diff += fabs(a[i] - b[i]), mag += fabs(a[i]);
    return mag > 0 ? diff / mag : 0;
  }
  double worst = 0;
  for (int c = 0; c < cascades; c++) {
    double best = INFINITY, mag = 0;
    for (int shift = 0; shift < 27; shift++) {
      int dx = shift % 3 - 1, dy = shift / 3 % 3 - 1, dz = shift / 9 - 1;
      double diff = 0;
      mag = 0;
      for (int z = 2; z < n - 2; z++)
        for (int y = 2; y < n - 2; y++)
          for (int x = 2; x < n - 2; x++)
            for (int k = 0; k < 4; k++) {
              /* rows top first: texel (c n^2 + z n + x, y) is row h - 1 - y */
              size_t ia = ((size_t)(h - 1 - y) * w + c * n * n + z * n + x) * 4 + k;
              size_t ib = ((size_t)(h - 1 - (y + dy)) * w + c * n * n + (z + dz) * n + x + dx) * 4 + k;
              diff += fabs(a[ia] - b[ib]);
              mag += fabs(a[ia]);
            }
      if (diff < best) best = diff;
    }
    if (mag > 0 && best / mag > worst) worst = best / mag;
  }
  return worst;
}

/* A camera move of a tenth of the finest cell, under a spot light and under
 * the sun (whose RSM tile follows what the camera sees, in whole texels),
 * with grids that hold the whole corner (the default: they stay put) and
 * with cascades 0 and 1 too small for it (lpv.extent 1: they follow the
 * camera, cascade 2 stays put; so too fitted to the view, lpv.fit "view"
 * with view_extent 1, whose cells of 1/32 are the power of two nearest the corner's diagonal
 * over 128, and which a sub-cell move leaves as they were): without the
 * geometry volume's surfels (which sample the
 * G-buffer, so move with the camera) every cascade's light stays exactly
 * where it was (no grid moved, and the VPLs sit on the same world points);
 * with them, within 2%; the image's indirect light on the white wall within
 * 2% (its pixels see the wall shifted), with the lookup at half size a side
 * (at a quarter, this image's 24 x 18 coarse pixels see the wall
 * shift by 2.0% under the sun with the grids kept; the volumes as here). */
static void cascades_do_not_shimmer_under_sub_cell_motion(void **state) {
  (void)state;
  const lm_light_type types[] = {LM_LIGHT_SPOT, LM_LIGHT_DIRECTIONAL};
  for (int k = 0; k < 12; k++) {
    bool surfels = k & 1, follow = k >= 4, view = k >= 8;
    /* 8 steps: lpv.sum_r8 below is the last step's sum */
    const char *const sets[] = {"ambient=0", "lpv.coarse=2", "lpv.steps=8", view ? "lpv.view_extent=1" : "ambient=0",
                                view ? "lpv.fit=view" : follow ? "lpv.extent=1" : "lpv.extent=3",
                                surfels ? NULL : "lpv.surfels=0", NULL};
    lm_scene *s = corner_scene(types[k / 2 % 2]);
    gl_result r = render_ok(s, "lpv+esm", sets, W, H);
    int w, h;
    float *before = gl_read_target(&r, "lpv.sum_r8", &w, &h), lit0[3];
    assert_non_null(before);
    white_wall(&r, -0.9f, 0.9f, lit0);
    /* cascade 0's cell: extent times the diagonal of [-1, 1] x [0, 1.5] x [-1, 1], over 32 x 4 cells */
    float cell = (follow ? 1.0f : 3.0f) * sqrtf(4 + 2.25f + 4) / 128;
    int cam = s->cameras[0].node;
    mat4 m;
    glm_translate_make(m, (vec3){0.1f * cell, 0.75f, 2});
    memcpy(s->nodes[cam].local, m, sizeof m);
    lm_scene_update(s);
    assert_true(gl_render_again(&r));
    float *after = gl_read_target(&r, "lpv.sum_r8", &w, &h), lit1[3];
    assert_non_null(after);
    white_wall(&r, -0.9f, 0.9f, lit1);
    if (follow) assert_true(w > 2 * 32 * 32 && h == 32); /* two 32^3 blocks, then cascade 2's */
    double volume = aligned_difference(before, after, w, h, follow ? 32 : 0, 2);
    print_message("%s%s, grids %s, sub-cell move: volume change %.2e, white wall %.5f -> %.5f\n",
                  k / 2 % 2 ? "sun" : "spot", surfels ? "" : " (no surfels)",
                  view ? "fitted to the view" : follow ? "following" : "kept",
                  volume, lit0[0], lit1[0]);
    assert_true(volume < (surfels ? 0.02 : 1e-5));
    assert_true(fabsf(lit1[0] - lit0[0]) < 0.02f * lit0[0]);
    free(before);
    free(after);
    gl_result_free(&r);
    lm_scene_destroy(s);
  }
}

/* A rectangle on the plane axis = at (0 x, 1 y, 2 z), u and v ranges over
 * the other two axes in order, facing `sign` along the axis. */
static void rect(lm_scene *s, int material, int axis, float at, float sign, float u0, float u1, float v0,
                 float v1) {
  int a = (axis + 1) % 3, b = (axis + 2) % 3;
  float c[4][3], n[3] = {0, 0, 0}, uv[4][2] = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  n[axis] = sign;
  for (int i = 0; i < 4; i++) {
    /* counter-clockwise seen from n: a, b, axis is a right-handed frame, so reverse for -axis */
    int k = sign > 0 ? i : 3 - i;
    c[i][axis] = at, c[i][a] = uv[k][0], c[i][b] = uv[k][1];
  }
  gl_quad(s, "room", material, (const float(*)[3])c, n);
}

/* A white room (albedo 0.8, or `albedo`) of [-2, 2] x [0, 2.5] x [-2, 2] with a window in
 * its +x wall (z -0.8 .. 0.8, y 1 .. 2): the sun shines in along (-1, -0.9,
 * 0) onto a patch of the floor, the ceiling in no sun. The camera at (1.6,
 * 0.7, 1.6) looks at the far upper corner (-2, 2.2, -2): walls, ceiling and
 * some of the floor. */
static lm_scene *window_room(mat4 view_proj, int w, int h, float albedo) {
  lm_scene *s = lm_scene_create("room");
  int white = gl_material(s, "white", albedo, albedo, albedo);
  rect(s, white, 1, 0, 1, -2, 2, -2, 2);        /* floor: z, x */
  rect(s, white, 1, 2.5f, -1, -2, 2, -2, 2);    /* ceiling */
  rect(s, white, 0, -2, 1, 0, 2.5f, -2, 2);     /* -x wall: y, z */
  rect(s, white, 2, -2, 1, -2, 2, 0, 2.5f);     /* -z wall: x, y */
  rect(s, white, 2, 2, -1, -2, 2, 0, 2.5f);     /* +z wall */
  rect(s, white, 0, 2, -1, 0, 1, -2, 2);        /* +x wall under the window */
  rect(s, white, 0, 2, -1, 2, 2.5f, -2, 2);     /* above it */
  rect(s, white, 0, 2, -1, 1, 2, -2, -0.8f);    /* beside it */
  rect(s, white, 0, 2, -1, 1, 2, 0.8f, 2);
  mat4 view, m;
  glm_lookat((vec3){0, 0, 0}, (vec3){-1, -0.9f, 0}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, m); /* the node's -Z along the sun's direction */
  int sun = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                     .casts_shadows = true, .node = sun});
  glm_lookat((vec3){1.6f, 0.7f, 1.6f}, (vec3){-2, 2.2f, -2}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, m);
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "corner", .fov_y = glm_rad(70.0f), .znear = 0.01f, .zfar = 100,
                                      .node = cam});
  lm_scene_update(s);
  mat4 proj;
  glm_perspective(glm_rad(70.0f), (float)w / (float)h, 0.01f, 100, proj);
  glm_mat4_mul(proj, view, view_proj);
  return s;
}

/* Mean linear RGB of the 7 x 7 pixels around world point p (rows top first). */
static void around(const gl_result *r, mat4 view_proj, const float p[3], float out[3]) {
  vec4 clip;
  glm_mat4_mulv(view_proj, (vec4){p[0], p[1], p[2], 1}, clip);
  int col = (int)((clip[0] / clip[3] * 0.5f + 0.5f) * r->width);
  int row = (int)((0.5f - clip[1] / clip[3] * 0.5f) * r->height);
  assert_true(col >= 3 && col < r->width - 3 && row >= 3 && row < r->height - 3);
  gl_region(r, col - 3, row - 3, col + 4, row + 4, out);
}

/* Light that has bounced twice or more: the ceiling of the window room,
 * which the sun never sees, gets more light with lpv.bounces 2 than with 1
 * (the walls the floor lights send it on), and the light grows less with
 * each bounce and stays under the geometric bound of albedo 0.8 (five times
 * the first bounce's); with albedo 1 it stays finite. */
static void bounces_reach_the_ceiling_and_stay_bounded(void **state) {
  (void)state;
  enum { RW = 80, RH = 60 };
  mat4 vp;
  lm_scene *s = window_room(vp, RW, RH, 0.8f);
  const float ceiling[3] = {-1.0f, 2.5f, -1.0f};
  static const char *const dl_sets[] = {"ambient=0", NULL};
  gl_result dl = render_ok(s, "dl+esm", dl_sets, RW, RH);
  float dark[3];
  around(&dl, vp, ceiling, dark);
  assert_true(dark[0] < 1e-4f);
  gl_result_free(&dl);
  const int bounces[] = {1, 2, 3, 4, 8};
  float light[5];
  for (int i = 0; i < 5; i++) {
    char set[32];
    snprintf(set, sizeof set, "lpv.bounces=%d", bounces[i]);
    const char *const sets[] = {"ambient=0", set, NULL};
    gl_result r = render_ok(s, "lpv+esm", sets, RW, RH);
    float v[3];
    around(&r, vp, ceiling, v);
    light[i] = gl_luminance(v);
    print_message("bounces %d: ceiling %.5f\n", bounces[i], light[i]);
    assert_true(gl_all_finite(&r));
    gl_result_free(&r);
  }
  assert_true(light[0] > 1e-3f);
  assert_true(light[1] > 1.1f * light[0]);
  for (int i = 1; i < 5; i++) assert_true(light[i] >= light[i - 1] * (1 - 1e-4f));
  assert_true(light[4] - light[3] < light[1] - light[0]);
  assert_true(light[4] < 5 * light[0]);
  lm_scene_destroy(s);
  /* Albedo 1 (no bound from the albedo), every bounce: finite. */
  s = window_room(vp, RW, RH, 1.0f);
  static const char *const white[] = {"ambient=0", "lpv.bounces=8", NULL};
  gl_result r = render_ok(s, "lpv+esm", white, RW, RH);
  float v[3];
  around(&r, vp, ceiling, v);
  print_message("albedo 1, bounces 8: ceiling %.5f\n", gl_luminance(v));
  assert_true(gl_all_finite(&r) && gl_target_finite(&r, "lpv.e"));
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* Under a uniform sky of 0.5 (the sun's power 0: its RSM exists, but sends
 * nothing), the ground in the corner of two walls 4 high, at (0.7, 0, 0.7),
 * sees less sky than open ground at (6, 0, 6): with lpv.sky_occlusion at its
 * default lpv+esm darkens the corner, with 0 (and dl+esm) it cannot. The
 * field is 20 wide, so a cell is about 1.3: the geometry volume knows
 * occluders of the cells' size, not a post (test_sky's). */
static void an_outdoor_corner_sees_less_sky_than_open_ground(void **state) {
  (void)state;
  enum { SW = 96, SH = 72 };
  mat4 vp;
  lm_scene *s = gl_sunlit_corner(SW, SH, (float *)vp);
  const float corner[3] = {0.7f, 0, 0.7f}, open[3] = {6, 0, 6};
  const char *const techs[] = {"lpv+esm", "lpv+esm", "dl+esm"};
  for (int t = 0; t < 3; t++) {
    const char *const sets[] = {"ambient=0", "sky=true", "sky.zenith=0.5", "sky.horizon=0.5",
                                t == 1 ? "lpv.sky_occlusion=0" : NULL, NULL};
    gl_result r = gl_render_ok(&(gl_run){.scene = s, .tech = techs[t], .sets = sets, .width = SW, .height = SH});
    float a[3], b[3];
    around(&r, vp, corner, a);
    around(&r, vp, open, b);
    float ratio = gl_luminance(a) / fmaxf(gl_luminance(b), 1e-6f);
    print_message("%s%s: corner %.4f, open ground %.4f (0.25), ratio %.3f\n", techs[t],
                  t == 1 ? " (sky_occlusion 0)" : "", gl_luminance(a), gl_luminance(b), ratio);
    assert_true(fabsf(gl_luminance(b) - 0.25f) < 0.03f);
    if (t == 0) assert_true(ratio < 0.85f);
    else assert_true(fabsf(ratio - 1) < 0.02f);
    gl_result_free(&r);
  }
  lm_scene_destroy(s);
}

/* A hut [-1, 1] x [0, 2] x [-1, 1] on ground 40 wide, seen from inside
 * toward the far edge: the cells follow what is asked of them, seen in the
 * volumes' layout (lpv.lua: a cascade keeps just the cells that hold the
 * scene along an axis where it fits, here the height, one cell either side).
 * Fitted to the scene's box (diagonal 56.6), cascade 0's cell is 6 x 56.6 /
 * 128 = 2.65: 3 rows, blocks of 18^2, 10^2 and 6^2 cells (every cascade
 * holds the ground). Fitted to the view (lpv.fit "view", view_extent 1: the
 * frustum, up to the ground's far corner 20.4 ahead, clipped to the scene's
 * box, is 31.4 x 2 x 20.6, diagonal 37.6, over 128 cells: 0.294, whose nearest power
 * of two is 1/4): 2 / 0.25 + 2 = 10 rows and three 32^2 blocks that follow
 * the camera. Capped (lpv.max_cell 0.1): 22 rows. */
static void cells_follow_the_box_the_camera_sees(void **state) {
  (void)state;
  enum { HW = 64, HH = 48 };
  lm_scene *s = lm_scene_create("hut");
  int grey = gl_material(s, "grey", 0.5f, 0.5f, 0.5f);
  rect(s, grey, 1, 0, 1, -20, 20, -20, 20); /* ground: z, x */
  for (int k = 0; k < 2; k++) {
    float o = k ? 0.9f : 1.0f, in = k ? -1.0f : 1.0f, top = k ? 1.8f : 2.0f; /* inner faces face in */
    rect(s, grey, 1, top, k ? -1.0f : 1.0f, -o, o, -o, o);    /* roof (ceiling): z, x */
    rect(s, grey, 0, -o, -in, 0, top, -o, o);                 /* -x wall: y, z */
    rect(s, grey, 0, o, in, 0, top, -o, o);                   /* +x wall */
    rect(s, grey, 2, -o, -in, -o, o, 0, top);                 /* -z wall: x, y */
    rect(s, grey, 2, o, in, -o, o, 0, top);                   /* +z wall */
  }
  mat4 view, m;
  glm_lookat((vec3){0, 0, 0}, (vec3){-0.3f, -1, -0.2f}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, m);
  int sun = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                     .casts_shadows = true, .node = sun});
  glm_lookat((vec3){0, 0.9f, 0.6f}, (vec3){0, 0.6f, -0.9f}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, m);
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "inside", .fov_y = glm_rad(60.0f), .znear = 0.01f, .zfar = 100,
                                      .node = cam});
  lm_scene_update(s);
  const struct {
    const char *set, *extent;
    int width, rows;
  } fits[] = {{NULL, NULL, 18 * 18 + 10 * 10 + 6 * 6, 3},
              {"lpv.fit=view", "lpv.view_extent=1", 3 * 32 * 32, 10},
              {"lpv.max_cell=0.1", NULL, 3 * 32 * 32, 22}};
  for (int t = 0; t < 3; t++) {
    const char *const sets[] = {"ambient=0", fits[t].extent ? fits[t].extent : "ambient=0", fits[t].set, NULL};
    gl_result r = gl_render_ok(&(gl_run){.scene = s, .tech = "lpv+esm", .sets = sets, .width = HW, .height = HH,
                                         .keep_targets = true});
    int w, h;
    float *v = gl_read_target(&r, "lpv.inject_r", &w, &h);
    assert_non_null(v);
    print_message("%s: volumes %d x %d\n", fits[t].set ? fits[t].set : "lpv.fit=scene", w, h);
    assert_int_equal(w, fits[t].width);
    assert_int_equal(h, fits[t].rows);
    assert_true(gl_all_finite(&r));
    free(v);
    gl_result_free(&r);
  }
  lm_scene_destroy(s);
}

/* The LPV's passes and volumes exist only in a frame whose technique reads
 * them, and then none is left out; without a light that casts shadows (no
 * RSM) lpv+esm is direct light alone. */
static void a_frame_that_reads_no_lpv_records_none_of_its_passes(void **state) {
  (void)state;
  const char *const techs[] = {"dl+esm", "isr+esm", "rsm+esm", "vpl+esm", "isr+rsm+esm", "lpv+esm", "isr+lpv+esm"};
  lm_scene *s = corner_scene(LM_LIGHT_DIRECTIONAL);
  for (int t = 0; t < 7; t++) {
    gl_result r = render_ok(s, techs[t], NULL, 48, 36);
    bool reads = t >= 5;
    lm_graph *g = lm_renderer_graph(r.renderer);
    assert_int_equal(gl_has_pass(&r, "lpv."), reads);
    assert_int_equal(lm_graph_find_target(g, "lpv.inject_r") >= 0, reads);
    assert_int_equal(lm_graph_find_target(g, "lpv.geometry") >= 0, reads);
    assert_int_equal(gl_culled(&r, "lpv."), 0);
    gl_result_free(&r);
  }
  s->lights[0].casts_shadows = false;
  gl_result r = render_ok(s, "lpv+esm", NULL, 48, 36);
  assert_false(gl_has_pass(&r, "lpv."));
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* The corner in other units (cameras and lights scaled with it): in units
 * that floats scale exactly (1/1024, 65536) the white wall's light is the
 * same within 0.5% (nothing in the LPV has a unit); in units 1e-3 and 1e5
 * within 10%: the shadow manager snaps the RSM's tiles on grids relative to
 * the scene's magnitude, so there the VPLs (one texel each) fall on other
 * texels, and the cells they land in change (measured: 6% at 1e-3, under
 * 0.1% at 1e5; rsm+esm, which takes many texels a pixel, 1%). */
static void any_unit_gives_the_same_light(void **state) {
  (void)state;
  static const char *const sets[] = {"ambient=0", NULL};
  float base[3];
  lm_scene *s = corner_scene(LM_LIGHT_DIRECTIONAL);
  gl_result r = render_ok(s, "lpv+esm", sets, W, H);
  white_wall(&r, -0.9f, 0.9f, base);
  gl_result_free(&r);
  lm_scene_destroy(s);
  const float units[] = {1.0f / 1024, 65536, 1e-3f, 1e5f}, bound[] = {0.005f, 0.005f, 0.1f, 0.1f};
  for (int i = 0; i < 4; i++) {
    s = corner_scene(LM_LIGHT_DIRECTIONAL);
    gl_rescale(s, units[i]);
    lm_scene_update(s);
    r = render_ok(s, "lpv+esm", sets, W, H);
    float v[3];
    white_wall(&r, -0.9f, 0.9f, v);
    print_message("unit %g: white wall %.5f (unit 1: %.5f)\n", units[i], v[0], base[0]);
    assert_true(fabsf(v[0] - base[0]) < bound[i] * base[0]);
    gl_result_free(&r);
    lm_scene_destroy(s);
  }
}

/* Every option at both ends, a point light inside a closed box seen from
 * outside, and the combined technique: finite images and volumes. */
static void extremes_stay_finite(void **state) {
  (void)state;
  static const char *const cases[][5] = {
      {"lpv.steps=0", NULL},
      {"lpv.steps=256", "lpv.cells=4", NULL},
      {"lpv.cells=64", "lpv.steps=1", "lpv.cascades=1", NULL},
      {"lpv.cascades=4", "lpv.cells=8", NULL},
      {"lpv.vpls=1", NULL},
      {"lpv.vpls=1024", "lpv.cascades=1", "lpv.steps=1", NULL},
      {"lpv.surfels=0", NULL},
      {"lpv.surfels=1024", "lpv.cascades=1", "lpv.steps=1", NULL},
      {"lpv.extent=1e-3", NULL},
      {"lpv.extent=64", NULL},
      {"lpv.cell=1e-30", NULL},
      {"lpv.cell=1e30", NULL},
      {"lpv.occlusion=0", "lpv.shift=0", NULL},
      {"lpv.coarse=8", "lpv.blur=32", "lpv.k=16", NULL},
      {"lpv.coarse=1", "lpv.blur=0", "lpv.reach=64", NULL},
      {"lpv.bounces=8", "lpv.steps=1", NULL},
      {"lpv.bounces=8", "lpv.surfels=0", NULL},
      {"sky=true", "sky.intensity=1e6", "lpv.bounces=8", "lpv.sky_cells=64", NULL},
      {"ambient=1e6", "lpv.sky_occlusion=0.5", "lpv.sky_cells=1", NULL},
      {"lpv.fit=view", "lpv.view_extent=1e-3", NULL},
      {"lpv.fit=view", "lpv.view_extent=64", "sky=true", "sky.intensity=1e6", NULL},
      {"lpv.max_cell=1e-30", NULL},
  };
  lm_scene *s = corner_scene(LM_LIGHT_DIRECTIONAL);
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    gl_result r = gl_render_ok(&(gl_run){.scene = s, .tech = "lpv+esm", .sets = cases[i], .width = 48, .height = 36,
                                         .keep_targets = true});
    if (gl_has_pass(&r, "lpv.lookup") && !gl_target_finite(&r, "lpv.e")) fail_msg("case %zu: lpv.e", i);
    if (!gl_all_finite(&r)) fail_msg("case %zu: the image", i);
    gl_result_free(&r);
  }
  gl_result r = render_ok(s, "isr+lpv+esm", NULL, 48, 36);
  gl_result_free(&r);
  static const char *const bounced[] = {"lpv.bounces=8", NULL};
  r = render_ok(s, "isr+lpv+esm", bounced, 48, 36);
  assert_true(gl_all_finite(&r));
  gl_result_free(&r);
  lm_scene_destroy(s);
  /* A point light inside a closed box, the camera outside it. */
  s = lm_scene_create("box");
  int grey = gl_material(s, "grey", 0.5f, 0.5f, 0.5f);
  static const float walls[6][4][3] = {
      {{-1, -1, 1}, {1, -1, 1}, {1, -1, -1}, {-1, -1, -1}}, {{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}},
      {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}}, {{1, -1, 1}, {-1, -1, 1}, {-1, 1, 1}, {1, 1, 1}},
      {{-1, -1, 1}, {-1, -1, -1}, {-1, 1, -1}, {-1, 1, 1}}, {{1, -1, -1}, {1, -1, 1}, {1, 1, 1}, {1, 1, -1}},
  };
  static const float normals[6][3] = {{0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}};
  for (int i = 0; i < 6; i++) gl_quad(s, "wall", grey, walls[i], normals[i]);
  mat4 m = GLM_MAT4_IDENTITY_INIT;
  int node = lm_scene_add_node(s, "lamp", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "lamp", .type = LM_LIGHT_POINT, .color = {1, 1, 1}, .power = 1,
                                     .falloff = LM_FALLOFF_INVERSE_SQUARE, .casts_shadows = true, .node = node});
  glm_translate_make(m, (vec3){0, 0, 4});
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "outside", .fov_y = glm_rad(45.0f), .znear = 0.01f, .zfar = 100,
                                      .node = cam});
  lm_scene_update(s);
  r = render_ok(s, "lpv+esm", NULL, 48, 36);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

static void bad_options_name_themselves(void **state) {
  (void)state;
  static const gl_bad_option cases[] = {
      {"lpv+esm", "lpv.cells=3", "lpv.cells"},         {"lpv+esm", "lpv.cells=65", "lpv.cells"},
      {"lpv+esm", "lpv.cells=8.5", "lpv.cells"},       {"lpv+esm", "lpv.steps=-1", "lpv.steps"},
      {"lpv+esm", "lpv.steps=257", "lpv.steps"},       {"lpv+esm", "lpv.cascades=0", "lpv.cascades"},
      {"lpv+esm", "lpv.cascades=5", "lpv.cascades"},   {"lpv+esm", "lpv.extent=0", "lpv.extent"},
      {"lpv+esm", "lpv.cell=-1", "lpv.cell"},          {"lpv+esm", "lpv.shift=2", "lpv.shift"},
      {"lpv+esm", "lpv.vpls=0", "lpv.vpls"},           {"lpv+esm", "lpv.surfels=-1", "lpv.surfels"},
      {"lpv+esm", "lpv.occlusion=2", "lpv.occlusion"}, {"lpv+esm", "lpv.reach=0.5", "lpv.reach"},
      {"lpv+esm", "lpv.coarse=3", "lpv.coarse"},       {"isr+lpv+esm", "lpv.blur=33", "lpv.blur"},
      {"isr+lpv+esm", "lpv.k=17", "lpv.k"},           {"lpv+esm", "lpv.bounces=0", "lpv.bounces"},
      {"lpv+esm", "lpv.bounces=9", "lpv.bounces"},     {"lpv+esm", "lpv.sky_occlusion=2", "lpv.sky_occlusion"},
      {"lpv+esm", "lpv.sky_cells=0", "lpv.sky_cells"},     {"lpv+esm", "lpv.fit=box", "lpv.fit"},
      {"lpv+esm", "lpv.view_extent=0", "lpv.view_extent"}, {"lpv+esm", "lpv.max_cell=-1", "lpv.max_cell"},
  };
  gl_assert_bad_options(cases, sizeof cases / sizeof *cases, "pp.lua:");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_lit_coloured_wall_tints_a_neighbouring_white_one),
      cmocka_unit_test(energy_does_not_grow_with_propagation_steps),
      cmocka_unit_test(bounces_reach_the_ceiling_and_stay_bounded),
      cmocka_unit_test(an_outdoor_corner_sees_less_sky_than_open_ground),
      cmocka_unit_test(cascades_do_not_shimmer_under_sub_cell_motion),
      cmocka_unit_test(cells_follow_the_box_the_camera_sees),
      cmocka_unit_test(a_frame_that_reads_no_lpv_records_none_of_its_passes),
      cmocka_unit_test(any_unit_gives_the_same_light),
      cmocka_unit_test(extremes_stay_finite),
      cmocka_unit_test(bad_options_name_themselves),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
