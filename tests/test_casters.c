/* Meshes at scale: nodes placed by EXT_mesh_gpu_instancing draw as the same
 * nodes written one by one (the G-buffer, the shadow atlas and the image),
 * and simplified copies (meshoptimizer, lm_scene_mesh.casters and .lods)
 * draw fewer triangles into the shadow tiles and the G-buffer and leave the
 * image within a stated error of the whole meshes', for a finely cut sphere,
 * a cone cut as exporters cut it (outdoor.glb's tree crowns) and a terrain;
 * the GPU's quantized vertices (lm_mesh) lie within their stated error of the
 * floats; the copies, made on worker threads, are the same on any number;
 * a large mesh's spatial chunks leave out what a view does not see
 * and render the image of the mesh drawn whole; the RSM's views keep their
 * senders' normals; copies whose corners mix a uv seam's sides are drawn by
 * no textured material.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _GNU_SOURCE /* sched_setaffinity: one worker thread */
#include <sched.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"
#include "scene/gltf.h"

static lm_scene *load(const char *name) {
  char path[1024];
  snprintf(path, sizeof path, "%s/../data/scenes/big/%s", LIMN_TEST_DIR, name);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

/* Mean |a - b| over a target of both runs, against b's mean |value|; max |a - b| in *worst. */
static double target_diff(gl_result *a, gl_result *b, const char *name, double *worst) {
  int wa, ha, wb, hb;
  bool normals = !strcmp(name, "gbuffer.nrm"); /* compared as normals, not as their encoding's bytes */
  float *ta = (normals ? gl_read_normals : gl_read_target)(a, name, &wa, &ha),
        *tb = (normals ? gl_read_normals : gl_read_target)(b, name, &wb, &hb);
  if (!ta || !tb) fail_msg("no target %s", name);
  assert_int_equal(wa, wb);
  assert_int_equal(ha, hb);
  double diff = 0, mean = 0;
  *worst = 0;
  for (size_t i = 0; i < (size_t)wa * ha * 4; i++) {
    double d = fabs((double)ta[i] - tb[i]);
    diff += d, mean += fabs((double)tb[i]), *worst = fmax(*worst, d);
  }
  free(ta), free(tb);
  return mean > 0 ? diff / mean : diff;
}

/* Mean |a - ref| over the images of both runs, against ref's mean (in *mean). */
static double image_diff(const gl_result *a, const gl_result *ref, double *mean) {
  int n = ref->width * ref->height * 3;
  *mean = 0;
  for (int i = 0; i < n; i++) *mean += ref->rgb[i];
  *mean /= n;
  return gl_mean_abs_diff(a->rgb, ref->rgb, n) / *mean;
}

/* big_small: 64 spheres as 64 nodes of four meshes; big_small_instanced: the
 * same spheres as four nodes carrying EXT_mesh_gpu_instancing. The loader
 * makes each instance a child node, so both draw the spheres in one call a
 * mesh. Tolerance: the node form's transforms went through JSON at 6
 * significant digits, the instanced one's are the floats themselves, so
 * positions differ by up to ~1e-5 of a unit: a pixel on an edge may flip.
 * Mean difference at most 1e-4 of the mean value in each target, and in
 * the image. */
static void instanced_nodes_render_as_the_nodes(void **state) {
  (void)state;
  lm_scene *nodes = load("big_small.glb"), *instanced = load("big_small_instanced.glb");
  int spheres = 0;
  for (int i = 0; i < instanced->node_count; i++) spheres += instanced->nodes[i].parent >= 0 && instanced->nodes[i].mesh >= 0;
  assert_int_equal(spheres, 64);
  const char *sets[] = {"shadow.simplify=0", "simplify=0", NULL}; /* the instancing alone */
  gl_result a = gl_render_ok(&(gl_run){.scene = instanced, .tech = "dl+esm", .sets = sets, .width = 128, .height = 96,
                                       .keep_targets = true});
  gl_result b = gl_render_ok(&(gl_run){.scene = nodes, .tech = "dl+esm", .sets = sets, .width = 128, .height = 96,
                                       .keep_targets = true});
  lm_scene_draw_stats sa = lm_renderer_draw_stats(a.renderer), sb = lm_renderer_draw_stats(b.renderer);
  lm_scene_draw_stats ha = lm_renderer_shadow_draw_stats(a.renderer), hb = lm_renderer_shadow_draw_stats(b.renderer);
  print_message("camera: %d nodes in %d calls (instanced) and %d in %d; shadow tiles: %d in %d and %d in %d\n",
                sa.drawn, sa.calls, sb.drawn, sb.calls, ha.drawn, ha.calls, hb.drawn, hb.calls);
  assert_int_equal(sa.drawn, sb.drawn);
  assert_int_equal(sa.triangles, sb.triangles);
  assert_int_equal(sa.calls, sb.calls); /* at most one a mesh either way */
  assert_true(sa.calls <= 5);
  assert_int_equal(ha.triangles, hb.triangles);
  assert_true(ha.drawn > 64);
  static const char *const targets[] = {"gbuffer.clr", "gbuffer.nrm", "gbuffer.dpt", "shadow.map"};
  for (size_t t = 0; t < sizeof targets / sizeof targets[0]; t++) {
    double worst, d = target_diff(&a, &b, targets[t], &worst);
    print_message("%-12s mean difference %.2g of the mean, largest %.3g\n", targets[t], d, worst);
    assert_true(d <= 1e-4);
  }
  double mean, d = image_diff(&a, &b, &mean);
  print_message("image        mean difference %.2g of the mean\n", d);
  assert_true(mean > 0.05 && d <= 1e-4);
  gl_result_free(&a), gl_result_free(&b);
  lm_scene_destroy(nodes), lm_scene_destroy(instanced);
}

/* A node of mesh `mesh` and material `mat` at (x, y, z). */
static void place(lm_scene *s, int mesh, int mat, float x, float y, float z) {
  mat4 m;
  glm_translate_make(m, (vec3){x, y, z});
  lm_scene_add_node(s, "ball", -1, (float *)m, mesh, mat);
}

/* A UV sphere of radius r, seg x rings quads (a seam of doubled vertices, as exporters write). */
static int sphere_mesh(lm_scene *s, float r, int seg, int rings) {
  int nv = (seg + 1) * (rings + 1), ni = seg * rings * 6, k = 0;
  float *v = malloc(sizeof(float) * 8 * (size_t)nv);
  uint32_t *ix = malloc(sizeof(uint32_t) * (size_t)ni);
  for (int j = 0; j <= rings; j++)
    for (int i = 0; i <= seg; i++) {
      float t = GLM_PIf * (float)j / (float)rings, p = 2 * GLM_PIf * (float)i / (float)seg;
      float n[3] = {sinf(t) * cosf(p), cosf(t), sinf(t) * sinf(p)}, *o = v + 8 * (j * (seg + 1) + i);
      o[0] = r * n[0], o[1] = r * n[1], o[2] = r * n[2], o[3] = n[0], o[4] = n[1], o[5] = n[2];
      o[6] = (float)i / (float)seg, o[7] = (float)j / (float)rings;
    }
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < seg; i++) {
      uint32_t a = (uint32_t)(j * (seg + 1) + i), b = a + (uint32_t)seg + 1;
      uint32_t q[6] = {a, a + 1, b + 1, a, b + 1, b};
      memcpy(ix + k, q, sizeof q), k += 6;
    }
  int id = lm_scene_add_mesh(s, "sphere", v, nv, ix, ni);
  free(v), free(ix);
  return id;
}

/* A cone of radius r and height h standing on y = 0, cut as exporters cut
 * one (and data/gen_scenes.c the outdoor scene's tree crowns): a tip vertex
 * for each of its seg sides, a ring for the sides and one for the base (each
 * with its own normals), so that every vertex shares its position with
 * another. */
static int cone_mesh(lm_scene *s, float r, float h, int seg) {
  int nv = seg + 2 * (seg + 1) + 1, ni = 6 * seg, k = 0, ring = seg, base = 2 * seg + 2;
  float *v = calloc((size_t)nv * 8, sizeof(float));
  uint32_t *ix = malloc(sizeof(uint32_t) * (size_t)ni);
  for (int i = 0; i <= seg; i++) {
    float a = 2 * GLM_PIf * (float)i / (float)seg, t = 2 * GLM_PIf * ((float)i + 0.5f) / (float)seg;
    float len = sqrtf(1 + (r / h) * (r / h)), *tip = v + 8 * i, *side = v + 8 * (ring + i), *under = v + 8 * (base + i);
    if (i < seg) tip[1] = h, tip[3] = cosf(t) / len, tip[4] = r / h / len, tip[5] = sinf(t) / len;
    side[0] = under[0] = r * cosf(a), side[2] = under[2] = r * sinf(a);
    side[3] = cosf(a) / len, side[4] = r / h / len, side[5] = sinf(a) / len, under[4] = -1;
  }
  v[8 * (nv - 1) + 4] = -1; /* the base's centre */
  for (int i = 0; i < seg; i++) {
    uint32_t q[6] = {(uint32_t)(ring + i), (uint32_t)i, (uint32_t)(ring + i + 1),
                     (uint32_t)(nv - 1), (uint32_t)(base + i), (uint32_t)(base + i + 1)};
    memcpy(ix + k, q, sizeof q), k += 6;
  }
  int id = lm_scene_add_mesh(s, "cone", v, nv, ix, ni);
  free(v), free(ix);
  return id;
}

/* Checks a chain of simplified copies of a mesh of `whole` triangles and the
 * given extent: each has at most 3/4 of the last's triangles and errs at
 * least as much, within the coarsest budget (LM_LOD_ERROR 4^(levels - 1) of
 * the extent). */
static void check_levels(const char *name, const lm_mesh_lod *lods, int levels, int whole, float extent) {
  for (int k = 0; k < levels; k++) {
    print_message("%s: level %d, %d triangles of %d, error %.4g (%.3g%% of its extent)\n", name, k, lods[k].count / 3,
                  whole, (double)lods[k].error, 100.0 * lods[k].error / extent);
    assert_true(lods[k].count > 0 && lods[k].count / 3 <= (k ? lods[k - 1].count / 3 : whole) * 3 / 4);
    assert_true(lods[k].error >= (k ? lods[k - 1].error : 0));
    assert_true(lods[k].error <= LM_LOD_ERROR * powf(4, LM_LOD_LEVELS - 1) * extent * 1.001f);
  }
}

static float mesh_extent(const lm_scene_mesh *m) {
  float extent = 0;
  for (int k = 0; k < 3; k++) extent = fmaxf(extent, m->bounds[1][k] - m->bounds[0][k]);
  return extent;
}

/* Nine finely cut spheres (64 x 32 quads), or cones (cone_mesh, 20 sides), on
 * a floor under a sun and a point light, seen from above at 45 degrees. */
static lm_scene *nine_scene(bool cones) {
  lm_scene *s = lm_scene_create(cones ? "cones" : "spheres");
  int floor = gl_material(s, "floor", 0.7f, 0.7f, 0.7f), paint = gl_material(s, "paint", 0.8f, 0.3f, 0.2f);
  gl_quad(s, "floor", floor, (const float[4][3]){{-8, 0, 8}, {8, 0, 8}, {8, 0, -8}, {-8, 0, -8}}, (const float[3]){0, 1, 0});
  int mesh = cones ? cone_mesh(s, 0.6f, 1.4f, 20) : sphere_mesh(s, 0.6f, 64, 32);
  for (int k = 0; k < 9; k++)
    place(s, mesh, paint, 2.0f * (float)(k % 3 - 1), cones ? 0 : 0.6f, 2.0f * (float)(k / 3 - 1));
  float w[16];
  lm_camera_look_at((float[]){-3, -4, -2}, (float[]){0, 0, 0}, w); /* the sun shines along (3, -4, 2) */
  for (int c = 0; c < 3; c++) w[12 + c] = 0;
  int sun = lm_scene_add_node(s, "sun", -1, w, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                    .casts_shadows = true, .node = sun});
  float at[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1.0f, 3, 1.0f, 1};
  int lamp = lm_scene_add_node(s, "lamp", -1, at, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "lamp", .type = LM_LIGHT_POINT, .color = {1, 0.9f, 0.8f}, .power = 2,
                                    .radius = 12, .casts_shadows = true, .node = lamp});
  lm_camera_look_at((float[]){0, 7, 7}, (float[]){0, 0, 0}, w);
  int cam = lm_scene_add_node(s, "camera", -1, w, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "view", .fov_y = glm_rad(50.0f), .znear = 0.1f, .zfar = 40, .node = cam});
  lm_scene_update(s);
  return s;
}

/* Simplified casters (the spheres', or the cones'): the mesh has caster
 * copies (check_levels); with shadow.simplify at its default (0.5 texel)
 * the tiles whose texels hide a copy's error draw it, and the image stays
 * within `bound` (mean absolute difference over the mean) of the one with
 * every caster whole (shadow.simplify=0); tiles of 128 texels make the
 * copies' error small against a texel, as far cascades and small tiles are. */
static void casters_keep_the_shadows(bool cones, double bound) {
  lm_scene *s = nine_scene(cones);
  const char *whole_sets[] = {"shadow.resolution=128", "shadow.simplify=0", "ambient=0.05", NULL};
  const char *simple_sets[] = {"shadow.resolution=128", "ambient=0.05", NULL};
  gl_result whole = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = whole_sets, .width = 128, .height = 96});
  const lm_scene_mesh *m = &s->meshes[1];
  assert_true(m->caster_levels > 0);
  check_levels(s->name, m->casters, m->caster_levels, m->index_count / 3, mesh_extent(m));
  assert_int_equal(s->meshes[0].caster_levels, 0); /* the floor: two triangles, drawn whole */
  lm_scene_draw_stats sw = lm_renderer_shadow_draw_stats(whole.renderer);
  gl_result simple = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = simple_sets, .width = 128, .height = 96});
  lm_scene_draw_stats ss = lm_renderer_shadow_draw_stats(simple.renderer);
  print_message("shadow tiles: %ld triangles whole, %ld with %d of %d nodes simplified\n", sw.triangles, ss.triangles,
                ss.simplified, ss.drawn);
  assert_int_equal(sw.simplified, 0);
  assert_int_equal(sw.drawn, ss.drawn);
  assert_true(ss.simplified > 0 && ss.triangles < sw.triangles);
  double mean, worst = 0, d = image_diff(&simple, &whole, &mean);
  for (int i = 0; i < whole.width * whole.height * 3; i++) worst = fmax(worst, fabs(whole.rgb[i] - simple.rgb[i]));
  print_message("image: mean difference %.3g%% of the mean (%.3g), largest %.3g\n", 100 * d, mean, worst);
  assert_true(mean > 0.05 && d <= bound);
  gl_result_free(&whole), gl_result_free(&simple);
  lm_scene_destroy(s);
}

/* The spheres: within 0.5%. */
static void simplified_casters_keep_the_shadows(void **state) {
  (void)state;
  casters_keep_the_shadows(false, 0.005);
}

/* The cones, every vertex of which shares its position with another: the
 * copies over positions alone are made over the distinct positions (before,
 * meshoptimizer kept every such vertex and the cone had no copy, nor had the
 * outdoor scene's 2000 tree crowns). Within 0.5%, as the spheres. */
static void simplified_cone_casters_keep_the_shadows(void **state) {
  (void)state;
  casters_keep_the_shadows(true, 0.005);
}

/* A terrain (a height field of 160 x 160 units, 64 x 64 quads, as
 * outdoor.glb's on a coarser grid) has a caster copy within 0.1 unit (the
 * first level's budget, LM_LOD_ERROR of its extent: a texel of a near
 * cascade), not only within 1.6 (1%, the first budget before): a tile whose
 * texels are a tenth of a unit or more draws a copy of it. */
/* A height field of 160 x 160 units cut into n x n quads as mesh "terrain" (its index). */
static int terrain_mesh(lm_scene *s, int n) {
  float *v = calloc((size_t)(n + 1) * (n + 1) * 8, sizeof(float));
  uint32_t *ix = malloc(sizeof(uint32_t) * (size_t)n * n * 6);
  for (int j = 0, k = 0; j <= n; j++)
    for (int i = 0; i <= n; i++, k++) {
      float x = -80 + 160.0f * (float)i / n, z = -80 + 160.0f * (float)j / n, *o = v + 8 * k;
      o[0] = x, o[1] = 2.5f * sinf(x * 0.08f) * cosf(z * 0.07f), o[2] = z, o[4] = 1; /* normals: up */
      o[6] = (float)i / n, o[7] = (float)j / n;
    }
  for (int j = 0, k = 0; j < n; j++)
    for (int i = 0; i < n; i++, k += 6) {
      uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + n + 1, q[6] = {a, b, a + 1, a + 1, b, b + 1};
      memcpy(ix + k, q, sizeof q);
    }
  int mesh = lm_scene_add_mesh(s, "terrain", v, (n + 1) * (n + 1), ix, n * n * 6);
  free(v), free(ix);
  return mesh;
}

static void a_terrain_has_copies_within_a_near_texel(void **state) {
  (void)state;
  enum { N = 64 };
  lm_scene *s = lm_scene_create("terrain");
  int mesh = terrain_mesh(s, N);
  place(s, mesh, gl_material(s, "grass", 0.3f, 0.5f, 0.2f), 0, 0, 0);
  lm_scene_update(s);
  lm_error err;
  assert_true(lm_scene_upload(s, &err));
  const lm_scene_mesh *m = &s->meshes[mesh];
  float extent = mesh_extent(m);
  assert_true(m->caster_levels > 1 && m->lod_levels > 1);
  check_levels("terrain casters", m->casters, m->caster_levels, N * N * 2, extent);
  check_levels("terrain", m->lods, m->lod_levels, N * N * 2, extent);
  assert_true(m->casters[0].error <= LM_LOD_ERROR * extent * 1.001f && m->casters[0].error <= 0.1f);
  assert_true(m->lods[0].error <= LM_LOD_ERROR * extent * 1.001f);
  lm_scene_destroy(s);
}

/* Simplified meshes in the G-buffer: with `simplify` at its default (0.25
 * pixel) the spheres, a tenth of a unit a pixel at 128x96, draw their second
 * copy (14% of the triangles, erring by 0.11 pixel; at 0.1 pixel, their
 * first: 56%, 0.03 pixel), with its normals and uvs (the seams kept); the
 * levels pass check_levels. The G-buffer's normals and the image stay
 * within 0.5% (mean absolute difference over the mean; measured 0.25% and
 * 0.30%) of those with every mesh whole (simplify=0), the casters' bound.
 * (At 0.5 pixel a copy 0.33 pixel off made the image differ by 3%, as the
 * lit sides move against their shadow maps' depths by about a texel.) */
static void simplified_meshes_keep_the_image(void **state) {
  (void)state;
  lm_scene *s = nine_scene(false);
  const char *whole_sets[] = {"simplify=0", "ambient=0.05", NULL};
  const char *simple_sets[] = {"ambient=0.05", NULL};
  gl_result whole = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = whole_sets, .width = 128, .height = 96});
  gl_result simple = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = simple_sets, .width = 128, .height = 96});
  const lm_scene_mesh *m = &s->meshes[1];
  assert_true(m->lod_levels > 0);
  check_levels("sphere", m->lods, m->lod_levels, m->index_count / 3, mesh_extent(m));
  lm_scene_draw_stats sw = lm_renderer_draw_stats(whole.renderer), ss = lm_renderer_draw_stats(simple.renderer);
  print_message("camera: %ld triangles whole, %ld with %d of %d nodes simplified\n", sw.triangles, ss.triangles,
                ss.simplified, ss.drawn);
  assert_int_equal(sw.simplified, 0);
  assert_int_equal(sw.drawn, ss.drawn);
  assert_true(ss.simplified == 9 && ss.triangles < sw.triangles);
  double worst, dn = target_diff(&simple, &whole, "gbuffer.nrm", &worst);
  print_message("gbuffer.nrm: mean difference %.3g%% of the mean, largest %.3g\n", 100 * dn, worst);
  double mean, d = image_diff(&simple, &whole, &mean);
  print_message("image: mean difference %.3g%% of the mean (%.3g)\n", 100 * d, mean);
  assert_true(mean > 0.05 && d <= 0.005);
  assert_true(dn <= 0.005);
  gl_result_free(&whole), gl_result_free(&simple);
  lm_scene_destroy(s);
}

/* The sphere of sphere_mesh flat-shaded, as exporters write one: each
 * triangle its own three vertices with the triangle's normal, so that every
 * vertex is a seam. */
static int flat_sphere_mesh(lm_scene *s, float r, int seg, int rings) {
  int nt = seg * rings * 2, k = 0;
  float *v = malloc(sizeof(float) * 8 * 3 * (size_t)nt);
  uint32_t *ix = malloc(sizeof(uint32_t) * 3 * (size_t)nt);
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < seg; i++)
      for (int half = 0; half < 2; half++) {
        const int corners[2][3][2] = {{{0, 0}, {1, 0}, {1, 1}}, {{0, 0}, {1, 1}, {0, 1}}};
        float p[3][3];
        for (int c = 0; c < 3; c++) {
          float t = GLM_PIf * (float)(j + corners[half][c][1]) / (float)rings;
          float a = 2 * GLM_PIf * (float)(i + corners[half][c][0]) / (float)seg;
          p[c][0] = r * sinf(t) * cosf(a), p[c][1] = r * cosf(t), p[c][2] = r * sinf(t) * sinf(a);
        }
        vec3 e1, e2, n;
        glm_vec3_sub(p[1], p[0], e1), glm_vec3_sub(p[2], p[0], e2), glm_vec3_cross(e1, e2, n);
        glm_vec3_normalize(n); /* a pole's degenerate triangle: a zero normal, as exporters leave it */
        for (int c = 0; c < 3; c++, k++) {
          float *o = v + 8 * (size_t)k;
          memcpy(o, p[c], sizeof p[c]), memcpy(o + 3, n, sizeof n);
          o[6] = (float)(i + corners[half][c][0]) / (float)seg, o[7] = (float)(j + corners[half][c][1]) / (float)rings;
          ix[k] = (uint32_t)k;
        }
      }
  int id = lm_scene_add_mesh(s, "flat sphere", v, 3 * nt, ix, 3 * nt);
  free(v), free(ix);
  return id;
}

/* A mesh's GPU indices (its own, then its copies'), read back. */
static uint32_t *read_indices(const lm_scene_mesh *m) {
  float *v = malloc(sizeof(float) * 8 * (size_t)m->vertex_count);
  uint32_t *ix = malloc(sizeof(uint32_t) * (size_t)m->gpu.index_count);
  lm_mesh_read(&m->gpu, v, m->vertex_count, ix, m->gpu.index_count);
  free(v);
  return ix;
}

/* Two scenes whose meshes went to the GPU with the same copies: the same
 * levels (triangles and errors) and the same index buffers. */
static void assert_same_copies(const lm_scene *a, const lm_scene *b) {
  assert_int_equal(a->mesh_count, b->mesh_count);
  for (int i = 0; i < a->mesh_count; i++) {
    const lm_scene_mesh *ma = &a->meshes[i], *mb = &b->meshes[i];
    assert_int_equal(ma->caster_levels, mb->caster_levels);
    assert_int_equal(ma->lod_levels, mb->lod_levels);
    assert_memory_equal(ma->casters, mb->casters, sizeof ma->casters[0] * (size_t)ma->caster_levels);
    assert_memory_equal(ma->lods, mb->lods, sizeof ma->lods[0] * (size_t)ma->lod_levels);
    assert_int_equal(ma->gpu.index_count, mb->gpu.index_count);
    uint32_t *ia = read_indices(ma), *ib = read_indices(mb);
    assert_memory_equal(ia, ib, sizeof *ia * (size_t)ma->gpu.index_count);
    free(ia), free(ib);
  }
}

/* Distance from p to the triangle abc: to its plane where p projects inside,
 * else to the nearest of its edges. */
static float point_triangle_distance(const float *p, const float *a, const float *b, const float *c) {
  const float *v[3] = {a, b, c};
  vec3 e1, e2, n, ap;
  glm_vec3_sub((float *)b, (float *)a, e1), glm_vec3_sub((float *)c, (float *)a, e2), glm_vec3_cross(e1, e2, n);
  glm_vec3_sub((float *)p, (float *)a, ap);
  float area = glm_vec3_norm(n);
  bool inside = area > 0;
  for (int i = 0; i < 3 && inside; i++) { /* p on the inner side of each edge's plane through n */
    vec3 edge, to, side;
    glm_vec3_sub((float *)v[(i + 1) % 3], (float *)v[i], edge), glm_vec3_sub((float *)p, (float *)v[i], to);
    glm_vec3_cross(edge, to, side);
    inside = glm_vec3_dot(side, n) >= 0;
  }
  if (inside) return fabsf(glm_vec3_dot(ap, n)) / area;
  float best = FLT_MAX;
  for (int i = 0; i < 3; i++) {
    vec3 edge, to, q;
    glm_vec3_sub((float *)v[(i + 1) % 3], (float *)v[i], edge), glm_vec3_sub((float *)p, (float *)v[i], to);
    float len2 = glm_vec3_norm2(edge), t = len2 > 0 ? glm_clamp(glm_vec3_dot(to, edge) / len2, 0, 1) : 0;
    glm_vec3_scale(edge, t, q);
    best = fminf(best, glm_vec3_distance(to, q));
  }
  return best;
}

/* How far the mesh lies from a copy: the largest distance of a vertex of the mesh to the copy's surface. */
static float copy_distance(const lm_scene_mesh *m, const uint32_t *copy, int count) {
  float worst = 0;
  for (int i = 0; i < m->vertex_count; i++) {
    const float *p = m->vertices + 8 * (size_t)i;
    float best = FLT_MAX;
    for (int t = 0; t + 2 < count && best > 0; t += 3)
      best = fminf(best, point_triangle_distance(p, m->vertices + 8 * (size_t)copy[t], m->vertices + 8 * (size_t)copy[t + 1],
                                                 m->vertices + 8 * (size_t)copy[t + 2]));
    worst = fmaxf(worst, best);
  }
  return worst;
}

/* A cone cut as exporters cut one (cone_mesh: every vertex shares its
 * position with another, so the camera's chain, which keeps the seams, makes
 * no copy) has camera copies made over its positions, each corner of a
 * copy's face taking the vertex at its position whose normal is nearest the
 * face's: every corner's normal lies within 60 degrees of its face's (taking
 * the first vertex at each position, a tip corner would take another side's
 * normal, a corner of the base the sides'). With `simplify` at 1 pixel the
 * nine cones (a tenth of a unit a pixel) draw copies: fewer triangles, and
 * the G-buffer's normals within 2% and the image within 5% (mean absolute
 * difference over the mean) of every mesh whole; the outdoor scene's tree
 * crowns are such cones. Measured: 104 triangles of 362, normals 1.55%,
 * image 4.38% (the nodes take the 8-triangle level, whose error made from the
 * mesh is 5.7% of its extent: made from the last copy it recorded more and
 * they took the 18-triangle one, 164 triangles, image 1.08%). */
static void cones_have_camera_copies_that_keep_their_normals(void **state) {
  (void)state;
  lm_scene *s = nine_scene(true);
  const char *whole_sets[] = {"simplify=0", "ambient=0.05", NULL};
  const char *simple_sets[] = {"simplify=1", "ambient=0.05", NULL};
  gl_result whole = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = whole_sets, .width = 128, .height = 96});
  gl_result simple = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = simple_sets, .width = 128, .height = 96});
  const lm_scene_mesh *m = &s->meshes[1];
  assert_true(m->lod_levels > 0);
  check_levels("cone", m->lods, m->lod_levels, m->index_count / 3, mesh_extent(m));
  uint32_t *ix = read_indices(m);
  float least = 1;
  for (int k = 0; k < m->lod_levels; k++)
    for (int t = m->lods[k].first; t + 2 < m->lods[k].first + m->lods[k].count; t += 3) {
      const float *a = m->vertices + 8 * (size_t)ix[t], *b = m->vertices + 8 * (size_t)ix[t + 1],
                  *c = m->vertices + 8 * (size_t)ix[t + 2];
      vec3 e1 = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2 = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, f;
      glm_vec3_cross(e1, e2, f);
      if (!(glm_vec3_norm(f) > 0)) continue;
      glm_vec3_normalize(f);
      for (int corner = 0; corner < 3; corner++) least = fminf(least, glm_vec3_dot(m->vertices + 8 * (size_t)ix[t + corner] + 3, f));
    }
  free(ix);
  print_message("cone: %d camera levels, the least cosine between a corner's normal and its face's %.3f\n",
                m->lod_levels, (double)least);
  assert_true(least >= 0.5f);
  lm_scene_draw_stats sw = lm_renderer_draw_stats(whole.renderer), ss = lm_renderer_draw_stats(simple.renderer);
  print_message("camera: %ld triangles whole, %ld with %d of %d nodes simplified\n", sw.triangles, ss.triangles,
                ss.simplified, ss.drawn);
  assert_true(sw.simplified == 0 && ss.simplified == 9 && ss.triangles < sw.triangles);
  double worst, dn = target_diff(&simple, &whole, "gbuffer.nrm", &worst);
  double mean, d = image_diff(&simple, &whole, &mean);
  print_message("gbuffer.nrm: mean difference %.3g%% of the mean (largest %.3g); image %.3g%% of the mean (%.3g)\n",
                100 * dn, worst, 100 * d, mean);
  assert_true(mean > 0.05 && d <= 0.05 && dn <= 0.02);
  gl_result_free(&whole), gl_result_free(&simple);
  lm_scene_destroy(s);
}

/* Eighteen meshes (spheres and flat-shaded spheres of several cuts, cones,
 * a bare triangle) uploaded: more than the worker threads keep waiting. */
/* A flat mesh of n x n quads in the plane y = h over [-2, 2]^2, each quad with
 * its own four vertices and uvs 0..1 (a tiled floor as exporters write one):
 * a uv seam at every inner position, none of normals. */
static int tiles_mesh(lm_scene *s, int n, float h) {
  float *v = calloc((size_t)n * n * 4 * 8, sizeof(float));
  uint32_t *ix = malloc(sizeof(uint32_t) * (size_t)n * n * 6);
  for (int q = 0; q < n * n; q++)
    for (int c = 0; c < 4; c++) {
      int u = c == 1 || c == 2, w = c >= 2;
      float *o = v + 8 * (4 * q + c);
      o[0] = -2 + 4.0f * (float)(q % n + u) / (float)n, o[1] = h, o[2] = -2 + 4.0f * (float)(q / n + w) / (float)n;
      o[4] = 1, o[6] = (float)u, o[7] = (float)w;
      uint32_t b = (uint32_t)(4 * q), t[6] = {b, b + 2, b + 1, b, b + 3, b + 2};
      if (c == 0) memcpy(ix + 6 * q, t, sizeof t);
    }
  int id = lm_scene_add_mesh(s, "tiles", v, n * n * 4, ix, n * n * 6);
  free(v), free(ix);
  return id;
}

/* Copies over positions take one side's uv at a uv seam: a flat tiled mesh
 * (tiles_mesh) loses nothing to the simplifier but its seams, so its copies
 * are two triangles whose corners carry the corner tiles' uvs, the whole mesh
 * one tile. Drawn with a texture (a disc on each tile, cut out by its alpha
 * as a mask), it draws no such copy, in the camera's passes nor in the shadow
 * tiles (a caster whose texture's alpha cuts its shadow): the image is the
 * one with every mesh whole, to the bit; the same mesh untextured beside it
 * still draws its copies. */
static void textured_copies_keep_their_uvs(void **state) {
  (void)state;
  lm_scene *s = lm_scene_create("tiles");
  int floor = gl_material(s, "floor", 0.7f, 0.7f, 0.7f), plain = gl_material(s, "plain", 0.3f, 0.5f, 0.8f);
  gl_quad(s, "floor", floor, (const float[4][3]){{-8, 0, 8}, {8, 0, 8}, {8, 0, -8}, {-8, 0, -8}}, (const float[3]){0, 1, 0});
  enum { T = 16 };
  unsigned char *rgba = malloc(T * T * 4);
  for (int y = 0; y < T; y++)
    for (int x = 0; x < T; x++) {
      float dx = ((float)x + 0.5f) / T - 0.5f, dy = ((float)y + 0.5f) / T - 0.5f;
      bool disc = dx * dx + dy * dy < 0.3f * 0.3f;
      unsigned char *o = rgba + 4 * (y * T + x);
      o[0] = disc ? 230 : 40, o[1] = 60, o[2] = disc ? 40 : 200, o[3] = disc ? 255 : 0;
    }
  int tex = lm_scene_add_texture(s, "discs", T, T, rgba);
  int cut = gl_material(s, "discs", 1, 1, 1);
  s->materials[cut].base_color_texture = tex + 1;
  s->material_pbr[cut] = (lm_material_pbr){.set = true, .alpha = 1, .alpha_mode = LM_ALPHA_MASK, .alpha_cutoff = 0.5f,
                                           .roughness = 1, .normal_scale = 1, .occlusion_strength = 1};
  int mesh = tiles_mesh(s, 8, 1.0f);
  place(s, mesh, cut, -2.2f, 0, 0);
  place(s, mesh, plain, 2.2f, 0, 0);
  float w[16];
  lm_camera_look_at((float[]){1, 4, 1}, (float[]){0, 0, 0}, w); /* the sun shines along (-1, -4, -1) */
  for (int c = 0; c < 3; c++) w[12 + c] = 0;
  int sun = lm_scene_add_node(s, "sun", -1, w, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                    .casts_shadows = true, .node = sun});
  lm_camera_look_at((float[]){0, 9, 5}, (float[]){0, 0, 0}, w);
  int cam = lm_scene_add_node(s, "camera", -1, w, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "view", .fov_y = glm_rad(50.0f), .znear = 0.1f, .zfar = 40, .node = cam});
  lm_scene_update(s);
  const char *whole_sets[] = {"shadow.resolution=128", "shadow.simplify=0", "simplify=0", "ambient=0.05", NULL};
  const char *simple_sets[] = {"shadow.resolution=128", "ambient=0.05", NULL};
  gl_result whole = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = whole_sets, .width = 128, .height = 96});
  gl_result simple = gl_render_ok(&(gl_run){.scene = s, .tech = "dl+esm", .sets = simple_sets, .width = 128, .height = 96});
  const lm_scene_mesh *m = &s->meshes[mesh];
  lm_scene_draw_stats cam_stats = lm_renderer_draw_stats(simple.renderer);
  lm_scene_draw_stats tile_stats = lm_renderer_shadow_draw_stats(simple.renderer);
  double mean, d = image_diff(&simple, &whole, &mean);
  print_message("tiles: %d camera and %d caster levels (uvs mixed: %d, %d), the coarsest %d triangles; nodes simplified: "
                "camera %d of %d, shadow tiles %d of %d; image: mean difference %.3g%% of the mean (%.3g)\n",
                m->lod_levels, m->caster_levels, m->lods_mix_uvs, m->casters_mix_uvs,
                m->lod_levels ? m->lods[m->lod_levels - 1].count / 3 : 0, cam_stats.simplified, cam_stats.drawn,
                tile_stats.simplified, tile_stats.drawn, 100 * d, mean);
  assert_true(m->lod_levels > 0 && m->caster_levels > 0 && m->lods_mix_uvs && m->casters_mix_uvs);
  assert_true(cam_stats.simplified > 0 && tile_stats.simplified > 0); /* the untextured node */
  assert_true(mean > 0.05 && d == 0);
  gl_result_free(&whole), gl_result_free(&simple);
  lm_scene_destroy(s);
}

static lm_scene *many_meshes(void) {
  lm_scene *s = lm_scene_create("many");
  int mat = gl_material(s, "paint", 0.8f, 0.3f, 0.2f);
  for (int k = 0; k < 6; k++) {
    place(s, sphere_mesh(s, 0.6f, 12 + 8 * k, 6 + 4 * k), mat, (float)k, 0, 0);
    place(s, flat_sphere_mesh(s, 0.6f, 12 + 8 * k, 6 + 4 * k), mat, (float)k, 0, 2);
    place(s, k < 5 ? cone_mesh(s, 0.6f, 1.4f, 16 + 4 * k) : sphere_mesh(s, 0.1f, 2, 2), mat, (float)k, 0, 4);
  }
  lm_scene_update(s);
  return s;
}

/* A closed mesh's caster copies are closed (engine/scene/lod.c): the office's desk legs, shelf and books
 * and the garage's floor stripes are flat-shaded boxes whose corners lie a few ulps apart, and were
 * simplified into open sheets or flattened into sheets drawn from both sides, so the lamps' tiles could hold
 * faces seen from behind (lm_shadow_front_lit). */
static void copies_of_closed_meshes_are_closed(void **state) {
  (void)state;
  const char *scenes[] = {"office", "garage"};
  int checked = 0;
  for (int i = 0; i < 2; i++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/../data/scenes/%s.glb", LIMN_TEST_DIR, scenes[i]);
    lm_error err;
    lm_scene *s = lm_scene_load_gltf(path, &err);
    if (!s || !lm_scene_upload(s, &err)) fail_msg("%s", err.msg);
    for (int k = 0; k < s->mesh_count; k++) {
      const lm_scene_mesh *m = &s->meshes[k];
      int *weld = malloc(sizeof *weld * (size_t)(m->vertex_count + 1));
      lm_weld_positions(m->vertices, m->vertex_count, weld);
      if (m->caster_levels > 0 && lm_indices_closed(m->indices, m->index_count, weld)) {
        const lm_mesh_lod *last = &m->casters[m->caster_levels - 1];
        int n = last->first + last->count;
        float *vertices = malloc(sizeof(float) * 8 * (size_t)m->vertex_count);
        uint32_t *indices = malloc(sizeof *indices * (size_t)n);
        lm_mesh_read(&m->gpu, vertices, m->vertex_count, indices, n);
        for (int l = 0; l < m->caster_levels; l++)
          if (!lm_indices_closed(indices + m->casters[l].first, m->casters[l].count, weld))
            fail_msg("%s %s: caster level %d (%d triangles) open", scenes[i], m->name, l, m->casters[l].count / 3);
        free(vertices), free(indices);
        checked++;
      }
      free(weld);
    }
    lm_scene_destroy(s);
  }
  print_message("%d closed meshes with caster copies\n", checked);
  assert_true(checked >= 5); /* desk legs, shelf, books, stripes, a car's part at least */
}

/* Simplified copies are made on worker threads, one a core, while meshes
 * are read, each mesh's GL buffers once its copies are done: the copies are
 * the same on one worker as on all (the buffers do not depend on the
 * threads' timing), each within its budget (check_levels); a flat-shaded
 * sphere, every vertex a seam, has caster copies and camera copies, both
 * over its positions (the camera's corners keeping their faces' normals),
 * and the bare mesh none. Loading a file to the GPU as it
 * is read (lm_scene_load_gpu: meshes wait while their copies are made, the
 * CPU copies freed after) gives the copies of loading it whole and then
 * uploading it. */
static void copies_are_the_same_on_any_number_of_threads(void **state) {
  (void)state;
  lm_error err;
  lm_scene *all = many_meshes(), *one = many_meshes();
  assert_true(lm_scene_upload(all, &err));
  cpu_set_t cores, first;
  assert_int_equal(sched_getaffinity(0, sizeof cores, &cores), 0);
  CPU_ZERO(&first);
  for (int c = 0; c < CPU_SETSIZE; c++)
    if (CPU_ISSET(c, &cores)) {
      CPU_SET(c, &first);
      break;
    }
  assert_int_equal(sched_setaffinity(0, sizeof first, &first), 0); /* lm_cpu_count: one worker */
  assert_int_equal(lm_cpu_count(), 1);
  bool uploaded = lm_scene_upload(one, &err);
  assert_int_equal(sched_setaffinity(0, sizeof cores, &cores), 0);
  assert_true(uploaded);
  print_message("%d cores\n", lm_cpu_count());
  assert_same_copies(all, one);
  double ratio = 0;
  for (int i = 0; i < all->mesh_count; i++) {
    const lm_scene_mesh *m = &all->meshes[i];
    check_levels(m->name, m->casters, m->caster_levels, m->index_count / 3, mesh_extent(m));
    check_levels(m->name, m->lods, m->lod_levels, m->index_count / 3, mesh_extent(m));
    uint32_t *ix = read_indices(m);
    for (int chain = 0; chain < 2; chain++)
      for (int k = 0; k < (chain ? m->lod_levels : m->caster_levels); k++) {
        const lm_mesh_lod *l = &(chain ? m->lods : m->casters)[k];
        float d = copy_distance(m, ix + l->first, l->count);
        ratio = fmax(ratio, d / l->error);
        print_message("%s %s level %d: the mesh lies within %.4g of it, its error %.4g\n", m->name,
                      chain ? "camera" : "casters", k, (double)d, (double)l->error);
      }
    free(ix);
    if (!strcmp(m->name, "flat sphere")) assert_true(m->caster_levels > 0 && m->lod_levels > 0);
    if (!strcmp(m->name, "sphere")) assert_true(m->index_count / 3 < LM_LOD_MIN_TRIANGLES ? !m->caster_levels && !m->lod_levels
                                                                                         : m->caster_levels && m->lod_levels);
  }
  print_message("the mesh's vertices lie within %.3g times a copy's error of it\n", ratio);
  /* meshoptimizer's error, where its collapses meet the mesh's planes, understates the distance of the
   * vertices it removed: up to 3.14x here (a 36 x 18 sphere's 143-triangle copy). The recorded error is
   * what the draws compare (shadow.simplify, simplify), and the images those allow are bounded apart. */
  assert_true(ratio > 0.5 && ratio <= 3.5);
  lm_scene_destroy(all), lm_scene_destroy(one);

  char path[1024];
  snprintf(path, sizeof path, "%s/../data/scenes/big/big_small.glb", LIMN_TEST_DIR);
  lm_scene *read = lm_scene_load_gpu(path, &err), *whole = lm_scene_load_gltf(path, &err);
  assert_non_null(read);
  assert_non_null(whole);
  assert_true(lm_scene_upload(read, &err) && lm_scene_upload(whole, &err));
  for (int i = 0; i < read->mesh_count; i++) assert_null(read->meshes[i].vertices);
  assert_same_copies(read, whole);
  lm_scene_destroy(read), lm_scene_destroy(whole);
}

/* Three nodes of one terrain (128 x 128 quads: 32768 triangles, 256
 * chunks) side by side under a sun, seen from a camera low over the middle
 * one looking along it, so that most of the terrains lies out of view and
 * out of some cascades: the chunked meshes leave out the chunks outside each
 * view (chunks_culled, fewer triangles) and render the same image as the
 * mesh drawn whole from its own triangle order (the reference: its GPU mesh
 * made again from the mesh's indices, no chunks). The same triangles
 * rasterize alike in any order and any split into draws, so the bound is 0
 * in the G-buffer and the image. (The shadow atlas differs where no pixel
 * reads it: a tile's view reaches beyond its cull volume, where a whole mesh
 * draws and its chunks outside that volume do not.) Every mesh and caster whole
 * (simplify=0, shadow.simplify=0): the chunking of the whole ranges alone. */
static void chunked_meshes_render_as_the_whole_mesh(void **state) {
  (void)state;
  lm_scene *sc[2];
  for (int k = 0; k < 2; k++) {
    lm_scene *s = sc[k] = lm_scene_create("terrains");
    int mesh = terrain_mesh(s, 128), grass = gl_material(s, "grass", 0.3f, 0.5f, 0.2f);
    for (int t = -1; t <= 1; t++) place(s, mesh, grass, 150.0f * (float)t, 0, 0);
    float w[16];
    lm_camera_look_at((float[]){3, 4, 2}, (float[]){0, 0, 0}, w); /* the sun shines down along (-3, -4, -2) */
    for (int c = 0; c < 3; c++) w[12 + c] = 0;
    int sun = lm_scene_add_node(s, "sun", -1, w, -1, -1);
    lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                      .casts_shadows = true, .node = sun});
    lm_camera_look_at((float[]){10, 20, 60}, (float[]){-10, 0, 0}, w);
    int cam = lm_scene_add_node(s, "camera", -1, w, -1, -1);
    lm_scene_add_camera(s, &(lm_camera){.name = "view", .fov_y = glm_rad(50.0f), .znear = 0.1f, .zfar = 200, .node = cam});
    lm_scene_update(s);
  }
  lm_scene_mesh *m = &sc[1]->meshes[0];
  uint32_t *order = memcpy(malloc(sizeof(uint32_t) * (size_t)m->index_count), m->indices,
                           sizeof(uint32_t) * (size_t)m->index_count);
  lm_error err;
  for (int k = 0; k < 2; k++) assert_true(lm_scene_upload(sc[k], &err));
  const lm_scene_mesh *c = &sc[0]->meshes[0];
  assert_int_equal(c->whole_chunks.count, 128 * 128 * 2 / LM_CHUNK_TRIANGLES);
  for (int k = 0, end = 0; k < c->whole_chunks.count; end = c->chunks[k].first + c->chunks[k].count, k++) {
    assert_int_equal(c->chunks[k].first, end); /* the chunks tile the mesh's range */
    assert_true(c->chunks[k].count >= 3 * LM_CHUNK_TRIANGLES && c->chunks[k].count < 6 * LM_CHUNK_TRIANGLES);
    assert_true(k < c->whole_chunks.count - 1 || end + c->chunks[k].count == c->index_count);
  }
  lm_mesh_destroy(&m->gpu); /* the reference: the mesh's own order, one range */
  lm_mesh_create(&m->gpu, m->vertices, m->vertex_count, NULL, order, m->index_count, false);
  m->whole_chunks.count = m->caster_levels = m->lod_levels = 0;
  free(order);
  const char *sets[] = {"simplify=0", "shadow.simplify=0", "ambient=0.05", NULL};
  gl_result a = gl_render_ok(&(gl_run){.scene = sc[0], .tech = "dl+esm", .sets = sets, .width = 128, .height = 96,
                                       .keep_targets = true});
  gl_result b = gl_render_ok(&(gl_run){.scene = sc[1], .tech = "dl+esm", .sets = sets, .width = 128, .height = 96,
                                       .keep_targets = true});
  lm_scene_draw_stats ca = lm_renderer_draw_stats(a.renderer), cb = lm_renderer_draw_stats(b.renderer);
  lm_scene_draw_stats ha = lm_renderer_shadow_draw_stats(a.renderer), hb = lm_renderer_shadow_draw_stats(b.renderer);
  print_message("camera: %ld triangles in %d calls chunked (%d chunks left out), %ld in %d whole; shadow tiles: %ld "
                "(%d left out) and %ld\n", ca.triangles, ca.calls, ca.chunks_culled, cb.triangles, cb.calls,
                ha.triangles, ha.chunks_culled, hb.triangles);
  assert_int_equal(ca.drawn, cb.drawn);
  assert_int_equal(cb.chunks_culled, 0);
  assert_true(ca.chunks_culled > 0 && ca.triangles < cb.triangles);
  assert_true(ha.chunks_culled > 0 && ha.triangles < hb.triangles);
  static const char *const targets[] = {"gbuffer.clr", "gbuffer.nrm", "gbuffer.dpt"};
  for (size_t t = 0; t < sizeof targets / sizeof targets[0]; t++) {
    double worst, d = target_diff(&a, &b, targets[t], &worst);
    print_message("%-12s mean difference %.2g of the mean, largest %.3g\n", targets[t], d, worst);
    assert_true(worst == 0);
  }
  int n = a.width * a.height * 3;
  double mean = 0, worst = 0;
  for (int i = 0; i < n; i++) mean += b.rgb[i], worst = fmax(worst, fabs(a.rgb[i] - b.rgb[i]));
  print_message("image: largest difference %.3g (mean %.3g)\n", worst, mean / n);
  assert_true(mean / n > 0.05 && worst == 0);
  gl_result_free(&a), gl_result_free(&b);
  lm_scene_destroy(sc[0]), lm_scene_destroy(sc[1]);
}

/* Deterministic numbers in [0, 1) (a linear congruential generator). */
static float next_unit(uint32_t *seed) {
  *seed = *seed * 1664525u + 1013904223u;
  return (float)(*seed >> 8) / 16777216.0f;
}

/* The GPU's copy of a mesh is quantized (lm_mesh): read back, every position
 * lies within LM_MESH_POSITION_ERROR of the mesh's extent (a box off the
 * origin, 30 units wide), every normal within LM_MESH_NORMAL_ERROR radians
 * (every octant, the axes and the seam of the octahedral map's fold), uvs
 * in [0, 1] within LM_MESH_UV_ERROR and others exactly (they stay floats),
 * indices exactly, in 16 bits below 65536 vertices and 32 above; a mesh that
 * deforms keeps its positions exact. */
static void quantized_vertices_read_back_within_their_error(void **state) {
  (void)state;
  enum { MANY = 70000 };
  float *v = malloc(sizeof(float) * 8 * MANY), *back = malloc(sizeof(float) * 8 * MANY);
  uint32_t *ix = malloc(sizeof(uint32_t) * 3 * MANY), *ix_back = malloc(sizeof(uint32_t) * 3 * MANY);
  static const float axes[8][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                                   {0.6f, 0.8f, 0}, {-0.6f, 0, -0.8f}};
  for (int pass = 0; pass < 3; pass++) {
    int count = pass == 1 ? MANY : 1000;
    bool tiled = pass == 2, deforms = pass == 2; /* pass 2: uvs beyond [0, 1], float positions */
    uint32_t seed = 7u + (uint32_t)pass;
    for (int i = 0; i < count; i++) {
      float *o = v + 8 * (size_t)i, n[3];
      for (int c = 0; c < 3; c++) n[c] = 2 * next_unit(&seed) - 1;
      if (i < 8) memcpy(n, axes[i], sizeof n);
      float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (len < 1e-3f) n[0] = 1, n[1] = n[2] = 0, len = 1;
      o[0] = 100 + 30 * next_unit(&seed), o[1] = -5 + 10 * next_unit(&seed), o[2] = 2 * next_unit(&seed);
      for (int c = 0; c < 3; c++) o[3 + c] = n[c] / len;
      o[6] = next_unit(&seed) * (tiled ? 8 : 1) - (tiled ? 2 : 0), o[7] = i == 9 ? 1.0f : next_unit(&seed);
    }
    for (int i = 0; i < 3 * count; i++) ix[i] = (uint32_t)(next_unit(&seed) * (float)count) % (uint32_t)count;
    ix[0] = (uint32_t)count - 1;
    lm_mesh m;
    lm_mesh_create(&m, v, count, NULL, ix, 3 * count, deforms);
    assert_int_equal(m.short_indices, count <= 65536);
    assert_int_equal(m.float_uvs, tiled);
    assert_int_equal(m.float_positions, deforms);
    lm_mesh_read(&m, back, count, ix_back, 3 * count);
    lm_mesh_destroy(&m);
    assert_memory_equal(ix, ix_back, sizeof *ix * 3 * (size_t)count);
    double position = 0, normal = 0, uv = 0;
    for (int i = 0; i < count; i++) {
      const float *a = v + 8 * (size_t)i, *b = back + 8 * (size_t)i;
      for (int c = 0; c < 3; c++) position = fmax(position, fabs((double)a[c] - b[c]));
      double cx = (double)a[4] * b[5] - (double)a[5] * b[4], cy = (double)a[5] * b[3] - (double)a[3] * b[5],
             cz = (double)a[3] * b[4] - (double)a[4] * b[3], dot = (double)a[3] * b[3] + (double)a[4] * b[4] + (double)a[5] * b[5];
      normal = fmax(normal, atan2(sqrt(cx * cx + cy * cy + cz * cz), dot)); /* the angle, exact when small */
      for (int c = 6; c < 8; c++) uv = fmax(uv, fabs((double)a[c] - b[c]));
    }
    print_message("%d vertices: positions within %.3g (%.3g of the 30-unit extent), normals %.3g rad, uvs %.3g\n",
                  count, position, position / 30, normal, uv);
    assert_true(deforms ? position == 0 : position <= LM_MESH_POSITION_ERROR * 30.0);
    assert_true(normal <= LM_MESH_NORMAL_ERROR);
    assert_true(tiled ? uv == 0 : uv <= LM_MESH_UV_ERROR);
  }
  free(v), free(back), free(ix), free(ix_back);
}

/* The spheres drawn from quantized positions against the same spheres
 * drawn from floats (the mesh made to deform, whose positions stay floats;
 * their normals are quantized alike, within LM_MESH_NORMAL_ERROR, below the
 * G-buffer's own half-float precision), every mesh whole: the G-buffer's
 * normals and the image within 0.1% (mean absolute difference over the
 * mean). */
static void quantized_positions_keep_the_image(void **state) {
  (void)state;
  lm_scene *quantized = nine_scene(false), *floats = nine_scene(false);
  lm_scene_mesh *m = &floats->meshes[1];
  m->rest = memcpy(malloc(sizeof(float) * 8 * (size_t)m->vertex_count), m->vertices, sizeof(float) * 8 * (size_t)m->vertex_count);
  const char *sets[] = {"simplify=0", "shadow.simplify=0", "ambient=0.05", NULL};
  gl_result q = gl_render_ok(&(gl_run){.scene = quantized, .tech = "dl+esm", .sets = sets, .width = 128, .height = 96});
  gl_result f = gl_render_ok(&(gl_run){.scene = floats, .tech = "dl+esm", .sets = sets, .width = 128, .height = 96});
  assert_false(quantized->meshes[1].gpu.float_positions);
  assert_true(floats->meshes[1].gpu.float_positions);
  double worst, dn = target_diff(&q, &f, "gbuffer.nrm", &worst);
  double mean, d = image_diff(&q, &f, &mean);
  print_message("quantized positions: gbuffer.nrm %.3g%% of the mean (largest %.3g), image %.3g%% of the mean (%.3g)\n",
                100 * dn, worst, 100 * d, mean);
  assert_true(mean > 0.05 && d <= 0.001 && dn <= 0.001);
  gl_result_free(&q), gl_result_free(&f);
  lm_scene_destroy(quantized), lm_scene_destroy(floats);
}

/* The RSM views draw the camera's copies, not the casters': a caster copy,
 * made over positions alone, gives each corner one of its faces' normals,
 * and the RSM stores the senders' normals. The held-out loft (boxes: every
 * corner shared by three faces) seen from its `back` view, rsm+esm: with
 * shadow.simplify at its default the image stays within 1% (mean absolute
 * difference over the mean) of the one with every mesh whole (measured 0:
 * the loft's camera copies keep their seams); through the caster copies
 * it was 77% of the mean away, its error against POV-Ray twice the whole's. */
static void rsm_views_keep_their_senders_normals(void **state) {
  (void)state;
  lm_error err;
  char path[1024];
  snprintf(path, sizeof path, "%s/../data/scenes/holdout/loft.glb", LIMN_TEST_DIR);
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  snprintf(path, sizeof path, "%s/../data/scenes/holdout/loft.cams", LIMN_TEST_DIR);
  int n, first = lm_scene_add_camera_list(s, path, &n, &err);
  if (first < 0 || n != 4) fail_msg("%s", first < 0 ? err.msg : "loft.cams: not 4 views");
  lm_camera c = s->cameras[0]; /* its `back` view as camera 0, the one a frame renders */
  s->cameras[0] = s->cameras[first + 3], s->cameras[first + 3] = c;
  const char *whole_sets[] = {"ambient=0", "shadow.simplify=0", NULL}, *simple_sets[] = {"ambient=0", NULL};
  gl_result whole = gl_render_ok(&(gl_run){.scene = s, .tech = "rsm+esm", .sets = whole_sets, .width = 96, .height = 72});
  gl_result simple = gl_render_ok(&(gl_run){.scene = s, .tech = "rsm+esm", .sets = simple_sets, .width = 96, .height = 72});
  int copied = 0; /* meshes with caster copies (made at upload) */
  for (int i = 0; i < s->mesh_count; i++) copied += s->meshes[i].caster_levels > 0;
  int count = whole.width * whole.height * 3;
  double mean = 0;
  for (int i = 0; i < count; i++) mean += whole.rgb[i];
  mean /= count;
  double d = gl_mean_abs_diff(whole.rgb, simple.rgb, count) / mean;
  print_message("loft back: %d meshes with caster copies; image: mean difference %.3g%% of the mean (%.3g)\n", copied,
                100 * d, mean);
  assert_true(copied > 0 && mean > 0.01 && d <= 0.01);
  gl_result_free(&whole), gl_result_free(&simple);
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(instanced_nodes_render_as_the_nodes),
      cmocka_unit_test(simplified_casters_keep_the_shadows),
      cmocka_unit_test(simplified_cone_casters_keep_the_shadows),
      cmocka_unit_test(a_terrain_has_copies_within_a_near_texel),
      cmocka_unit_test(chunked_meshes_render_as_the_whole_mesh),
      cmocka_unit_test(simplified_meshes_keep_the_image),
      cmocka_unit_test(quantized_vertices_read_back_within_their_error),
      cmocka_unit_test(quantized_positions_keep_the_image),
      cmocka_unit_test(copies_are_the_same_on_any_number_of_threads),
      cmocka_unit_test(rsm_views_keep_their_senders_normals),
      cmocka_unit_test(cones_have_camera_copies_that_keep_their_normals),
      cmocka_unit_test(textured_copies_keep_their_uvs),
      cmocka_unit_test(copies_of_closed_meshes_are_closed),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
