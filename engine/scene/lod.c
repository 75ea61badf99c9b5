/* Simplified copies of the scene's meshes (lm_scene_mesh.casters, .lods),
 * made by meshoptimizer on worker threads while the file is still being
 * read: a job makes one chain of one mesh from the mesh's own vertices and
 * indices, and the context thread, which alone may call GL, creates a
 * mesh's buffers once both its chains are done, in the order the meshes
 * came (lm_scene_upload_mesh, lm_scene_finish_meshes), and takes a job
 * itself where it would wait. A copy depends on its mesh alone, so the
 * buffers are the same whatever the threads' timing. */
#include "scene/scene_internal.h"

#include <float.h>
#include <math.h>
#include <meshoptimizer.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

enum { CASTERS, CAMERA, CHAINS };
#define MAX_THREADS 64

typedef struct lod_job {
  const float *vertices; /* the mesh's own, kept until its buffers are made */
  const uint32_t *indices;
  size_t vertex_count, index_count;
  uint32_t *out; /* the chain's indices, one level after another */
  size_t len;
  lm_mesh_lod lods[LM_LOD_LEVELS]; /* first: within out */
  int levels;
  bool mixes_uvs; /* made over positions where vertices at one position differ in uv */
  float *welded;  /* made over positions: the vertices welded (lm_welded_vertices), the casters' kept for the buffers */
  bool done;
} lod_job;

typedef struct lm_lod_work {
  pthread_mutex_t lock;
  pthread_cond_t wake, done; /* a job queued (or quit), a job done */
  pthread_t threads[MAX_THREADS];
  int thread_count;
  lod_job **jobs;   /* CHAINS a mesh, in the order the meshes came */
  int *meshes;      /* the mesh of each CHAINS jobs */
  int job_count, job_cap, mesh_cap;
  int taken;        /* jobs a worker has begun */
  int collected;    /* jobs whose mesh is on the GPU (the first ones) */
  bool quit;
  double cpu_ms, wait_ms; /* the jobs' CPU time, the context thread's waits */
} lm_lod_work;

/* Whether meshoptimizer can take one edge of the mesh within the coarsest
 * budget. It picks the edges it may collapse by the mesh alone and then
 * takes those within the budget, so if none goes there, none goes within
 * any level's budget, and no level can be made. */
static bool reducible(uint32_t *to, const uint32_t *from, size_t n, const float *vertices, size_t nv, size_t stride) {
  float coarsest = LM_LOD_ERROR * powf(4, LM_LOD_LEVELS - 1);
  return meshopt_simplify(to, from, n, vertices, nv, stride, n / 4, coarsest, 0, NULL) < n;
}

/* Whether no vertex is shared by two triangles: a mesh flat-shaded as exporters write one, every vertex
 * a seam, of which copies that keep the seams (the camera's) can seldom be made: worth asking first. */
static bool each_vertex_once(const uint32_t *indices, size_t n, size_t nv) {
  unsigned char *seen = calloc(nv > 0 ? nv : 1, 1);
  size_t i = 0;
  for (; i < n && indices[i] < nv && !seen[indices[i]]; i++) seen[indices[i]] = 1;
  free(seen);
  return i == n;
}

/* A camera copy made over positions alone shades with a vertex of the mesh at each corner of its faces:
 * one whose normal lies within acos(LOD_NORMAL_COS), 60 degrees, of its face's (corners_by_normal). */
#define LOD_NORMAL_COS 0.5f

/* Writes the corners of a copy's faces (to: its indices over the distinct positions, kept of them) into
 * copy, each the vertex at its position (members[start[p] .. start[p + 1])) whose normal lies nearest the
 * face's (as its winding gives it): where the mesh splits a position by normal (a cone's tip, a
 * flat-shaded box), the face keeps its own. False when a corner has none within LOD_NORMAL_COS of its
 * face (a face turned over, or across an edge of the mesh): no copy to shade with. */
static bool corners_by_normal(const float *mesh, const float *positions, const uint32_t *to, size_t kept,
                              const uint32_t *start, const uint32_t *members, uint32_t *copy) {
  for (size_t t = 0; t + 2 < kept; t += 3) {
    const float *a = positions + (size_t)to[t] * 8, *b = positions + (size_t)to[t + 1] * 8,
                *c = positions + (size_t)to[t + 2] * 8;
    float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    float f[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    float len = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (!(len > 0)) continue; /* no area: it draws nothing */
    for (int k = 0; k < 3; k++) {
      uint32_t p = to[t + k];
      float most = -INFINITY;
      for (uint32_t i = start[p]; i < start[p + 1]; i++) {
        const float *n = mesh + (size_t)members[i] * 8 + 3;
        float d = (n[0] * f[0] + n[1] * f[1] + n[2] * f[2]) / len;
        if (d > most) most = d, copy[t + k] = members[i];
      }
      if (!(most >= LOD_NORMAL_COS)) return false;
    }
  }
  return true;
}

static int u64_cmp(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

bool lm_indices_closed(const uint32_t *indices, int count, const int *weld) {
  int n = count > 0 ? count / 3 * 3 : 0, m = 0;
  uint64_t *edges = lm_alloc(sizeof *edges * (size_t)(n + 1)), *reversed = lm_alloc(sizeof *reversed * (size_t)(n + 1));
  for (int t = 0; t < n; t += 3) {
    uint32_t v[3];
    for (int k = 0; k < 3; k++) v[k] = weld ? (uint32_t)weld[indices[t + k]] : indices[t + k];
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue; /* no area: rasterizes nothing */
    for (int k = 0; k < 3; k++, m++) {
      uint64_t a = v[k], b = v[(k + 1) % 3];
      edges[m] = a << 32 | b, reversed[m] = b << 32 | a;
    }
  }
  qsort(edges, (size_t)m, sizeof *edges, u64_cmp);
  qsort(reversed, (size_t)m, sizeof *reversed, u64_cmp);
  bool closed = !memcmp(edges, reversed, sizeof *edges * (size_t)m);
  free(edges), free(reversed);
  return closed;
}

typedef struct face_key { uint32_t v[3]; } face_key;
static int face_cmp(const void *a, const void *b) { return memcmp(a, b, sizeof(face_key)); }
static face_key face_of(uint32_t a, uint32_t b, uint32_t c) { /* its least corner first, winding kept */
  return a < b && a < c ? (face_key){{a, b, c}} : b < c ? (face_key){{b, c, a}} : (face_key){{c, a, b}};
}

/* Whether some triangle's reverse is among the `count` indices too: a sheet drawn from both sides (a thin
 * box collapsed flat), closed but without volume, whose one side each light sees from behind. */
static bool has_sheet(const uint32_t *indices, size_t count) {
  size_t n = count / 3;
  face_key *faces = lm_alloc(sizeof *faces * (n + 1));
  for (size_t t = 0; t < n; t++) faces[t] = face_of(indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]);
  qsort(faces, n, sizeof *faces, face_cmp);
  bool sheet = false;
  for (size_t t = 0; t < n && !sheet; t++) {
    face_key r = face_of(faces[t].v[0], faces[t].v[2], faces[t].v[1]);
    sheet = bsearch(&r, faces, n, sizeof *faces, face_cmp) != NULL;
  }
  free(faces);
  return sheet;
}

typedef struct weld_key { int32_t p[3]; int i; } weld_key;
static int weld_cmp(const void *a, const void *b) {
  const weld_key *x = a, *y = b;
  int c = memcmp(x->p, y->p, sizeof x->p);
  return c ? c : (x->i > y->i) - (x->i < y->i);
}

/* Positions rounded to 1/65536 of the extent: whole fractions of the extent (its middle: 0 in a mesh
 * about the origin) lie at the middle of a step, not at a rounding edge; a copy rounded to the next step
 * is left apart (an open edge, for lm_indices_closed). */
void lm_weld_positions(const float *vertices, int count, int *weld) {
  int nv = count > 0 ? count : 0;
  weld_key *keys = lm_alloc(sizeof *keys * (size_t)(nv + 1));
  float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX}, extent = 0.0f;
  for (int i = 0; i < nv; i++)
    for (int c = 0; c < 3; c++) {
      float x = vertices[8 * (size_t)i + c];
      if (isfinite(x)) lo[c] = fminf(lo[c], x), hi[c] = fmaxf(hi[c], x);
    }
  for (int c = 0; c < 3; c++) extent = fmaxf(extent, hi[c] - lo[c]);
  float step = extent > 0.0f && isfinite(extent) ? extent / 65536.0f : 1.0f;
  for (int i = 0; i < nv; i++) {
    for (int c = 0; c < 3; c++) {
      float q = floorf((vertices[8 * (size_t)i + c] - lo[c]) / step + 0.5f);
      keys[i].p[c] = isfinite(q) && fabsf(q) < 1e9f ? (int32_t)q : INT32_MIN;
    }
    keys[i].i = i;
  }
  qsort(keys, (size_t)nv, sizeof *keys, weld_cmp);
  for (int i = 0, first = 0; i < nv; i++) {
    if (i == 0 || memcmp(keys[i].p, keys[i - 1].p, sizeof keys[i].p)) first = keys[i].i;
    weld[keys[i].i] = first;
  }
  free(keys);
}

float *lm_welded_vertices(const float *vertices, int count) {
  int nv = count > 0 ? count : 0, *weld = lm_alloc(sizeof *weld * (size_t)(nv + 1));
  float *out = lm_alloc(sizeof *out * 8 * (size_t)(nv + 1));
  memcpy(out, vertices, sizeof *out * 8 * (size_t)nv);
  lm_weld_positions(vertices, nv, weld);
  for (int i = 0; i < nv; i++) memcpy(out + 8 * (size_t)i, vertices + 8 * (size_t)weld[i], sizeof *out * 3);
  free(weld);
  return out;
}

/* Makes up to LM_LOD_LEVELS simplified copies of a mesh into j->out and
 * j->lods, level k within a budget of LM_LOD_ERROR times 4^k of the extent,
 * with at most a quarter of the last kept level's triangles as its target.
 * Every level is made from the mesh itself, erring no less than the finer
 * ones: not from the last copy, whose errors add up, so that its coarse
 * levels recorded more error for as many triangles and nodes drew finer
 * copies (the 64 x 30 sphere of the big scene: 138 triangles recorded at
 * 3.8% of the extent, 34 at 14.1%, against 132 at 3.2% and 33 at 11.3% from
 * the mesh; its moving frames' shadow tiles drew 1.23-1.41x the triangles,
 * for a tenth of two levels' work at load). A level that keeps over 3/4 of
 * the last's triangles is left out. Over positions alone (casters), the mesh is first made of its
 * distinct positions (a seam, vertices that differ only in normal or uv,
 * would stop the simplifier there), each copy's indices then naming one
 * vertex at each position; otherwise the seams stay, and so the normals and
 * uvs the camera sees. by_normal (over positions): each corner of a copy's
 * face takes the vertex at its position whose normal is nearest the face's,
 * a level without one near enough left out (corners_by_normal): the
 * camera's chain where its seams stop the simplifier. */
static void simplify_levels(lod_job *j, bool positions, bool by_normal) {
  size_t n = j->index_count, nv = j->vertex_count, stride = 8 * sizeof(float);
  uint32_t *from = lm_alloc(sizeof *from * n), *to = lm_alloc(sizeof *to * n), *first = NULL;
  uint32_t *start = NULL, *members = NULL; /* by_normal: the vertices at each distinct position */
  const float *vertices = j->vertices;
  float *distinct = NULL;
  if (positions) {
    /* Not meshopt_generateShadowIndexBuffer alone: meshoptimizer (0.18) still sees the vertices its indices
     * no longer use beside the ones they do, and keeps every such seam vertex where it is, so a cone cut as
     * exporters cut it (a tip vertex a side, a ring a side and one for its base) kept all its triangles. */
    uint32_t *remap = lm_alloc(sizeof *remap * (nv > 0 ? nv : 1));
    if (!j->welded) j->welded = lm_welded_vertices(j->vertices, (int)nv);
    struct meshopt_Stream xyz = {j->welded, 3 * sizeof(float), stride};
    size_t unique = meshopt_generateVertexRemapMulti(remap, j->indices, n, nv, &xyz, 1);
    distinct = lm_alloc(stride * (unique > 0 ? unique : 1));
    meshopt_remapVertexBuffer(distinct, j->welded, nv, stride, remap);
    meshopt_remapIndexBuffer(from, j->indices, n, remap);
    first = lm_alloc(sizeof *first * (unique > 0 ? unique : 1));
    for (size_t i = nv; i-- > 0;)
      if (remap[i] != ~0u) first[remap[i]] = (uint32_t)i;
    for (size_t i = 0; i < nv && !j->mixes_uvs; i++) { /* a uv seam: a copy's corner takes one side's uv */
      if (remap[i] == ~0u) continue;
      const float *uv = j->vertices + i * 8 + 6, *other = j->vertices + (size_t)first[remap[i]] * 8 + 6;
      j->mixes_uvs = uv[0] != other[0] || uv[1] != other[1];
    }
    if (by_normal) {
      start = lm_alloc(sizeof *start * (unique + 1)), members = lm_alloc(sizeof *members * (nv > 0 ? nv : 1));
      memset(start, 0, sizeof *start * (unique + 1));
      for (size_t i = 0; i < nv; i++)
        if (remap[i] != ~0u) start[remap[i] + 1]++;
      for (size_t p = 0; p < unique; p++) start[p + 1] += start[p];
      uint32_t *fill = lm_alloc(sizeof *fill * (unique > 0 ? unique : 1));
      memcpy(fill, start, sizeof *fill * unique);
      for (size_t i = 0; i < nv; i++)
        if (remap[i] != ~0u) members[fill[remap[i]]++] = (uint32_t)i;
      free(fill);
    }
    free(remap);
    vertices = distinct, nv = unique;
  } else {
    memcpy(from, j->indices, sizeof *from * n);
  }
  /* Each kept level has at most 3/4 of the last's indices: 2.3 times the mesh's in all. */
  j->out = lm_alloc(sizeof *j->out * (n * 7 / 3 + 1));
  float scale = meshopt_simplifyScale(vertices, nv, stride), error = 0, budget = LM_LOD_ERROR;
  size_t last = n;
  /* A level that removes nothing, or a flat-shaded mesh's camera chain before it: is any level possible? */
  bool probed = !positions && each_vertex_once(from, n, nv);
  /* A closed mesh's caster copies stay closed: a shadow tile whose casters are closed solids holds no face
   * seen from behind (lm_shadow_front_lit), and meshoptimizer may open a thin box (a desk's leg) into
   * sheets, or flatten it into one drawn from both sides; such a level is left out, the next budget tried. */
  bool closed = positions && lm_indices_closed(from, (int)n, NULL);
  int levels = probed && !reducible(to, from, n, vertices, nv, stride) ? 0 : LM_LOD_LEVELS;
  for (int k = 0; k < levels; k++, budget *= 4) { /* a budget too tight for a level: the next one */
    float step = 0; /* meshoptimizer's error, relative to the extent (of every vertex) as its target is */
    size_t kept = meshopt_simplify(to, from, n, vertices, nv, stride, last / 4, budget, 0, &step);
    if (kept == n && !probed && !(probed = true, reducible(to, from, n, vertices, nv, stride))) break;
    if (kept == 0 || kept > last * 3 / 4 || !(step >= 0)) continue;
    uint32_t *copy = j->out + j->len;
    for (size_t i = 0; i < kept; i++) copy[i] = first ? first[to[i]] : to[i];
    if (by_normal && !corners_by_normal(j->vertices, vertices, to, kept, start, members, copy)) continue;
    if (closed && (!lm_indices_closed(to, (int)kept, NULL) || has_sheet(to, kept))) continue;
    error = fmaxf(error, step); /* levels err no less than the finer ones (node_lod walks them so) */
    j->lods[j->levels++] = (lm_mesh_lod){(int)j->len, (int)kept, error * scale};
    j->len += kept, last = kept;
  }
  free(from), free(to), free(first), free(distinct), free(start), free(members);
}

/* Runs the next job not begun; called and returns with w->lock held. */
static void run_next(lm_lod_work *w) {
  int i = w->taken++;
  lod_job *j = w->jobs[i];
  pthread_mutex_unlock(&w->lock);
  double t0 = lm_thread_cpu_ms();
  bool casters = i % CHAINS == CASTERS;
  simplify_levels(j, casters, false);
  if (!casters && j->levels == 0) { /* seams that leave no copy (a cone's tip a side): over positions */
    free(j->out);
    j->out = NULL, j->len = 0;
    simplify_levels(j, true, true);
  }
  double ms = lm_thread_cpu_ms() - t0;
  pthread_mutex_lock(&w->lock);
  j->done = true;
  w->cpu_ms += ms;
  pthread_cond_broadcast(&w->done);
}

static void *worker(void *arg) {
  lm_lod_work *w = arg;
  pthread_mutex_lock(&w->lock);
  for (;;) {
    while (!w->quit && w->taken == w->job_count) pthread_cond_wait(&w->wake, &w->lock);
    if (w->quit) break; /* the jobs not begun are dropped (lm_scene_drop_meshes) */
    run_next(w);
  }
  pthread_mutex_unlock(&w->lock);
  return NULL;
}

/* The end of a mesh's upload, with copies or without: a GPU-only scene frees its CPU copy. */
void lm_scene_mesh_uploaded(lm_scene *s, int i) {
  lm_scene_mesh *m = &s->meshes[i];
  m->dirty = m->simplifying = false;
  if (s->gpu_only && !m->rest) {
    free(m->vertices), free(m->indices);
    m->vertices = NULL, m->indices = NULL;
  }
}

/* The mesh's own indices, then its caster levels, then the camera's, to the GPU. */
static void make_buffers(lm_scene *s, int mesh, lod_job *const jobs[CHAINS]) {
  lm_scene_mesh *m = &s->meshes[mesh];
  size_t n = (size_t)m->index_count, len = n;
  uint32_t *indices = lm_alloc(sizeof *indices * (n + jobs[CASTERS]->len + jobs[CAMERA]->len));
  memcpy(indices, m->indices, sizeof *indices * n);
  lm_mesh_lod *levels[CHAINS] = {m->casters, m->lods};
  int *counts[CHAINS] = {&m->caster_levels, &m->lod_levels};
  m->casters_mix_uvs = jobs[CASTERS]->mixes_uvs, m->lods_mix_uvs = jobs[CAMERA]->mixes_uvs;
  for (int c = 0; c < CHAINS; c++) {
    const lod_job *j = jobs[c];
    memcpy(indices + len, j->out, sizeof *indices * j->len);
    for (int k = 0; k < j->levels; k++) levels[c][k] = j->lods[k], levels[c][k].first += (int)len;
    *counts[c] = j->levels, len += j->len;
  }
  lm_scene_mesh_chunk(m, indices);
  lm_mesh_create(&m->gpu, jobs[CASTERS]->welded, m->vertex_count, m->tangents, indices, (int)len, false);
  free(indices);
  lm_scene_mesh_uploaded(s, mesh);
}

static void free_job(lod_job *j) {
  if (j) free(j->out), free(j->welded);
  free(j);
}

/* Makes the buffers of the meshes whose copies are done, in order, until
 * at most `pending` meshes are left waiting (0: all; waits for them). */
static void collect(lm_scene *s, int pending) {
  lm_lod_work *w = s->lod_work;
  pthread_mutex_lock(&w->lock);
  while (w->collected < w->job_count) {
    lod_job **jobs = w->jobs + w->collected;
    bool done = true;
    for (int c = 0; c < CHAINS; c++) done = done && jobs[c]->done;
    if (!done && (w->job_count - w->collected) / CHAINS <= pending) break;
    if (!done && w->taken < w->job_count) { /* a job not begun: made here rather than waited for */
      run_next(w);
      continue;
    }
    if (!done) {
      double t0 = lm_now_ms();
      pthread_cond_wait(&w->done, &w->lock);
      w->wait_ms += lm_now_ms() - t0;
      continue;
    }
    int mesh = w->meshes[w->collected / CHAINS];
    lod_job *pair[CHAINS] = {jobs[CASTERS], jobs[CAMERA]};
    pthread_mutex_unlock(&w->lock); /* the workers go on while GL takes the buffers */
    make_buffers(s, mesh, pair);
    pthread_mutex_lock(&w->lock);
    for (int c = 0; c < CHAINS; c++) free_job(w->jobs[w->collected + c]), w->jobs[w->collected + c] = NULL;
    w->collected += CHAINS;
  }
  pthread_mutex_unlock(&w->lock);
}

static lm_lod_work *start(void) {
  lm_lod_work *w = lm_alloc(sizeof *w);
  pthread_mutex_init(&w->lock, NULL);
  pthread_cond_init(&w->wake, NULL);
  pthread_cond_init(&w->done, NULL);
  int want = lm_cpu_count() < MAX_THREADS ? lm_cpu_count() : MAX_THREADS;
  for (int i = 0; i < want; i++)
    if (pthread_create(&w->threads[w->thread_count], NULL, worker, w) == 0) w->thread_count++;
  return w;
}

void lm_scene_simplify_mesh(lm_scene *s, int mesh) {
  if (!s->lod_work) s->lod_work = start();
  lm_lod_work *w = s->lod_work;
  const lm_scene_mesh *m = &s->meshes[mesh];
  pthread_mutex_lock(&w->lock);
  int cap = w->mesh_cap;
  w->jobs = lm_grow(w->jobs, &w->job_cap, w->job_count + CHAINS, sizeof *w->jobs);
  w->meshes = lm_grow(w->meshes, &cap, w->job_count / CHAINS + 1, sizeof *w->meshes);
  w->mesh_cap = cap;
  w->meshes[w->job_count / CHAINS] = mesh;
  for (int c = 0; c < CHAINS; c++) {
    lod_job *j = lm_alloc(sizeof *j);
    *j = (lod_job){.vertices = m->vertices, .indices = m->indices, .vertex_count = (size_t)m->vertex_count,
                   .index_count = (size_t)m->index_count};
    w->jobs[w->job_count++] = j;
  }
  pthread_cond_broadcast(&w->wake);
  pthread_mutex_unlock(&w->lock);
  /* Meshes waiting keep their CPU copies: a few a worker keep every worker busy and the memory small
   * (none where no thread could start: this thread makes them). */
  collect(s, 2 * w->thread_count);
}

static void stop(lm_scene *s) {
  lm_lod_work *w = s->lod_work;
  pthread_mutex_lock(&w->lock);
  w->quit = true;
  pthread_cond_broadcast(&w->wake);
  pthread_mutex_unlock(&w->lock);
  for (int i = 0; i < w->thread_count; i++) pthread_join(w->threads[i], NULL);
  for (int i = w->collected; i < w->job_count; i++) free_job(w->jobs[i]); /* a scene destroyed half-read */
  pthread_cond_destroy(&w->wake);
  pthread_cond_destroy(&w->done);
  pthread_mutex_destroy(&w->lock);
  free(w->jobs), free(w->meshes), free(w);
  s->lod_work = NULL;
}

void lm_scene_finish_meshes(lm_scene *s) {
  if (!s->lod_work) return;
  lm_lod_work *w = s->lod_work;
  collect(s, 0);
  lm_debug("scene '%s': %d meshes simplified on %d threads and this one: %.0f ms of CPU time, %.0f ms waited for",
           s->name, w->job_count / CHAINS, w->thread_count, w->cpu_ms, w->wait_ms);
  stop(s);
}

void lm_scene_drop_meshes(lm_scene *s) {
  if (s->lod_work) stop(s);
}
