/* Sky light (scripts/sky.lua): a uniform sky gives a Lambertian surface its
 * albedo times the sky's radiance under every technique, the GI techniques
 * occlude it beside an obstacle where `dl` cannot, a sky of intensity 0
 * changes nothing, and bad options are refused by name. POV-Ray agreement:
 * tests/test_sky_pov.sh.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_test.h"

static gl_result render_ok(lm_scene *s, const char *tech, const char *const *sets) {
  return gl_render_ok(&(gl_run){.scene = s, .tech = tech, .sets = sets, .width = 96, .height = 72});
}

/* The field with its sun off: the sky alone lights it. */
static lm_scene *shaded_field(void) {
  lm_error err;
  lm_scene *s = lm_scene_builtin("field", &err);
  assert_non_null(s);
  s->lights[0].power = 0.0f;
  return s;
}

static void a_uniform_sky_gives_albedo_times_radiance(void **state) {
  (void)state;
  lm_scene *s = shaded_field();
  static const char *const uniform[] = {"ambient=0", "sky=true", "sky.zenith=0.5", "sky.horizon=0.5", NULL};
  static const char *const techs[] = {"dl", "isr", "ssao", "ssdo", "lpv+esm"};
  for (int t = 0; t < 5; t++) {
    gl_result r = render_ok(s, techs[t], uniform);
    float ground[3];
    gl_region(&r, 40, 66, 56, 71, ground); /* open ground at the bottom, in front of every post */
    printf("%s: open ground under a uniform sky of 0.5: %.4f %.4f %.4f (albedo 0.45 0.5 0.35 times 0.5)\n",
           techs[t], ground[0], ground[1], ground[2]);
    static const float albedo[3] = {0.45f, 0.5f, 0.35f};
    for (int k = 0; k < 3; k++)
      if (!(fabsf(ground[k] - 0.5f * albedo[k]) < 0.04f * albedo[k])) fail_msg("%s: channel %d %g", techs[t], k, ground[k]);
    gl_result_free(&r);
  }
  lm_scene_destroy(s);
}

/* Background pixels show the sky, as POV-Ray's camera sees its sky_sphere:
 * a uniform sky of 0.5 in the sky above the field under every technique, and
 * a sky brighter at the zenith brighter toward the image's top. */
static void the_sky_is_seen_where_no_geometry_is(void **state) {
  (void)state;
  lm_scene *s = shaded_field();
  static const char *const uniform[] = {"ambient=0", "sky=true", "sky.zenith=0.5", "sky.horizon=0.5", NULL};
  static const char *const techs[] = {"dl", "isr", "ssao", "ssdo", "isr+esm"};
  for (int t = 0; t < 5; t++) {
    gl_result r = render_ok(s, techs[t], uniform);
    float top[3];
    gl_region(&r, 0, 0, 95, 3, top);
    printf("%s: the sky above the field: %.4f %.4f %.4f (0.5)\n", techs[t], top[0], top[1], top[2]);
    for (int k = 0; k < 3; k++) assert_float_equal(top[k], 0.5f, 0.01f);
    gl_result_free(&r);
  }
  static const char *const gradient[] = {"ambient=0", "sky=true", "sky.zenith=1", "sky.horizon=0.1", NULL};
  gl_result r = render_ok(s, "dl", gradient);
  float high[3], low[3];
  gl_region(&r, 0, 0, 95, 1, high);
  gl_region(&r, 0, 12, 95, 13, low);
  printf("gradient sky: %.4f at the top, %.4f lower\n", gl_luminance(high), gl_luminance(low));
  assert_true(gl_luminance(high) > gl_luminance(low) + 0.02f);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* Mean of the 3 x 3 pixels around world point p seen through vp. */
static float luminance_at(const gl_result *r, mat4 vp, float x, float y, float z) {
  vec4 q;
  glm_mat4_mulv(vp, (vec4){x, y, z, 1.0f}, q);
  int col = (int)((q[0] / q[3] * 0.5f + 0.5f) * (float)r->width), row = (int)((0.5f - q[1] / q[3] * 0.5f) * (float)r->height);
  assert_true(col >= 1 && col < r->width - 1 && row >= 1 && row < r->height - 1);
  float c[3];
  gl_region(r, col - 1, row - 1, col + 1, row + 1, c);
  return gl_luminance(c);
}

/* Looking down at a post's side from the side: the ground at its foot sees
 * less sky than the ground 2 m away, which `dl` cannot know. */
static void gi_occludes_the_sky_beside_an_obstacle(void **state) {
  (void)state;
  lm_scene *s = shaded_field();
  mat4 view, world, proj, vp;
  glm_lookat((vec3){3.0f, 4.0f, 2.0f}, (vec3){0.8f, 0.0f, 2.0f}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, world);
  lm_scene_node_set_world(s, s->cameras[0].node, (float *)world);
  glm_perspective(s->cameras[0].fov_y, 96.0f / 72.0f, s->cameras[0].znear, s->cameras[0].zfar, proj);
  glm_mat4_mul(proj, view, vp);
  static const char *const sky[] = {"ambient=0", "sky=true", NULL};
  static const char *const techs[] = {"dl", "isr", "ssao"};
  for (int t = 0; t < 3; t++) {
    gl_result r = render_ok(s, techs[t], sky);
    /* post_0_2's +x face is at x = 0.3 */
    float ratio = luminance_at(&r, vp, 0.4f, 0.0f, 2.0f) / fmaxf(luminance_at(&r, vp, 2.3f, 0.0f, 2.0f), 1e-6f);
    printf("%s: ground at a post's foot over ground 2 m away: %.3f\n", techs[t], ratio);
    if (t == 0 ? !(fabsf(ratio - 1.0f) < 0.02f) : !(ratio < 0.95f)) fail_msg("%s: ratio %g", techs[t], ratio);
    gl_result_free(&r);
  }
  lm_scene_destroy(s);
}

static void a_sky_of_intensity_0_changes_nothing(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("field", &err);
  static const char *const off[] = {"sky=false", NULL}, *const zero[] = {"sky=true", "sky.intensity=0", NULL};
  gl_result a = render_ok(s, "isr+esm", off), b = render_ok(s, "isr+esm", zero);
  for (int i = 0; i < a.width * a.height * 3; i++)
    if (fabsf(a.rgb[i] - b.rgb[i]) > 1e-5f) fail_msg("value %d: %g against %g", i, a.rgb[i], b.rgb[i]);
  gl_result_free(&a);
  gl_result_free(&b);
  lm_scene_destroy(s);
}

static void bad_sky_options_are_refused(void **state) {
  (void)state;
  static const gl_bad_option cases[] = {
      {"dl", "sky.zenith=blue", "sky.zenith must be \"r,g,b\" or one number, each in 0..1e6 (got blue)"},
      {"dl", "sky.horizon=1,2", "sky.horizon must be"},
      {"dl", "sky.horizon=-1", "sky.horizon must be"},
      {"dl", "sky.intensity=-1", "sky.intensity must be a finite number in 0..1e+06 (got -1)"},
  };
  gl_assert_bad_options(cases, sizeof cases / sizeof *cases, "pp.lua:");
  /* A map that is not there: the message names it (the sky is on). */
  static const char *const map[] = {"sky=true", "sky.map=/tmp/limn-no-such-sky.exr", NULL};
  gl_result r = gl_render(&(gl_run){.tech = "dl", .sets = map, .width = 16, .height = 12});
  assert_false(r.ok);
  if (!strstr(r.err.msg, "limn-no-such-sky.exr")) fail_msg("%s", r.err.msg);
  gl_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_uniform_sky_gives_albedo_times_radiance),
      cmocka_unit_test(the_sky_is_seen_where_no_geometry_is),
      cmocka_unit_test(gi_occludes_the_sky_beside_an_obstacle),
      cmocka_unit_test(a_sky_of_intensity_0_changes_nothing),
      cmocka_unit_test(bad_sky_options_are_refused),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
