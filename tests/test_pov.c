/* POV-Ray export (engine/scene/pov.h): what the SDL says about the camera,
 * lights and materials, and what it refuses or warns about by name. No GL,
 * no POV-Ray (tests/test_pov_faithful.sh renders with it).
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

#include "scene/pov.h"

static lm_pov_desc desc_for(int w, int h) {
  lm_pov_desc d = {.width = w, .height = h, .radiosity = true, .shadows = true, .strict = true};
  lm_pov_radiosity_defaults(&d.rad);
  return d;
}

/* The three numbers after `key <` in the text. */
static void vector_after(const char *text, const char *key, double v[3]) {
  const char *p = strstr(text, key);
  assert_non_null(p);
  assert_int_equal(sscanf(p + strlen(key), " <%lf, %lf, %lf>", &v[0], &v[1], &v[2]), 3);
}

static void camera_lights_and_materials_match(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err);
  assert_non_null(s);
  lm_pov_desc d = desc_for(128, 96);
  lm_buf out = {0}, warn = {0};
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_null(warn.data); /* everything in cornell_pov matches */
  const char *t = out.data;
  assert_non_null(strstr(t, "#version 3.7;"));
  assert_non_null(strstr(t, "assumed_gamma 1\n"));
  /* the seed's radiosity settings, brightness 1 */
  assert_non_null(strstr(t, "count 250\n    error_bound 0.25\n    pretrace_start 0.08\n    pretrace_end 0.01\n"
                            "    recursion_limit 2\n    brightness 1\n"));
  /* camera at (0, 1, 3.4) looking down -Z; far plane 20 away, vertical fov 45
   * degrees: up spans 2 * 20 * tan(22.5), right that times 128/96 */
  double loc[3], dir[3], right[3], up[3];
  vector_after(t, "\n  location", loc);
  vector_after(t, "\n  direction", dir);
  vector_after(t, "\n  right", right);
  vector_after(t, "\n  up", up);
  assert_float_equal(loc[1], 1.0, 1e-6);
  assert_float_equal(loc[2], 3.4, 1e-6);
  assert_float_equal(dir[0], 0, 1e-5);
  assert_float_equal(dir[2], -20, 1e-4);
  double h = 2 * 20 * tan(3.14159265358979323846 / 8);
  assert_float_equal(up[1], h, 1e-4);
  assert_float_equal(right[0], h * 128.0 / 96.0, 1e-4);
  assert_float_equal(right[1], 0, 1e-6);
  /* inverse square: colour 2.4 * (1, 0.95, 0.85) / (2 f^2), fade_power 2, f a
   * millionth of the bounding sphere's radius (the box: 2 x 2 x 2) */
  double col[3], f;
  const char *light = strstr(t, "// light 'ceiling_light'");
  vector_after(light, "color rgb", col);
  assert_int_equal(sscanf(strstr(light, "fade_distance"), "fade_distance %lf", &f), 1);
  assert_float_equal(f, LM_POV_FADE_FRACTION * sqrt(3.0), 1e-12);
  double k = 1.0 / (2 * f * f);
  assert_float_equal(col[0] / k, 2.4, 1e-6);
  assert_float_equal(col[2] / k, 2.4 * 0.85, 1e-6);
  assert_non_null(strstr(light, "\n  fade_power 2"));
  /* the sun is parallel, placed outside the box, shining along its node's -Z */
  const char *sun = strstr(t, "// light 'sun'");
  assert_non_null(sun);
  double sloc[3], sat[3];
  vector_after(sun, "light_source {\n ", sloc);
  vector_after(sun, "point_at", sat);
  assert_non_null(strstr(sun, "parallel"));
  assert_true(sloc[1] > 2.0);
  assert_true(sat[1] < sloc[1]); /* shining down */
  /* the spot: radius = inner, falloff = outer, tightness 0 */
  assert_non_null(strstr(t, "spotlight\n  radius 8\n  falloff 16\n  tightness 0\n"));
  /* materials: pigment, Lambert with kd, Phong, no ambient */
  assert_non_null(strstr(t, "// material 'red'\n#declare limn_material_1 = texture {\n"
                            "  pigment { rgb <0.629999995, 0.0649999976, 0.0500000007> }\n"
                            "  finish { ambient 0 emission 0 diffuse 1 brilliance 1 phong 0 phong_size 1 }"));
  assert_non_null(strstr(t, "phong 0.150000006 phong_size 24"));
  /* one mesh2 per mesh node, the cube's world transform applied */
  int meshes = 0;
  for (const char *p = t; (p = strstr(p, "mesh2 {")); p++) meshes++;
  assert_int_equal(meshes, 7);
  assert_non_null(strstr(t, "// node 'tall_box', mesh 'cube'"));
  assert_null(strstr(t, "no_shadow"));
  assert_null(strstr(t, "shadowless"));
  lm_buf_free(&out);

  /* without radiosity and shadows */
  d.radiosity = false;
  d.shadows = false;
  assert_true(lm_pov_export(s, &d, &out, NULL, &err));
  assert_null(strstr(out.data, "radiosity"));
  int no_shadow = 0;
  for (const char *p = out.data; (p = strstr(p, "no_shadow")); p++) no_shadow++;
  assert_int_equal(no_shadow, 7);
  lm_buf_free(&out);
  lm_scene_destroy(s);
}

/* A reflective material becomes POV-Ray's finish reflection; an override past 1 is clamped, with a warning. */
static void reflective_materials_write_reflection(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err); /* lights POV-Ray matches: no other warning */
  assert_non_null(s);
  int red = lm_scene_find_material(s, "red");
  s->materials[red].reflectivity = 0.75f;
  lm_pov_desc d = {.camera = 0, .width = 64, .height = 48, .shadows = true};
  lm_buf out = {0}, warn = {0};
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(out.data, "  finish { ambient 0 emission 0 diffuse 1 brilliance 1 phong 0 phong_size 1 "
                                   "reflection 0.75 }"));
  int count = 0;
  for (const char *p = out.data; (p = strstr(p, "reflection")); p++) count++;
  assert_int_equal(count, 1); /* only the reflective material */
  assert_null(warn.data);
  lm_buf_free(&out);
  lm_buf_free(&warn);
  s->materials[red].reflectivity = 2;
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(out.data, "reflection 1 }"));
  assert_non_null(strstr(warn.data, "material 'red': reflectivity outside [0, 1]"));
  d.strict = true;
  lm_buf_free(&out);
  assert_false(lm_pov_export(s, &d, &out, NULL, &err));
  assert_non_null(strstr(err.msg, "reflectivity"));
  lm_buf_free(&out);
  lm_buf_free(&warn);
  lm_scene_destroy(s);
}

/* The box's vertex (0.5, 0.5, 0.5) of tall_box lands at T * R * S of it. */
static void mesh_vertices_are_in_world_space(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  lm_pov_desc d = desc_for(64, 48);
  d.strict = false;
  lm_buf out = {0};
  assert_true(lm_pov_export(s, &d, &out, NULL, &err));
  const char *tall = strstr(out.data, "// node 'tall_box'");
  assert_non_null(tall);
  double ys[2] = {INFINITY, -INFINITY};
  const char *p = strstr(tall, "vertex_vectors {");
  const char *end = strstr(tall, "normal_vectors");
  for (p = strchr(p, '<'); p && p < end; p = strchr(p + 1, '<')) {
    double v[3];
    assert_int_equal(sscanf(p, "<%lf, %lf, %lf>", &v[0], &v[1], &v[2]), 3);
    ys[0] = fmin(ys[0], v[1]), ys[1] = fmax(ys[1], v[1]);
  }
  /* centred at y 0.6, 1.2 tall: from the floor to 1.2 */
  assert_float_equal(ys[0], 0.0, 1e-5);
  assert_float_equal(ys[1], 1.2, 1e-5);
  lm_buf_free(&out);
  lm_scene_destroy(s);
}

/* The seed's window falloff (eq 16) cannot be written: refused by name, or
 * written without falloff with a warning naming the light. The built-in
 * box's light made the seed's way: */
static void window_falloff_is_refused_or_warned_by_name(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  s->lights[0].falloff = LM_FALLOFF_WINDOW;
  lm_pov_desc d = desc_for(64, 48);
  lm_buf out = {0}, warn = {0};
  assert_false(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(err.msg, "light 'ceiling_light': the window falloff"));
  lm_buf_free(&out);
  d.strict = false;
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(warn.data, "light 'ceiling_light': the window falloff"));
  assert_null(strstr(out.data, "fade_power"));
  lm_buf_free(&out);
  lm_buf_free(&warn);
  lm_scene_destroy(s);
}

/* The built-in box's one light is an inverse-square point light: it
 * exports exactly (fade_power 2), so the box has a POV-Ray reference. */
static void builtin_cornell_exports_exactly(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell", &err);
  assert_int_equal(s->light_count, 1);
  lm_pov_desc d = desc_for(64, 48);
  lm_buf out = {0}, warn = {0};
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_null(warn.data);
  assert_non_null(strstr(out.data, "fade_power 2"));
  lm_buf_free(&out);
  lm_scene_destroy(s);
}

/* glTF's range window (LM_FALLOFF_RANGE): no range, or one so far that the
 * window stays within LM_POV_RANGE_EXACT of 1 over the scene, is written as
 * inverse square; a nearer range is refused by name, saying why. */
static void range_window_is_exact_or_refused_by_name(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err);
  lm_light *l = &s->lights[0];
  assert_int_equal(l->falloff, LM_FALLOFF_INVERSE_SQUARE);
  lm_pov_desc d = desc_for(64, 48);
  lm_buf square = {0}, out = {0}, warn = {0};
  assert_true(lm_pov_export(s, &d, &square, NULL, &err));
  l->falloff = LM_FALLOFF_RANGE;
  float ranges[] = {0, 100};
  for (int i = 0; i < 2; i++) {
    l->radius = ranges[i];
    assert_true(lm_pov_export(s, &d, &out, &warn, &err));
    assert_null(warn.data);
    assert_string_equal(out.data, square.data);
    lm_buf_free(&out);
  }
  l->radius = 3;
  assert_false(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(err.msg, "light 'ceiling_light': range 3: the KHR_lights_punctual window"));
  assert_non_null(strstr(err.msg, "no POV-Ray light fades to zero at a distance"));
  lm_buf_free(&out);
  d.strict = false;
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(warn.data, "light 'ceiling_light': range 3"));
  assert_string_equal(out.data, square.data);
  lm_buf_free(&out);
  lm_buf_free(&warn);
  lm_buf_free(&square);
  lm_scene_destroy(s);
}

/* --materials pbr: POV-Ray's closest finish for each material, written even
 * when strict, each named in a warning; Phong materials get the metallic and
 * roughness the pbr technique derives for them. */
static void pbr_materials_are_approximated_and_said(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err);
  lm_pov_desc d = desc_for(64, 48);
  d.pbr_materials = true;
  lm_buf out = {0}, warn = {0};
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(warn.data, "material 'red': metallic-roughness written as POV-Ray's closest finish"));
  /* red: kd 1, shininess 1: metallic 0, roughness (2 / 3)^(1/4) */
  assert_non_null(strstr(out.data, "// material 'red' (metallic 0, roughness 0.904: approximated)"));
  assert_non_null(strstr(out.data, "diffuse 1 brilliance 1 specular"));
  assert_null(strstr(out.data, " phong "));
  lm_buf_free(&out);
  lm_buf_free(&warn);
  lm_scene_destroy(s);
}

/* The C twin of lighting.glsl's light_falloff, and where each light ends. */
static void falloff_and_reach(void **state) {
  (void)state;
  assert_float_equal(lm_light_falloff(LM_FALLOFF_NONE, 7, 1), 1, 0);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_INVERSE_SQUARE, 2, 1), 0.25, 1e-7);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_INVERSE_SQUARE, 0, 1), 1e8, 1);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_WINDOW, 1, 2), 0.75, 1e-7);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_WINDOW, 3, 2), 0, 0);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_RANGE, 2, 0), 0.25, 1e-7);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_RANGE, 2, 4), (1 - 1 / 16.0) / 4, 1e-7);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_RANGE, 4, 4), 0, 0);
  assert_float_equal(lm_light_falloff(LM_FALLOFF_RANGE, 9, 4), 0, 0);
  lm_light l = {.type = LM_LIGHT_POINT, .falloff = LM_FALLOFF_RANGE, .radius = 4};
  assert_float_equal(lm_light_reach(&l), 4, 0);
  l.radius = 0;
  assert_true(isinf(lm_light_reach(&l)));
  l.falloff = LM_FALLOFF_WINDOW, l.radius = 3;
  assert_float_equal(lm_light_reach(&l), 3, 0);
  l.falloff = LM_FALLOFF_INVERSE_SQUARE;
  assert_true(isinf(lm_light_reach(&l)));
  l.type = LM_LIGHT_DIRECTIONAL, l.falloff = LM_FALLOFF_WINDOW;
  assert_true(isinf(lm_light_reach(&l)));
}

static void unmatched_spots_and_materials_are_named(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err);
  lm_pov_desc d = desc_for(64, 48);
  lm_buf out = {0}, warn = {0};
  s->lights[2].outer_cone = 1.5707964f; /* 90 degrees */
  assert_false(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(err.msg, "light 'spot': spot cone of 90 degrees"));
  lm_buf_free(&out);
  /* the engine sees only cosines: a negative angle is its size */
  s->lights[2].inner_cone = -0.1f;
  s->lights[2].outer_cone = -0.3f;
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  char want[128];
  snprintf(want, sizeof want, "radius %.9g\n  falloff %.9g\n", glm_deg(0.1f), glm_deg(0.3f));
  assert_non_null(strstr(out.data, want));
  lm_buf_free(&out);
  s->lights[2].outer_cone = 0.3f;
  s->lights[2].casts_shadows = false;
  assert_false(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(err.msg, "light 'spot': a spot that casts no shadows"));
  lm_buf_free(&out);
  s->lights[2].casts_shadows = true;
  s->materials[1].color[0] = 1.5f;
  assert_false(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(err.msg, "material 'red': colour, kd or ks outside [0, 1]"));
  lm_buf_free(&out);
  d.strict = false;
  assert_true(lm_pov_export(s, &d, &out, &warn, &err));
  assert_non_null(strstr(out.data, "pigment { rgb <1, 0.0649999976, 0.0500000007> }")); /* clamped as the G-buffer does */
  assert_non_null(strstr(warn.data, "material 'red'"));
  lm_buf_free(&out);
  lm_buf_free(&warn);
  lm_scene_destroy(s);
}

static void bad_views_are_refused(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_pov", &err);
  lm_pov_desc d = desc_for(64, 48);
  lm_buf out = {0};
  d.camera = 3;
  assert_false(lm_pov_export(s, &d, &out, NULL, &err));
  assert_string_equal(err.msg, "camera 3: scene 'cornell_pov' has 1 camera(s)");
  d.camera = 0;
  d.rad.pretrace_end = 0.5; /* past pretrace_start */
  assert_false(lm_pov_export(s, &d, &out, NULL, &err));
  assert_non_null(strstr(err.msg, "pretrace_end"));
  d.rad.pretrace_end = 0.01;
  s->lights[0].power = INFINITY;
  assert_false(lm_pov_export(s, &d, &out, NULL, &err));
  assert_string_equal(err.msg, "light 'ceiling_light': a coordinate or colour is not finite (Inf or NaN)");
  s->lights[0].power = 2.4f;
  s->meshes[0].indices[2] = 99;
  assert_false(lm_pov_export(s, &d, &out, NULL, &err));
  assert_non_null(strstr(err.msg, "node 'floor': mesh 'floor': index 2 is 99, past its 4 vertices"));
  lm_buf_free(&out);
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(camera_lights_and_materials_match),
      cmocka_unit_test(reflective_materials_write_reflection),
      cmocka_unit_test(mesh_vertices_are_in_world_space),
      cmocka_unit_test(window_falloff_is_refused_or_warned_by_name),
      cmocka_unit_test(builtin_cornell_exports_exactly),
      cmocka_unit_test(range_window_is_exact_or_refused_by_name),
      cmocka_unit_test(falloff_and_reach),
      cmocka_unit_test(pbr_materials_are_approximated_and_said),
      cmocka_unit_test(unmatched_spots_and_materials_are_named),
      cmocka_unit_test(bad_views_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
