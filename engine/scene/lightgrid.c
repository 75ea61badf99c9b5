/* Clustered light culling: the camera's frustum cut into screen tiles and
 * depth slices (exponential between near and far, so the grid has no unit);
 * each cluster lists the lights whose reach touches its box. Built on the CPU
 * once a frame, read by every lighting pass through LimnLightGrid
 * (shaders/common.glsl). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

enum {
  TILE_PX = 32,     /* tile side in output pixels */
  SLICES = 24,      /* depth slices between near and far */
  HEADER = 12,      /* words before the cells: ivec4 grid, vec4 slicing, uvec4 global */
};

float lm_light_data_reach(const lm_light_data *d) {
  lm_light l = {.type = (lm_light_type)(int)(d->position[3] + 0.5f),
                .falloff = (lm_falloff)(int)(d->params[1] + 0.5f),
                .radius = d->color[3]};
  return lm_light_reach(&l);
}

static void push(lm_light_grid *g, uint32_t word) {
  if (g->count == g->cap) {
    g->cap = g->cap ? 2 * g->cap : 4096;
    g->data = lm_realloc(g->data, g->cap * sizeof *g->data);
  }
  g->data[g->count++] = word;
}

static uint32_t float_bits(float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

/* View-space depth (positive) of slice boundary k. */
static float slice_depth(const lm_light_grid *g, int k) {
  return g->near * expf((float)k / g->slice_scale);
}

/* The view-space box of cluster (tx, ty, k), slightly padded so that a point
 * the shader rounds into this cluster lies inside it. */
static void cluster_box(const lm_light_grid *g, const lm_frame_data *f, int tx, int ty, int k, float lo[3],
                        float hi[3]) {
  float z0 = slice_depth(g, k), z1 = slice_depth(g, k + 1);
  float nx0 = 2.0f * (float)(tx * g->tile_px) * f->output_size[2] - 1.0f;
  float nx1 = 2.0f * (float)((tx + 1) * g->tile_px) * f->output_size[2] - 1.0f;
  float ny0 = 2.0f * (float)(ty * g->tile_px) * f->output_size[3] - 1.0f;
  float ny1 = 2.0f * (float)((ty + 1) * g->tile_px) * f->output_size[3] - 1.0f;
  /* Symmetric perspective: x_view = ndc_x * z / P00, y_view = ndc_y * z / P11. */
  float sx = 1.0f / f->proj[0], sy = 1.0f / f->proj[5];
  float xs[4] = {nx0 * z0 * sx, nx1 * z0 * sx, nx0 * z1 * sx, nx1 * z1 * sx};
  float ys[4] = {ny0 * z0 * sy, ny1 * z0 * sy, ny0 * z1 * sy, ny1 * z1 * sy};
  lo[0] = hi[0] = xs[0], lo[1] = hi[1] = ys[0];
  for (int i = 1; i < 4; i++) {
    lo[0] = fminf(lo[0], xs[i]), hi[0] = fmaxf(hi[0], xs[i]);
    lo[1] = fminf(lo[1], ys[i]), hi[1] = fmaxf(hi[1], ys[i]);
  }
  lo[2] = -z1, hi[2] = -z0;
  float pad = 1e-3f * z1;
  for (int i = 0; i < 3; i++) lo[i] -= pad, hi[i] += pad;
}

/* Whether a light at view-space c with reach r (infinite for a spot of
 * unbounded falloff; and, for a spot under 90 degrees, axis `axis` and cone
 * cosine cos_outer) can touch the box. */
static bool touches(const float c[3], float r, const float *axis, float cos_outer, const float lo[3],
                    const float hi[3]) {
  float d2 = 0;
  for (int i = 0; i < 3; i++) {
    float e = c[i] < lo[i] ? lo[i] - c[i] : c[i] > hi[i] ? c[i] - hi[i] : 0;
    d2 += e * e;
  }
  if (!isinf(r) && d2 > r * r) return false;
  if (!axis) return true;
  /* The cone against the box's bounding sphere: the sphere's distance from
   * the cone's surface, and its extent along the axis. */
  float m[3], v[3], rad2 = 0, len2 = 0, along = 0;
  for (int i = 0; i < 3; i++) {
    m[i] = 0.5f * (lo[i] + hi[i]);
    rad2 += 0.25f * (hi[i] - lo[i]) * (hi[i] - lo[i]);
    v[i] = m[i] - c[i];
    len2 += v[i] * v[i];
    along += v[i] * axis[i];
  }
  float rad = sqrtf(rad2), sin_outer = sqrtf(fmaxf(0, 1 - cos_outer * cos_outer));
  float across = sqrtf(fmaxf(0, len2 - along * along));
  float gap = cos_outer * across - along * sin_outer;
  return !(gap > rad || along < -rad);
}

/* A spot whose cone is under 90 degrees: culled by its cone, whatever its reach. */
static bool is_cone(const lm_light_data *l) {
  return (int)(l->position[3] + 0.5f) == LM_LIGHT_SPOT && l->direction[3] > 0;
}

/* Does the light reach every cluster (infinite reach and no cone)? */
static bool everywhere(const lm_light_data *l) { return isinf(lm_light_data_reach(l)) && !is_cone(l); }

typedef struct near_light {
  float pos[3], axis[3], reach, cos_outer;
  bool spot; /* a cone under 90 degrees */
  int index;
} near_light;

static void to_view(const float m[16], const float p[3], float w, float out[3]) {
  for (int i = 0; i < 3; i++) out[i] = m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i] * w;
}

void lm_light_grid_build(lm_light_grid *g, const lm_frame_data *f, const lm_light_data *lights, int n, bool cull) {
  g->count = 0;
  g->tile_px = TILE_PX;
  g->tiles_x = ((int)f->output_size[0] + TILE_PX - 1) / TILE_PX;
  g->tiles_y = ((int)f->output_size[1] + TILE_PX - 1) / TILE_PX;
  g->slices = SLICES;
  g->near = f->clip[0], g->far = f->clip[1];
  float ratio = f->clip[1] / f->clip[0];
  g->slice_scale = ratio > 1.0001f ? (float)SLICES / logf(ratio) : 0;
  /* Lights with a finite reach or a cone, in view space; the others reach
   * every cluster. */
  near_light *near = lm_alloc(sizeof *near * (size_t)(n > 0 ? n : 1));
  int near_count = 0;
  for (int i = 0; i < n; i++) {
    const lm_light_data *l = &lights[i];
    if (everywhere(l)) continue;
    near_light *q = &near[near_count++];
    to_view(f->view, l->position, 1, q->pos);
    to_view(f->view, l->direction, 0, q->axis);
    q->reach = lm_light_data_reach(l), q->cos_outer = l->direction[3], q->index = i;
    q->spot = is_cone(l);
  }
  /* No grid (every light everywhere) when asked, when the camera gives no
   * slices, or when no light has a finite reach: nothing to cull. */
  if (!cull || !(g->slice_scale > 0) || g->tiles_x < 1 || g->tiles_y < 1 || !near_count) g->tile_px = 0;
  int clusters = g->tile_px ? g->tiles_x * g->tiles_y * g->slices : 0;
  /* Header, then two words a cluster (offset into the words after the
   * header, count), the lights that reach everywhere, the cluster lists. */
  uint32_t head[HEADER] = {(uint32_t)g->tiles_x, (uint32_t)g->tiles_y, (uint32_t)g->slices, (uint32_t)g->tile_px,
                           float_bits(g->slice_scale), float_bits(g->near), 0, 0, 0, 0, 0, 0};
  for (int i = 0; i < HEADER; i++) push(g, head[i]);
  for (int c = 0; c < 2 * clusters; c++) push(g, 0);
  uint32_t global_offset = (uint32_t)(g->count - HEADER), global = 0;
  for (int i = 0; i < n; i++)
    if (clusters && everywhere(&lights[i])) push(g, (uint32_t)i), global++;
  g->data[8] = global, g->data[9] = global_offset;
  g->listed = 0;
  for (int c = 0; c < clusters; c++) {
    int tx = c % g->tiles_x, ty = c / g->tiles_x % g->tiles_y, k = c / (g->tiles_x * g->tiles_y);
    float lo[3], hi[3];
    cluster_box(g, f, tx, ty, k, lo, hi);
    uint32_t offset = (uint32_t)(g->count - HEADER), count = 0;
    for (int i = 0; i < near_count; i++) {
      const near_light *q = &near[i];
      if (q->reach > 0 && touches(q->pos, q->reach, q->spot ? q->axis : NULL, q->cos_outer, lo, hi))
        push(g, (uint32_t)q->index), count++;
    }
    g->data[HEADER + 2 * c] = offset, g->data[HEADER + 2 * c + 1] = count;
    g->listed += count;
  }
  free(near);
  g->global = (int)global;
}

int lm_light_grid_cluster(const lm_light_grid *g, float x, float y, float depth01) {
  float z = depth01 * g->far;
  if (!g->tile_px || !(z >= g->near)) return -1;
  int tx = (int)floorf(x / (float)g->tile_px), ty = (int)floorf(y / (float)g->tile_px);
  int k = (int)floorf(logf(z / g->near) * g->slice_scale);
  if (tx < 0 || ty < 0 || tx >= g->tiles_x || ty >= g->tiles_y || k < 0 || k >= g->slices) return -1;
  return (k * g->tiles_y + ty) * g->tiles_x + tx;
}

int lm_light_grid_count(const lm_light_grid *g, int cluster, int light_count) {
  return cluster < 0 ? light_count : g->global + (int)g->data[HEADER + 2 * cluster + 1];
}

bool lm_light_grid_has(const lm_light_grid *g, int cluster, int light) {
  if (cluster < 0) return true;
  const uint32_t *global = g->data + HEADER + g->data[9];
  const uint32_t *list = g->data + HEADER + g->data[HEADER + 2 * cluster];
  for (int j = 0; j < g->global; j++)
    if (global[j] == (uint32_t)light) return true;
  for (uint32_t j = 0; j < g->data[HEADER + 2 * cluster + 1]; j++)
    if (list[j] == (uint32_t)light) return true;
  return false;
}

void lm_light_grid_free(lm_light_grid *g) {
  free(g->data);
  memset(g, 0, sizeof *g);
}
