/* Spatial chunks of large static meshes: each index range a mesh draws (the
 * mesh whole, each simplified copy) is cut into clusters of triangles that
 * lie near one another, with their own bounds, so that a draw whose view
 * sees only part of a large mesh (a terrain under the camera, a cascade's
 * scrolled strip) leaves the rest out (lm_scene_draw). */
#include "scene/scene_internal.h"

#include <float.h>
#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>

/* Cuts indices[first .. first + count) into chunks of at least
 * LM_CHUNK_TRIANGLES triangles (none when fewer than two would come of it):
 * the triangles sorted along meshoptimizer's space-filling curve over their
 * centres, so that each run of the curve is a compact cluster. Returns how
 * many chunks it wrote to out. */
static int chunk_range(const lm_scene_mesh *m, uint32_t *indices, int first, int count, lm_mesh_chunk *out) {
  int triangles = count / 3, n = triangles / LM_CHUNK_TRIANGLES;
  if (n < 2) return 0;
  uint32_t *sorted = lm_alloc(sizeof *sorted * (size_t)count);
  meshopt_spatialSortTriangles(sorted, indices + first, (size_t)count, m->vertices, (size_t)m->vertex_count,
                               8 * sizeof(float));
  memcpy(indices + first, sorted, sizeof *sorted * (size_t)count);
  free(sorted);
  for (int c = 0; c < n; c++) {
    int a = (int)((long)triangles * c / n), b = (int)((long)triangles * (c + 1) / n);
    lm_mesh_chunk *k = &out[c];
    *k = (lm_mesh_chunk){first + 3 * a, 3 * (b - a), {{FLT_MAX, FLT_MAX, FLT_MAX}, {-FLT_MAX, -FLT_MAX, -FLT_MAX}}};
    for (int i = first + 3 * a; i < first + 3 * b; i++) {
      const float *p = m->vertices + (size_t)indices[i] * 8;
      if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
      for (int j = 0; j < 3; j++) k->bounds[0][j] = fminf(k->bounds[0][j], p[j]), k->bounds[1][j] = fmaxf(k->bounds[1][j], p[j]);
    }
    if (!(k->bounds[0][0] <= k->bounds[1][0])) memcpy(k->bounds, m->bounds, sizeof k->bounds); /* no finite vertex */
  }
  return n;
}

void lm_scene_mesh_chunk(lm_scene_mesh *m, uint32_t *indices) {
  free(m->chunks);
  m->chunks = NULL, m->chunk_count = 0;
  memset(&m->whole_chunks, 0, sizeof m->whole_chunks);
  memset(m->caster_chunks, 0, sizeof m->caster_chunks);
  memset(m->lod_chunks, 0, sizeof m->lod_chunks);
  if (m->rest || m->index_count / 3 < LM_CHUNK_MIN_TRIANGLES) return; /* a deformed mesh's bounds move */
  int cap = m->index_count / 3 / LM_CHUNK_TRIANGLES;
  for (int k = 0; k < m->caster_levels; k++) cap += m->casters[k].count / 3 / LM_CHUNK_TRIANGLES;
  for (int k = 0; k < m->lod_levels; k++) cap += m->lods[k].count / 3 / LM_CHUNK_TRIANGLES;
  m->chunks = lm_alloc(sizeof *m->chunks * (size_t)cap);
  const lm_mesh_lod whole = {0, m->index_count, 0};
  const lm_mesh_lod *ranges[3] = {&whole, m->casters, m->lods};
  lm_chunk_span *spans[3] = {&m->whole_chunks, m->caster_chunks, m->lod_chunks};
  int levels[3] = {1, m->caster_levels, m->lod_levels};
  for (int c = 0; c < 3; c++)
    for (int k = 0; k < levels[c]; k++) {
      int n = chunk_range(m, indices, ranges[c][k].first, ranges[c][k].count, m->chunks + m->chunk_count);
      spans[c][k] = (lm_chunk_span){m->chunk_count, n};
      m->chunk_count += n;
    }
}
