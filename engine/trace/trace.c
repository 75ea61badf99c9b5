/* trace: each mesh's triangles in an Embree scene of their own, instanced
 * once a mesh node under a top-level scene, rays spread over pthreads (see
 * trace.h for what is kept and why Embree, and why instances). */
#define _GNU_SOURCE
#include "trace/trace.h"

#include <cglm/cglm.h>
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CHUNK = 256 }; /* rays a thread takes at a time */

/* Beyond this magnitude Embree treats a corner as invalid (its limit is 1.844e18). */
#define EMBREE_RANGE 1e18f

/* One scene mesh (or the triangles given directly) in its own space: an
 * Embree scene of one triangle geometry over buffers it shares with us. */
typedef struct trace_mesh {
  float *xyz;           /* positions, 3 floats a vertex (+1: Embree reads 16 bytes) */
  uint32_t *corners;    /* 3 vertex indices a kept triangle */
  int *prim;            /* kept triangle -> its index in the mesh or in the array given */
  int vertex_count, count, skipped;
  float bounds[2][3];   /* around the kept triangles' corners (when built: a deformed mesh's first pose) */
  RTCGeometry geometry; /* NULL (and no scene) when it keeps no triangle */
  RTCScene scene;
} trace_mesh;

/* One mesh node: an instance of its mesh's scene. */
typedef struct trace_node {
  int node, mesh;       /* node -1: the triangles given directly (mesh 0) */
  int vertex_count, index_count; /* its mesh's sizes when built: a change is a rebuild */
  float world[16];      /* the transform the instance has */
  float normal[3][3];   /* its inverse transpose's upper 3x3 (normal[column][row]) */
  bool active;          /* the transform is invertible and keeps the mesh within Embree's range */
  int first;            /* lm_trace_hit.tri of its first triangle */
  RTCGeometry instance; /* NULL when its mesh keeps no triangle */
} trace_node;

struct lm_trace {
  RTCDevice device;
  RTCScene scene;         /* the instances */
  const lm_scene *source; /* NULL for triangles given directly */
  trace_mesh *meshes;     /* one a scene mesh (built when a node uses it), or one for triangles given */
  int mesh_count;
  trace_node *nodes;
  int node_count;
  int count;              /* hit numbers: every node's mesh's triangles */
  lm_trace_stats stats;
};

static bool finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }
static void sub3(const float *a, const float *b, float *o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static void cross3(const float *a, const float *b, float *o) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}
static float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static bool in_range(const float *p) {
  return fabsf(p[0]) < EMBREE_RANGE && fabsf(p[1]) < EMBREE_RANGE && fabsf(p[2]) < EMBREE_RANGE;
}

/* Corners finite and within Embree's range with a finite, non-zero cross
 * product (no squares: they would underflow for a tiny triangle that Embree
 * still hits). */
static bool tri_usable(const float *a, const float *b, const float *c) {
  if (!finite3(a) || !finite3(b) || !finite3(c) || !in_range(a) || !in_range(b) || !in_range(c)) return false;
  float e1[3], e2[3], n[3];
  sub3(b, a, e1);
  sub3(c, a, e2);
  cross3(e1, e2, n);
  return finite3(n) && (n[0] != 0 || n[1] != 0 || n[2] != 0);
}

static void embree_error(void *user, enum RTCError code, const char *msg) {
  (void)user;
  lm_warn("trace: Embree error %d: %s", (int)code, msg ? msg : "");
}

/* ---- meshes ------------------------------------------------------------- */
/* The mesh's scene over m->xyz's kept triangles, committed. */
static void mesh_commit(lm_trace *t, trace_mesh *m) {
  for (int k = 0; k < 3; k++) m->bounds[0][k] = m->bounds[1][k] = 0;
  for (int i = 0; i < m->count * 3; i++)
    for (int k = 0; k < 3; k++) {
      float v = m->xyz[(size_t)m->corners[i] * 3 + k];
      m->bounds[0][k] = i ? fminf(m->bounds[0][k], v) : v, m->bounds[1][k] = i ? fmaxf(m->bounds[1][k], v) : v;
    }
  if (m->count == 0) return;
  m->geometry = rtcNewGeometry(t->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(m->geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->xyz, 0, 3 * sizeof(float),
                             (size_t)m->vertex_count);
  rtcSetSharedGeometryBuffer(m->geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->corners, 0,
                             3 * sizeof(uint32_t), (size_t)m->count);
  rtcCommitGeometry(m->geometry);
  m->scene = rtcNewScene(t->device);
  rtcAttachGeometry(m->scene, m->geometry);
  rtcCommitScene(m->scene);
}

/* Positions of a mesh's current pose. */
static void mesh_positions(trace_mesh *tm, const lm_scene_mesh *m) {
  for (int i = 0; i < m->vertex_count; i++) memcpy(tm->xyz + (size_t)i * 3, m->vertices + (size_t)i * 8, 3 * sizeof(float));
}

/* Scene mesh `mi`, kept by the rules in trace.h. */
static void mesh_build(lm_trace *t, int mi) {
  trace_mesh *tm = &t->meshes[mi];
  const lm_scene_mesh *m = &t->source->meshes[mi];
  const float *judged = m->rest ? m->rest : m->vertices; /* a deformed mesh: at rest, so poses keep the set */
  *tm = (trace_mesh){.vertex_count = m->vertex_count};
  tm->xyz = lm_alloc(((size_t)m->vertex_count * 3 + 1) * sizeof(float));
  mesh_positions(tm, m);
  int tris = m->index_count / 3;
  tm->corners = lm_alloc((size_t)(tris ? tris : 1) * 3 * sizeof(uint32_t));
  tm->prim = lm_alloc((size_t)(tris ? tris : 1) * sizeof(int));
  for (int k = 0; k < tris; k++) {
    const uint32_t *c = m->indices + (size_t)k * 3;
    uint32_t n = (uint32_t)m->vertex_count;
    if (c[0] >= n || c[1] >= n || c[2] >= n || !tri_usable(judged + c[0] * 8, judged + c[1] * 8, judged + c[2] * 8)) {
      tm->skipped++;
      continue;
    }
    memcpy(tm->corners + (size_t)tm->count * 3, c, 3 * sizeof(uint32_t));
    tm->prim[tm->count++] = k;
  }
  mesh_commit(t, tm);
}

/* ---- nodes -------------------------------------------------------------- */
/* Places the node's instance at `world`: active when the transform is
 * finite and invertible and puts the mesh's box within Embree's range. */
static void node_place(trace_node *n, const float *world, const float bounds[2][3]) {
  memcpy(n->world, world, sizeof n->world);
  mat4 w, inv;
  memcpy(w, world, sizeof w);
  glm_mat4_inv(w, inv); /* normals by the inverse transpose: inv's rows */
  bool ok = glm_mat4_det(w) != 0;
  for (int c = 0; c < 3; c++)
    for (int r = 0; r < 3; r++) n->normal[c][r] = inv[r][c], ok = ok && isfinite(inv[r][c]);
  for (int k = 0; k < 16; k++) ok = ok && isfinite(world[k]);
  for (int c = 0; c < 8 && ok; c++) { /* the box's corners */
    float p[3];
    for (int r = 0; r < 3; r++)
      p[r] = w[0][r] * bounds[c & 1][0] + w[1][r] * bounds[c >> 1 & 1][1] + w[2][r] * bounds[c >> 2][2] + w[3][r];
    ok = finite3(p) && in_range(p);
  }
  n->active = ok;
  if (!n->instance) return;
  float xfm[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}; /* an inactive one is disabled at the identity */
  if (ok)
    for (int c = 0; c < 4; c++)
      for (int r = 0; r < 3; r++) xfm[c * 3 + r] = world[c * 4 + r];
  rtcSetGeometryTransform(n->instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
  if (ok) rtcEnableGeometry(n->instance);
  else rtcDisableGeometry(n->instance);
  rtcCommitGeometry(n->instance);
}

/* Kept and skipped triangles over the nodes, from their meshes and whether they are active. */
static void count_triangles(lm_trace *t) {
  t->stats.triangles = t->stats.skipped = 0;
  for (int i = 0; i < t->node_count; i++) {
    const trace_node *n = &t->nodes[i];
    const trace_mesh *m = &t->meshes[n->mesh];
    t->stats.triangles += n->active ? m->count : 0;
    t->stats.skipped += m->skipped + (n->active ? 0 : m->count);
  }
}

/* The top-level scene over t->nodes, each with its mesh built: numbering, instancing, committing. */
static void commit_nodes(lm_trace *t, double t0) {
  static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  t->scene = rtcNewScene(t->device);
  t->count = 0;
  for (int i = 0; i < t->node_count; i++) {
    trace_node *n = &t->nodes[i];
    trace_mesh *m = &t->meshes[n->mesh];
    n->first = t->count;
    t->count += m->count;
    if (m->scene) {
      n->instance = rtcNewGeometry(t->device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(n->instance, m->scene);
      rtcAttachGeometryByID(t->scene, n->instance, (unsigned)i);
      t->stats.instances++;
    }
    node_place(n, n->node >= 0 ? t->source->nodes[n->node].world : identity, m->bounds);
  }
  rtcCommitScene(t->scene);
  count_triangles(t);
  t->stats.build_ms = lm_now_ms() - t0;
}

static void release_all(lm_trace *t) {
  for (int i = 0; i < t->node_count; i++)
    if (t->nodes[i].instance) rtcReleaseGeometry(t->nodes[i].instance);
  if (t->scene) rtcReleaseScene(t->scene);
  for (int i = 0; i < t->mesh_count; i++) {
    trace_mesh *m = &t->meshes[i];
    if (m->geometry) rtcReleaseGeometry(m->geometry);
    if (m->scene) rtcReleaseScene(m->scene);
    free(m->xyz), free(m->corners), free(m->prim);
  }
  free(t->meshes), free(t->nodes);
  t->meshes = NULL, t->nodes = NULL, t->scene = NULL;
  t->mesh_count = t->node_count = t->count = 0;
}

static bool mesh_node(const lm_scene *sc, int i) { return sc->nodes[i].mesh >= 0 && sc->nodes[i].mesh < sc->mesh_count; }

static void build_scene(lm_trace *t) {
  double t0 = lm_now_ms();
  const lm_scene *sc = t->source;
  t->stats = (lm_trace_stats){0};
  t->mesh_count = sc->mesh_count;
  t->meshes = lm_alloc((size_t)(sc->mesh_count ? sc->mesh_count : 1) * sizeof *t->meshes);
  bool *used = lm_alloc((size_t)(sc->mesh_count ? sc->mesh_count : 1) * sizeof *used);
  memset(used, 0, (size_t)(sc->mesh_count ? sc->mesh_count : 1) * sizeof *used);
  int n = 0;
  for (int i = 0; i < sc->node_count; i++)
    if (mesh_node(sc, i)) n++, used[sc->nodes[i].mesh] = true;
  for (int i = 0; i < sc->mesh_count; i++) {
    if (used[i]) mesh_build(t, i), t->stats.meshes += t->meshes[i].scene != NULL;
    else t->meshes[i] = (trace_mesh){0};
  }
  free(used);
  t->nodes = lm_alloc((size_t)(n ? n : 1) * sizeof *t->nodes);
  for (int i = 0; i < sc->node_count; i++) {
    if (!mesh_node(sc, i)) continue;
    const lm_scene_mesh *m = &sc->meshes[sc->nodes[i].mesh];
    t->nodes[t->node_count++] = (trace_node){.node = i, .mesh = sc->nodes[i].mesh, .vertex_count = m->vertex_count,
                                             .index_count = m->index_count};
  }
  commit_nodes(t, t0);
}

static lm_trace *trace_new(void) {
  lm_trace *t = lm_alloc(sizeof *t);
  *t = (lm_trace){0};
  char config[32];
  snprintf(config, sizeof config, "threads=%d", lm_cpu_count());
  t->device = rtcNewDevice(config);
  if (t->device) rtcSetDeviceErrorFunction(t->device, embree_error, NULL);
  else lm_warn("trace: Embree refused a device (error %d): every ray misses", (int)rtcGetDeviceError(NULL));
  return t;
}

lm_trace *lm_trace_create(const lm_scene *sc, lm_trace_stats *stats) {
  lm_trace *t = trace_new();
  t->source = sc;
  if (t->device) build_scene(t);
  if (stats) *stats = t->stats;
  return t;
}

lm_trace *lm_trace_create_triangles(const float *xyz, int count, lm_trace_stats *stats) {
  lm_trace *t = trace_new();
  if (!t->device) {
    if (stats) *stats = t->stats;
    return t;
  }
  double t0 = lm_now_ms();
  count = count > 0 ? count : 0;
  t->meshes = lm_alloc(sizeof *t->meshes);
  t->mesh_count = 1;
  trace_mesh *m = &t->meshes[0];
  *m = (trace_mesh){0};
  m->xyz = lm_alloc(((size_t)count * 9 + 1) * sizeof(float));
  m->corners = lm_alloc((size_t)(count ? count : 1) * 3 * sizeof(uint32_t));
  m->prim = lm_alloc((size_t)(count ? count : 1) * sizeof(int));
  for (int i = 0; i < count; i++) {
    const float *c = xyz + (size_t)i * 9;
    if (!tri_usable(c, c + 3, c + 6)) {
      m->skipped++;
      continue;
    }
    memcpy(m->xyz + (size_t)m->count * 9, c, 9 * sizeof(float));
    for (int k = 0; k < 3; k++) m->corners[m->count * 3 + k] = (uint32_t)(m->count * 3 + k);
    m->prim[m->count++] = i;
  }
  m->vertex_count = m->count * 3;
  mesh_commit(t, m);
  t->stats.meshes = m->scene != NULL;
  t->nodes = lm_alloc(sizeof *t->nodes);
  t->node_count = 1;
  t->nodes[0] = (trace_node){.node = -1, .mesh = 0};
  commit_nodes(t, t0);
  if (stats) *stats = t->stats;
  return t;
}

/* Whether `sc` has the mesh nodes t was built over, over meshes of the same sizes. */
static bool same_nodes(const lm_trace *t, const lm_scene *sc) {
  if (t->source == NULL || sc->mesh_count < t->mesh_count) return false;
  int k = 0;
  for (int i = 0; i < sc->node_count; i++) {
    if (!mesh_node(sc, i)) continue;
    if (k == t->node_count) return false;
    const trace_node *n = &t->nodes[k++];
    const lm_scene_mesh *m = &sc->meshes[sc->nodes[i].mesh];
    if (n->node != i || n->mesh != sc->nodes[i].mesh || n->vertex_count != m->vertex_count ||
        n->index_count != m->index_count)
      return false;
  }
  return k == t->node_count;
}

void lm_trace_update(lm_trace *t, const lm_scene *sc, lm_trace_stats *stats) {
  if (!t->device) {
    if (stats) *stats = t->stats;
    return;
  }
  double t0 = lm_now_ms();
  if (!same_nodes(t, sc)) {
    release_all(t);
    t->source = sc;
    build_scene(t);
    if (stats) *stats = t->stats;
    return;
  }
  t->source = sc;
  /* deformed meshes: their new pose, their scene rebuilt (Embree's refit would
   * need the scene's two-level mode, which rebuilds every geometry's BVH) */
  for (int i = 0; i < t->mesh_count; i++) {
    trace_mesh *m = &t->meshes[i];
    if (!m->scene || !sc->meshes[i].rest) continue;
    mesh_positions(m, &sc->meshes[i]);
    rtcUpdateGeometryBuffer(m->geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(m->geometry);
    rtcCommitScene(m->scene);
  }
  int moved = 0;
  for (int i = 0; i < t->node_count; i++) {
    trace_node *n = &t->nodes[i];
    const lm_node *node = &sc->nodes[n->node];
    const lm_scene_mesh *m = &sc->meshes[n->mesh];
    if (!m->rest && !memcmp(n->world, node->world, sizeof n->world)) continue; /* neither moved nor deformed */
    node_place(n, node->world, t->meshes[n->mesh].bounds);
    moved += n->instance != NULL;
  }
  rtcCommitScene(t->scene);
  count_triangles(t);
  t->stats.refitted = true;
  t->stats.moved = moved;
  t->stats.build_ms = lm_now_ms() - t0;
  if (stats) *stats = t->stats;
}

void lm_trace_destroy(lm_trace *t) {
  if (!t) return;
  release_all(t);
  if (t->device) rtcReleaseDevice(t->device);
  free(t);
}

/* ---- tracing ------------------------------------------------------------ */
static void miss(lm_trace_hit *hit) { *hit = (lm_trace_hit){.t = INFINITY, .tri = -1}; }

/* The ray as Embree takes it, or false when it misses by trace.h's rules.
 * The direction is scaled by a power of two (exact) to a largest component in
 * [0.5, 1), so that tiny and huge directions trace as well as unit ones; *e
 * scales t back. Embree takes tnear <= t <= tfar, the API tmin < t < tmax. */
static bool embree_ray(const lm_trace_ray *r, struct RTCRayHit *rh, int *e) {
  bool zero = r->dir[0] == 0 && r->dir[1] == 0 && r->dir[2] == 0;
  if (!finite3(r->origin) || !finite3(r->dir) || zero || !(r->tmax > r->tmin) || isnan(r->tmin)) return false;
  frexpf(fmaxf(fabsf(r->dir[0]), fmaxf(fabsf(r->dir[1]), fabsf(r->dir[2]))), e);
  float tmin = ldexpf(r->tmin, *e), tmax = ldexpf(r->tmax, *e);
  if (!(tmax > tmin)) return false;
  *rh = (struct RTCRayHit){
      .ray = {.org_x = r->origin[0], .org_y = r->origin[1], .org_z = r->origin[2],
              .tnear = nextafterf(fmaxf(tmin, 0), INFINITY), .dir_x = ldexpf(r->dir[0], -*e),
              .dir_y = ldexpf(r->dir[1], -*e), .dir_z = ldexpf(r->dir[2], -*e), .tfar = nextafterf(tmax, -INFINITY),
              .mask = 0xffffffffu},
      .hit = {.geomID = RTC_INVALID_GEOMETRY_ID, .instID = {RTC_INVALID_GEOMETRY_ID}}};
  return rh->ray.tfar >= rh->ray.tnear;
}

/* The hit Embree found, in the API's numbering and units. */
static bool hit_from(const lm_trace *t, const struct RTCRayHit *rh, int e, lm_trace_hit *hit) {
  unsigned node = rh->hit.instID[0];
  if (rh->hit.geomID == RTC_INVALID_GEOMETRY_ID || node >= (unsigned)t->node_count) return miss(hit), false;
  float tt = ldexpf(rh->ray.tfar, -e);
  if (!isfinite(tt)) return miss(hit), false; /* farther than a float holds */
  *hit = (lm_trace_hit){tt, rh->hit.u, rh->hit.v, t->nodes[node].first + (int)rh->hit.primID};
  return true;
}

bool lm_trace_intersect(const lm_trace *t, const lm_trace_ray *r, lm_trace_hit *hit) {
  struct RTCRayHit rh;
  int e;
  if (!t->scene || t->count == 0 || !embree_ray(r, &rh, &e)) return miss(hit), false;
  struct RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1(t->scene, &context, &rh);
  return hit_from(t, &rh, e, hit);
}

typedef struct trace_job {
  const lm_trace *t;
  const lm_trace_ray *rays;
  lm_trace_hit *hits;
  int count;
  atomic_int next;
} trace_job;

static void *trace_worker(void *arg) {
  trace_job *j = arg;
  for (;;) {
    int b = atomic_fetch_add(&j->next, CHUNK);
    if (b >= j->count) break;
    int e = b + CHUNK < j->count ? b + CHUNK : j->count;
    for (int i = b; i < e; i++) lm_trace_intersect(j->t, &j->rays[i], &j->hits[i]);
  }
  return NULL;
}

void lm_trace_rays(const lm_trace *t, const lm_trace_ray *rays, lm_trace_hit *hits, int count, int threads) {
  if (count <= 0) return;
  if (threads <= 0) threads = lm_cpu_count();
  int chunks = (count + CHUNK - 1) / CHUNK;
  if (threads > chunks) threads = chunks;
  if (threads > 256) threads = 256;
  trace_job j = {.t = t, .rays = rays, .hits = hits, .count = count};
  atomic_init(&j.next, 0);
  pthread_t tid[256];
  int started = 0;
  for (int i = 1; i < threads; i++)
    if (pthread_create(&tid[started], NULL, trace_worker, &j) == 0) started++; /* fewer threads if refused */
  trace_worker(&j);
  for (int i = 0; i < started; i++) pthread_join(tid[i], NULL);
}

/* The node whose triangles hit number `tri` is among (their first numbers ascend). */
static const trace_node *node_of(const lm_trace *t, int tri) {
  int lo = 0, hi = t->node_count - 1;
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (t->nodes[mid].first <= tri) lo = mid;
    else hi = mid - 1;
  }
  return &t->nodes[lo]; /* the last of those sharing a first number: an empty one is never last */
}

void lm_trace_surface_at(const lm_trace *t, const lm_trace_ray *r, const lm_trace_hit *h, lm_trace_surface *out) {
  *out = (lm_trace_surface){.node = -1, .prim = -1};
  if (h->tri < 0 || h->tri >= t->count) return;
  const trace_node *n = node_of(t, h->tri);
  const trace_mesh *m = &t->meshes[n->mesh];
  int i = h->tri - n->first;
  const uint32_t *c = m->corners + (size_t)i * 3;
  for (int k = 0; k < 3; k++) out->position[k] = r->origin[k] + h->t * r->dir[k];
  float p[3][3], e1[3], e2[3], ng[3], nn[3];
  for (int v = 0; v < 3; v++) { /* the corners in world space */
    const float *o = m->xyz + c[v] * 3;
    for (int k = 0; k < 3; k++)
      p[v][k] = n->world[k] * o[0] + n->world[4 + k] * o[1] + n->world[8 + k] * o[2] + n->world[12 + k];
  }
  sub3(p[1], p[0], e1);
  sub3(p[2], p[0], e2);
  cross3(e1, e2, ng);
  float w = 1 - h->u - h->v;
  if (n->node >= 0) {
    const lm_scene_mesh *sm = &t->source->meshes[n->mesh];
    const float *a = sm->vertices + c[0] * 8, *b = sm->vertices + c[1] * 8, *d = sm->vertices + c[2] * 8;
    float on[3];
    for (int k = 0; k < 3; k++) on[k] = w * a[3 + k] + h->u * b[3 + k] + h->v * d[3 + k];
    for (int k = 0; k < 3; k++) nn[k] = n->normal[0][k] * on[0] + n->normal[1][k] * on[1] + n->normal[2][k] * on[2];
    for (int k = 0; k < 2; k++) out->uv[k] = w * a[6 + k] + h->u * b[6 + k] + h->v * d[6 + k];
  } else {
    memcpy(nn, ng, sizeof nn);
  }
  /* both sides shade, as in POV-Ray: each normal is turned to face the ray;
   * no usable vertex normal: the face's; a face too thin for one: against the ray */
  float len = sqrtf(dot3(nn, nn));
  if (!(len > 1e-30f) || !isfinite(len)) memcpy(nn, ng, sizeof nn), len = sqrtf(dot3(nn, nn));
  if (!(len > 1e-30f) || !isfinite(len)) memcpy(nn, r->dir, sizeof nn), len = sqrtf(dot3(nn, nn));
  if (!(len > 1e-30f) || !isfinite(len)) nn[0] = nn[1] = 0, nn[2] = 1, len = 1; /* a ray too tiny to square */
  float sgn = dot3(nn, r->dir) > 0 ? -1.0f : 1.0f;
  for (int k = 0; k < 3; k++) out->normal[k] = sgn * nn[k] / len;
  out->node = n->node;
  out->prim = m->prim[i];
}
