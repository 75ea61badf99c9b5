/* Image-space radiosity (scripts/isr.lua) on the built-in Cornell box through
 * pp.lua: colour bleeding, ambient occlusion in corners, coarse versus full
 * size, finite results at extreme parameters, option errors, and that the
 * dl technique records no ISR pass. Needs a GL context (llvmpipe will do). */
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

static lm_scene *scene;

static int setup(void **state) {
  lm_error err;
  scene = lm_scene_builtin("cornell", &err);
  return scene ? gl_test_setup(state) : -1;
}

static int teardown(void **state) {
  lm_scene_destroy(scene);
  return gl_test_teardown(state);
}

typedef struct image {
  gl_result r;
  float *lit; /* the script's presented target, before the output stage sanitizes */
  const float *rgb;
} image;

/* Renders one frame of pp.lua with technique `tech` and "name=value" options
 * (NULL-terminated). Returns false with the message in err. */
static bool render(const char *tech, const char *const *sets, image *out, lm_error *err) {
  out->r = gl_render(&(gl_run){.scene = scene, .tech = tech, .sets = sets, .width = W, .height = H});
  *err = out->r.err;
  out->rgb = out->r.rgb;
  int w, h;
  out->lit = out->r.ok ? gl_read_target(&out->r, "lit", &w, &h) : NULL;
  return out->r.ok;
}

static void image_free(image *im) {
  gl_result_free(&im->r);
  free(im->lit);
  free(im);
}

static image *render_ok(const char *tech, const char *const *sets) {
  image *im = calloc(1, sizeof *im);
  assert_non_null(im);
  lm_error err;
  if (!render(tech, sets, im, &err)) fail_msg("%s: %s", tech, err.msg);
  return im;
}

/* Pixel of a world point for the box's camera (cornell.c: eye (0, 1, 3.4)
 * looking down -z, fov_y 45 degrees), top row first. */
static void project(float x, float y, float z, int *col, int *row) {
  float depth = 3.4f - z, t = tanf(0.5f * 45.0f * 3.14159265f / 180.0f), aspect = (float)W / H;
  *col = (int)((x / (depth * t * aspect) + 1) * 0.5f * W);
  *row = (int)((1 - (y - 1) / (depth * t)) * 0.5f * H);
}

/* Mean colour of the (2r+1)^2 pixels around a world point. */
static void mean_around(const image *im, float x, float y, float z, int r, double out[3]) {
  int c0, r0;
  project(x, y, z, &c0, &r0);
  out[0] = out[1] = out[2] = 0;
  for (int row = r0 - r; row <= r0 + r; row++)
    for (int col = c0 - r; col <= c0 + r; col++)
      for (int k = 0; k < 3; k++) out[k] += im->rgb[(row * W + col) * 3 + k];
  for (int k = 0; k < 3; k++) out[k] /= (2 * r + 1) * (2 * r + 1);
}

/* Surfaces beside a coloured wall take its colour: ISR raises the ratio of
 * the wall's channel to the other wall's over direct light alone. The floor
 * by the red wall is brightly lit, so bleeding shifts its ratio by about
 * 1.5% (the seed's simple scenes gained 0.2-3.3%); the dimmer ceiling by the
 * green wall shifts by about 3.5%. */
static void indirect_light_bleeds_wall_colour(void **state) {
  (void)state;
  image *dl = render_ok("dl", NULL), *isr = render_ok("isr", NULL);
  double d[3], i[3];
  mean_around(dl, -0.85f, 0.0f, 0.3f, 3, d); /* floor by the red wall */
  mean_around(isr, -0.85f, 0.0f, 0.3f, 3, i);
  double red_dl = d[0] / d[1], red_isr = i[0] / i[1];
  mean_around(dl, 0.85f, 2.0f, 0.3f, 3, d);  /* ceiling by the green wall */
  mean_around(isr, 0.85f, 2.0f, 0.3f, 3, i);
  double green_dl = d[1] / d[0], green_isr = i[1] / i[0];
  print_message("red/green on the floor by the red wall: dl %.4f isr %.4f\n"
                "green/red on the ceiling by the green wall: dl %.4f isr %.4f\n",
                red_dl, red_isr, green_dl, green_isr);
  assert_true(red_isr > red_dl * 1.01);
  assert_true(green_isr > green_dl * 1.02);
  image_free(dl);
  image_free(isr);
}

/* With k_ISR = 0 and k_SSAO = 1, eq 29 is direct light times accessibility,
 * so isr / dl is the accessibility A: lower in the edge where the back wall
 * meets the green wall than in the open middle of the back wall. */
static void occlusion_darkens_inside_corners(void **state) {
  (void)state;
  static const char *const sets[] = {"isr.k_isr=0", "isr.k_ssao=1", NULL};
  image *dl = render_ok("dl", NULL), *ao = render_ok("isr", sets);
  double d[3], a[3];
  mean_around(dl, 0.9f, 1.0f, -1.0f, 3, d);
  mean_around(ao, 0.9f, 1.0f, -1.0f, 3, a);
  double corner = a[1] / d[1];
  mean_around(dl, 0.3f, 1.3f, -1.0f, 3, d);
  mean_around(ao, 0.3f, 1.3f, -1.0f, 3, a);
  double open = a[1] / d[1];
  print_message("accessibility: corner %.3f, open wall %.3f\n", corner, open);
  assert_true(open > 0.9 && open <= 1.0 + 1e-4); /* occlusion only darkens */
  assert_true(corner < open - 0.1);
  image_free(dl);
  image_free(ao);
}

/* The seed's mean error, sum(|dR| + |dG| + |dB|) / (3 w h), between the
 * coarse (factor 2) and the full-size ISR stays under 0.01 (linear), with
 * k_ISR = k_SSAO = 1 so that the ISR terms weigh all they can. */
static void coarse_and_full_size_agree(void **state) {
  (void)state;
  static const char *const full[] = {"isr.coarse=1", "isr.k_isr=1", "isr.k_ssao=1", NULL};
  static const char *const half[] = {"isr.coarse=2", "isr.k_isr=1", "isr.k_ssao=1", NULL};
  image *a = render_ok("isr", full), *b = render_ok("isr", half);
  double sum = 0;
  for (int i = 0; i < W * H * 3; i++) sum += fabs(a->rgb[i] - b->rgb[i]);
  double mean_error = sum / (3.0 * W * H);
  print_message("mean error coarse 1 vs 2: %.5f\n", mean_error);
  assert_true(mean_error < 0.01);
  image_free(a);
  image_free(b);
}

static bool all_finite(const image *im) {
  for (int i = 0; i < W * H * 4; i++)
    if (!isfinite(im->lit[i]) || im->lit[i] < 0) return false;
  return true;
}

/* Extremes of every option give finite, non-negative light before the output
 * stage (which would hide a NaN). */
static void extreme_parameters_stay_finite(void **state) {
  (void)state;
  static const char *const cases[][6] = {
      {"isr.samples=1", "isr.radius=1e-6", NULL},
      {"isr.samples=256", "isr.radius=1e6", "isr.coarse=1", NULL},
      {"isr.samples=2", "isr.radius=1e6", "isr.coarse=4", "isr.blur=0", NULL},
      {"isr.k_isr=0", "isr.k_ssao=0", "isr.blur=32", NULL},
      {"isr.k_isr=1", "isr.k_ssao=1", "isr.sender=lit", "isr.bounces=4", NULL},
      {"isr.radius=1e-30", "isr.coarse=1", "isr.sender=lit", "isr.bounces=2", NULL},
  };
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    image *im = calloc(1, sizeof *im);
    lm_error err;
    if (!render("isr", cases[c], im, &err)) fail_msg("case %zu: %s", c, err.msg);
    if (!all_finite(im)) fail_msg("case %zu (%s ...): a NaN, Inf or negative value", c, cases[c][0]);
    image_free(im);
  }
}

/* Out-of-range options stop the frame with the option's name. */
static void bad_options_name_themselves(void **state) {
  (void)state;
  static const struct {
    const char *set, *expect;
  } cases[] = {
      {"isr.samples=0", "isr.samples must be a whole number in 1..256 (got 0)"},
      {"isr.samples=2.5", "isr.samples must be"},
      {"isr.coarse=3", "isr.coarse must be 1, 2 or 4"},
      {"isr.radius=0", "isr.radius must be a positive"},
      {"isr.k_ssao=-1", "isr.k_ssao must be in 0..1"},
      {"isr.sender=sun", "isr.sender must be \"albedo\" or \"lit\" (got sun)"},
      {"isr.bounces=5", "isr.bounces must be"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    image *im = calloc(1, sizeof *im);
    const char *sets[] = {cases[i].set, NULL};
    lm_error err;
    if (render("isr", sets, im, &err)) fail_msg("%s: rendered", cases[i].set);
    if (!strstr(err.msg, cases[i].expect) || !strstr(err.msg, "pp.lua:"))
      fail_msg("%s: '%s'", cases[i].set, err.msg);
    image_free(im);
  }
}

static void dl_records_no_isr_pass(void **state) {
  (void)state;
  image *dl = render_ok("dl", NULL), *isr = render_ok("isr", NULL);
  assert_false(gl_has_pass(&dl->r, "isr."));
  assert_true(gl_has_pass(&isr->r, "isr."));
  lm_graph *g = lm_renderer_graph(isr->r.renderer);
  for (int i = 0; i < lm_graph_pass_count(g); i++) /* every ISR pass reaches the output */
    assert_false(lm_graph_pass(g, i).culled);
  image_free(dl);
  image_free(isr);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(indirect_light_bleeds_wall_colour),
      cmocka_unit_test(occlusion_darkens_inside_corners),
      cmocka_unit_test(coarse_and_full_size_agree),
      cmocka_unit_test(extreme_parameters_stay_finite),
      cmocka_unit_test(bad_options_name_themselves),
      cmocka_unit_test(dl_records_no_isr_pass),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
