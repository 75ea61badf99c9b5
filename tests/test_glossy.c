/* Glossy indirect light (scripts/glossy.lua, shaders/glossy.frag) with
 * materials=pbr: a mirror-like metal sphere shows the lit red wall it faces,
 * and the sky where the screen shows nothing; a lit wall behind the camera
 * through the light propagation volumes (glossy.fallback); no composite
 * gives a metal an ambient term, nor does the std technique a glTF metal;
 * Phong frames are unchanged bit for bit; extremes stay finite; bad options
 * name themselves.
 * Needs a GL context (llvmpipe will do).
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
#include "scene/gltf.h"

enum { W = 96, H = 72 };

static const float EYE[3] = {1.0f, 0.6f, 2.5f}, AT[3] = {-0.6f, 0.0f, 0.0f};
/* The camera of the wall behind it (metal_sphere's behind) */
static const float BACK_EYE[3] = {2.0f, 0.3f, 0.3f}, BACK_AT[3] = {0.0f, 0.0f, 0.0f};

/* A sphere of radius 0.5 at the origin (metal of base colour `albedo`, its
 * roughness from `shininess`: the pbr technique's metallic 1 - k_d = 1), a
 * red wall at x = -1.5 facing +x, lit by the sun shining along -x; the camera
 * at EYE looks at AT. With behind, the wall stands at x = 3 facing -x, behind
 * the camera at BACK_EYE looking at BACK_AT, and the sun shines along
 * (1, -0.6, 0): the sphere's shadow falls low on the wall, and the side of
 * the sphere the camera sees is in shade. */
static lm_scene *metal_sphere_at(float albedo, float shininess, bool behind, mat4 vp) {
  lm_scene *s = lm_scene_create("sphere");
  lm_material metal = {.name = "metal", .color = {albedo, albedo, albedo}, .rho = 0.5f, .ka = 1, .kd = 0, .ks = 1,
                       .shininess = shininess};
  int m = lm_scene_add_material(s, &metal);
  mat4 id = GLM_MAT4_IDENTITY_INIT, view, world;
  lm_scene_add_node(s, "ball", -1, (float *)id, gl_uv_sphere(s, "ball", 0.5f), m);
  int red = gl_material(s, "red", 0.8f, 0.1f, 0.1f);
  if (behind)
    gl_quad(s, "wall", red, (const float[4][3]){{3, -3, -3}, {3, -3, 3}, {3, 3, 3}, {3, 3, -3}},
            (const float[3]){-1, 0, 0});
  else
    gl_quad(s, "wall", red, (const float[4][3]){{-1.5f, -2, 3}, {-1.5f, -2, -3}, {-1.5f, 2, -3}, {-1.5f, 2, 3}},
            (const float[3]){1, 0, 0});
  glm_lookat((vec3){0, 0, 0}, behind ? (vec3){1, -0.6f, 0} : (vec3){-1, -0.1f, 0}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, world);
  int sun = lm_scene_add_node(s, "sun", -1, (float *)world, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                     .casts_shadows = true, .node = sun});
  const float *eye = behind ? BACK_EYE : EYE, *at = behind ? BACK_AT : AT;
  glm_lookat((vec3){eye[0], eye[1], eye[2]}, (vec3){at[0], at[1], at[2]}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, world);
  int cam = lm_scene_add_node(s, "camera", -1, (float *)world, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "front", .fov_y = glm_rad(60.0f), .znear = 0.01f, .zfar = 100,
                                      .node = cam});
  lm_scene_update(s);
  mat4 proj;
  glm_perspective(glm_rad(60.0f), (float)W / H, 0.01f, 100, proj);
  glm_mat4_mul(proj, view, vp);
  return s;
}

static lm_scene *metal_sphere(float albedo, float shininess, mat4 vp) {
  return metal_sphere_at(albedo, shininess, false, vp);
}

/* Mean linear RGB of the 3 x 3 pixels around the sphere's point whose
 * mirror reflects the ray of the camera at eye into direction d (unit). */
static void reflecting_from(const gl_result *r, mat4 vp, const float eye[3], const float d[3], float out[3]) {
  vec3 toward, n;
  glm_vec3_normalize_to((vec3){eye[0], eye[1], eye[2]}, toward); /* from the centre: the sphere is small */
  glm_vec3_add(toward, (vec3){d[0], d[1], d[2]}, n);
  glm_vec3_normalize(n);
  vec4 c;
  glm_mat4_mulv(vp, (vec4){0.5f * n[0], 0.5f * n[1], 0.5f * n[2], 1}, c);
  int col = (int)((c[0] / c[3] * 0.5f + 0.5f) * r->width), row = (int)((0.5f - c[1] / c[3] * 0.5f) * r->height);
  assert_true(col >= 1 && col < r->width - 1 && row >= 1 && row < r->height - 1);
  gl_region(r, col - 1, row - 1, col + 1, row + 1, out);
}

static void reflecting(const gl_result *r, mat4 vp, const float d[3], float out[3]) {
  reflecting_from(r, vp, EYE, d, out);
}

static gl_result render_ok(lm_scene *s, const char *const *sets) {
  return gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = sets, .width = W, .height = H});
}

/* The sphere's point that faces the wall (its mirror direction -x) shows
 * the wall's red with glossy light and next to nothing without (a metal has
 * no diffuse light and the sun's highlight lies on its other side); the
 * point whose mirror direction is up, where the screen shows nothing, the
 * sky's 0.5 times the metal's Fresnel (base colour 0.9). */
static void a_metal_sphere_shows_the_lit_wall_and_the_sky(void **state) {
  (void)state;
  mat4 vp;
  lm_scene *s = metal_sphere(0.9f, 1e6f, vp);
  static const char *const on[] = {"ambient=0", "materials=pbr", "glossy=true", "sky=true", "sky.zenith=0.5",
                                   "sky.horizon=0.5", NULL};
  static const char *const off[] = {"ambient=0", "materials=pbr", "sky=true", "sky.zenith=0.5", "sky.horizon=0.5",
                                    NULL};
  gl_result a = render_ok(s, on), b = render_ok(s, off);
  const float west[3] = {-1, 0, 0}, up[3] = {0, 1, 0};
  float w_on[3], w_off[3], u_on[3], u_off[3];
  reflecting(&a, vp, west, w_on);
  reflecting(&b, vp, west, w_off);
  reflecting(&a, vp, up, u_on);
  reflecting(&b, vp, up, u_off);
  print_message("facing the wall: %.4f %.4f %.4f with glossy, %.4f %.4f %.4f without\n", w_on[0], w_on[1], w_on[2],
                w_off[0], w_off[1], w_off[2]);
  print_message("facing up: %.4f with glossy, %.4f without (sky 0.5)\n", gl_luminance(u_on), gl_luminance(u_off));
  assert_true(w_on[0] > 0.1f && w_on[0] > 3 * w_on[1] && w_on[0] > 3 * w_on[2]);
  assert_true(w_off[0] < 0.02f);
  assert_true(gl_luminance(u_on) > 0.35f && gl_luminance(u_on) < 0.55f);
  assert_true(gl_luminance(u_off) < 0.05f);
  gl_result_free(&a);
  gl_result_free(&b);
  lm_scene_destroy(s);
}

/* The sphere's point that faces the camera mirrors the lit red wall behind
 * it, which the screen cannot show: lpv+esm's volumes bring its red
 * (glossy.fallback=volume, the default), the sky fallback nothing (no sky). */
static void the_volumes_show_what_the_screen_cannot(void **state) {
  (void)state;
  mat4 vp;
  lm_scene *s = metal_sphere_at(0.9f, 1e6f, true, vp);
  static const char *const volume[] = {"ambient=0", "materials=pbr", "glossy=true", NULL};
  static const char *const sky[] = {"ambient=0", "materials=pbr", "glossy=true", "glossy.fallback=sky", NULL};
  gl_result a = gl_render_ok(&(gl_run){.scene = s, .tech = "lpv+esm", .sets = volume, .width = W, .height = H});
  gl_result b = gl_render_ok(&(gl_run){.scene = s, .tech = "lpv+esm", .sets = sky, .width = W, .height = H});
  float back[3], v[3], k[3];
  glm_vec3_normalize_to((vec3){BACK_EYE[0], BACK_EYE[1], BACK_EYE[2]}, back);
  reflecting_from(&a, vp, BACK_EYE, back, v);
  reflecting_from(&b, vp, BACK_EYE, back, k);
  print_message("facing the camera: %.4f %.4f %.4f through the volumes, %.4f %.4f %.4f the sky\n", v[0], v[1], v[2],
                k[0], k[1], k[2]);
  assert_true(v[0] > 0.02f && v[0] > 3 * v[1] && v[0] > 3 * v[2]);
  assert_true(k[0] < 0.5f * v[0]);
  gl_result_free(&a);
  gl_result_free(&b);
  lm_scene_destroy(s);
}

/* A metal has no diffuse colour: no composite gives it an ambient term, as
 * the direct pass gives none (gbuffer.glsl's ambient_light): ISR's
 * (isr_light.frag) and the screen-space occlusions' (gi_apply.frag), which
 * gave the metal its base colour times the ambient light. */
static void no_composite_gives_a_metal_an_ambient_term(void **state) {
  (void)state;
  mat4 vp;
  lm_scene *s = metal_sphere(0.9f, 1e6f, vp);
  static const char *const sets[] = {"ambient=0.5", "materials=pbr", NULL};
  const float up[3] = {0, 1, 0};
  float dl[3];
  gl_result b = render_ok(s, sets);
  reflecting(&b, vp, up, dl);
  assert_true(gl_luminance(dl) < 0.02f);
  static const char *const techs[] = {"isr+esm", "ssao+esm", "ssdo+esm"};
  for (size_t i = 0; i < sizeof techs / sizeof *techs; i++) {
    float gi[3];
    gl_result a = gl_render_ok(&(gl_run){.scene = s, .tech = techs[i], .sets = sets, .width = W, .height = H});
    reflecting(&a, vp, up, gi);
    print_message("metal facing up, ambient 0.5: %s %.4f, dl+esm %.4f\n", techs[i], gl_luminance(gi),
                  gl_luminance(dl));
    assert_true(gl_luminance(gi) < 0.02f);
    gl_result_free(&a);
  }
  gl_result_free(&b);
  lm_scene_destroy(s);
}

/* A glTF metal (the loader's Phong values, lm_gltf_phong) under a uniform
 * sky of 0.5 alone (the sun's power 0) in the std technique: its point whose mirror direction is up
 * takes the sky by its Phong lobe alone (2 k_s / (n + 2), under 0.001 at
 * roughness 0.05), as Cycles' and POV-Ray's references draw it, in dl+esm
 * and the default; the same sphere as a dielectric takes its albedo times
 * the sky. A sky of 1e6 leaves every frame finite. */
static void a_gltf_metal_under_the_sky_reflects_it_by_its_lobe(void **state) {
  (void)state;
  static const char *const techs[] = {"dl+esm", "isr+rsm+esm"};
  const float up[3] = {0, 1, 0}, grey[3] = {0.9f, 0.9f, 0.9f};
  for (int metal = 0; metal <= 1; metal++)
    for (size_t t = 0; t < sizeof techs / sizeof *techs; t++) {
      mat4 vp;
      lm_scene *s = metal_sphere(0.9f, 1, vp);
      s->materials[0] = lm_gltf_phong(grey, (float)metal, 0.05f);
      snprintf(s->materials[0].name, sizeof s->materials[0].name, "metal");
      s->lights[0].power = 0; /* the sky alone */
      const char *const sky[] = {"ambient=0", "sky=true", "sky.zenith=0.5", "sky.horizon=0.5", NULL};
      gl_result r = gl_render_ok(&(gl_run){.scene = s, .tech = techs[t], .sets = sky, .width = W, .height = H});
      float c[3];
      reflecting(&r, vp, up, c);
      print_message("%s, metallic %d, under a uniform sky of 0.5: %.4f\n", techs[t], metal, gl_luminance(c));
      if (metal) assert_true(gl_luminance(c) < 0.01f);
      else assert_true(gl_luminance(c) > 0.25f && gl_luminance(c) < 0.5f); /* 0.9 x 0.5, less what is occluded */
      gl_result_free(&r);
      const char *const bright[] = {"sky=true", "sky.intensity=1e6", NULL};
      r = gl_render_ok(&(gl_run){.scene = s, .tech = techs[t], .sets = bright, .width = W, .height = H});
      assert_true(gl_all_finite(&r));
      gl_result_free(&r);
      lm_scene_destroy(s);
    }
}

/* Phong frames record no glossy pass: the image is the same bit for bit. */
static void phong_frames_are_unchanged(void **state) {
  (void)state;
  mat4 vp;
  lm_scene *s = metal_sphere(0.9f, 100, vp);
  static const char *const on[] = {"glossy=true", "sky=true", NULL}, *const off[] = {"sky=true", NULL};
  gl_result a = render_ok(s, on), b = render_ok(s, off);
  assert_false(gl_has_pass(&a, "glossy"));
  assert_memory_equal(a.rgb, b.rgb, sizeof(float) * 3 * W * H);
  gl_result_free(&a);
  gl_result_free(&b);
  lm_scene_destroy(s);
}

/* Roughness 0 (shininess 1e30) and 1 (shininess 0), albedo 1, a sky of 1e6,
 * one sample of one step and 64 of 256, each also through the volumes'
 * fallback (lpv+esm): finite. */
static void extremes_stay_finite(void **state) {
  (void)state;
  const float shininess[] = {1e30f, 0, 1e6f, 1e6f, 1e30f, 0, 1e6f};
  const char *const tech[] = {"dl+esm", "dl+esm", "dl+esm", "dl+esm", "lpv+esm", "lpv+esm", "lpv+esm"};
  const char *const extra[][3] = {{"glossy.samples=64", "glossy.steps=256", NULL},
                                  {"glossy.samples=1", "glossy.steps=1", NULL},
                                  {"sky.intensity=1e6", "glossy.thickness=0", NULL},
                                  {"glossy.thickness=1", "ambient=1e6", NULL},
                                  {"sky.intensity=1e6", "lpv.bounces=8", NULL},
                                  {"glossy.samples=1", "lpv.sky_occlusion=0", NULL},
                                  {"sky.intensity=1e6", "lpv.steps=0", NULL}};
  for (int i = 0; i < 7; i++) {
    mat4 vp;
    lm_scene *s = metal_sphere_at(1.0f, shininess[i], i >= 4, vp);
    const char *const sets[] = {"materials=pbr", "glossy=true", "sky=true", extra[i][0], extra[i][1], NULL};
    gl_result r = gl_render_ok(&(gl_run){.scene = s, .tech = tech[i], .sets = sets, .width = W, .height = H});
    assert_true(gl_has_pass(&r, "glossy"));
    if (!gl_all_finite(&r) || !gl_target_finite(&r, "glossy.out")) fail_msg("case %d: not finite", i);
    gl_result_free(&r);
    lm_scene_destroy(s);
  }
}

static void bad_options_name_themselves(void **state) {
  (void)state;
  static const gl_bad_option cases[] = {
      {"dl+esm", "glossy.samples=0", "glossy.samples"},     {"dl+esm", "glossy.samples=65", "glossy.samples"},
      {"dl+esm", "glossy.steps=0", "glossy.steps"},         {"dl+esm", "glossy.thickness=2", "glossy.thickness"},
      {"dl+esm", "glossy.thickness=-1", "glossy.thickness"}, {"dl+esm", "glossy.fallback=tracer", "glossy.fallback"},
  };
  gl_assert_bad_options(cases, sizeof cases / sizeof *cases, "pp.lua:");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_metal_sphere_shows_the_lit_wall_and_the_sky),
      cmocka_unit_test(the_volumes_show_what_the_screen_cannot),
      cmocka_unit_test(no_composite_gives_a_metal_an_ambient_term),
      cmocka_unit_test(a_gltf_metal_under_the_sky_reflects_it_by_its_lobe),
      cmocka_unit_test(phong_frames_are_unchanged),
      cmocka_unit_test(extremes_stay_finite),
      cmocka_unit_test(bad_options_name_themselves),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
