/* trace: binned-SAH BVH over world-space triangles, traversed front to back
 * with a fixed stack, rays spread over pthreads (see trace.h for why a BVH). */
#define _GNU_SOURCE
#include "trace/trace.h"

#include <cglm/cglm.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

enum {
  BINS = 16,     /* SAH candidate planes per axis: 15 */
  MAX_LEAF = 8,  /* larger leaves are split even when the SAH would not */
  CHUNK = 256,   /* rays a thread takes at a time */
};

/* Inner node: count 0, children first and first + 1. Leaf: tris first .. first + count. */
typedef struct bvh_node {
  float lo[3];
  int first;
  float hi[3];
  int count;
} bvh_node;

/* Corner 0 and the two edges from it (Moller-Trumbore needs no more). */
typedef struct tri_geo {
  float v0[3], e1[3], e2[3];
} tri_geo;

/* Per-corner attributes for the hit record. */
typedef struct tri_attr {
  float n[3][3], uv[3][2];
} tri_attr;

/* Triangles as collected, in scene order: corners, attributes, and where they came from. */
typedef struct tri_set {
  float *xyz;     /* 9 per triangle */
  tri_attr *attr; /* NULL for triangles given directly */
  int *node, *prim;
  int count, cap, skipped;
} tri_set;

struct lm_trace {
  bvh_node *nodes;
  int node_count;
  tri_geo *geo;     /* in leaf order */
  tri_attr *attr;   /* in leaf order; NULL when triangles were given directly */
  int *order;       /* leaf slot -> index in the collected set */
  int *src_node, *src_prim; /* collected order, to tell a refit from a rebuild */
  int count;
  lm_trace_stats stats;
};

/* ---- collecting --------------------------------------------------------- */
static bool finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static void sub3(const float *a, const float *b, float *o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static void cross3(const float *a, const float *b, float *o) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}
static float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* A triangle is kept when its corners are finite and its area is finite and not zero. */
static bool tri_usable(const float *c) {
  if (!finite3(c) || !finite3(c + 3) || !finite3(c + 6)) return false;
  float e1[3], e2[3], n[3];
  sub3(c + 3, c, e1);
  sub3(c + 6, c, e2);
  cross3(e1, e2, n);
  float a = dot3(n, n);
  return isfinite(a) && a > 0;
}

static int set_push(tri_set *s, const float *c, const tri_attr *attr, int node, int prim) {
  if (!tri_usable(c)) return s->skipped++, -1;
  if (s->count == s->cap) {
    int cap = s->cap;
    s->xyz = lm_grow(s->xyz, &cap, s->count + 1, 9 * sizeof(float));
    cap = s->cap;
    s->node = lm_grow(s->node, &cap, s->count + 1, sizeof(int));
    cap = s->cap;
    s->prim = lm_grow(s->prim, &cap, s->count + 1, sizeof(int));
    if (attr) {
      cap = s->cap;
      s->attr = lm_grow(s->attr, &cap, s->count + 1, sizeof(tri_attr));
    }
    s->cap = cap;
  }
  memcpy(s->xyz + (size_t)s->count * 9, c, 9 * sizeof(float));
  if (attr) s->attr[s->count] = *attr;
  s->node[s->count] = node;
  s->prim[s->count] = prim;
  return s->count++;
}

static void set_free(tri_set *s) {
  free(s->xyz), free(s->attr), free(s->node), free(s->prim);
  *s = (tri_set){0};
}

static void collect_scene(const lm_scene *sc, tri_set *s) {
  for (int ni = 0; ni < sc->node_count; ni++) {
    const lm_node *n = &sc->nodes[ni];
    if (n->mesh < 0 || n->mesh >= sc->mesh_count) continue;
    const lm_scene_mesh *m = &sc->meshes[n->mesh];
    mat4 world, inv;
    memcpy(world, n->world, sizeof world);
    glm_mat4_inv(world, inv); /* normals by the inverse transpose: inv's rows */
    for (int t = 0; t + 2 < m->index_count; t += 3) {
      float c[9];
      tri_attr a;
      bool ok = true;
      for (int k = 0; k < 3 && ok; k++) {
        uint32_t vi = m->indices[t + k];
        if (vi >= (uint32_t)m->vertex_count) {
          ok = false;
          break;
        }
        const float *v = m->vertices + (size_t)vi * 8;
        for (int r = 0; r < 3; r++) {
          c[k * 3 + r] = world[0][r] * v[0] + world[1][r] * v[1] + world[2][r] * v[2] + world[3][r];
          a.n[k][r] = inv[r][0] * v[3] + inv[r][1] * v[4] + inv[r][2] * v[5];
        }
        a.uv[k][0] = v[6], a.uv[k][1] = v[7];
      }
      if (!ok) {
        s->skipped++;
        continue;
      }
      set_push(s, c, &a, ni, t / 3);
    }
  }
}

/* ---- building ----------------------------------------------------------- */
typedef struct box {
  float lo[3], hi[3];
} box;

static void box_empty(box *b) {
  for (int k = 0; k < 3; k++) b->lo[k] = INFINITY, b->hi[k] = -INFINITY;
}
static void box_grow(box *b, const float *p) {
  for (int k = 0; k < 3; k++) b->lo[k] = fminf(b->lo[k], p[k]), b->hi[k] = fmaxf(b->hi[k], p[k]);
}
static void box_merge(box *b, const box *o) {
  for (int k = 0; k < 3; k++) b->lo[k] = fminf(b->lo[k], o->lo[k]), b->hi[k] = fmaxf(b->hi[k], o->hi[k]);
}
/* Half the surface area (the factor cancels in the heuristic); may be Inf for vast boxes. */
static float box_area(const box *b) {
  float d[3];
  for (int k = 0; k < 3; k++) d[k] = fmaxf(b->hi[k] - b->lo[k], 0.0f);
  return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

typedef struct build_task {
  int node, begin, end, depth;
} build_task;

/* The centroid bin of a triangle along `axis`, in [0, BINS). */
static int bin_of(float c, float lo, float scale) {
  float f = (c - lo) * scale;
  int b = f >= 0 ? (int)fminf(f, BINS - 1) : 0;
  return b;
}

static void build(lm_trace *t, const tri_set *s) {
  int n = s->count;
  t->count = n;
  box *tb = lm_alloc((size_t)(n ? n : 1) * sizeof *tb);
  float *cen = lm_alloc((size_t)(n ? n : 1) * 3 * sizeof *cen);
  int *refs = lm_alloc((size_t)(n ? n : 1) * sizeof *refs);
  for (int i = 0; i < n; i++) {
    const float *c = s->xyz + (size_t)i * 9;
    box_empty(&tb[i]);
    for (int k = 0; k < 3; k++) box_grow(&tb[i], c + k * 3);
    /* a third of each corner: the sum could overflow where the corners do not */
    for (int k = 0; k < 3; k++) cen[i * 3 + k] = c[k] / 3 + c[3 + k] / 3 + c[6 + k] / 3;
    refs[i] = i;
  }
  t->nodes = lm_alloc((size_t)(2 * n + 1) * sizeof *t->nodes);
  t->node_count = 1;
  t->stats = (lm_trace_stats){.triangles = n, .skipped = s->skipped};
  build_task stack[2 * LM_TRACE_MAX_DEPTH + 4];
  int sp = 0;
  stack[sp++] = (build_task){0, 0, n, 0};
  while (sp > 0) {
    build_task k = stack[--sp];
    bvh_node *node = &t->nodes[k.node];
    box nb, cb;
    box_empty(&nb), box_empty(&cb);
    for (int i = k.begin; i < k.end; i++) box_merge(&nb, &tb[refs[i]]), box_grow(&cb, &cen[refs[i] * 3]);
    if (k.begin == k.end) nb = (box){{0, 0, 0}, {0, 0, 0}}; /* the empty scene's root */
    memcpy(node->lo, nb.lo, sizeof nb.lo);
    memcpy(node->hi, nb.hi, sizeof nb.hi);
    node->first = k.begin;
    node->count = k.end - k.begin;
    int cnt = k.end - k.begin;
    if (k.depth > t->stats.depth) t->stats.depth = k.depth;
    if (cnt <= 2 || k.depth >= LM_TRACE_MAX_DEPTH) continue;
    /* Binned SAH: cost of a split ~ area(L) n(L) + area(R) n(R), of a leaf ~ area n. */
    float best = INFINITY;
    int best_axis = -1, best_split = 0;
    for (int ax = 0; ax < 3; ax++) {
      float ext = cb.hi[ax] - cb.lo[ax];
      if (!(ext > 0) || !isfinite(ext)) continue;
      float scale = BINS / ext;
      if (!isfinite(scale)) continue;
      int bc[BINS] = {0};
      box bb[BINS];
      for (int b = 0; b < BINS; b++) box_empty(&bb[b]);
      for (int i = k.begin; i < k.end; i++) {
        int b = bin_of(cen[refs[i] * 3 + ax], cb.lo[ax], scale);
        bc[b]++;
        box_merge(&bb[b], &tb[refs[i]]);
      }
      float right_area[BINS];
      int right_count[BINS];
      box acc;
      box_empty(&acc);
      int c = 0;
      for (int b = BINS - 1; b > 0; b--) {
        box_merge(&acc, &bb[b]);
        c += bc[b];
        right_area[b] = box_area(&acc), right_count[b] = c;
      }
      box_empty(&acc);
      c = 0;
      for (int b = 0; b < BINS - 1; b++) {
        box_merge(&acc, &bb[b]);
        c += bc[b];
        if (c == 0 || right_count[b + 1] == 0) continue;
        float cost = box_area(&acc) * c + right_area[b + 1] * right_count[b + 1];
        if (cost < best) best = cost, best_axis = ax, best_split = b + 1;
      }
    }
    if (best_axis < 0) continue; /* every centroid in one bin: a leaf, however large */
    if (cnt <= MAX_LEAF && !(best < box_area(&nb) * cnt)) continue;
    float scale = BINS / (cb.hi[best_axis] - cb.lo[best_axis]);
    int mid = k.begin;
    for (int i = k.begin; i < k.end; i++) {
      if (bin_of(cen[refs[i] * 3 + best_axis], cb.lo[best_axis], scale) < best_split) {
        int tmp = refs[i];
        refs[i] = refs[mid], refs[mid++] = tmp;
      }
    }
    int l = t->node_count;
    t->node_count += 2;
    node->first = l;
    node->count = 0;
    stack[sp++] = (build_task){l, k.begin, mid, k.depth + 1};
    stack[sp++] = (build_task){l + 1, mid, k.end, k.depth + 1};
  }
  t->order = refs;
  t->geo = lm_alloc((size_t)(n ? n : 1) * sizeof *t->geo);
  t->attr = s->attr ? lm_alloc((size_t)n * sizeof *t->attr) : NULL;
  free(tb);
  free(cen);
}

/* Corners and attributes into leaf order (after a build or for a refit). */
static void place_triangles(lm_trace *t, const tri_set *s) {
  for (int i = 0; i < t->count; i++) {
    const float *c = s->xyz + (size_t)t->order[i] * 9;
    memcpy(t->geo[i].v0, c, 3 * sizeof(float));
    sub3(c + 3, c, t->geo[i].e1);
    sub3(c + 6, c, t->geo[i].e2);
    if (t->attr) t->attr[i] = s->attr[t->order[i]];
  }
}

/* Boxes from the triangles up: children come after their parent. */
static void refit(lm_trace *t) {
  for (int i = t->node_count - 1; i >= 0; i--) {
    bvh_node *nd = &t->nodes[i];
    box b;
    box_empty(&b);
    if (nd->count > 0) {
      for (int j = nd->first; j < nd->first + nd->count; j++) {
        const tri_geo *g = &t->geo[j];
        float p[3];
        box_grow(&b, g->v0);
        for (int k = 0; k < 3; k++) p[k] = g->v0[k] + g->e1[k];
        box_grow(&b, p);
        for (int k = 0; k < 3; k++) p[k] = g->v0[k] + g->e2[k];
        box_grow(&b, p);
      }
    } else if (i == 0 && t->count == 0) {
      b = (box){{0, 0, 0}, {0, 0, 0}};
    } else {
      b = (box){{0}, {0}};
      memcpy(b.lo, t->nodes[nd->first].lo, sizeof b.lo);
      memcpy(b.hi, t->nodes[nd->first].hi, sizeof b.hi);
      box o;
      memcpy(o.lo, t->nodes[nd->first + 1].lo, sizeof o.lo);
      memcpy(o.hi, t->nodes[nd->first + 1].hi, sizeof o.hi);
      box_merge(&b, &o);
    }
    memcpy(nd->lo, b.lo, sizeof b.lo);
    memcpy(nd->hi, b.hi, sizeof b.hi);
  }
}

static void count_nodes(lm_trace *t) {
  t->stats.nodes = t->node_count;
  t->stats.leaves = 0;
  for (int i = 0; i < t->node_count; i++) t->stats.leaves += t->nodes[i].count > 0 || (i == 0 && t->count == 0);
}

static void release(lm_trace *t) {
  free(t->nodes), free(t->geo), free(t->attr), free(t->order), free(t->src_node), free(t->src_prim);
}

/* Builds t from the collected set, keeping its source keys; frees the set. */
static void build_from(lm_trace *t, tri_set *s) {
  double t0 = lm_now_ms();
  build(t, s);
  place_triangles(t, s);
  count_nodes(t);
  t->src_node = s->node, t->src_prim = s->prim;
  s->node = s->prim = NULL;
  set_free(s);
  t->stats.build_ms = lm_now_ms() - t0;
}

lm_trace *lm_trace_create(const lm_scene *sc, lm_trace_stats *stats) {
  lm_trace *t = lm_alloc(sizeof *t);
  *t = (lm_trace){0};
  tri_set s = {0};
  collect_scene(sc, &s);
  build_from(t, &s);
  if (stats) *stats = t->stats;
  return t;
}

lm_trace *lm_trace_create_triangles(const float *xyz, int count, lm_trace_stats *stats) {
  lm_trace *t = lm_alloc(sizeof *t);
  *t = (lm_trace){0};
  tri_set s = {0};
  for (int i = 0; i < count; i++) set_push(&s, xyz + (size_t)i * 9, NULL, -1, i);
  build_from(t, &s);
  if (stats) *stats = t->stats;
  return t;
}

void lm_trace_update(lm_trace *t, const lm_scene *sc, lm_trace_stats *stats) {
  double t0 = lm_now_ms();
  tri_set s = {0};
  collect_scene(sc, &s);
  bool same = s.count == t->count && (!t->count || (t->attr && !memcmp(s.node, t->src_node, (size_t)s.count * sizeof(int)) &&
                                                    !memcmp(s.prim, t->src_prim, (size_t)s.count * sizeof(int))));
  if (same) {
    place_triangles(t, &s);
    refit(t);
    t->stats.refitted = true;
    t->stats.skipped = s.skipped;
    set_free(&s);
    t->stats.build_ms = lm_now_ms() - t0;
  } else {
    release(t);
    *t = (lm_trace){0};
    build_from(t, &s);
  }
  if (stats) *stats = t->stats;
}

void lm_trace_destroy(lm_trace *t) {
  if (!t) return;
  release(t);
  free(t);
}

/* ---- traversal ---------------------------------------------------------- */
/* Plain comparisons, not fminf/fmaxf (library calls for their NaN rules):
 * slab distances are never NaN, since corners and origins are finite and the
 * inverse direction is finite and non-zero. */
static inline float min2(float a, float b) { return a < b ? a : b; }
static inline float max2(float a, float b) { return a > b ? a : b; }

/* Entry distance of the ray into the box, or false when it misses it before tmax. */
static inline bool box_hit(const bvh_node *n, const float *o, const float *inv, float tmin, float tmax, float *tn) {
  float a0 = (n->lo[0] - o[0]) * inv[0], b0 = (n->hi[0] - o[0]) * inv[0];
  float a1 = (n->lo[1] - o[1]) * inv[1], b1 = (n->hi[1] - o[1]) * inv[1];
  float a2 = (n->lo[2] - o[2]) * inv[2], b2 = (n->hi[2] - o[2]) * inv[2];
  float lo = max2(max2(tmin, min2(a0, b0)), max2(min2(a1, b1), min2(a2, b2)));
  float hi = min2(min2(tmax, max2(a0, b0)), min2(max2(a1, b1), max2(a2, b2)));
  *tn = lo;
  return lo <= hi;
}

bool lm_trace_intersect(const lm_trace *t, const lm_trace_ray *r, lm_trace_hit *hit) {
  *hit = (lm_trace_hit){.t = INFINITY, .tri = -1};
  const float *o = r->origin;
  bool zero = r->dir[0] == 0 && r->dir[1] == 0 && r->dir[2] == 0;
  if (!finite3(o) || !finite3(r->dir) || zero || !(r->tmax > r->tmin) || isnan(r->tmin)) return false;
  if (t->count == 0) return false;
  /* The direction scaled by a power of two (exact) to a largest component in
   * [0.5, 1), so that a zero component can become a tiny one (no 0 * Inf in
   * the slabs) without bending the ray; t scales back at the end. */
  int e;
  frexpf(fmaxf(fabsf(r->dir[0]), fmaxf(fabsf(r->dir[1]), fabsf(r->dir[2]))), &e);
  float d[3], inv[3];
  for (int k = 0; k < 3; k++) {
    d[k] = ldexpf(r->dir[k], -e);
    float dk = fabsf(d[k]) < 1e-30f ? copysignf(1e-30f, d[k]) : d[k];
    inv[k] = 1.0f / dk;
  }
  float tmin = ldexpf(r->tmin, e), tmax = ldexpf(r->tmax, e);
  if (!(tmax > tmin)) return false;
  float best = tmax, tn;
  if (!box_hit(&t->nodes[0], o, inv, tmin, best, &tn)) return false;
  struct {
    int node;
    float t;
  } stack[LM_TRACE_MAX_DEPTH + 2];
  int sp = 0, idx = 0;
  for (;;) {
    const bvh_node *nd = &t->nodes[idx];
    if (nd->count > 0) {
      for (int i = nd->first; i < nd->first + nd->count; i++) {
        const tri_geo *g = &t->geo[i];
        float p[3], s[3], q[3];
        cross3(d, g->e2, p);
        float det = dot3(g->e1, p);
        if (det == 0) continue;
        float id = 1.0f / det;
        sub3(o, g->v0, s);
        float u = dot3(s, p) * id;
        if (!(u >= 0 && u <= 1)) continue;
        cross3(s, g->e1, q);
        float v = dot3(d, q) * id;
        if (!(v >= 0 && u + v <= 1)) continue;
        float tt = dot3(g->e2, q) * id;
        if (!(tt > tmin && tt < best)) continue;
        best = tt;
        *hit = (lm_trace_hit){tt, u, v, i};
      }
    } else {
      int l = nd->first;
      float tl, tr;
      bool hl = box_hit(&t->nodes[l], o, inv, tmin, best, &tl);
      bool hr = box_hit(&t->nodes[l + 1], o, inv, tmin, best, &tr);
      if (hl && hr) {
        int nearer = tl <= tr ? l : l + 1;
        stack[sp].node = nearer == l ? l + 1 : l;
        stack[sp++].t = tl <= tr ? tr : tl;
        idx = nearer;
        continue;
      }
      if (hl || hr) {
        idx = hl ? l : l + 1;
        continue;
      }
    }
    /* pop the next subtree still nearer than the best hit */
    while (sp > 0 && !(stack[sp - 1].t <= best)) sp--;
    if (sp == 0) break;
    idx = stack[--sp].node;
  }
  hit->t = ldexpf(hit->t, -e);
  if (!isfinite(hit->t)) *hit = (lm_trace_hit){.t = INFINITY, .tri = -1}; /* farther than a float holds */
  return hit->tri >= 0;
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

void lm_trace_surface_at(const lm_trace *t, const lm_trace_ray *r, const lm_trace_hit *h, lm_trace_surface *out) {
  *out = (lm_trace_surface){.node = -1, .prim = -1};
  if (h->tri < 0 || h->tri >= t->count) return;
  const tri_geo *g = &t->geo[h->tri];
  for (int k = 0; k < 3; k++) out->position[k] = r->origin[k] + h->t * r->dir[k];
  float ng[3], n[3];
  cross3(g->e1, g->e2, ng);
  float w = 1 - h->u - h->v;
  if (t->attr) {
    const tri_attr *a = &t->attr[h->tri];
    for (int k = 0; k < 3; k++) n[k] = w * a->n[0][k] + h->u * a->n[1][k] + h->v * a->n[2][k];
    for (int k = 0; k < 2; k++) out->uv[k] = w * a->uv[0][k] + h->u * a->uv[1][k] + h->v * a->uv[2][k];
  } else {
    memcpy(n, ng, sizeof n);
  }
  /* both sides shade, as in POV-Ray: each normal is turned to face the ray */
  float gl = sqrtf(dot3(ng, ng)); /* kept triangles have a finite, non-zero area */
  float len = sqrtf(dot3(n, n));
  if (!(len > 1e-30f) || !isfinite(len)) memcpy(n, ng, sizeof n), len = gl; /* no usable vertex normal */
  float sgn = dot3(n, r->dir) > 0 ? -1.0f : 1.0f;
  for (int k = 0; k < 3; k++) out->normal[k] = sgn * n[k] / len;
  int src = t->order[h->tri];
  out->node = t->src_node[src];
  out->prim = t->src_prim[src];
}
