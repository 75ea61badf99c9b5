/* The tutorial's pipelines (scripts/examples/, scripts/README.md), each
 * image checked against what its code says, and pp.lua's technique rows:
 * the engine lists them as written, and a bad row is refused naming its
 * line.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#include "gl_test.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "script/script.h"

#define W 64
#define H 48

/* tint.frag: each channel times its gain, mixed with the input by
 * strength; read before the output stage, in the targets' half floats. */
static void post_effect_scales_each_channel_by_its_gain(void **state) {
  (void)state;
  const char *off[] = {"tint.enabled=false", NULL};
  const char *on[] = {"tint.r=1", "tint.g=0.5", "tint.b=0.25", NULL};
  const char *half[] = {"tint.r=1", "tint.g=0.5", "tint.b=0.25", "tint.strength=0.5", NULL};
  const char *script = "scripts/examples/post_effect.lua";
  gl_result a = gl_render_ok(&(gl_run){.script = script, .sets = off, .width = W, .height = H});
  assert_false(gl_has_pass(&a, "tint")); /* off records no pass */
  int w, h;
  float *lit = gl_read_target(&a, "lit", &w, &h);
  assert_non_null(lit);
  double mean = 0;
  for (int i = 0; i < w * h; i++) mean += gl_luminance(lit + 4 * i) / (w * h);
  assert_true(mean > 0.02); /* a lit box, not black */
  const char *const *sets[2] = {on, half};
  const double gains[2][3] = {{1, 0.5, 0.25}, {1, 0.75, 0.625}};
  for (int k = 0; k < 2; k++) {
    gl_result b = gl_render_ok(&(gl_run){.script = script, .sets = sets[k], .width = W, .height = H});
    int tw, th;
    float *tint = gl_read_target(&b, "tint", &tw, &th);
    assert_non_null(tint);
    assert_int_equal(tw * th, w * h);
    for (int i = 0; i < w * h; i++)
      for (int c = 0; c < 3; c++) {
        double want = lit[4 * i + c] * gains[k][c];
        if (fabs(tint[4 * i + c] - want) > 1e-3 * want + 1e-5)
          fail_msg("pixel %d channel %d: %g, want %g", i, c, tint[4 * i + c], want);
      }
    free(tint);
    gl_result_free(&b);
  }
  free(lit);
  gl_result_free(&a);
}

/* The row added in mixed_gi.lua: listed after pp.lua's with its key, both
 * modules' passes recorded, and where dl+esm has only the ambient term (in
 * shadow) the LPV's bounce makes it brighter. */
static void mixed_technique_is_a_row_brighter_in_shadow(void **state) {
  (void)state;
  const char *script = "scripts/examples/mixed_gi.lua";
  gl_result dl = gl_render_ok(&(gl_run){.script = script, .tech = "dl+esm", .width = W, .height = H});
  gl_result mix = gl_render_ok(&(gl_run){.script = script, .tech = "lpv+ssao+esm", .width = W, .height = H});
  int n = lm_pipeline_technique_count(mix.pipeline);
  assert_int_equal(n, 14);
  assert_string_equal(lm_pipeline_technique_name(mix.pipeline, n - 1), "lpv+ssao+esm");
  assert_string_equal(lm_pipeline_technique_key(mix.pipeline, n - 1), "F10");
  assert_true(gl_has_pass(&mix, "lpv.lookup"));
  assert_true(gl_has_pass(&mix, "ssao.apply"));
  /* In shadow: lit by the ambient term alone (0.02 times albedo at most), not background. */
  double in_dl = 0, in_mix = 0;
  int shadowed = 0;
  for (int i = 0; i < W * H; i++) {
    float l = gl_luminance(dl.rgb + 3 * i);
    if (l > 1e-4f && l < 0.02f) {
      in_dl += l, in_mix += gl_luminance(mix.rgb + 3 * i), shadowed++;
    }
  }
  print_message("%d pixels in shadow: dl+esm %.4f, lpv+ssao+esm %.4f\n", shadowed, in_dl / shadowed,
                in_mix / shadowed);
  assert_true(shadowed > W * H / 50);
  assert_true(in_mix > 1.5 * in_dl);
  gl_result_free(&dl);
  gl_result_free(&mix);
}

/* debug_view.lua shows G-buffer values as they are: normals 0.5 n + 0.5 on
 * the box's walls, depth / far (far 20) at their distance from the camera
 * (0, 1, 3.4) along -z. */
static void debug_view_shows_the_target_values(void **state) {
  (void)state;
  const char *script = "scripts/examples/debug_view.lua";
  gl_result r = gl_render(&(gl_run){.script = script, .width = W, .height = H});
  assert_true(r.ok);
  const struct {
    float p[3], want[3];
  } normals[] = {{{-0.5f, 0.0f, 0.6f}, {0.5f, 1.0f, 0.5f}},   /* floor, +y */
                 {{-1.0f, 1.4f, 0.5f}, {1.0f, 0.5f, 0.5f}},   /* left wall, +x */
                 {{1.0f, 1.4f, 0.5f}, {0.0f, 0.5f, 0.5f}},    /* right wall, -x */
                 {{0.5f, 1.5f, -1.0f}, {0.5f, 0.5f, 1.0f}}};  /* back wall, +z */
  for (size_t i = 0; i < sizeof normals / sizeof *normals; i++) {
    float got[3];
    gl_mean_around(&r, normals[i].p[0], normals[i].p[1], normals[i].p[2], 1, got);
    for (int c = 0; c < 3; c++)
      if (fabsf(got[c] - normals[i].want[c]) > 0.01f) fail_msg("normal %zu channel %d: %g", i, c, got[c]);
  }
  assert_true(gl_set(&r, "show=dpt") && gl_set(&r, "scale=1") && gl_set(&r, "offset=0"));
  assert_true(gl_render_again(&r));
  /* The back wall faces the camera: one depth all over; the floor's
   * changes across a pixel. */
  const struct {
    float p[3], tolerance;
  } depths[] = {{{0.5f, 1.5f, -1.0f}, 1e-4f}, {{-0.8f, 1.8f, -1.0f}, 1e-4f}, {{-0.5f, 0.0f, 0.6f}, 0.005f}};
  for (size_t i = 0; i < sizeof depths / sizeof *depths; i++) {
    float got[3], want = (3.4f - depths[i].p[2]) / 20.0f;
    gl_mean_around(&r, depths[i].p[0], depths[i].p[1], depths[i].p[2], 0, got);
    if (fabsf(got[0] - want) > depths[i].tolerance) fail_msg("depth %zu: %g, want %g", i, got[0], want);
  }
  /* A target the debug view does not offer is refused by name. */
  assert_true(gl_set(&r, "show=vel"));
  assert_false(gl_render_again(&r));
  assert_non_null(strstr(r.err.msg, "show must be one of clr, nrm, dpt, mat (got vel)"));
  gl_result_free(&r);
}

/* --list-options and the viewer read pp.lua's rows: every
 * `technique{ "name"` line of the file, in order, and the seed's keys. */
static void rows_are_the_techniques(void **state) {
  (void)state;
  char path[1024];
  snprintf(path, sizeof path, "%s/scripts/pp.lua", gl_root());
  lm_error err;
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = path}, &err);
  if (!p) fail_msg("%s", err.msg);
  char *text = lm_read_file(path, NULL, &err);
  assert_non_null(text);
  int n = 0;
  for (const char *s = text; (s = strstr(s, "\ntechnique{ \"")); s++) {
    const char *name = s + strlen("\ntechnique{ \""), *end = strchr(name, '"');
    assert_true(n < lm_pipeline_technique_count(p));
    if (strncmp(lm_pipeline_technique_name(p, n), name, (size_t)(end - name)) ||
        lm_pipeline_technique_name(p, n)[end - name])
      fail_msg("technique %d: %s, the file's row %.*s", n, lm_pipeline_technique_name(p, n), (int)(end - name), name);
    n++;
  }
  assert_int_equal(n, 13);
  assert_int_equal(lm_pipeline_technique_count(p), n);
  /* The default first, then the seed viewer's F2-F5 modes with their keys; no other row has one. */
  assert_string_equal(lm_pipeline_technique_name(p, 0), "isr+rsm+esm");
  const char *keys[] = {"F2", "F3", "F4", "F5"}, *techs[] = {"isr+esm", "isr", "dl+esm", "dl"};
  for (int i = 0; i < n; i++) {
    const char *key = lm_pipeline_technique_key(p, i);
    if (i >= 1 && i <= 4) {
      assert_string_equal(lm_pipeline_technique_name(p, i), techs[i - 1]);
      assert_string_equal(key, keys[i - 1]);
    } else {
      assert_null(key);
    }
  }
  free(text);
  lm_pipeline_destroy(p);
}

/* A row with a module that does not exist, a field or a value a row does
 * not have, or a module that is not an effect stops the script at its line. */
static void bad_rows_are_refused_naming_their_line(void **state) {
  (void)state;
  static const struct {
    const char *row, *expect;
  } cases[] = {
      {"technique{ \"x\", lighting = \"nope\" }", "rows.lua:3: technique x: lighting: no module nope"},
      {"technique{ \"x\", shadow = true }", "rows.lua:3: technique x: 'shadow' is not a field of a row"},
      {"technique{ \"x\", key = \"F6\" }", "rows.lua:3: technique x: key cannot be 'F6'"},
      {"technique{ \"x\", key = \"F2\" }", "rows.lua:3: technique x: key F2 is isr+esm's"},
      {"technique{ \"dl\" }", "rows.lua:3: technique dl: needs a name of its own"},
      {"technique{ \"x\", offscreen = \"gbuffer\" }", "rows.lua:3: technique x: offscreen: gbuffer is not an effect"},
      {"technique{ \"x\", lighting = \"isr\", temporal = \"rsm\" }", "rows.lua:3: technique x: temporal must be"},
      {"technique{ \"x\", offscreen = \"lpv\", joins = \"march\" }", "rows.lua:3: technique x: joins = \"march\" needs"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char text[512], path[1024];
    snprintf(text, sizeof text, "require \"pp\"\nlocal technique = require(\"techniques\").add\n%s\n", cases[i].row);
    assert_true(gl_write_file("rows.lua", text));
    snprintf(path, sizeof path, "%s/rows.lua", gl_root());
    lm_error err;
    lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = path}, &err);
    if (p) fail_msg("%s: loaded", cases[i].row);
    if (!strstr(err.msg, cases[i].expect)) fail_msg("%s: '%s'", cases[i].row, err.msg);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(post_effect_scales_each_channel_by_its_gain),
      cmocka_unit_test(mixed_technique_is_a_row_brighter_in_shadow),
      cmocka_unit_test(debug_view_shows_the_target_values),
      cmocka_unit_test(rows_are_the_techniques),
      cmocka_unit_test(bad_rows_are_refused_naming_their_line),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
