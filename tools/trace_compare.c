/* The tracer's hand-written BVH (engine/trace) against Embree on one scene:
 * build time, rays a second and refit time, with the same triangles and
 * rays, on the same threads; the figures engine/trace/trace.h quotes.
 *
 *   build/trace_compare data/scenes/big/big.glb [THREADS]
 *
 * Rays: 800x450 camera rays from above one corner of the scene's bounds
 * towards its centre (coherent), and as many from random points in the
 * bounds in random directions (incoherent, as reflections off rough
 * surfaces are). Refit: every mesh node moved by 1% of the scene's size.
 * Each figure the median of 3 runs, wall clock (CLOCK_MONOTONIC); the two
 * must agree on which rays hit and where (a count of the rays that do not). */
#define _POSIX_C_SOURCE 200809L
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf.h"
#include "trace/trace.h"

enum { RUNS = 3, WIDTH = 800, HEIGHT = 450, CHUNK = 256 };

/* Every mesh node's triangles in world space, 9 floats each. */
static float *world_triangles(const lm_scene *s, int *count) {
  size_t n = 0;
  for (int i = 0; i < s->node_count; i++)
    if (s->nodes[i].mesh >= 0) n += (size_t)s->meshes[s->nodes[i].mesh].index_count / 3;
  float *xyz = malloc((n * 9 + 4) * sizeof(float)), *o = xyz; /* Embree reads 16 bytes of the last corner */
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *node = &s->nodes[i];
    if (node->mesh < 0) continue;
    const lm_scene_mesh *m = &s->meshes[node->mesh];
    for (int k = 0; k < m->index_count; k++, o += 3) {
      const float *p = &m->vertices[(size_t)m->indices[k] * 8], *w = node->world;
      for (int c = 0; c < 3; c++) o[c] = w[c] * p[0] + w[4 + c] * p[1] + w[8 + c] * p[2] + w[12 + c];
    }
  }
  *count = (int)n;
  return xyz;
}

static float uniform(unsigned *state) { return (float)rand_r(state) / (float)RAND_MAX; }

static void make_rays(const lm_scene *s, lm_trace_ray *coherent, lm_trace_ray *incoherent, int n) {
  float lo[3], hi[3], centre[3], eye[3], size = 0;
  lm_scene_bounds(s, lo, hi);
  for (int k = 0; k < 3; k++) centre[k] = (lo[k] + hi[k]) / 2, size = fmaxf(size, hi[k] - lo[k]);
  eye[0] = lo[0], eye[1] = hi[1] + 0.25f * size, eye[2] = lo[2];
  float f[3], r[3], u[3], up[3] = {0, 1, 0};
  for (int k = 0; k < 3; k++) f[k] = centre[k] - eye[k];
  float fl = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (int k = 0; k < 3; k++) f[k] /= fl;
  r[0] = f[1] * up[2] - f[2] * up[1], r[1] = f[2] * up[0] - f[0] * up[2], r[2] = f[0] * up[1] - f[1] * up[0];
  float rl = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int k = 0; k < 3; k++) r[k] /= rl;
  u[0] = r[1] * f[2] - r[2] * f[1], u[1] = r[2] * f[0] - r[0] * f[2], u[2] = r[0] * f[1] - r[1] * f[0];
  float half = tanf(0.5f * 60 * 3.14159265f / 180);
  for (int y = 0, i = 0; y < HEIGHT; y++)
    for (int x = 0; x < WIDTH; x++, i++) {
      float sx = (2 * (x + 0.5f) / WIDTH - 1) * half * WIDTH / HEIGHT, sy = (1 - 2 * (y + 0.5f) / HEIGHT) * half;
      lm_trace_ray *ray = &coherent[i];
      for (int k = 0; k < 3; k++) ray->origin[k] = eye[k], ray->dir[k] = f[k] + sx * r[k] + sy * u[k];
      ray->tmin = 0, ray->tmax = INFINITY;
    }
  unsigned state = 1;
  for (int i = 0; i < n; i++) {
    lm_trace_ray *ray = &incoherent[i];
    float z = 2 * uniform(&state) - 1, a = 2 * 3.14159265f * uniform(&state), rr = sqrtf(fmaxf(0, 1 - z * z));
    for (int k = 0; k < 3; k++) ray->origin[k] = lo[k] + (hi[k] - lo[k]) * uniform(&state);
    ray->dir[0] = rr * cosf(a), ray->dir[1] = z, ray->dir[2] = rr * sinf(a);
    ray->tmin = 1e-4f * size, ray->tmax = INFINITY;
  }
}

typedef struct embree_job {
  RTCScene scene;
  const lm_trace_ray *rays;
  lm_trace_hit *hits;
  int count;
  atomic_int next;
} embree_job;

static void *embree_worker(void *arg) {
  embree_job *j = arg;
  struct RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (int at; (at = atomic_fetch_add(&j->next, CHUNK)) < j->count;)
    for (int i = at; i < at + CHUNK && i < j->count; i++) {
      const lm_trace_ray *r = &j->rays[i];
      struct RTCRayHit rh = {.ray = {.org_x = r->origin[0], .org_y = r->origin[1], .org_z = r->origin[2],
                                     .tnear = r->tmin, .dir_x = r->dir[0], .dir_y = r->dir[1], .dir_z = r->dir[2],
                                     .tfar = r->tmax, .mask = 0xffffffffu},
                             .hit = {.geomID = RTC_INVALID_GEOMETRY_ID}};
      rtcIntersect1(j->scene, &context, &rh);
      bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      j->hits[i] = (lm_trace_hit){.t = hit ? rh.ray.tfar : INFINITY, .u = rh.hit.u, .v = rh.hit.v,
                                  .tri = hit ? (int)rh.hit.primID : -1};
    }
  return NULL;
}

static void embree_rays(RTCScene scene, const lm_trace_ray *rays, lm_trace_hit *hits, int count, int threads) {
  embree_job j = {.scene = scene, .rays = rays, .hits = hits, .count = count};
  pthread_t t[64];
  for (int i = 1; i < threads; i++) pthread_create(&t[i], NULL, embree_worker, &j);
  embree_worker(&j);
  for (int i = 1; i < threads; i++) pthread_join(t[i], NULL);
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median3(double *v) {
  qsort(v, RUNS, sizeof *v, cmp_double);
  return v[RUNS / 2];
}

/* Rays where one hits and the other misses, or where the distances differ by more than 1e-4 relative. */
static int disagreements(const lm_trace_hit *a, const lm_trace_hit *b, int n) {
  int bad = 0;
  for (int i = 0; i < n; i++)
    bad += (a[i].tri < 0) != (b[i].tri < 0) || (a[i].tri >= 0 && fabsf(a[i].t - b[i].t) > 1e-4f * fmaxf(1, a[i].t));
  return bad;
}

/* Embree's triangle geometry over xyz: shared vertex buffer, indices 0, 1, 2, ... */
static RTCGeometry embree_geometry(RTCDevice device, float *xyz, int count, unsigned *indices) {
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, xyz, 0, 3 * sizeof(float),
                             (size_t)count * 3);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices, 0, 3 * sizeof(unsigned),
                             (size_t)count);
  rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_REFIT); /* kept for the refit; the first commit builds */
  rtcCommitGeometry(g);
  return g;
}

int main(int argc, char **argv) {
  if (argc < 2 || argc > 3) {
    fprintf(stderr, "usage: trace_compare SCENE.glb [THREADS]\n");
    return 2;
  }
  int threads = argc == 3 ? atoi(argv[2]) : 2;
  if (threads < 1 || threads > 64) threads = 2;
  lm_error err;
  lm_scene *s = lm_scene_load(argv[1], &err);
  if (!s) {
    fprintf(stderr, "trace_compare: %s\n", err.msg);
    return 2;
  }
  char config[32];
  snprintf(config, sizeof config, "threads=%d", threads);
  RTCDevice device = rtcNewDevice(config);
  int n = WIDTH * HEIGHT, count = 0;
  lm_trace_ray *rays[2] = {malloc(sizeof(lm_trace_ray) * (size_t)n), malloc(sizeof(lm_trace_ray) * (size_t)n)};
  lm_trace_hit *mine = malloc(sizeof(lm_trace_hit) * (size_t)n), *theirs = malloc(sizeof(lm_trace_hit) * (size_t)n);
  make_rays(s, rays[0], rays[1], n);

  double build[2][RUNS], trace[2][2][RUNS], refit[2][RUNS];
  lm_trace_stats stats = {0};
  lm_trace *t = NULL;
  float *xyz = NULL;
  unsigned *indices = NULL;
  RTCScene scene = NULL;
  for (int run = 0; run < RUNS; run++) {
    if (t) lm_trace_destroy(t);
    double t0 = lm_now_ms();
    t = lm_trace_create(s, &stats);
    build[0][run] = lm_now_ms() - t0;
    if (scene) rtcReleaseScene(scene);
    free(xyz), free(indices);
    t0 = lm_now_ms();
    xyz = world_triangles(s, &count);
    indices = malloc(sizeof(unsigned) * 3 * (size_t)count);
    for (unsigned i = 0; i < 3u * (unsigned)count; i++) indices[i] = i;
    scene = rtcNewScene(device);
    RTCGeometry g = embree_geometry(device, xyz, count, indices);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    build[1][run] = lm_now_ms() - t0;
  }
  int bad[2];
  for (int set = 0; set < 2; set++) {
    for (int run = 0; run < RUNS; run++) {
      double t0 = lm_now_ms();
      lm_trace_rays(t, rays[set], mine, n, threads);
      double t1 = lm_now_ms();
      embree_rays(scene, rays[set], theirs, n, threads);
      trace[0][set][run] = t1 - t0, trace[1][set][run] = lm_now_ms() - t1;
    }
    bad[set] = disagreements(mine, theirs, n);
  }
  /* Refit: every mesh node moved, then each structure brought up to date. */
  float lo[3], hi[3];
  lm_scene_bounds(s, lo, hi);
  float step = 0.01f * fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
  int refits = 0, kept = stats.triangles;
  for (int run = 0; run < RUNS; run++) {
    for (int i = 0; i < s->node_count; i++)
      if (s->nodes[i].mesh >= 0) s->nodes[i].world[12] += step;
    double t0 = lm_now_ms();
    lm_trace_update(t, s, &stats);
    refit[0][run] = lm_now_ms() - t0;
    refits += stats.refitted;
    t0 = lm_now_ms();
    int again;
    float *moved = world_triangles(s, &again);
    memcpy(xyz, moved, sizeof(float) * 9 * (size_t)count);
    free(moved);
    RTCGeometry g = rtcGetGeometry(scene, 0);
    rtcUpdateGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(g);
    rtcCommitScene(scene);
    refit[1][run] = lm_now_ms() - t0;
  }
  double after[2][RUNS];
  for (int run = 0; run < RUNS; run++) {
    double t0 = lm_now_ms();
    lm_trace_rays(t, rays[1], mine, n, threads);
    double t1 = lm_now_ms();
    embree_rays(scene, rays[1], theirs, n, threads);
    after[0][run] = t1 - t0, after[1][run] = lm_now_ms() - t1;
  }
  int bad_after = disagreements(mine, theirs, n);

  printf("%s: %d triangles (%d kept by engine/trace), %d threads, medians of %d runs, wall clock "
         "(CLOCK_MONOTONIC)\n", argv[1], count, kept, threads, RUNS);
  printf("  %-34s %14s %14s %8s\n", "", "engine/trace", "Embree 3", "ratio");
  double b0 = median3(build[0]), b1 = median3(build[1]);
  printf("  %-34s %11.1f ms %11.1f ms %8.2f\n", "build (from the scene's nodes)", b0, b1, b0 / b1);
  const char *names[2] = {"coherent rays (800x450 camera)", "incoherent rays (random)"};
  for (int set = 0; set < 2; set++) {
    double m0 = median3(trace[0][set]), m1 = median3(trace[1][set]);
    printf("  %-34s %8.2f Mray/s %8.2f Mray/s %8.2f   (%d of %d rays disagree)\n", names[set], n / m0 * 1e-3,
           n / m1 * 1e-3, m1 / m0, bad[set], n);
  }
  double r0 = median3(refit[0]), r1 = median3(refit[1]);
  printf("  %-34s %11.1f ms %11.1f ms %8.2f   (engine/trace refitted %d of %d times, else rebuilt; %d -> %d "
         "triangles kept)\n", "refit after every node moved", r0, r1, r0 / r1, refits, RUNS, kept, stats.triangles);
  double a0 = median3(after[0]), a1 = median3(after[1]);
  printf("  %-34s %8.2f Mray/s %8.2f Mray/s %8.2f   (%d of %d rays disagree)\n", "incoherent rays after the refit",
         n / a0 * 1e-3, n / a1 * 1e-3, a1 / a0, bad_after, n);
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  lm_trace_destroy(t);
  free(xyz), free(indices), free(rays[0]), free(rays[1]), free(mine), free(theirs);
  lm_scene_destroy(s);
  return 0;
}
