/* trace: a CPU ray tracer over a scene's triangles (no GL), for the hybrid
 * reflections of seed 003 chapter 6: the GPU writes ray origins and
 * directions, the CPU finds what they hit, the GPU lights the hits.
 *
 * The acceleration structure is Embree's (Debian libembree-dev, Embree 3),
 * not the seed's kd-tree (seed 003 lines 1966-1976), which must be rebuilt
 * when anything moves. Each mesh is an Embree scene in its own space, built
 * once however many nodes use it, and each mesh node an instance of it under
 * a top-level scene: when nodes move, lm_trace_update sets their transforms
 * and rebuilds only the top level over the instances (a deformed mesh's own
 * scene is rebuilt at its new pose). Embree's refit of world-space geometry
 * (RTC_BUILD_QUALITY_REFIT) was tried first: Embree 3.13 honours it only in
 * its two-level mode, whose commit took as long as a full build whatever
 * moved. Embree replaced a hand-written binned-SAH BVH; figures against it on
 * the big scene in docs/benchmarks.md ("The ray tracer").
 *
 * Which triangles are kept is decided in the mesh's own space, where moving
 * a node cannot change it: a triangle is kept when its corner indices are in
 * range and its corners (a deformed mesh's at rest) are finite, within what
 * Embree holds (magnitude below 1e18) and with a finite, non-zero cross
 * product. A mesh node is traced when its transform is finite and invertible
 * and puts the mesh within that range; the triangles of a node that is not
 * (a node scaled to zero) are skipped until it is. Skipped triangles are
 * counted in lm_trace_stats.skipped, never an error. A scene of no triangles
 * traces: every ray misses. */
#ifndef LIMN_TRACE_H
#define LIMN_TRACE_H

#include "scene/scene.h"

typedef struct lm_trace lm_trace;

/* A ray: hits at t in (tmin, tmax) along origin + t * dir count (a tmin below
 * 0 counts as 0: Embree finds no hits behind the origin). dir need not
 * be unit length (t is then in its units). A ray with a non-finite origin or
 * direction, a zero direction, or tmax <= tmin misses. tmax may be INFINITY. */
typedef struct lm_trace_ray {
  float origin[3], tmin;
  float dir[3], tmax;
} lm_trace_ray;

/* The nearest hit: tri < 0 for a miss; u, v barycentric (of corners 1, 2). */
typedef struct lm_trace_hit {
  float t, u, v;
  int tri;
} lm_trace_hit;

typedef struct lm_trace_stats {
  int triangles;  /* kept */
  int skipped;    /* degenerate, not finite, or beyond what Embree holds */
  int meshes;     /* meshes with kept triangles: an Embree scene (and BVH) each */
  int instances;  /* mesh nodes instancing them */
  int moved;      /* lm_trace_update: instances moved (their node moved or their mesh deformed) */
  bool refitted;  /* lm_trace_update: updated in place (false: rebuilt) */
  double build_ms;
} lm_trace_stats;

/* What a hit sees, for the hit record the GPU lights. */
typedef struct lm_trace_surface {
  float position[3]; /* origin + t * dir */
  float normal[3];   /* interpolated vertex normal, world space, unit, facing the ray */
  float uv[2];
  int node;          /* scene node of the triangle (its material: lm_scene_node_material); -1 for triangles given directly */
  int prim;          /* the triangle's index in its mesh, or in the array given */
} lm_trace_surface;

/* Builds over every mesh node of `s` (world transforms as lm_scene_update left
 * them). Never fails for bad geometry; stats may be NULL. `s` must outlive the
 * tracer: lm_trace_surface_at reads its meshes' normals and texture
 * coordinates. Embree's build threads: one an online core. */
lm_trace *lm_trace_create(const lm_scene *s, lm_trace_stats *stats);
/* Builds over `count` triangles given as 9 floats each (three corners). */
lm_trace *lm_trace_create_triangles(const float *xyz, int count, lm_trace_stats *stats);
/* After nodes moved or meshes deformed: moves the instances of those that
 * did (stats->refitted) when `s` has the same mesh nodes over meshes of the
 * same sizes, else rebuilds. Meshes other than deformed ones are taken to be
 * as they were built. */
void lm_trace_update(lm_trace *t, const lm_scene *s, lm_trace_stats *stats);
/* Releases the structure and its Embree device (and so the device's threads). */
void lm_trace_destroy(lm_trace *t);

/* The nearest hit of one ray; false (hit->tri = -1) when it misses. */
bool lm_trace_intersect(const lm_trace *t, const lm_trace_ray *ray, lm_trace_hit *hit);
/* Traces rays[0 .. count) into hits[0 .. count) on `threads` threads (<= 0:
 * every online core). Threads take chunks of consecutive rays from a shared
 * counter (seed 003 lines 2035-2046 use a queue of 40x40-pixel tiles; callers
 * with image-ordered rays get coherent chunks the same way). */
void lm_trace_rays(const lm_trace *t, const lm_trace_ray *rays, lm_trace_hit *hits, int count, int threads);
/* The surface at a hit (hit->tri >= 0). */
void lm_trace_surface_at(const lm_trace *t, const lm_trace_ray *ray, const lm_trace_hit *hit,
                         lm_trace_surface *out);

#endif
