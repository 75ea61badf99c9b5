/* Ray-traced reflections through pp.lua (scripts/reflections.lua) on
 * whatever EGL offers: the mirror of cornell_mirror shows the (red) tall box
 * exactly where the CPU tracer says its reflection lands, follows the box
 * when it moves, and the passes are left out where nothing reflects.
 * (The agreement with POV-Ray is tests/test_pov_faithful.sh.)
 * Each test stands alone (it makes and frees its own), so tests read alike. */
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
#include "trace/trace.h"

enum { W = 96, H = 72 };

static int find_node(const lm_scene *s, const char *name) {
  int i = lm_scene_find_node(s, name);
  if (i < 0) fail_msg("no node '%s'", name);
  return i;
}

/* What each pixel's centre sees in the mirror, by the CPU tracer alone: the
 * node its reflection hits, -1 where the pixel is not on the mirror, -2 where
 * the reflection leaves the box (open front). */
static void predict(const lm_scene *s, int mirror, int out[H][W]) {
  lm_trace *t = lm_trace_create(s, NULL);
  lm_frame_data f;
  lm_scene_frame_data(s, 0, W, H, &f);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      float u = (x + 0.5f) / W, v = 1 - (y + 0.5f) / H; /* rows from the top */
      lm_trace_ray r = {.tmax = INFINITY};
      for (int k = 0; k < 3; k++)
        r.origin[k] = f.camera_pos[k], r.dir[k] = f.frustum_o[k] + f.frustum_u[k] * u + f.frustum_v[k] * v;
      lm_trace_hit h;
      out[y][x] = -1;
      if (!lm_trace_intersect(t, &r, &h)) continue;
      lm_trace_surface sf;
      lm_trace_surface_at(t, &r, &h, &sf);
      if (sf.node != mirror) continue;
      float dn = r.dir[0] * sf.normal[0] + r.dir[1] * sf.normal[1] + r.dir[2] * sf.normal[2];
      lm_trace_ray rr = {.tmin = 1e-4f, .tmax = INFINITY};
      for (int k = 0; k < 3; k++)
        rr.origin[k] = sf.position[k], rr.dir[k] = r.dir[k] - 2 * dn * sf.normal[k];
      lm_trace_surface rs;
      out[y][x] = lm_trace_intersect(t, &rr, &h) ? (lm_trace_surface_at(t, &rr, &h, &rs), rs.node) : -2;
    }
  lm_trace_destroy(t);
}

/* Counts mirror pixels whose colour says what the prediction says: red where
 * the red box is seen, not red elsewhere. Pixels beside a change of what is
 * seen are left out (the half-size rays and the upsampling blur edges). */
static void agreement(const gl_result *r, int p[H][W], int box, int *agree, int *total, int *red) {
  *agree = *total = *red = 0;
  for (int y = 1; y < H - 1; y++)
    for (int x = 1; x < W - 1; x++) {
      if (p[y][x] == -1) continue;
      bool edge = false;
      for (int dy = -2; dy <= 2; dy++)
        for (int dx = -2; dx <= 2; dx++) {
          int yy = y + dy, xx = x + dx;
          if (yy >= 0 && yy < H && xx >= 0 && xx < W && p[yy][xx] != p[y][x]) edge = true;
        }
      if (edge) continue;
      const float *c = r->rgb + ((size_t)y * W + x) * 3;
      bool looks_red = c[0] > 0.05f && c[0] > 3 * c[1] && c[0] > 3 * c[2];
      bool want_red = p[y][x] == box;
      if (getenv("LIMN_TEST_VERBOSE") && looks_red != want_red)
        print_message("(%d,%d) want %d got %.3f %.3f %.3f\n", x, y, want_red, c[0], c[1], c[2]);
      (*total)++;
      *red += want_red;
      *agree += looks_red == want_red;
    }
}

static void a_mirror_shows_the_box_where_the_tracer_says(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_mirror", &err);
  assert_non_null(s);
  int box = find_node(s, "tall_box"), mirror = find_node(s, "left");
  s->nodes[box].material = lm_scene_add_material(s, &(lm_material){.name = "red", .color = {1, 0, 0}, .ka = 1, .kd = 1,
                                                                   .shininess = 1});
  static int p[H][W];
  predict(s, mirror, p);
  /* ambient light shows the box's faces the lights do not reach (the mirror, black, takes none) */
  const char *on[] = {"ambient=0.3", "reflections.enabled=true", "reflections.scale=1", NULL};
  gl_result r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = on, .width = W, .height = H,
                                    .check_finite = true});
  if (!r.ok) fail_msg("%s", r.err.msg);
  assert_true(gl_all_finite(&r));
  int agree, total, red;
  agreement(&r, p, box, &agree, &total, &red);
  print_message("mirror: %d of %d pixels agree with the tracer (%d show the box)\n", agree, total, red);
  assert_true(red > 40);
  assert_true(total - red > 100);
  assert_true(agree >= total - total / 50);

  /* the box moves toward the front: the renderer refits its BVH and the reflection follows */
  s->nodes[box].local[14] += 0.3f;
  lm_scene_update(s);
  static int q[H][W];
  predict(s, mirror, q);
  int moved = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) moved += (p[y][x] == box) != (q[y][x] == box);
  assert_true(moved > 40);
  assert_true(gl_render_again(&r));
  agreement(&r, q, box, &agree, &total, &red);
  print_message("moved: %d of %d agree (%d show the box)\n", agree, total, red);
  assert_true(red > 40);
  assert_true(agree >= total - total / 50);
  gl_result_free(&r);

  /* without reflections the (black, non-diffuse) mirror stays black */
  const char *off[] = {"ambient=0", NULL};
  r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = off, .width = W, .height = H});
  assert_true(r.ok);
  assert_false(gl_has_pass(&r, "reflect."));
  float c[3];
  gl_region(&r, 2, H / 3, 6, 2 * H / 3, c);
  assert_true(gl_luminance(c) < 0.01f);
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* A gpu_only scene (as the command line's renderers load one) frees its
 * meshes' CPU vertices and indices at the upload, and reads them back from
 * the GPU when a technique traces: the indices exactly, the vertices as the
 * GPU draws them (quantized: positions within LM_MESH_POSITION_ERROR of a
 * mesh's extent, normals LM_MESH_NORMAL_ERROR radians, uvs LM_MESH_UV_ERROR);
 * the reflection is the same to 1e-4 (mean absolute difference). */
static void a_gpu_only_scene_reads_its_vertices_back(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_mirror", &err), *kept = lm_scene_builtin("cornell_mirror", &err);
  assert_non_null(s);
  assert_non_null(kept);
  s->gpu_only = true;
  const char *off[] = {"ambient=0.3", NULL}, *on[] = {"ambient=0.3", "reflections.enabled=true", NULL};
  gl_result r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = off, .width = W, .height = H});
  if (!r.ok) fail_msg("%s", r.err.msg);
  assert_true(s->mesh_count > 0);
  for (int i = 0; i < s->mesh_count; i++) assert_null(s->meshes[i].vertices), assert_null(s->meshes[i].indices);
  gl_result_free(&r);
  r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = on, .width = W, .height = H, .check_finite = true});
  if (!r.ok) fail_msg("%s", r.err.msg);
  gl_result k = gl_render(&(gl_run){.scene = kept, .tech = "dl", .sets = on, .width = W, .height = H});
  if (!k.ok) fail_msg("%s", k.err.msg);
  for (int i = 0; i < s->mesh_count; i++) {
    const lm_scene_mesh *m = &s->meshes[i], *w = &kept->meshes[i];
    assert_non_null(m->vertices);
    float extent = fmaxf(fmaxf(m->bounds[1][0] - m->bounds[0][0], m->bounds[1][1] - m->bounds[0][1]),
                         m->bounds[1][2] - m->bounds[0][2]);
    for (int v = 0; v < m->vertex_count; v++) {
      const float *a = m->vertices + 8 * v, *b = w->vertices + 8 * v;
      for (int c = 0; c < 3; c++) assert_true(fabsf(a[c] - b[c]) <= LM_MESH_POSITION_ERROR * extent);
      double cx = (double)a[4] * b[5] - (double)a[5] * b[4], cy = (double)a[5] * b[3] - (double)a[3] * b[5],
             cz = (double)a[3] * b[4] - (double)a[4] * b[3], dot = (double)a[3] * b[3] + (double)a[4] * b[4] + (double)a[5] * b[5];
      assert_true(atan2(sqrt(cx * cx + cy * cy + cz * cz), dot) <= LM_MESH_NORMAL_ERROR); /* the angle, exact when small */
      for (int c = 6; c < 8; c++) assert_true(fabsf(a[c] - b[c]) <= LM_MESH_UV_ERROR);
    }
    assert_memory_equal(m->indices, w->indices, sizeof(uint32_t) * (size_t)m->index_count);
  }
  assert_true(gl_all_finite(&r));
  double d = gl_mean_abs_diff(r.rgb, k.rgb, 3 * W * H);
  print_message("reflection from read-back vertices: mean difference %.3g\n", d);
  assert_true(d <= 1e-4);
  gl_result_free(&k);
  gl_result_free(&r);
  lm_scene_destroy(kept);
  lm_scene_destroy(s);
}

/* With reflections on but no reflective material, no reflection pass is recorded. */
static void nothing_reflective_records_no_pass(void **state) {
  (void)state;
  const char *on[] = {"reflections.enabled=true", NULL};
  gl_result r = gl_render(&(gl_run){.tech = "dl+esm", .sets = on, .width = 32, .height = 24});
  assert_true(r.ok);
  assert_false(gl_has_pass(&r, "reflect."));
  gl_result_free(&r);
  const char *bad[] = {"reflections.enabled=true", "reflections.scale=0.3", NULL};
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_mirror", &err);
  r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = bad, .width = 32, .height = 24});
  assert_false(r.ok);
  assert_non_null(strstr(r.err.msg, "reflections.scale must be one of 1, 0.5, 0.25"));
  gl_result_free(&r);
  lm_scene_destroy(s);
}

/* Every technique with shadows, at the seed's half size: finite, the mirror lit. */
static void every_technique_reflects(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_builtin("cornell_mirror", &err);
  const char *techs[] = {"isr+esm", "dl+esm", "ssdo+esm", "ssao+esm"};
  const char *on[] = {"reflections.enabled=true", NULL};
  for (int i = 0; i < 4; i++) {
    gl_result r = gl_render(&(gl_run){.scene = s, .tech = techs[i], .sets = on, .width = 48, .height = 36,
                                      .check_finite = true});
    if (!r.ok) fail_msg("%s: %s", techs[i], r.err.msg);
    assert_true(gl_has_pass(&r, "reflect.trace"));
    float c[3];
    gl_region(&r, 8, 14, 12, 22, c); /* on the mirror */
    assert_true(gl_luminance(c) > 0.02f);
    gl_result_free(&r);
  }
  lm_scene_destroy(s);
}

/* The same mirror in units 1e-3 and 1e5 (the rays' offset is a share of the
 * eye distance, max_distance 0 is unlimited): finite and the same image; a
 * 1x1 output reflects too. */
static void reflections_hold_at_every_scale(void **state) {
  (void)state;
  const char *on[] = {"ambient=0", "reflections.enabled=true", NULL};
  const float units[] = {1, 1e-3f, 1e5f};
  float ratio1 = 0;
  for (int i = 0; i < 3; i++) {
    lm_error err;
    lm_scene *s = lm_scene_builtin("cornell_mirror", &err);
    for (int l = 0; l < s->light_count; l++) s->lights[l].falloff = LM_FALLOFF_NONE; /* light free of the unit */
    if (units[i] != 1) gl_rescale(s, units[i]);
    gl_result r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = on, .width = 48, .height = 36,
                                      .check_finite = true});
    if (!r.ok) fail_msg("%s", r.err.msg);
    assert_true(gl_all_finite(&r));
    float c[3], all[3];
    gl_region(&r, 8, 10, 12, 26, c);
    gl_region(&r, 0, 0, 47, 35, all);
    float ratio = gl_luminance(c) / gl_luminance(all);
    if (i == 0) ratio1 = ratio;
    print_message("unit %g: mirror / image %.4f (unit 1: %.4f)\n", units[i], ratio, ratio1);
    assert_true(gl_luminance(c) > 0.0f && isfinite(ratio));
    assert_true(fabsf(ratio - ratio1) < 0.02f * ratio1);
    gl_result_free(&r);
    if (i == 0) {
      r = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = on, .width = 1, .height = 1, .check_finite = true});
      if (!r.ok) fail_msg("1x1: %s", r.err.msg);
      assert_true(gl_all_finite(&r));
      gl_result_free(&r);
    }
    lm_scene_destroy(s);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_mirror_shows_the_box_where_the_tracer_says),
      cmocka_unit_test(nothing_reflective_records_no_pass),
      cmocka_unit_test(a_gpu_only_scene_reads_its_vertices_back),
      cmocka_unit_test(every_technique_reflects),
      cmocka_unit_test(reflections_hold_at_every_scale),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
