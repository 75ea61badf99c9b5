/* The same image in any unit and at any depth range (issue 16): a scene whose
 * root is scaled by s (cameras under it, lights' ranges converted as an
 * exporter would) renders within a stated tolerance of the scale-1 image, and
 * so does a camera with near 1e-5 and far 1e6. At 96x72: the field under a
 * sun (cascades), the Cornell box under a spot light, and the office (glTF,
 * a sunlit room, a camera-list view). A camera under a mirrored node sees
 * the same image as its unmirrored twin. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"
#include "scene/gltf.h"

enum { W = 96, H = 72 };
/* Relative mean difference from the scale-1 image (sum |a - b| / sum |a|). */
#define TOLERANCE 0.02

static const float scales[] = {1e-3f, 1e-2f, 1e-1f, 1e3f, 1e5f};

/* The scene `name` (built in, or data/scenes/NAME.glb seen from the first
 * view of its camera list) in a unit s times smaller (gl_rescale). */
static lm_scene *scaled(const char *name, float s) {
  lm_error err;
  char path[1024];
  snprintf(path, sizeof path, "%s/../data/scenes/%s.glb", LIMN_TEST_DIR, name);
  lm_scene *scene = strcmp(name, "office") ? lm_scene_builtin(name, &err) : lm_scene_load_gltf(path, &err);
  if (!scene) fail_msg("%s: %s", name, err.msg);
  if (!strcmp(name, "office")) {
    int n;
    snprintf(path, sizeof path, "%s/../data/scenes/%s.cams", LIMN_TEST_DIR, name);
    int first = lm_scene_add_camera_list(scene, path, &n, &err);
    if (first < 0) fail_msg("%s", err.msg);
    lm_camera c = scene->cameras[0];
    scene->cameras[0] = scene->cameras[first], scene->cameras[first] = c;
  }
  if (!strcmp(name, "cornell")) { /* its point light as a spot shining down */
    scene->lights[0].type = LM_LIGHT_SPOT;
    scene->lights[0].inner_cone = glm_rad(55.0f);
    scene->lights[0].outer_cone = glm_rad(75.0f);
  }
  if (s != 1.0f) gl_rescale(scene, s);
  return scene;
}

static double relative_difference(const gl_result *a, const gl_result *b) {
  double diff = 0, sum = 0;
  for (size_t i = 0; i < (size_t)W * H * 3; i++) {
    diff += fabs((double)a->rgb[i] - b->rgb[i]);
    sum += fabs((double)a->rgb[i]);
  }
  return diff / fmax(sum, 1e-30);
}

static gl_result render_with(lm_scene *s, const char *tech, float unit, const char *const *more) {
  /* Every default is relative to the view (ISR's rays march from a pixel's
   * footprint to the view's edge): nothing is given in the unit. */
  const char *sets[8] = {NULL};
  for (int i = 0; more && more[i] && i < 7; i++) sets[i] = more[i];
  gl_result r = gl_render(&(gl_run){.scene = s, .tech = tech, .sets = sets, .width = W, .height = H});
  if (!r.ok) fail_msg("%s: %s", tech, r.err.msg);
  if (!gl_all_finite(&r)) fail_msg("%s at scale %g: a pixel is NaN, Inf or negative", tech, unit);
  return r;
}

static gl_result render(lm_scene *s, const char *tech, float unit) { return render_with(s, tech, unit, NULL); }

static void sweep(const char *name) {
  static const char *const techs[] = {"dl+esm", "isr+esm"};
  bool ok = true;
  for (int t = 0; t < 2; t++) {
    lm_scene *one = scaled(name, 1.0f);
    gl_result ref = render(one, techs[t], 1.0f);
    for (size_t k = 0; k < sizeof scales / sizeof *scales; k++) {
      lm_scene *s = scaled(name, scales[k]);
      gl_result r = render(s, techs[t], scales[k]);
      double d = relative_difference(&ref, &r);
      float all[3];
      gl_region(&r, 0, 0, W - 1, H - 1, all);
      printf("%s %s scale %g: relative mean difference %.4f (mean %.4f)\n", name, techs[t], scales[k], d, gl_luminance(all));
      ok &= d < TOLERANCE;
      gl_result_free(&r);
      lm_scene_destroy(s);
    }
    one->cameras[0].znear = 1e-5f;
    one->cameras[0].zfar = 1e6f;
    gl_result r = render(one, techs[t], 1.0f);
    double d = relative_difference(&ref, &r);
    printf("%s %s near 1e-5 far 1e6: relative mean difference %.4f\n", name, techs[t], d);
    ok &= d < TOLERANCE;
    gl_result_free(&r);
    gl_result_free(&ref);
    lm_scene_destroy(one);
  }
  if (!ok) fail_msg("%s: an image differs by %.0f%% or more from scale 1", name, TOLERANCE * 100);
}

/* View depth (gbuffer.dpt times far) of every pixel, 0 where nothing is. */
static float *view_depths(lm_scene *s) {
  gl_result r = gl_render(&(gl_run){.scene = s, .tech = "dl", .width = W, .height = H});
  assert_true(r.ok);
  lm_renderer_set_sharing(r.renderer, false); /* keep gbuffer.dpt readable */
  assert_true(gl_render_again(&r));
  int w, h;
  float *dpt = gl_read_target(&r, "gbuffer.dpt", &w, &h);
  assert_non_null(dpt);
  lm_frame_data cam;
  lm_scene_frame_data(s, 0, W, H, &cam);
  for (size_t i = 0; i < (size_t)w * h; i++) dpt[i] = dpt[i * 4] * cam.clip[1];
  gl_result_free(&r);
  return dpt;
}

/* Near 1e-5 and far 1e6 (a ratio of 1e11): the depth test still finds the
 * nearest surface everywhere, and the G-buffer's depth agrees with that of
 * near 0.1, far 100 to float precision, whatever the unit. */
static void depth_is_exact_at_a_near_far_ratio_of_1e11(void **state) {
  (void)state;
  for (int u = 0; u < 3; u++) {
    float unit = u == 0 ? 1.0f : u == 1 ? 1e-3f : 1e5f;
    lm_scene *s = scaled("cornell", unit);
    s->cameras[0].znear = 0.1f, s->cameras[0].zfar = 100.0f;
    float *ref = view_depths(s);
    s->cameras[0].znear = 1e-5f, s->cameras[0].zfar = 1e6f;
    float *d = view_depths(s);
    double worst = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
      if ((ref[i] > 0) != (d[i] > 0)) fail_msg("unit %g: pixel %zu covered in one image only", unit, i);
      if (ref[i] > 0) worst = fmax(worst, fabs(d[i] - ref[i]) / ref[i]);
    }
    printf("unit %g: near 1e-5 far 1e6 against near 0.1 far 100: largest relative depth difference %.3g\n", unit,
           worst);
    if (!(worst < 1e-5)) fail_msg("unit %g: depth differs by %g", unit, worst);
    free(ref);
    free(d);
    lm_scene_destroy(s);
  }
}

static void the_sun_on_the_field_at_every_scale(void **state) {
  (void)state;
  sweep("field");
}

static void a_spot_in_the_box_at_every_scale(void **state) {
  (void)state;
  sweep("cornell");
}

/* The case: a sunlit room from glTF, its camera list's first view. */
static void the_office_at_every_scale(void **state) {
  (void)state;
  sweep("office");
}

/* Depth of field with its defaults (autofocus, range and lens relative to
 * the focus and the field of view) blurs the same in any unit. */
static void depth_of_field_defaults_hold_at_every_scale(void **state) {
  (void)state;
  static const char *const range[] = {"dof=true", NULL}, *const lens[] = {"dof=true", "dof.mode=lens", "dof.f_number=0.5", NULL};
  const char *const *modes[] = {range, lens};
  for (int m = 0; m < 2; m++) {
    lm_scene *one = scaled("cornell", 1.0f);
    gl_result ref = render_with(one, "dl", 1.0f, modes[m]), sharp = render(one, "dl", 1.0f);
    double blur = relative_difference(&ref, &sharp);
    for (int u = 0; u < 2; u++) {
      float unit = u ? 1e5f : 1e-3f;
      lm_scene *s = scaled("cornell", unit);
      gl_result r = render_with(s, "dl", unit, modes[m]);
      double d = relative_difference(&ref, &r);
      printf("dof %s at scale %g: relative mean difference %.4f (the blur itself: %.4f)\n", m ? "lens" : "range",
             unit, d, blur);
      if (!(d < TOLERANCE && blur > 2 * d)) fail_msg("dof at scale %g: %g (blur %g)", unit, d, blur);
      gl_result_free(&r);
      lm_scene_destroy(s);
    }
    gl_result_free(&ref);
    gl_result_free(&sharp);
    lm_scene_destroy(one);
  }
}

/* A camera under a mirrored node (scale -1 along x) at the eye, direction
 * and up of camera 0, its own x axis mirrored so that its world transform
 * is camera 0's with x negated: it sees camera 0's image, not the mirror
 * image (which the view had, its triangles wound the other way). */
static void a_camera_under_a_mirror_sees_the_scene_unmirrored(void **state) {
  (void)state;
  lm_scene *s = scaled("cornell", 1.0f);
  gl_result ref = render(s, "dl", 1.0f);
  const float mirror[16] = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  float local[16];
  memcpy(local, s->nodes[s->cameras[0].node].world, sizeof local);
  for (int k = 0; k < 3; k++) local[k] = -local[k];              /* its x axis mirrored ... */
  for (int c = 0; c < 4; c++) local[c * 4] = -local[c * 4];      /* ... under the mirror: world = mirror x local */
  int parent = lm_scene_add_node(s, "mirror", -1, mirror, -1, -1);
  lm_camera cam = s->cameras[0];
  cam.node = lm_scene_add_node(s, "mirrored camera", parent, local, -1, -1);
  s->cameras[0] = cam;
  lm_scene_update(s);
  const float *w = s->nodes[cam.node].world;
  double det = (double)w[0] * (w[5] * w[10] - w[9] * w[6]) - w[4] * (w[1] * w[10] - w[9] * w[2]) +
               w[8] * (w[1] * w[6] - w[5] * w[2]);
  assert_true(det < -0.99); /* the test's premise */
  gl_result r = render(s, "dl", 1.0f);
  double d = relative_difference(&ref, &r);
  printf("a camera under a mirror: relative mean difference %.6f from the plain camera's image\n", d);
  if (!(d < 1e-4)) fail_msg("the mirrored camera's image differs by %g", d);
  gl_result_free(&r);
  gl_result_free(&ref);
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(depth_is_exact_at_a_near_far_ratio_of_1e11),
      cmocka_unit_test(the_sun_on_the_field_at_every_scale),
      cmocka_unit_test(a_spot_in_the_box_at_every_scale),
      cmocka_unit_test(the_office_at_every_scale),
      cmocka_unit_test(depth_of_field_defaults_hold_at_every_scale),
      cmocka_unit_test(a_camera_under_a_mirror_sees_the_scene_unmirrored),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
