/* The tracer (engine/trace) on one scene: build time, rays a second, and the
 * update after nodes move; the figures docs/benchmarks.md quotes.
 *
 *   build/trace_bench data/scenes/big/big.glb [THREADS]
 *
 * Rays: 800x450 camera rays from above one corner of the scene's bounds
 * towards its centre (coherent), and as many from random points in the
 * bounds in random directions (incoherent, as reflections off rough
 * surfaces are). Updates: every mesh node moved by 1% of the scene's size,
 * then one mesh node in ten; after them the updated structure must find
 * what a fresh build over the moved scene finds (a count of the rays that do
 * not). Each figure the median of 3 runs, wall clock (CLOCK_MONOTONIC). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf.h"
#include "trace/trace.h"

enum { RUNS = 3, WIDTH = 800, HEIGHT = 450 };

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

/* Moves every `every`-th mesh node by `step` along x, then brings t up to date; its time, and stats. */
static double move_and_update(lm_scene *s, lm_trace *t, int every, float step, lm_trace_stats *st) {
  for (int i = 0, k = 0; i < s->node_count; i++)
    if (s->nodes[i].mesh >= 0 && k++ % every == 0) s->nodes[i].world[12] += step;
  double t0 = lm_now_ms();
  lm_trace_update(t, s, st);
  return lm_now_ms() - t0;
}

int main(int argc, char **argv) {
  if (argc < 2 || argc > 3) {
    fprintf(stderr, "usage: trace_bench SCENE.glb [THREADS]\n");
    return 2;
  }
  int threads = argc == 3 ? atoi(argv[2]) : 2;
  if (threads < 1 || threads > 64) threads = 2;
  lm_error err;
  lm_scene *s = lm_scene_load(argv[1], &err);
  if (!s) {
    fprintf(stderr, "trace_bench: %s\n", err.msg);
    return 2;
  }
  int n = WIDTH * HEIGHT;
  lm_trace_ray *rays[2] = {malloc(sizeof(lm_trace_ray) * (size_t)n), malloc(sizeof(lm_trace_ray) * (size_t)n)};
  lm_trace_hit *hits = malloc(sizeof(lm_trace_hit) * (size_t)n), *fresh = malloc(sizeof(lm_trace_hit) * (size_t)n);
  make_rays(s, rays[0], rays[1], n);

  double build[RUNS], trace[2][RUNS];
  lm_trace_stats stats = {0};
  lm_trace *t = NULL;
  for (int run = 0; run < RUNS; run++) {
    lm_trace_destroy(t);
    double t0 = lm_now_ms();
    t = lm_trace_create(s, &stats);
    build[run] = lm_now_ms() - t0;
  }
  for (int set = 0; set < 2; set++)
    for (int run = 0; run < RUNS; run++) {
      double t0 = lm_now_ms();
      lm_trace_rays(t, rays[set], hits, n, threads);
      trace[set][run] = lm_now_ms() - t0;
    }
  float lo[3], hi[3];
  lm_scene_bounds(s, lo, hi);
  float step = 0.01f * fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
  double all[RUNS], tenth[RUNS];
  int refits = 0, moved_all = 0, moved_tenth = 0;
  for (int run = 0; run < RUNS; run++) {
    all[run] = move_and_update(s, t, 1, step, &stats);
    refits += stats.refitted, moved_all = stats.moved;
    tenth[run] = move_and_update(s, t, 10, step, &stats);
    refits += stats.refitted, moved_tenth = stats.moved;
  }
  double after[RUNS], rebuilt[RUNS];
  lm_trace_stats fresh_stats;
  lm_trace *f = lm_trace_create(s, &fresh_stats);
  for (int run = 0; run < RUNS; run++) {
    double t0 = lm_now_ms();
    lm_trace_rays(t, rays[1], hits, n, threads);
    double t1 = lm_now_ms();
    lm_trace_rays(f, rays[1], fresh, n, threads);
    after[run] = t1 - t0, rebuilt[run] = lm_now_ms() - t1;
  }
  int bad = disagreements(hits, fresh, n);

  printf("%s: %d triangles kept (%d skipped), %d meshes as %d instances, %d threads, medians of %d runs, wall "
         "clock (CLOCK_MONOTONIC)\n", argv[1], stats.triangles, stats.skipped, stats.meshes, stats.instances, threads,
         RUNS);
  printf("  %-44s %11.1f ms\n", "build (from the scene's nodes)", median3(build));
  const char *names[2] = {"coherent rays (800x450 camera)", "incoherent rays (random)"};
  for (int set = 0; set < 2; set++)
    printf("  %-44s %8.2f Mray/s\n", names[set], n / median3(trace[set]) * 1e-3);
  printf("  %-44s %11.1f ms   (%d instances moved)\n", "update after every mesh node moved", median3(all),
         moved_all);
  printf("  %-44s %11.1f ms   (%d instances moved)\n", "update after one mesh node in ten moved",
         median3(tenth), moved_tenth);
  printf("  %-44s %8.2f Mray/s   (%d of %d updates in place, else rebuilt)\n", "incoherent rays after the updates",
         n / median3(after) * 1e-3, refits, 2 * RUNS);
  printf("  %-44s %8.2f Mray/s   (%d of %d rays disagree with the updated one)\n",
         "incoherent rays, fresh build of the moved scene", n / median3(rebuilt) * 1e-3, bad, n);
  lm_trace_destroy(f);
  lm_trace_destroy(t);
  free(rays[0]), free(rays[1]), free(hits), free(fresh);
  lm_scene_destroy(s);
  return bad != 0;
}
