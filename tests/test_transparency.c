/* Blended materials (glTF alphaMode BLEND, glass): data/scenes/glass.gltf, a
 * green glass pane before an orange wall, lit by a sun at 45 degrees. The
 * wall is seen through the pane tinted by its transmission, the pane's
 * shadow is lighter than an opaque pane's, a scene without blended
 * materials records no extra pass, bad values are refused by name, and the
 * glTF and POV-Ray exports carry the glass.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
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
#include "gltf_test.h"
#include "scene/gltf.h"
#include "scene/pov.h"

enum { W = 96, H = 72 };

static lm_scene *glass_scene(void) {
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(LIMN_TEST_DIR "/../data/scenes/glass.gltf", &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

static lm_material_pbr *glass_of(lm_scene *s) {
  int m = lm_scene_find_material(s, "glass");
  assert_true(m >= 0);
  return &s->material_pbr[m];
}

/* The mean linear RGB of the three places the test looks at: the wall seen
 * through the pane, the pane's shadow on the wall, and the open wall. */
typedef struct glass_view {
  float through[3], shadow[3], open[3];
  char passes[2048];
  int targets;
  bool transmit; /* the frame has the target shadow.transmit */
} glass_view;

static glass_view render_glass(lm_scene *s, const char *tech, const char *materials) {
  const char *sets[] = {"ambient=0", materials, NULL};
  gl_result g = gl_render(&(gl_run){.scene = s, .tech = tech, .sets = sets, .width = W, .height = H,
                                    .check_finite = true});
  if (!g.ok) fail_msg("%s %s: %s", tech, materials, g.err.msg);
  assert_true(gl_all_finite(&g));
  glass_view v;
  /* The pane (x -1.5..0, y -1..1 at z 1.5) covers pixels 26..48 x 21..50 from
   * the eye at z 6; its shadow falls 1.5 to the right, on pixels 48..64 x 25..47. */
  gl_region(&g, 32, 30, 42, 42, v.through);
  gl_region(&g, 52, 30, 60, 42, v.shadow);
  gl_region(&g, 76, 30, 82, 42, v.open);
  gl_pass_names(&g, v.passes, sizeof v.passes);
  v.targets = lm_graph_target_count(lm_renderer_graph(g.renderer));
  v.transmit = lm_graph_find_target(lm_renderer_graph(g.renderer), "shadow.transmit") >= 0;
  gl_result_free(&g);
  return v;
}

/* The loader's reading of the pane's glass extensions. */
static void glass_extensions_are_read(void **state) {
  (void)state;
  lm_scene *s = glass_scene();
  const lm_material_pbr *p = glass_of(s);
  assert_int_equal(p->alpha_mode, LM_ALPHA_BLEND);
  assert_float_equal(p->transmission, 1.0, 1e-6);
  assert_float_equal(p->ior, 1.5, 1e-6);
  assert_float_equal(p->thickness, 0.01, 1e-6);
  assert_float_equal(p->attenuation_distance, 0.05, 1e-6);
  assert_float_equal(p->attenuation_color[0], 0.9, 1e-6);
  assert_float_equal(p->attenuation_color[1], 1.0, 1e-6);
  assert_true(lm_scene_has_blend(s));
  lm_scene_destroy(s);
}

/* `got`, the wall seen through the glass or in its shadow, is the open
 * wall's light times the glass's transmittance: (1 - F) base absorbed, per
 * channel (absorbed: 0.9^0.2 in r and b); tinted: green against red, three
 * times the open wall's ratio. */
static void assert_transmitted(const char *materials, const char *where, const float got[3], const float open[3]) {
  const float base[3] = {0.3f, 0.9f, 0.4f}, absorbed[3] = {0.979f, 1.0f, 0.979f};
  for (int c = 0; c < 3; c++) {
    float want = 0.96f * base[c] * absorbed[c] * open[c];
    if (fabsf(got[c] - want) > 0.06f * open[c] + 0.002f)
      fail_msg("%s: channel %d %s %.4f, want %.4f", materials, c, where, (double)got[c], (double)want);
  }
  assert_true(got[1] / got[0] > 2.5f * open[1] / open[0]);
}

/* Through the pane the wall keeps its light times the glass's
 * transmittance, (1 - F) base absorbed, F the Fresnel of ior 1.5 (0.04 at
 * normal incidence; the view is within 20 degrees of it); in the pane's
 * shadow the sun keeps the same share per channel (the shadow pass's
 * transmittance output, at normal incidence: tinted), where an opaque
 * pane's stops it all. */
static void the_wall_is_seen_through_tinted_and_the_shadow_lighter(void **state) {
  (void)state;
  lm_scene *s = glass_scene();
  lm_material_pbr *p = glass_of(s);
  static const char *const materials[] = {"materials=phong", "materials=pbr"};
  for (int k = 0; k < 2; k++) {
    p->alpha_mode = LM_ALPHA_BLEND;
    glass_view glass = render_glass(s, "dl+esm", materials[k]);
    p->alpha_mode = LM_ALPHA_OPAQUE;
    glass_view opaque = render_glass(s, "dl+esm", materials[k]);
    float open = gl_luminance(glass.open);
    printf("%s: open wall %.4f (%.3f %.3f %.3f); through the glass %.3f %.3f %.3f; its shadow %.3f %.3f %.3f, "
           "an opaque pane's %.4f\n", materials[k], (double)open, (double)glass.open[0], (double)glass.open[1],
           (double)glass.open[2], (double)glass.through[0], (double)glass.through[1], (double)glass.through[2],
           (double)glass.shadow[0], (double)glass.shadow[1], (double)glass.shadow[2],
           (double)gl_luminance(opaque.shadow));
    assert_true(open > 0.1f);
    assert_transmitted(materials[k], "through the glass", glass.through, glass.open);
    /* the opaque pane stops the sun; the glass lets its transmittance through, tinted */
    assert_true(gl_luminance(opaque.shadow) < 0.05f * open);
    assert_transmitted(materials[k], "in the glass's shadow", glass.shadow, glass.open);
  }
  lm_scene_destroy(s);
}

/* Back to front: a red pane (alpha 0.5, no transmission) 0.75 behind the
 * green one (the same), added to the scene after it. Each pane alone gives
 * P = a S + (1 - a) W over the wall W; both, the far one drawn first, give
 * G + (1 - a)(R - W), and drawn the other way R + (1 - a)(G - W). No
 * shadows (dl): the panes' own light S is the same alone and together. */
static void blended_nodes_draw_back_to_front(void **state) {
  (void)state;
  lm_scene *s = glass_scene();
  lm_material_pbr *green = glass_of(s);
  green->transmission = 0, green->alpha = 0.5f;
  int near = lm_scene_find_node(s, "pane"), pane_mesh = s->nodes[near].mesh;
  lm_material red_m = *lm_scene_node_material(s, &s->nodes[near]);
  snprintf(red_m.name, sizeof red_m.name, "red");
  red_m.color[0] = 0.9f, red_m.color[1] = 0.1f, red_m.color[2] = 0.1f;
  int red = lm_scene_add_material(s, &red_m);
  s->material_pbr[red] = *green;
  const float behind[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -0.75f, 1};
  int far = lm_scene_add_node(s, "far pane", -1, behind, pane_mesh, red);
  lm_scene_update(s);
  /* the wall behind them, both panes, the green alone, the red alone */
  float wall[3], both[3], g_only[3], r_only[3];
  static const int shown[4][2] = {{0, 0}, {1, 1}, {1, 0}, {0, 1}}; /* near, far */
  float *out[4] = {wall, both, g_only, r_only};
  for (int k = 0; k < 4; k++) {
    s->nodes[near].mesh = shown[k][0] ? pane_mesh : -1;
    s->nodes[far].mesh = shown[k][1] ? pane_mesh : -1;
    glass_view v = render_glass(s, "dl", "materials=phong");
    memcpy(out[k], v.through, sizeof v.through);
  }
  for (int c = 0; c < 3; c++) {
    float right = g_only[c] + 0.5f * (r_only[c] - wall[c]), wrong = r_only[c] + 0.5f * (g_only[c] - wall[c]);
    printf("channel %d: both %.4f; far first %.4f, near first %.4f\n", c, (double)both[c], (double)right,
           (double)wrong);
    assert_float_equal(both[c], right, 0.002f);
  }
  assert_true(fabsf(both[0] - (r_only[0] + 0.5f * (g_only[0] - wall[0]))) > 0.05f); /* the order shows */
  lm_scene_destroy(s);
}

/* The GI techniques take the glass too (finite, seen through, tinted). */
static void glass_over_gi_techniques(void **state) {
  (void)state;
  lm_scene *s = glass_scene();
  static const char *const techs[] = {"isr+esm", "isr+rsm+esm", "lpv+esm"};
  for (int i = 0; i < 3; i++) {
    glass_view v = render_glass(s, techs[i], "materials=phong");
    assert_non_null(strstr(v.passes, "transparent"));
    assert_true(v.through[1] / v.through[0] > 2.5f * v.open[1] / v.open[0]);
  }
  lm_scene_destroy(s);
}

/* Blended materials get the indirect light opaque ones get from light
 * propagation volumes: in the Cornell box a white pane faces the camera with
 * the ceiling light behind its plane, so with ambient 0 only bounce light
 * reaches its face. Blended (alpha 1, no transmission: all its light its
 * own) it is black without GI (dl+esm), and lpv+esm lights it as it lights
 * the same pane opaque (the volumes read at the pane itself): within 25%
 * (measured 9%), finite. */
static void a_blended_pane_takes_the_bounce_light(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_non_null(s);
  int m = lm_scene_add_material(s, &(lm_material){.name = "pane", .color = {0.8f, 0.8f, 0.8f}, .rho = 0.8f,
                                                  .ka = 1, .kd = 1, .shininess = 1});
  lm_material_pbr *pbr = &s->material_pbr[m];
  *pbr = lm_scene_material_pbr(s, m, &s->materials[m]);
  pbr->set = true, pbr->ior = 1.5f;
  const float corners[4][3] = {{-0.5f, 0.3f, 0.6f}, {0.5f, 0.3f, 0.6f}, {0.5f, 1.1f, 0.6f}, {-0.5f, 1.1f, 0.6f}};
  float v[4 * 8];
  for (int i = 0; i < 4; i++) {
    float *o = v + i * 8;
    memcpy(o, corners[i], sizeof corners[i]);
    o[3] = 0, o[4] = 0, o[5] = 1; /* facing the camera; the light (y 1.85, z 0) lies behind its plane */
    o[6] = (float)(i == 1 || i == 2), o[7] = (float)(i >= 2);
  }
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  lm_scene_add_node(s, "pane", -1, id, lm_scene_add_mesh(s, "pane", v, 4, idx, 6), m);
  lm_scene_update(s);
  static const char *const techs[] = {"dl+esm", "lpv+esm"};
  for (int t = 0; t < 2; t++) {
    float pane[2];
    for (int blend = 0; blend < 2; blend++) {
      s->material_pbr[m].alpha_mode = blend ? LM_ALPHA_BLEND : LM_ALPHA_OPAQUE;
      const char *sets[] = {"ambient=0", NULL};
      gl_result g = gl_render(&(gl_run){.scene = s, .tech = techs[t], .sets = sets, .width = W, .height = H,
                                        .frames = 2, .check_finite = true});
      if (!g.ok) fail_msg("%s: %s", techs[t], g.err.msg);
      assert_true(gl_all_finite(&g));
      float rgb[3];
      gl_mean_around(&g, 0, 0.7f, 0.6f, 2, rgb);
      pane[blend] = gl_luminance(rgb);
      gl_result_free(&g);
    }
    printf("%-8s the pane's bounce light: opaque %.5f, blended %.5f\n", techs[t], pane[0], pane[1]);
    if (t == 0)
      assert_true(pane[1] < 1e-5f); /* no direct light, no ambient: black without GI */
    else if (!(fabsf(pane[1] - pane[0]) < 0.25f * pane[0] && pane[0] > 1e-3f))
      fail_msg("%s: the blended pane gets %g, the opaque one %g", techs[t], pane[1], pane[0]);
  }
  lm_scene_destroy(s);
}

/* A scene without blended materials records no forward pass and no target
 * for it: the same frame as with the glass, less the pass "transparent" and
 * the shadow pass's transmittance target. */
static void no_blended_material_no_pass(void **state) {
  (void)state;
  lm_scene *s = glass_scene();
  lm_material_pbr *p = glass_of(s);
  glass_view with = render_glass(s, "dl+esm", "materials=pbr");
  p->alpha_mode = LM_ALPHA_OPAQUE;
  assert_false(lm_scene_has_blend(s));
  glass_view without = render_glass(s, "dl+esm", "materials=pbr");
  printf("with glass: %s\nwithout: %s\n", with.passes, without.passes);
  assert_non_null(strstr(with.passes, "transparent"));
  assert_null(strstr(without.passes, "transparent"));
  assert_true(with.transmit && !without.transmit);
  assert_int_equal(with.targets, without.targets + 1);
  /* the pass lists differ by that pass alone */
  char *at = strstr(with.passes, "transparent");
  size_t len = strlen("transparent");
  char less[sizeof with.passes];
  snprintf(less, sizeof less, "%.*s%s", (int)(at - with.passes), with.passes, at[len] == ' ' ? at + len + 1 : at + len);
  size_t n = strlen(less);
  if (n && less[n - 1] == ' ') less[n - 1] = '\0';
  char trimmed[sizeof without.passes];
  snprintf(trimmed, sizeof trimmed, "%s", without.passes);
  n = strlen(trimmed);
  if (n && trimmed[n - 1] == ' ') trimmed[n - 1] = '\0';
  assert_string_equal(less, trimmed);
  lm_scene_destroy(s);
}

/* A one-triangle file whose material 0 ("pane") has `material` (JSON members). */
static const char *glass_file(const char *name, const char *material) {
  static blob b;
  b.len = 0;
  const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  blob_add(&b, tri, sizeof tri);
  char json[2048];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
           "\"materials\":[{\"name\":\"pane\",%s}],"
           "\"buffers\":[{\"uri\":\"%%s\",\"byteLength\":%%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
           "\"min\":[0,0,0],\"max\":[1,1,0]}]}",
           material);
  return write_gltf(name, json, &b);
}

/* Bad values fail the file naming the material, extension and field; an
 * OPAQUE material with transmission (as Blender writes glass) is blended. */
static void bad_glass_values_are_refused_by_name(void **state) {
  (void)state;
  static const struct { const char *material, *expect; } bad[] = {
    {"\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1.5]}", "material 0 ('pane'): baseColorFactor's alpha"},
    {"\"extensions\":{\"KHR_materials_ior\":{\"ior\":0}}", "material 0 ('pane'): KHR_materials_ior.ior must be"},
    /* JSON has no NaN or Inf: an overflowing number is the parser's to refuse, naming it */
    {"\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1e999}}", "1e999"},
    {"\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":-0.5}}",
     "KHR_materials_transmission.transmissionFactor must be a number in [0, 1]"},
    {"\"extensions\":{\"KHR_materials_volume\":{\"attenuationColor\":[1,2,1]}}",
     "material 0 ('pane'): KHR_materials_volume.attenuationColor"},
    {"\"extensions\":{\"KHR_materials_volume\":{\"attenuationDistance\":\"far\"}}",
     "KHR_materials_volume.attenuationDistance must be"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    lm_error err;
    lm_scene *s = lm_scene_load_gltf(glass_file("bad.gltf", bad[i].material), &err);
    if (s) fail_msg("case %zu loaded", i);
    if (!strstr(err.msg, bad[i].expect)) fail_msg("case %zu: %s", i, err.msg);
  }
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(
      glass_file("blender.gltf", "\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,0.2]},"
                                 "\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":0.8}}"),
      &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->material_pbr[0].alpha_mode, LM_ALPHA_BLEND);
  assert_float_equal(s->material_pbr[0].alpha, 1.0, 0); /* OPAQUE: its alpha is not coverage */
  assert_float_equal(s->material_pbr[0].ior, 1.5, 1e-6);
  lm_scene_destroy(s);
}

/* export-gltf writes the glass back (read again: the same values); the
 * POV-Ray export writes it as filter and transmit, with its absorption. */
static void exports_carry_the_glass(void **state) {
  (void)state;
  lm_scene *s = glass_scene();
  lm_error err;
  const char *path = path_of("glass_out.gltf");
  if (!lm_scene_write_gltf(s, path, NULL, &err)) fail_msg("%s", err.msg);
  lm_scene *back = lm_scene_load_gltf(path, &err);
  if (!back) fail_msg("%s", err.msg);
  const lm_material_pbr *a = glass_of(s), *b = glass_of(back);
  assert_int_equal(b->alpha_mode, LM_ALPHA_BLEND);
  assert_float_equal(b->transmission, a->transmission, 1e-6);
  assert_float_equal(b->ior, a->ior, 1e-6);
  assert_float_equal(b->thickness, a->thickness, 1e-6);
  assert_float_equal(b->attenuation_distance, a->attenuation_distance, 1e-6);
  for (int c = 0; c < 3; c++) assert_float_equal(b->attenuation_color[c], a->attenuation_color[c], 1e-6);
  lm_scene_destroy(back);

  lm_buf out = {0};
  lm_pov_desc d = {.camera = 0, .width = W, .height = H, .shadows = true};
  if (!lm_pov_export(s, &d, &out, NULL, &err)) fail_msg("%s", err.msg);
  int m = lm_scene_find_material(s, "glass");
  char want[160];
  /* filter a t = 1 (tinted by the colour), transmit 1 - a = 0 */
  snprintf(want, sizeof want, "#declare limn_material_%d = texture {\n  pigment { rgbft <0.300000012, 0.899999976, "
           "0.400000006, 1, 0> }", m);
  if (!strstr(out.data, want)) fail_msg("no '%s' in:\n%s", want, out.data);
  snprintf(want, sizeof want, "interior { limn_material_%d_interior }", m);
  assert_non_null(strstr(out.data, want));
  assert_non_null(strstr(out.data, "fade_power 1001 fade_distance 0.0500000007"));
  lm_buf_free(&out);
  lm_scene_destroy(s);
}

static int setup(void **state) {
  if (gltf_test_setup(state)) return -1;
  return gl_test_setup(state);
}

static int teardown(void **state) {
  gltf_test_teardown(state);
  return gl_test_teardown(state);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(glass_extensions_are_read),
      cmocka_unit_test(the_wall_is_seen_through_tinted_and_the_shadow_lighter),
      cmocka_unit_test(blended_nodes_draw_back_to_front),
      cmocka_unit_test(glass_over_gi_techniques),
      cmocka_unit_test(a_blended_pane_takes_the_bounce_light),
      cmocka_unit_test(no_blended_material_no_pass),
      cmocka_unit_test(bad_glass_values_are_refused_by_name),
      cmocka_unit_test(exports_carry_the_glass),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
