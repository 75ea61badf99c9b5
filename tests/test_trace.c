/* The CPU ray tracer (engine/trace, on Embree): it finds what brute force
 * finds, bad geometry and bad rays are skipped, a mirror shows the object its
 * mirror image predicts, moved nodes are refitted (not rebuilt) and then find
 * what a fresh build finds. No GL needed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "trace/trace.h"

/* A small deterministic generator, so that failures reproduce. */
static uint32_t rng_state = 12345;
static float rnd(void) {
  rng_state = rng_state * 1664525u + 1013904223u;
  return (float)(rng_state >> 8) / 16777216.0f;
}

/* Nearest hit over every triangle, in double precision: the reference. */
static double brute_nearest(const float *xyz, int count, const lm_trace_ray *r, int *which) {
  double best = r->tmax;
  *which = -1;
  for (int i = 0; i < count; i++) {
    const float *c = xyz + i * 9;
    double e1[3], e2[3], s[3], p[3], q[3], d[3];
    for (int k = 0; k < 3; k++)
      e1[k] = c[3 + k] - c[k], e2[k] = c[6 + k] - c[k], s[k] = r->origin[k] - c[k], d[k] = r->dir[k];
    p[0] = d[1] * e2[2] - d[2] * e2[1], p[1] = d[2] * e2[0] - d[0] * e2[2], p[2] = d[0] * e2[1] - d[1] * e2[0];
    double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (fabs(det) < 1e-300) continue;
    double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    q[0] = s[1] * e1[2] - s[2] * e1[1], q[1] = s[2] * e1[0] - s[0] * e1[2], q[2] = s[0] * e1[1] - s[1] * e1[0];
    double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    if (u < 0 || v < 0 || u + v > 1 || t <= r->tmin || t >= best) continue;
    best = t, *which = i;
  }
  return best;
}

static void bvh_agrees_with_brute_force(void **state) {
  (void)state;
  enum { TRIS = 3000, RAYS = 4000 };
  float *xyz = malloc(TRIS * 9 * sizeof(float));
  for (int i = 0; i < TRIS; i++) { /* small triangles in a unit cube, some long slivers */
    float c[3] = {rnd(), rnd(), rnd()}, size = i % 10 == 0 ? 0.5f : 0.04f;
    for (int v = 0; v < 3; v++)
      for (int k = 0; k < 3; k++) xyz[i * 9 + v * 3 + k] = c[k] + (rnd() - 0.5f) * size;
  }
  lm_trace_stats st;
  lm_trace *t = lm_trace_create_triangles(xyz, TRIS, &st);
  assert_int_equal(st.triangles, TRIS);
  assert_int_equal(st.skipped, 0);
  assert_int_equal(st.meshes, 1); /* triangles given directly: one mesh, one instance */
  assert_int_equal(st.instances, 1);
  lm_trace_ray *rays = malloc(RAYS * sizeof *rays);
  lm_trace_hit *hits = malloc(RAYS * sizeof *hits);
  for (int i = 0; i < RAYS; i++) {
    float o[3] = {rnd() * 1.2f - 0.1f, rnd() * 1.2f - 0.1f, rnd() * 1.2f - 0.1f};
    float d[3] = {rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f};
    if (i % 7 == 0) d[i % 3] = 0, d[(i + 1) % 3] = 0, d[(i + 2) % 3] = 1; /* axis-aligned: zero components */
    rays[i] = (lm_trace_ray){{o[0], o[1], o[2]}, 0, {d[0], d[1], d[2]}, i % 5 == 0 ? 0.3f : INFINITY};
  }
  lm_trace_rays(t, rays, hits, RAYS, 2);
  int hit_count = 0;
  for (int i = 0; i < RAYS; i++) {
    int which;
    double want = brute_nearest(xyz, TRIS, &rays[i], &which);
    lm_trace_hit one;
    bool hit = lm_trace_intersect(t, &rays[i], &one);
    assert_int_equal(hit, which >= 0);
    assert_int_equal(one.tri, hits[i].tri); /* threads find what one ray alone finds */
    if (!hit) continue;
    hit_count++;
    /* the same distance (a different triangle only where two lie as near) */
    assert_true(fabs(one.t - want) <= 1e-4 * (1 + want));
    lm_trace_surface s;
    lm_trace_surface_at(t, &rays[i], &one, &s);
    if (s.prim != which) {
      int other;
      lm_trace_ray only = rays[i];
      only.tmax = (float)want * 1.001f + 1e-6f;
      brute_nearest(xyz + s.prim * 9, 1, &only, &other);
      assert_int_equal(other, 0);
    }
    assert_true(fabsf(s.normal[0] * s.normal[0] + s.normal[1] * s.normal[1] + s.normal[2] * s.normal[2] - 1) < 1e-4f);
  }
  print_message("%d of %d rays hit\n", hit_count, RAYS);
  assert_true(hit_count > RAYS / 4); /* the comparison covered hits, not only misses */
  free(rays), free(hits), free(xyz);
  lm_trace_destroy(t);
}

static void empty_scenes_trace(void **state) {
  (void)state;
  lm_trace_stats st;
  lm_trace *t = lm_trace_create_triangles(NULL, 0, &st);
  assert_int_equal(st.triangles, 0);
  lm_trace_ray r = {{0, 0, 0}, 0, {0, 0, -1}, INFINITY};
  lm_trace_hit h;
  assert_false(lm_trace_intersect(t, &r, &h));
  assert_int_equal(h.tri, -1);
  lm_trace_hit hs[600];
  lm_trace_ray rs[600];
  for (int i = 0; i < 600; i++) rs[i] = r;
  lm_trace_rays(t, rs, hs, 600, 0);
  for (int i = 0; i < 600; i++) assert_int_equal(hs[i].tri, -1);
  lm_trace_destroy(t);

  lm_scene *s = lm_scene_create("empty");
  lm_scene_update(s);
  t = lm_trace_create(s, &st);
  assert_int_equal(st.triangles, 0);
  assert_false(lm_trace_intersect(t, &r, &h));
  lm_trace_update(t, s, &st);
  assert_true(st.refitted);
  assert_false(lm_trace_intersect(t, &r, &h));
  lm_trace_destroy(t);
  lm_scene_destroy(s);
}

static void degenerate_triangles_are_skipped(void **state) {
  (void)state;
  const float nan = NAN, inf = INFINITY;
  const float bad[][9] = {
      {0, 0, 0, 0, 0, 0, 0, 0, 0},        /* a point */
      {0, 0, 0, 1, 1, 1, 2, 2, 2},        /* collinear */
      {0, 0, 0, 1, 0, 0, 1, 0, 0},        /* two corners the same */
      {nan, 0, 0, 1, 0, 0, 0, 1, 0},      /* NaN */
      {0, 0, 0, inf, 0, 0, 0, 1, 0},      /* Inf */
      {0, 0, 0, 3e38f, 0, 0, 0, 3e38f, 0}, /* finite corners, area overflows */
      {-3e38f, 0, 0, 3e38f, 0, 0, 0, 1, 0}, /* an edge overflows */
  };
  int n = sizeof bad / sizeof bad[0];
  lm_trace_stats st;
  lm_trace *t = lm_trace_create_triangles(&bad[0][0], n, &st);
  assert_int_equal(st.triangles, 0);
  assert_int_equal(st.skipped, n);
  lm_trace_ray r = {{0.2f, 0.2f, 1}, 0, {0, 0, -1}, INFINITY};
  lm_trace_hit h;
  assert_false(lm_trace_intersect(t, &r, &h));
  lm_trace_destroy(t);

  /* the same with one good triangle among them: it alone is hit */
  float mixed[8][9];
  memcpy(mixed, bad, sizeof bad);
  const float good[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  memcpy(mixed[n], good, sizeof good);
  t = lm_trace_create_triangles(&mixed[0][0], n + 1, &st);
  assert_int_equal(st.triangles, 1);
  assert_true(lm_trace_intersect(t, &r, &h));
  assert_float_equal(h.t, 1, 1e-6);
  lm_trace_surface s;
  lm_trace_surface_at(t, &r, &h, &s);
  assert_int_equal(s.prim, n);
  assert_float_equal(s.normal[2], 1, 1e-6); /* facing the ray */

  /* bad rays miss without a fault */
  const lm_trace_ray rays[] = {
      {{nan, 0, 1}, 0, {0, 0, -1}, INFINITY}, {{0.2f, 0.2f, 1}, 0, {0, 0, 0}, INFINITY},
      {{0.2f, 0.2f, 1}, 0, {0, 0, inf}, INFINITY}, {{0.2f, 0.2f, 1}, 2, {0, 0, -1}, 1},
      {{0.2f, 0.2f, 1}, nan, {0, 0, -1}, INFINITY}, {{0.2f, 0.2f, 1}, 0, {0, 0, -1}, nan},
      {{0.2f, 0.2f, 1}, 0, {0, 0, -1e-38f}, INFINITY}, /* tiny but fine: still hits */
  };
  for (int i = 0; i < 7; i++) assert_int_equal(lm_trace_intersect(t, &rays[i], &h), i == 6);
  lm_trace_destroy(t);
}

static void translate_scale(float m[16], float x, float y, float z, float sx, float sy, float sz) {
  memset(m, 0, 16 * sizeof(float));
  m[0] = sx, m[5] = sy, m[10] = sz, m[15] = 1;
  m[12] = x, m[13] = y, m[14] = z;
}

/* Gives node its local matrix m and updates the scene and the tracer (*st). */
static void move_node(lm_scene *s, lm_trace *t, int node, const float m[16], lm_trace_stats *st) {
  memcpy(s->nodes[node].local, m, 16 * sizeof(float));
  lm_scene_update(s);
  lm_trace_update(t, s, st);
}

/* Node `node` loses its mesh: the tracer rebuilds (no refit) and then holds
 * `triangles`. Frees the tracer and the scene: the tests end with it. */
static void drop_mesh_rebuilds(lm_scene *s, lm_trace *t, int node, int triangles) {
  lm_trace_stats st;
  s->nodes[node].mesh = -1;
  lm_scene_update(s);
  lm_trace_update(t, s, &st);
  assert_false(st.refitted);
  assert_int_equal(st.triangles, triangles);
  lm_trace_destroy(t);
  lm_scene_destroy(s);
}

/* Where the segment from `o` along `d` enters the box lo..hi; -1 when it misses. */
static float slab(const float o[3], const float d[3], const float lo[3], const float hi[3]) {
  float t0 = 0, t1 = INFINITY;
  for (int k = 0; k < 3; k++) {
    if (fabsf(d[k]) < 1e-12f) {
      if (o[k] < lo[k] || o[k] > hi[k]) return -1;
      continue;
    }
    float a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
    t0 = fmaxf(t0, fminf(a, b)), t1 = fminf(t1, fmaxf(a, b));
  }
  return t0 <= t1 ? t0 : -1;
}

/* A mirror (a flat box, top face at y = 0) under a red cube: an eye above
 * looks down at the mirror; each reflected ray must hit the cube exactly where
 * the straight ray from the eye meets the cube's mirror image (y -> -y). */
static void mirror_shows_the_known_object(void **state) {
  (void)state;
  lm_scene *s = lm_scene_create("mirror");
  int box = lm_scene_add_cube(s, "box", 1);
  int mirror_mat = lm_scene_add_material(s, &(lm_material){.name = "mirror", .color = {1, 1, 1}, .kd = 1});
  int red = lm_scene_add_material(s, &(lm_material){.name = "red", .color = {1, 0, 0}, .kd = 1});
  float m[16];
  translate_scale(m, 0, -0.05f, 0, 4, 0.05f, 4); /* top face at y = 0 */
  int mirror_node = lm_scene_add_node(s, "mirror", -1, m, box, mirror_mat);
  const float c[3] = {1.0f, 1.0f, -0.5f}, half[3] = {0.3f, 0.4f, 0.5f};
  translate_scale(m, c[0], c[1], c[2], half[0], half[1], half[2]);
  int cube = lm_scene_add_node(s, "cube", -1, m, box, red);
  lm_scene_update(s);
  lm_trace_stats st;
  lm_trace *t = lm_trace_create(s, &st);
  assert_int_equal(st.triangles, 24);

  const float eye[3] = {-1.5f, 2.0f, 0.5f};
  const float lo[3] = {c[0] - half[0], -c[1] - half[1], c[2] - half[2]};
  const float hi[3] = {c[0] + half[0], -c[1] + half[1], c[2] + half[2]}; /* the mirror image */
  int shown = 0, agree = 0, total = 0;
  for (int j = 0; j < 24; j++)
    for (int i = 0; i < 32; i++) {
      float p[3] = {-2.0f + 4.0f * (i + 0.5f) / 32, 0, -2.0f + 4.0f * (j + 0.5f) / 24};
      float d[3] = {p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]};
      /* the primary ray must find the mirror first (the cube may hide it) */
      lm_trace_ray pr = {{eye[0], eye[1], eye[2]}, 0, {d[0], d[1], d[2]}, INFINITY};
      lm_trace_hit ph;
      assert_true(lm_trace_intersect(t, &pr, &ph));
      lm_trace_surface ps;
      lm_trace_surface_at(t, &pr, &ph, &ps);
      if (ps.node != mirror_node) continue;
      total++;
      assert_float_equal(ps.normal[1], 1, 1e-5);
      /* reflect about the normal, as the GPU's ray pass does */
      lm_trace_ray rr = {{ps.position[0], ps.position[1], ps.position[2]}, 1e-4f, {d[0], -d[1], d[2]}, INFINITY};
      lm_trace_hit rh;
      bool hit = lm_trace_intersect(t, &rr, &rh);
      float te = slab(eye, d, lo, hi);
      bool want = te >= 0;
      if (!hit) {
        agree += !want;
        continue;
      }
      lm_trace_surface rs;
      lm_trace_surface_at(t, &rr, &rh, &rs);
      bool on_cube = rs.node == cube;
      agree += on_cube == want;
      if (!on_cube || !want) continue;
      shown++;
      assert_int_equal(s->nodes[rs.node].material, red);
      /* eye + te d is the image point; its mirror (y -> -y) is where the reflected ray lands */
      float img[3] = {eye[0] + te * d[0], -(eye[1] + te * d[1]), eye[2] + te * d[2]};
      for (int k = 0; k < 3; k++) assert_float_equal(rs.position[k], img[k], 1e-4);
    }
  assert_true(total > 500);
  assert_true(shown > 20);          /* the cube is seen in the mirror */
  assert_true(agree >= total - 2);  /* and only where its image is (grazing edges aside) */

  /* the cube moves: a refit, and the reflection follows it */
  translate_scale(m, -1.0f, 1.0f, -0.5f, half[0], half[1], half[2]);
  move_node(s, t, cube, m, &st);
  assert_true(st.refitted);
  lm_trace_ray down = {{-1.0f, 5, -0.5f}, 0, {0, -1, 0}, INFINITY};
  lm_trace_hit h;
  assert_true(lm_trace_intersect(t, &down, &h));
  assert_float_equal(h.t, 5 - 1.4f, 1e-5);
  down.origin[0] = 1.0f;
  assert_true(lm_trace_intersect(t, &down, &h));
  assert_float_equal(h.t, 5, 1e-5); /* where the cube was: the mirror */

  /* a node gains no mesh but loses one: a rebuild */
  drop_mesh_rebuilds(s, t, cube, 12);
}

/* A sphere of radius 1 from rings x segments quads, each pole quad split as
 * any other: at the north pole one of its two triangles has two corners on
 * the pole (zero area: sin 0 is 0); at the south pole sinf(pi) is -8.7e-8,
 * so those corners differ by a few 1e-8 and the triangles are slivers that
 * a move can flatten (as on the big scene's spheres). Returns the mesh. */
static int add_uv_sphere(lm_scene *s, int rings, int segments) {
  int nv = (rings + 1) * (segments + 1);
  float *v = calloc((size_t)nv * 8, sizeof(float));
  uint32_t *idx = malloc((size_t)rings * segments * 6 * sizeof(uint32_t));
  for (int r = 0; r <= rings; r++)
    for (int g = 0; g <= segments; g++) {
      float th = 3.14159265f * r / rings, ph = 2 * 3.14159265f * g / segments;
      float *p = v + (r * (segments + 1) + g) * 8;
      p[0] = sinf(th) * cosf(ph), p[1] = cosf(th), p[2] = sinf(th) * sinf(ph);
      memcpy(p + 3, p, 3 * sizeof(float));
      p[6] = (float)g / segments, p[7] = (float)r / rings;
    }
  int k = 0;
  for (int r = 0; r < rings; r++)
    for (int g = 0; g < segments; g++) {
      uint32_t a = (uint32_t)(r * (segments + 1) + g), b = a + 1, c = a + (uint32_t)segments + 1, d = c + 1;
      idx[k++] = a, idx[k++] = c, idx[k++] = b, idx[k++] = b, idx[k++] = c, idx[k++] = d;
    }
  int m = lm_scene_add_mesh(s, "sphere", v, nv, idx, k);
  free(v), free(idx);
  return m;
}

/* Hits of the same rays in two structures over the same scene: the same
 * distance, the same triangle unless another lies as near, finite unit normals. */
static int assert_same_hits(const lm_trace *a, const lm_trace *b, const lm_trace_ray *rays, int n) {
  int hits = 0;
  for (int i = 0; i < n; i++) {
    lm_trace_hit ha, hb;
    bool hit = lm_trace_intersect(a, &rays[i], &ha);
    assert_int_equal(hit, lm_trace_intersect(b, &rays[i], &hb));
    if (!hit) continue;
    hits++;
    assert_true(fabsf(ha.t - hb.t) <= 1e-5f * (1 + ha.t));
    lm_trace_surface sa, sb;
    lm_trace_surface_at(a, &rays[i], &ha, &sa);
    lm_trace_surface_at(b, &rays[i], &hb, &sb);
    if (ha.tri != hb.tri) continue; /* a tie at an edge */
    assert_int_equal(sa.node, sb.node);
    assert_int_equal(sa.prim, sb.prim);
    float len = sqrtf(sa.normal[0] * sa.normal[0] + sa.normal[1] * sa.normal[1] + sa.normal[2] * sa.normal[2]);
    assert_true(fabsf(len - 1) < 1e-4f);
  }
  return hits;
}

/* 64 spheres of 1,536 triangles (98,304; the north pole's of zero area
 * skipped, the south pole's slivers kept) sharing one mesh, and a triangle a
 * millionth of a unit across, moved to x = z = 1000 where its world corners
 * would round to one float: each move updates only the nodes that moved,
 * never rebuilds, keeps every triangle, and the updated structure finds what
 * a fresh build of the moved scene finds. */
static void moving_nodes_are_refitted(void **state) {
  (void)state;
  enum { SIDE = 8, RINGS = 24, SEGMENTS = 32, RAYS = 3000 };
  lm_scene *s = lm_scene_create("moving");
  int sphere = add_uv_sphere(s, RINGS, SEGMENTS);
  const float tiny_v[3 * 8] = {0, 0, 0, 0, 1, 0, 0, 0, 1e-6f, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1e-6f, 0, 1, 0, 0, 0};
  const uint32_t tiny_i[3] = {0, 1, 2};
  int tiny = lm_scene_add_mesh(s, "tiny", tiny_v, 3, tiny_i, 3);
  int mat = lm_scene_add_material(s, &(lm_material){.name = "grey", .color = {0.5f, 0.5f, 0.5f}, .kd = 1});
  float m[16];
  for (int i = 0; i < SIDE * SIDE; i++) {
    translate_scale(m, 3.0f * (i % SIDE), 0, 3.0f * (i / SIDE), 1, 1, 1);
    lm_scene_add_node(s, "ball", -1, m, sphere, mat);
  }
  translate_scale(m, 0, 5, 0, 1, 1, 1);
  int tiny_node = lm_scene_add_node(s, "tiny", -1, m, tiny, mat);
  lm_scene_update(s);
  lm_trace_stats st;
  lm_trace *t = lm_trace_create(s, &st);
  int kept = st.triangles;
  assert_int_equal(st.meshes, 2);
  assert_int_equal(st.instances, SIDE * SIDE + 1);
  assert_int_equal(st.skipped, SIDE * SIDE * SEGMENTS); /* each north pole quad's zero-area half */
  assert_int_equal(kept + st.skipped, SIDE * SIDE * RINGS * SEGMENTS * 2 + 1);

  lm_trace_ray *rays = malloc(RAYS * sizeof *rays);
  for (int frame = 1; frame <= 3; frame++) {
    /* frame 1 moves every node, frames 2 and 3 one ball in four (turned and scaled too) */
    int moved = 0;
    for (int i = 0; i < SIDE * SIDE; i++) {
      if (frame > 1 && i % 4 != frame) continue;
      float *l = s->nodes[i].local, a = 0.3f * frame;
      translate_scale(l, 3.0f * (i % SIDE) + 0.2f * frame, 0.1f * frame, 3.0f * (i / SIDE), 1, 1, 1);
      l[0] = cosf(a) * 0.8f, l[2] = -sinf(a) * 0.8f, l[8] = sinf(a) * 1.2f, l[10] = cosf(a) * 1.2f;
      moved++;
    }
    if (frame == 1) {
      translate_scale(m, 1000, 0, 1000, 1, 1, 1);
      memcpy(s->nodes[tiny_node].local, m, sizeof m);
      moved++;
    }
    lm_scene_update(s);
    lm_trace_update(t, s, &st);
    assert_true(st.refitted);
    assert_int_equal(st.moved, moved);
    assert_int_equal(st.triangles, kept);
    lm_trace *fresh = lm_trace_create(s, NULL);
    for (int i = 0; i < RAYS; i++) { /* down onto the grid and across it */
      float o[3] = {rnd() * 3 * SIDE - 1.5f, 3, rnd() * 3 * SIDE - 1.5f};
      float d[3] = {rnd() - 0.5f, -1, rnd() - 0.5f};
      if (i % 3 == 0) o[1] = rnd() * 2 - 1, d[1] = rnd() * 0.2f - 0.1f;
      rays[i] = (lm_trace_ray){{o[0], o[1], o[2]}, 0, {d[0], d[1], d[2]}, INFINITY};
    }
    int hits = assert_same_hits(t, fresh, rays, RAYS);
    assert_true(hits > RAYS / 3);
    lm_trace_destroy(fresh);
    /* straight down onto a ball's top, beside its pole, where its node now puts it */
    for (int i = 0; i < SIDE * SIDE; i += 9) {
      const float *w = s->nodes[i].world;
      lm_trace_ray down = {{w[12] + 0.01f, 10, w[14] + 0.013f}, 0, {0, -1, 0}, INFINITY};
      lm_trace_hit h;
      assert_true(lm_trace_intersect(t, &down, &h));
      assert_float_equal(h.t, 10 - (w[13] + 1), 0.01); /* within the top ring's cap height */
    }
  }
  free(rays);
  lm_trace_destroy(t);
  lm_scene_destroy(s);
}

/* Bad geometry in a scene: a mesh with a good triangle, a zero-area one, one
 * with a NaN corner and one with an index out of range, on nodes placed
 * normally, scaled to nothing, beyond Embree's range and with a NaN
 * transform. Only the good triangle of the normal node is traced; the others
 * are skipped until their nodes come back (in place, no rebuild); a node
 * scaled to nothing along one axis is not traced. */
static void degenerate_scene_geometry(void **state) {
  (void)state;
  lm_scene *s = lm_scene_create("bad");
  const float nan = NAN;
  float v[6 * 8] = {0};
  const float corners[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {2, 0, 0}, {nan, 0, 0}, {0, 0, 2}};
  for (int i = 0; i < 6; i++) memcpy(v + i * 8, corners[i], sizeof corners[i]), v[i * 8 + 4] = 1;
  /* good; zero area (a corner twice); a NaN corner; an index out of range */
  const uint32_t idx[12] = {0, 2, 1, 0, 1, 1, 4, 1, 2, 0, 1, 9};
  int mesh = lm_scene_add_mesh(s, "bad", v, 6, idx, 12);
  float m[16];
  translate_scale(m, 0, 0, 0, 1, 1, 1);
  int good = lm_scene_add_node(s, "good", -1, m, mesh, -1);
  translate_scale(m, 5, 0, 0, 0, 0, 0);
  int flat = lm_scene_add_node(s, "flat", -1, m, mesh, -1);
  translate_scale(m, 1e19f, 0, 0, 1, 1, 1);
  int far = lm_scene_add_node(s, "far", -1, m, mesh, -1);
  translate_scale(m, nan, 0, 0, 1, 1, 1);
  lm_scene_add_node(s, "nan", -1, m, mesh, -1);
  lm_scene_update(s);
  lm_trace_stats st;
  lm_trace *t = lm_trace_create(s, &st);
  assert_int_equal(st.triangles, 1);         /* good's good triangle */
  assert_int_equal(st.skipped, 4 * 3 + 3);   /* three bad a node; flat's, far's and nan's good one */

  lm_trace_ray down = {{0.2f, 1, 0.2f}, 0, {0, -1, 0}, INFINITY};
  lm_trace_hit h;
  lm_trace_surface sf;
  assert_true(lm_trace_intersect(t, &down, &h));
  assert_float_equal(h.t, 1, 1e-6);
  lm_trace_surface_at(t, &down, &h, &sf);
  assert_int_equal(sf.node, good);
  assert_int_equal(sf.prim, 0);
  assert_float_equal(sf.normal[1], 1, 1e-6);
  lm_trace_ray at_flat = {{5, 1, 0}, 0, {0, -1, 0}, INFINITY};
  assert_false(lm_trace_intersect(t, &at_flat, &h)); /* a point: never hit */

  /* far comes back: traced again, in place */
  translate_scale(m, 0, 0, 5, 1, 1, 1);
  move_node(s, t, far, m, &st);
  assert_true(st.refitted);
  assert_int_equal(st.moved, 1);
  assert_int_equal(st.triangles, 2);
  lm_trace_ray at_far = {{0.2f, 1, 5.2f}, 0, {0, -1, 0}, INFINITY};
  assert_true(lm_trace_intersect(t, &at_far, &h));
  lm_trace_surface_at(t, &at_far, &h, &sf);
  assert_int_equal(sf.node, far);

  /* flat is scaled up: in place, and now it is hit, facing the ray */
  translate_scale(m, 5, 0, 0, 1, 1, 1);
  move_node(s, t, flat, m, &st);
  assert_true(st.refitted);
  assert_int_equal(st.moved, 1);
  at_flat.origin[0] = 5.2f;
  assert_true(lm_trace_intersect(t, &at_flat, &h));
  lm_trace_surface_at(t, &at_flat, &h, &sf);
  assert_int_equal(sf.node, flat);
  assert_float_equal(sf.normal[1], 1, 1e-6);

  assert_int_equal(st.triangles, 3);

  /* scaled to nothing along y (no inverse for its normals): not traced, even where it lies */
  translate_scale(m, 5, 0, 0, 1, 0, 1);
  move_node(s, t, flat, m, &st);
  assert_true(st.refitted);
  assert_int_equal(st.triangles, 2);
  assert_false(lm_trace_intersect(t, &at_flat, &h));

  /* a node loses its mesh: a rebuild */
  drop_mesh_rebuilds(s, t, s->node_count - 1, 2);
}

/* A deformed mesh (one with a rest pose, as lm_scene_set_time poses morph
 * targets and skins): its new pose is traced after an update in place. */
static void deformed_mesh_follows_its_pose(void **state) {
  (void)state;
  lm_scene *s = lm_scene_create("deformed");
  int box = lm_scene_add_cube(s, "box", 1);
  float m[16];
  translate_scale(m, 0, 0, 0, 1, 1, 1);
  lm_scene_add_node(s, "box", -1, m, box, -1);
  lm_scene_add_node(s, "still", -1, m, -1, -1);
  lm_scene_mesh *mesh = &s->meshes[box];
  size_t bytes = (size_t)mesh->vertex_count * 8 * sizeof(float);
  mesh->rest = malloc(bytes); /* freed with the scene */
  memcpy(mesh->rest, mesh->vertices, bytes);
  lm_scene_update(s);
  lm_trace_stats st;
  lm_trace *t = lm_trace_create(s, &st);
  lm_trace_ray down = {{0.2f, 5, 0.3f}, 0, {0, -1, 0}, INFINITY};
  lm_trace_hit h;
  assert_true(lm_trace_intersect(t, &down, &h));
  assert_float_equal(h.t, 4, 1e-5);
  for (int i = 0; i < mesh->vertex_count; i++) mesh->vertices[i * 8 + 1] *= 2; /* the pose: twice as tall */
  lm_trace_update(t, s, &st);
  assert_true(st.refitted);
  assert_int_equal(st.moved, 1);
  assert_true(lm_trace_intersect(t, &down, &h));
  assert_float_equal(h.t, 3, 1e-5);
  lm_trace_destroy(t);
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(bvh_agrees_with_brute_force),
      cmocka_unit_test(empty_scenes_trace),
      cmocka_unit_test(degenerate_triangles_are_skipped),
      cmocka_unit_test(mirror_shows_the_known_object),
      cmocka_unit_test(moving_nodes_are_refitted),
      cmocka_unit_test(degenerate_scene_geometry),
      cmocka_unit_test(deformed_mesh_follows_its_pose),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
