/* The extreme-case suite (docs/extremes.md has the table): each case renders
 * and asserts finite output and a sane image.
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
#include <string.h>

#include "gl_test.h"
#include "scene/gltf.h"
#include "trace/trace.h"

static lm_scene *builtin(const char *name) {
  lm_error err;
  lm_scene *s = lm_scene_builtin(name, &err);
  assert_non_null(s);
  return s;
}

static gl_result render_ok(lm_scene *s, const char *tech, const char *const *sets, int w, int h) {
  return gl_render_ok(&(gl_run){.scene = s, .tech = tech, .sets = sets, .width = w, .height = h});
}

static float mean_luminance(const gl_result *r) {
  float all[3];
  gl_region(r, 0, 0, r->width - 1, r->height - 1, all);
  return gl_luminance(all);
}

static const char *const every_technique[] = {"isr+esm", "isr",     "dl+esm",  "dl",      "ssdo+esm",    "ssdo",
                                              "ssao+esm", "ssao", "rsm+esm", "vpl+esm", "isr+rsm+esm",
                                              "lpv+esm", "isr+lpv+esm"};
enum { TECHNIQUES = sizeof every_technique / sizeof *every_technique };

/* Radiance from 1e-8 to 1e6 in one image: a blinding light, a faint background. */
static void hdr_radiance_from_1e_8_to_1e6(void **state) {
  (void)state;
  lm_scene *s = builtin("cornell");
  s->lights[0].power = 1e6f;
  static const char *const plain[] = {"background=1e-8", NULL};
  static const char *const mapped[] = {"background=1e-8", "hdr=true", "bloom=true", NULL};
  for (int t = 0; t < TECHNIQUES; t++) {
    gl_result r = render_ok(s, every_technique[t], plain, 64, 48);
    assert_true(mean_luminance(&r) > 1e3f); /* linear output keeps the radiance */
    gl_result_free(&r);
  }
  gl_result r = render_ok(s, "isr+esm", mapped, 64, 48);
  assert_true(mean_luminance(&r) <= 1.0f); /* tone mapped into display range */
  gl_result_free(&r);
  s->lights[0].power = 1e-8f;
  r = render_ok(s, "dl", NULL, 64, 48);
  assert_true(mean_luminance(&r) < 0.05f);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* The point light inside the tall box: with shadows the room goes dark. */
static void a_light_inside_geometry(void **state) {
  (void)state;
  lm_scene *s = builtin("cornell");
  float *m = s->nodes[s->lights[0].node].local;
  m[12] = -0.35f, m[13] = 0.6f, m[14] = -0.35f;
  lm_scene_update(s);
  gl_result open = render_ok(s, "dl", NULL, 128, 96), closed = render_ok(s, "dl+esm", NULL, 128, 96);
  printf("light in the box: mean luminance %.4f without shadows, %.4f with\n", mean_luminance(&open),
         mean_luminance(&closed));
  assert_true(mean_luminance(&closed) < 0.2f * mean_luminance(&open));
  gl_result_free(&open);
  gl_result_free(&closed);
  lm_scene_destroy(s);
}

/* Camera near 1e-4 and far 1e6: depth precision at its worst. */
static void near_1e_4_far_1e6(void **state) {
  (void)state;
  lm_scene *s = builtin("cornell");
  s->cameras[0].znear = 1e-4f;
  s->cameras[0].zfar = 1e6f;
  for (int t = 0; t < TECHNIQUES; t++) {
    gl_result r = render_ok(s, every_technique[t], NULL, 128, 96);
    float left[3];
    gl_region(&r, 22, 40, 32, 55, left); /* the red wall still reads red */
    if (!(left[0] > 2 * left[1])) fail_msg("%s: left wall %g %g %g", every_technique[t], left[0], left[1], left[2]);
    gl_result_free(&r);
  }
  lm_scene_destroy(s);
}

static void outputs_of_1x1_and_8192x8192(void **state) {
  (void)state;
  lm_scene *s = builtin("cornell");
  for (int t = 0; t < TECHNIQUES; t++) {
    gl_result r = render_ok(s, every_technique[t], NULL, 1, 1);
    gl_result_free(&r);
  }
  gl_result r = render_ok(s, "dl", NULL, 8192, 8192);
  float centre[3];
  gl_region(&r, 4000, 4000, 4100, 4100, centre); /* the back wall */
  assert_true(gl_luminance(centre) > 0.1f);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

static void zero_lights_and_64_lights(void **state) {
  (void)state;
  lm_scene *s = builtin("cornell");
  gl_result one = render_ok(s, "dl", NULL, 64, 48);
  lm_light light = s->lights[0];
  s->light_count = 0;
  for (int t = 0; t < TECHNIQUES; t++) {
    gl_result r = render_ok(s, every_technique[t], NULL, 64, 48);
    assert_true(mean_luminance(&r) < 0.05f); /* ambient only */
    gl_result_free(&r);
  }
  for (int i = 0; i < 64; i++) {
    lm_light l = light;
    l.power = 0.05f;
    l.casts_shadows = i % 8 == 0;
    mat4 m;
    glm_translate_make(m, (vec3){-0.9f + 1.8f * (float)(i % 8) / 7.0f, 1.9f, -0.9f + 1.8f * (float)(i / 8) / 7.0f});
    l.node = lm_scene_add_node(s, "light", -1, (float *)m, -1, -1);
    lm_scene_add_light(s, &l);
  }
  lm_scene_update(s);
  assert_int_equal(s->light_count, 64);
  gl_result many = render_ok(s, "isr+esm", NULL, 64, 48);
  assert_true(mean_luminance(&many) > 0.5f * mean_luminance(&one));
  gl_result_free(&many);
  gl_result_free(&one);
  lm_scene_destroy(s);
}

/* A scene of one triangle whose corners coincide, and one with a NaN corner. */
static void degenerate_and_nan_geometry(void **state) {
  (void)state;
  for (int kind = 0; kind < 2; kind++) {
    lm_scene *s = lm_scene_create("degenerate");
    float v[3 * 8] = {0};
    for (int i = 0; i < 3; i++) v[i * 8 + 2] = -2.0f; /* all at one point */
    if (kind == 1) v[8] = NAN, v[9] = 1, v[16] = 1; /* a real triangle with a NaN corner */
    uint32_t idx[3] = {0, 1, 2};
    mat4 id = GLM_MAT4_IDENTITY_INIT;
    lm_material m = {"m", {0.5f, 0.5f, 0.5f}, 0.5f, 1, 1, 0, 1, 0, 0};
    lm_scene_add_node(s, "tri", -1, (float *)id, lm_scene_add_mesh(s, "tri", v, 3, idx, 3),
                      lm_scene_add_material(s, &m));
    int ln = lm_scene_add_node(s, "light", -1, (float *)id, -1, -1);
    lm_scene_add_light(s, &(lm_light){.name = "l", .type = LM_LIGHT_POINT, .color = {1, 1, 1}, .power = 1,
                                       .radius = 10, .casts_shadows = true, .node = ln});
    lm_scene_update(s);
    for (int t = 0; t < TECHNIQUES; t++) {
      gl_result r = render_ok(s, every_technique[t], NULL, 64, 48);
      assert_true(mean_luminance(&r) < 0.5f);
      gl_result_free(&r);
    }
    lm_scene_destroy(s);
  }
}

/* PCSS with light sizes 0 and 1e30 (the sun's capped at 3 rad), penumbrae of
 * 1 and 64 texels, near 1e-4 and far 1e6, on the box (point light) and the
 * field (sun): finite, and shadows darken without ever brightening (a
 * 3 rad sun spreads every penumbra over 64 texels: 1.2% darker). */
static void pcss_sizes_and_depth_ranges_at_both_ends(void **state) {
  (void)state;
  static const char *const sizes[][4] = {
      {"shadow.technique=pcss", "shadow.size=0", "shadow.penumbra=1", NULL},
      {"shadow.technique=pcss", "shadow.size=1e30", "shadow.penumbra=64", NULL},
      {"shadow.technique=pcss", "shadow.size=1e-30", "shadow.penumbra=64", NULL},
      {"shadow.technique=pcss", NULL}};
  const char *const scenes[] = {"cornell", "field"};
  for (int k = 0; k < 2; k++) {
    lm_scene *s = builtin(scenes[k]);
    for (int range = 0; range < 2; range++) {
      if (range) s->cameras[0].znear = 1e-4f, s->cameras[0].zfar = 1e6f;
      gl_result plain = render_ok(s, "dl", NULL, 64, 48);
      for (size_t i = 0; i < sizeof sizes / sizeof *sizes; i++) {
        gl_result r = render_ok(s, "dl+esm", sizes[i], 64, 48);
        float lit = mean_luminance(&r), all = mean_luminance(&plain);
        printf("pcss %s %s near %g: %s: mean luminance %.4f (no shadows %.4f)\n", scenes[k], sizes[i][1] ? sizes[i][1] : "",
               (double)s->cameras[0].znear, sizes[i][2] ? sizes[i][2] : "", lit, all);
        if (!(lit <= all * 1.001f && lit < 0.995f * all))
          fail_msg("%s %s: %g against %g", scenes[k], sizes[i][1] ? sizes[i][1] : "defaults", lit, all);
        gl_result_free(&r);
      }
      gl_result_free(&plain);
    }
    lm_scene_destroy(s);
  }
}

/* The ray tracer over the box at unit scales 1e-6 .. 1e6 (a scaled root,
 * cameras with it), and over corners at +-1e9 (the largest glTF coordinate)
 * beside a 1e-9 triangle: every hit finite, the same pixels hit at every scale. */
static void ray_tracing_at_extreme_scales(void **state) {
  (void)state;
  enum { W = 32, H = 24 };
  const float scales[] = {1e-6f, 1, 1e6f};
  int hits_at_1 = -1, hits[3];
  for (int si = 0; si < 3; si++) {
    lm_scene *s = builtin("cornell");
    mat4 m = GLM_MAT4_IDENTITY_INIT;
    glm_scale_uni(m, scales[si]);
    lm_scene_add_root(s, "unit", (float *)m);
    lm_scene_update(s);
    lm_trace *t = lm_trace_create(s, NULL);
    lm_frame_data f;
    lm_scene_frame_data(s, 0, W, H, &f);
    hits[si] = 0;
    for (int y = 0; y < H; y++)
      for (int x = 0; x < W; x++) {
        lm_trace_ray r = {.tmax = INFINITY};
        for (int k = 0; k < 3; k++)
          r.origin[k] = f.camera_pos[k],
          r.dir[k] = f.frustum_o[k] + f.frustum_u[k] * (x + 0.5f) / W + f.frustum_v[k] * (y + 0.5f) / H;
        lm_trace_hit h;
        if (!lm_trace_intersect(t, &r, &h)) continue;
        hits[si]++;
        lm_trace_surface sf;
        lm_trace_surface_at(t, &r, &h, &sf);
        assert_true(isfinite(h.t) && h.t > 0);
        for (int k = 0; k < 3; k++) assert_true(isfinite(sf.position[k]) && isfinite(sf.normal[k]));
      }
    if (scales[si] == 1) hits_at_1 = hits[si];
    lm_trace_destroy(t);
    lm_scene_destroy(s);
  }
  assert_true(hits_at_1 > W * H / 2);
  for (int si = 0; si < 3; si++) assert_true(abs(hits[si] - hits_at_1) <= 2);

  const float far_tris[2][9] = {{-1e9f, -1e9f, -1e9f, 1e9f, -1e9f, -1e9f, 0, 1e9f, -1e9f},
                                {0, 0, 0, 1e-9f, 0, 0, 0, 1e-9f, 0}};
  lm_trace_stats st;
  lm_trace *t = lm_trace_create_triangles(&far_tris[0][0], 2, &st);
  assert_int_equal(st.triangles, 2);
  lm_trace_hit h;
  lm_trace_ray tiny = {{2.5e-10f, 2.5e-10f, 1}, 0, {0, 0, -1}, INFINITY};
  assert_true(lm_trace_intersect(t, &tiny, &h));
  assert_float_equal(h.t, 1, 1e-6);
  lm_trace_ray huge = {{1e8f, -5e8f, 1e9f}, 0, {0, 0, -1}, INFINITY};
  assert_true(lm_trace_intersect(t, &huge, &h));
  assert_float_equal(h.t, 2e9f, 1e3);
  lm_trace_surface sf;
  lm_trace_surface_at(t, &huge, &h, &sf);
  for (int k = 0; k < 3; k++) assert_true(isfinite(sf.position[k]) && isfinite(sf.normal[k]));
  lm_trace_destroy(t);
}

/* A target larger than the GL limit is refused, naming it and its size. */
static void oversize_targets_are_refused(void **state) {
  (void)state;
  const char *path = "/tmp/limn-extremes-huge.lua";
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs("Techniques = { 'x' }\nfunction OnRender()\n"
        "  local t = target{ 'huge', format = 'r32f', size = { 65536, 65536 } }\n"
        "  scene{ 'fill', technique = 'shadow', out = t }\n  present(t)\nend\n", f);
  fclose(f);
  lm_scene *s = builtin("cornell");
  gl_result r = gl_render(&(gl_run){.scene = s, .script = path, .width = 8, .height = 8});
  assert_false(r.ok);
  if (!strstr(r.err.msg, "target 'huge': size 65536x65536 is outside 1x1 ..")) fail_msg("%s", r.err.msg);
  gl_result_free(&r);
  remove(path);
  lm_scene_destroy(s);
}

/* Every post effect at once over every lighting technique on every scene
 * of data/scenes: finite before the output stage too (the lit target the
 * technique hands to the effects). */
static void every_effect_on_every_test_scene(void **state) {
  (void)state;
  static const char *const scenes[] = {"cornell.glb", "primitives.glb", "office.glb", "garage.glb", "outdoor.glb"};
  static const char *const all[] = {"hdr=true", "bloom=true", "dof=true", "motion_blur=true", "sepia=true",
                                    "radial_blur=true", "glass=true", "tiles=true", NULL};
  for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++) {
    char path[1200];
    snprintf(path, sizeof path, "%s/data/scenes/%s", LIMN_SOURCE_ROOT, scenes[i]);
    lm_error err;
    lm_scene *s = lm_scene_load(path, &err);
    if (!s) fail_msg("%s", err.msg);
    for (int t = 0; t < TECHNIQUES; t++) {
      gl_result r = render_ok(s, every_technique[t], all, 64, 48);
      const char *tech = every_technique[t];
      const char *lit = !strncmp(tech, "ssdo", 4) ? "ssdo.lit" : !strncmp(tech, "ssao", 4) ? "ssao.lit" : "lit";
      if (!gl_target_finite(&r, lit)) fail_msg("%s, %s: a non-finite %s value", scenes[i], tech, lit);
      assert_true(mean_luminance(&r) > 1e-3f);
      gl_result_free(&r);
    }
    lm_scene_destroy(s);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(hdr_radiance_from_1e_8_to_1e6),
      cmocka_unit_test(a_light_inside_geometry),
      cmocka_unit_test(near_1e_4_far_1e6),
      cmocka_unit_test(outputs_of_1x1_and_8192x8192),
      cmocka_unit_test(zero_lights_and_64_lights),
      cmocka_unit_test(degenerate_and_nan_geometry),
      cmocka_unit_test(pcss_sizes_and_depth_ranges_at_both_ends),
      cmocka_unit_test(ray_tracing_at_extreme_scales),
      cmocka_unit_test(oversize_targets_are_refused),
      cmocka_unit_test(every_effect_on_every_test_scene),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
