#include "shadow/shadow.h"

#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { KIND_NONE, KIND_CASCADES, KIND_SPOT, KIND_POINT };

int lm_shadow_technique_parse(const char *name) {
  static const char *names[] = {"esm", "pcf", "poisson", "hard", "pcss"};
  for (int i = 0; i < 5; i++)
    if (!strcmp(names[i], name)) return i;
  return -1;
}

void lm_shadow_settings_default(lm_shadow_settings *s) {
  *s = (lm_shadow_settings){.technique = LM_SHADOW_ESM, .resolution = 512, .c = 16.0f, .blur = 0,
                            .cascades = 3, .lambda = 0.75f, .distance = 0.0f,
                            .blend = 0.1f, .radius = 2.5f, .stabilize = true, .cache = true, .coverage = true,
                            .size = -1.0f, .penumbra = 16.0f, .rsm_resolution = 8192, .simplify = 0.5f};
  s->bias = 1.0f; /* texels; the seed has 0: lit slanted surfaces then lose 1-2% to ESM */
}

/* An up vector that is not parallel to dir. */
static void up_for(const vec3 dir, vec3 up) {
  if (fabsf(dir[1]) < 0.99f)
    glm_vec3_copy((vec3){0, 1, 0}, up);
  else
    glm_vec3_copy((vec3){1, 0, 0}, up);
}

/* A tile of `size` texels a side (placed by pack_tiles); its casters are
 * culled against `cull` (NULL: view_proj). */
static int add_view(lm_shadow_plan *plan, int size, mat4 view_proj, const float depth[4], const float texel[4],
                    mat4 cull) {
  int i = plan->view_count++;
  plan->views = lm_realloc(plan->views, sizeof *plan->views * (size_t)plan->view_count);
  plan->view_data = lm_realloc(plan->view_data, sizeof *plan->view_data * (size_t)plan->view_count);
  memcpy(plan->view_data[i].view_proj, view_proj, 64);
  memcpy(plan->view_data[i].depth, depth, 16);
  memcpy(plan->view_data[i].texel, texel, 16);
  memcpy(plan->view_data[i].bounds, (float[4]){0, 0, 1, 1}, 16);
  memcpy(plan->views[i].view_proj, view_proj, 64);
  memcpy(plan->views[i].depth, depth, 16);
  memcpy(plan->views[i].cull, cull ? cull : view_proj, 64);
  plan->views[i].width = plan->views[i].height = size;
  return i;
}

/* Camera frustum corners between view depths z0 and z1, in world space. */
static void slice_corners(const lm_frame_data *cam, float z0, float z1, vec3 out[8]) {
  float far = cam->clip[1];
  for (int c = 0; c < 8; c++) {
    float z = c & 4 ? z1 : z0, u = c & 1 ? 1.0f : 0.0f, v = c & 2 ? 1.0f : 0.0f;
    for (int k = 0; k < 3; k++)
      out[c][k] = cam->camera_pos[k] +
                  (cam->frustum_o[k] + cam->frustum_u[k] * u + cam->frustum_v[k] * v) * (z / far);
  }
}

/* Practical split scheme: a lambda blend of logarithmic and uniform splits. */
static float split_depth(float n, float f, int i, int count, float lambda) {
  float t = (float)i / (float)count;
  float lg = n * powf(f / n, t), un = n + (f - n) * t;
  return lambda * lg + (1.0f - lambda) * un;
}

/* x rounded up (or down) to a step of 1/16 .. 1/32 of itself: a relative
 * grid, so that small changes leave it alone in any unit. */
static float round_relative(float x, bool up) {
  if (!(x > 0) || !isfinite(x)) return x;
  float q = exp2f(floorf(log2f(x)) - 4.0f);
  return (up ? ceilf(x / q) : floorf(x / q)) * q;
}

/* The camera depths of the mesh nodes the camera sees, within near .. far:
 * where receivers can be. The whole near .. far when it sees none. */
static void visible_depth(const lm_scene *s, const lm_frame_data *cam, float out[2]) {
  float n = cam->clip[0], f = cam->clip[1], lo[3], hi[3];
  out[0] = f, out[1] = n;
  for (int i = 0; i < s->node_count; i++) {
    if (!lm_scene_node_bounds(s, i, lo, hi) || lm_box_outside_frustum(cam->view_proj, lo, hi)) continue;
    for (int c = 0; c < 8; c++) {
      vec4 p = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2], 1};
      float z = -(cam->view[2] * p[0] + cam->view[6] * p[1] + cam->view[10] * p[2] + cam->view[14]);
      out[0] = fminf(out[0], z), out[1] = fmaxf(out[1], z);
    }
  }
  out[0] = fmaxf(out[0], n), out[1] = fminf(out[1], f);
  if (!(out[0] < out[1])) out[0] = n, out[1] = f;
}

/* Narrows [*zn, *zf] to the light-view depths of the mesh nodes inside the
 * tile's rectangle l..r x b..t (casters and receivers alike); unchanged
 * when none is. The caller handles a range this leaves empty. */
static void caster_depth(const lm_scene *s, mat4 view, float l, float r, float b, float t, float *zn, float *zf) {
  float cmin = FLT_MAX, cmax = -FLT_MAX, lo[3], hi[3];
  for (int i = 0; i < s->node_count; i++) {
    if (!lm_scene_node_bounds(s, i, lo, hi)) continue;
    float bl[3], bh[3]; /* the box in the light's view (this runs over every node for every tile of every frame) */
    lm_box_transform((const float *)view, lo, hi, bl, bh);
    if (bh[0] < l || bl[0] > r || bh[1] < b || bl[1] > t) continue;
    cmin = fminf(cmin, -bh[2]), cmax = fmaxf(cmax, -bl[2]); /* the light looks down -z */
  }
  if (cmin > cmax) return;
  *zn = fmaxf(*zn, cmin), *zf = fminf(*zf, cmax);
}

/* How far from a receiver's texel a lookup reads, in texels: the filter's
 * reach, the ESM blur's, one for texel snapping and the normal offset of the
 * lookup (bias times the filter's spread, at least 1; PCSS's a texel: shadow.glsl). */
static float filter_reach(const lm_shadow_settings *st) {
  float r = st->technique == LM_SHADOW_PCSS ? st->penumbra : st->technique == LM_SHADOW_POISSON ? st->radius : 1.5f;
  float offset = st->bias * (st->technique == LM_SHADOW_PCSS ? 1.0f : fmaxf(r, 1.0f));
  return r + (float)st->blur + 1.0f + offset;
}

/* Clips the convex polygon p (n vertices) to the half-space where
 * sign * (v[axis] - at) >= 0; returns the new count (at most n + 1). */
static int clip_polygon(vec3 *p, int n, int axis, float at, float sign) {
  vec3 out[16];
  int m = 0;
  for (int i = 0; i < n && m < 15; i++) {
    const float *a = p[i], *b = p[(i + 1) % n];
    float da = sign * (a[axis] - at), db = sign * (b[axis] - at);
    if (da >= 0) glm_vec3_copy((float *)a, out[m++]);
    if ((da < 0) != (db < 0)) glm_vec3_lerp((float *)a, (float *)b, da / (da - db), out[m++]);
  }
  memcpy(p, out, sizeof *out * (size_t)m);
  return m;
}

/* The vertices of the camera slice z0 .. z1 within the box lo..hi (both
 * convex): each face of the slice clipped to the box, and the box's corners
 * inside the slice. At most 6 * 10 + 8 into out; 0 when they do not meet. */
static int slice_in_box(const lm_frame_data *cam, float z0, float z1, const float lo[3], const float hi[3],
                        vec3 out[68]) {
  vec3 corners[8];
  slice_corners(cam, z0, z1, corners);
  /* Corner c has bit 1 for u, 2 for v, 4 for far: a face holds one bit fixed. */
  static const int cycle[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  int n = 0;
  for (int face = 0; face < 6; face++) {
    int fixed = face / 2, a = (fixed + 1) % 3, b = (fixed + 2) % 3;
    vec3 poly[16];
    for (int i = 0; i < 4; i++)
      glm_vec3_copy(corners[(face % 2) << fixed | cycle[i][0] << a | cycle[i][1] << b], poly[i]);
    int m = 4;
    for (int k = 0; k < 3 && m > 0; k++) {
      m = clip_polygon(poly, m, k, lo[k], 1.0f);
      if (m > 0) m = clip_polygon(poly, m, k, hi[k], -1.0f);
    }
    for (int i = 0; i < m && i < 10; i++) glm_vec3_copy(poly[i], out[n++]);
  }
  for (int c = 0; c < 8; c++) {
    vec4 p = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2], 1}, q;
    glm_mat4_mulv((vec4 *)cam->view_proj, p, q);
    float z = -(cam->view[2] * p[0] + cam->view[6] * p[1] + cam->view[10] * p[2] + cam->view[14]);
    if (z >= z0 && z <= z1 && fabsf(q[0]) <= q[3] && fabsf(q[1]) <= q[3]) glm_vec3_copy(p, out[n++]);
  }
  return n;
}

/* A cascade's casters: its tile's square holds the sphere around the camera
 * slice, but lookups read it only for receivers in the slice (camera depths
 * zr .. z1, zr where the last cascade's blend begins) and within the scene's
 * bounds. A caster matters when it lies over their light-space rectangle
 * (widened by the filter's reach of `texel`-sized texels) and not beyond the
 * farthest of them: cull against that box, within the tile's (l, r, b, t,
 * zn, zf). */
static void cascade_cull(const lm_frame_data *cam, mat4 view, float zr, float z1, const float bounds[2][3],
                         float texel, float reach, float step, const float tile[6], mat4 cull) {
  vec3 p[68];
  int n = slice_in_box(cam, zr, z1, bounds[0], bounds[1], p);
  float l = FLT_MAX, r = -FLT_MAX, b = FLT_MAX, t = -FLT_MAX, far = -FLT_MAX;
  for (int i = 0; i < n; i++) {
    vec4 w = {p[i][0], p[i][1], p[i][2], 1}, q;
    glm_mat4_mulv(view, w, q);
    l = fminf(l, q[0]), r = fmaxf(r, q[0]), b = fminf(b, q[1]), t = fmaxf(t, q[1]);
    far = fmaxf(far, -q[2]); /* the light looks down -z */
  }
  float pad = texel * reach;
  l = fmaxf(l - pad, tile[0]), r = fminf(r + pad, tile[1]), b = fmaxf(b - pad, tile[2]), t = fminf(t + pad, tile[3]);
  /* The far end snapped out to four of the tile's depth steps: a camera
   * moving a little keeps it, so that the tile can scroll (engine/render;
   * one step flipped it every few frames of a forward walk). */
  far = fminf(tile[4] + ceilf((far + pad - tile[4]) / (4.0f * step)) * 4.0f * step, tile[5]);
  if (!(l < r && b < t && far > tile[4])) l = tile[0], r = tile[1], b = tile[2], t = tile[3], far = tile[5];
  mat4 proj;
  glm_ortho(l, r, b, t, tile[4], far, proj);
  glm_mat4_mul(proj, view, cull);
}

/* A tile of the cell's `tile` texels halved `level` times (never empty). */
static int tile_size(int tile, int level) { return tile >> level > 0 ? tile >> level : 1; }

/* A cascade's depth row: zn .. zf in depths from its eye plane `eye` (along
 * the light), row[0..1] the last frame's as depths along the light (0 0:
 * none) and then this frame's. The eye plane steps with the camera's moves
 * along the light, and with it a row made from it: last frame's row is kept
 * while it holds zn .. zf and spans at most LM_SHADOW_RANGE_SLACK times
 * them; a row made anew reaches as far past them either way as that allows,
 * in whole steps, so that the next eye steps keep it. */
static void cascade_row(float eye, float step, float row[2], float *zn, float *zf) {
  double n = (double)eye + *zn, f = (double)eye + *zf, span = f - n;
  if (!(row[1] > row[0] && row[0] <= n && row[1] >= f && row[1] - row[0] <= span * LM_SHADOW_RANGE_SLACK)) {
    double pad = row[1] > row[0] ? floor((LM_SHADOW_RANGE_SLACK - 1.0) * span / 2.0 / step) * step : 0;
    row[0] = (float)(n - pad), row[1] = (float)(f + pad);
  }
  *zn = (float)((double)row[0] - eye), *zf = (float)((double)row[1] - eye);
}

/* One orthographic tile along dir over the camera's slice z0 .. z1: a
 * cascade (grow 0; its receivers from camera depth zr), or the RSM's wide
 * tile over the slice's bounding sphere with its radius times grow. */
static void add_slice_view(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam, vec3 dir,
                           float z0, float z1, float zr, const float bounds[2][3], float grow, float *row) {
  const lm_shadow_settings *st = &plan->settings;
  vec3 corners[8], center = {0, 0, 0};
  slice_corners(cam, z0, z1, corners);
  for (int c = 0; c < 8; c++) glm_vec3_muladds(corners[c], 1.0f / 8.0f, center);
  float l, r, b, t, extent = 0;
  for (int c = 0; c < 8; c++) extent = fmaxf(extent, glm_vec3_distance(corners[c], center));
  extent = round_relative(extent * fmaxf(grow, 1.0f) * 1.0001f, true);
  /* The eye sits on a plane across the light snapped to steps of extent/16,
   * so a small camera move changes no stored depth. */
  float step = extent / 16.0f, along = glm_vec3_dot(center, dir);
  float behind = along - floorf(along / step) * step; /* in [0, step) */
  vec3 up, eye;
  up_for(dir, up);
  glm_vec3_copy(center, eye);
  glm_vec3_muladds(dir, -(behind + extent), eye);
  mat4 view, proj, vp;
  glm_lookat(eye, center, up, view);
  /* The eye plane's depth as snapped, not as the eye's dot product gives it back: that cancels terms
   * as large as the scene and moved a tile's depth row by float noise (2e-7 in clip z, outdoor.glb)
   * from frame to frame, so a cascade that only moved across the light could not scroll. */
  view[3][2] = floorf(along / step) * step - extent;
  if (st->stabilize) {
    /* A sphere around the slice does not change as the camera turns
     * (seed 003); rounding its radius keeps float noise from resizing it. */
    l = b = -extent, r = t = extent;
  } else {
    l = b = FLT_MAX, r = t = -FLT_MAX;
    for (int c = 0; c < 8; c++) {
      vec4 p = {corners[c][0], corners[c][1], corners[c][2], 1}, q;
      glm_mat4_mulv(view, p, q);
      l = fminf(l, q[0]), r = fmaxf(r, q[0]), b = fminf(b, q[1]), t = fmaxf(t, q[1]);
    }
    /* The RSM's tile grows about its centre as the sphere's radius does (senders off screen). */
    float g = fmaxf(grow, 1.0f), cx = 0.5f * (l + r), cy = 0.5f * (b + t), hx = 0.5f * (r - l) * g,
          hy = 0.5f * (t - b) * g;
    l = cx - hx, r = cx + hx, b = cy - hy, t = cy + hy;
  }
  /* Depth spans the slice's sphere (whatever `behind` is), narrowed to the
   * meshes inside the tile and snapped to steps, so ESM's c acts on a short
   * range and no light leaks across a big scene. Casters nearer the light
   * than the near plane are clamped onto it by depth clamping in the
   * shadow pass ("pancaking"). */
  float zn = 0, zf = 2.0f * extent + step;
  if (grow > 0) {
    /* The RSM's tile: every mesh in the rectangle, however deep (a sender
     * below the slice's sphere still lights it), a step to spare at either
     * end so that none lies on a clip plane. */
    zf = FLT_MAX;
    caster_depth(s, view, l, r, b, t, &zn, &zf);
    zn = fmaxf(floorf(zn / step) * step - step, 0.0f), zf = ceilf(zf / step) * step + step;
  } else {
    caster_depth(s, view, l, r, b, t, &zn, &zf);
    zn = fmaxf(floorf(zn / step) * step, 0.0f), zf = fminf(ceilf(zf / step) * step, 2.0f * extent + step);
  }
  if (!(zf > zn) || !isfinite(zf)) zn = 0, zf = 2.0f * extent + step;
  if (row) cascade_row(view[3][2], step, row, &zn, &zf);
  glm_ortho(l, r, b, t, zn, zf, proj);
  glm_mat4_mul(proj, view, vp);
  int size = grow > 0 ? plan->rsm_tile : plan->tile;
  if (st->stabilize) {
    /* Texel snapping: move the projection so the world origin falls on a
     * texel corner; a camera moving by less than a texel moves no edge. */
    vec4 origin = {0, 0, 0, 1}, o;
    glm_mat4_mulv(vp, origin, o);
    float half = (float)size * 0.5f;
    float dx = (roundf(o[0] * half) - o[0] * half) / half, dy = (roundf(o[1] * half) - o[1] * half) / half;
    proj[3][0] += dx, proj[3][1] += dy;
    glm_mat4_mul(proj, view, vp);
  }
  float texel = (r - l) / (float)size;
  mat4 cull;
  if (grow <= 0)
    cascade_cull(cam, view, zr, z1, bounds, texel, filter_reach(st), step, (float[6]){l, r, b, t, zn, zf}, cull);
  /* A texel's world width, the world depth the tile's 0..1 spans, and its world height: unstabilized,
   * the tile is a rectangle, and an RSM texel's area is width times height (rsm.glsl). */
  add_view(plan, size, vp, (float[4]){0, 0, 0, 0}, (float[4]){texel, zf - zn, (t - b) / (float)size, 0},
           grow <= 0 ? cull : NULL);
}

/* Cascades cover the depths where receivers are seen (plan->seen), snapped
 * outwards to a relative grid so that a small camera move keeps them, or
 * the last frame's depths while they hold these and reach not much past
 * them (lm_shadow_settings.last_range); kept in plan->range. */
static void cascade_range(lm_shadow_plan *plan, float *n, float *reach) {
  *n = round_relative(plan->seen[0], false), *reach = round_relative(plan->seen[1], true);
  if (plan->settings.distance > 0) *reach = fminf(plan->settings.distance, *reach);
  if (!(*reach > *n)) *reach = *n * 1.001f;
  const float *last = plan->settings.last_range;
  if (last[0] > 0 && last[0] <= *n && last[0] * LM_SHADOW_RANGE_SLACK >= *n && last[1] >= *reach &&
      last[1] <= *reach * LM_SHADOW_RANGE_SLACK)
    *n = last[0], *reach = last[1];
  else if (last[0] > 0) {
    /* A camera in motion plans them anew with room either way (half the slack's ratio), so that
     * the next frames, which see a little nearer or farther, keep them (a forward walk's nearest
     * depth falls a little each frame: planned to the grid alone, it asked again every few). */
    float half = sqrtf(LM_SHADOW_RANGE_SLACK);
    *n = round_relative(plan->seen[0] / half, false), *reach = round_relative(plan->seen[1] * half, true);
    if (plan->settings.distance > 0) *reach = fminf(plan->settings.distance, *reach);
    if (!(*reach > *n)) *reach = *n * 1.001f;
  }
  plan->range[0] = *n, plan->range[1] = *reach;
}

static void plan_cascades(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam,
                          const lm_light_data *light, lm_shadow_light_data *out) {
  const lm_shadow_settings *st = &plan->settings;
  vec3 dir;
  glm_vec3_normalize_to((float *)light->direction, dir);
  float n, reach;
  cascade_range(plan, &n, &reach);
  out->info[0] = plan->view_count;
  out->info[1] = st->cascades;
  out->info[2] = KIND_CASCADES;
  float bounds[2][3];
  lm_scene_bounds(s, bounds[0], bounds[1]);
  for (int k = 0; k < st->cascades; k++) {
    float z0 = split_depth(n, reach, k, st->cascades, st->lambda);
    float z1 = split_depth(n, reach, k + 1, st->cascades, st->lambda);
    /* shadow.glsl blends the last `blend` share of cascade k - 1 into this one. */
    float zr = k > 0 ? z0 - (z0 - split_depth(n, reach, k - 1, st->cascades, st->lambda)) * st->blend : z0;
    out->splits[k] = z1;
    int slot = (int)(out - plan->lights) * LM_SHADOW_MAX_CASCADES + k;
    float *row = plan->depths[slot];
    memcpy(row, plan->last_depths ? plan->last_depths[slot] : (float[2]){0, 0}, sizeof(float[2]));
    add_slice_view(plan, s, cam, dir, z0, z1, zr, (const float(*)[3])bounds, 0.0f, row);
  }
}

/* The RSM's wide tile of a directional light: what its cascades cover and
 * around it, in one; after every shadow view (plan_rsm_views moves it into
 * the RSM atlas). */
static void plan_wide_tile(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam,
                           const lm_light_data *light, lm_shadow_light_data *out) {
  vec3 dir;
  glm_vec3_normalize_to((float *)light->direction, dir);
  float n, reach;
  cascade_range(plan, &n, &reach);
  out->cube[1] = plan->view_count, out->cube[2] = 1;
  add_slice_view(plan, s, cam, dir, n, reach, n, NULL, plan->settings.rsm, NULL);
}

/* Range of a point or spot light: where its light ends (lm_light_reach: the
 * seed's window or a glTF range), or the whole scene when that is nearer. */
static float light_range(const lm_scene *s, const lm_light *l, const vec3 pos) {
  float reach = lm_light_reach(l);
  if (l->falloff == LM_FALLOFF_WINDOW && reach > 0) return reach;
  float bmin[3], bmax[3], range = 0;
  lm_scene_bounds(s, bmin, bmax);
  for (int c = 0; c < 8; c++) {
    vec3 p = {c & 1 ? bmax[0] : bmin[0], c & 2 ? bmax[1] : bmin[1], c & 4 ? bmax[2] : bmin[2]};
    range = fmaxf(range, glm_vec3_distance(p, (float *)pos));
  }
  if (!(range > 0 && isfinite(range))) return reach > 0 && isfinite(reach) ? reach : 1.0f;
  return fminf(range * 1.01f, reach);
}

/* The view-projection of a square perspective view; its projection's x and
 * y scale (1 / tan(fov / 2)) in *scale. */
static float perspective_view_proj(const vec3 pos, const vec3 dir, float fov, float range, mat4 vp) {
  vec3 up, target;
  up_for(dir, up);
  glm_vec3_add((float *)pos, (float *)dir, target);
  mat4 view, proj;
  glm_lookat((float *)pos, target, up, view);
  glm_perspective(fov, 1.0f, range * 1e-4f, range, proj);
  glm_mat4_mul(proj, view, vp);
  return proj[0][0];
}

static void plan_perspective(lm_shadow_plan *plan, int size, const vec3 pos, const vec3 dir, float fov,
                             float range) {
  mat4 vp;
  float scale = perspective_view_proj(pos, dir, fov, range, vp);
  /* A texel's world size per unit of distance, the world depth 0..1 spans, and the projection's scale
   * (shadow.glsl projects a cube face by its axes with it). */
  add_view(plan, size, vp, (float[4]){pos[0], pos[1], pos[2], 1.0f / range},
           (float[4]){2.0f * tanf(fov * 0.5f) / (float)size, range, scale, 0}, NULL);
}

/* Point light: cube faces +X -X +Y -Y +Z -Z (shadow.glsl picks by major axis). */
static const float cube_faces[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

/* All n points beyond the same clip plane of view_proj. */
static bool points_outside(mat4 vp, const vec3 *p, int n) {
  int outside[6] = {0};
  for (int i = 0; i < n; i++) {
    vec4 q, w = {p[i][0], p[i][1], p[i][2], 1};
    glm_mat4_mulv(vp, w, q);
    for (int k = 0; k < 3; k++) outside[2 * k] += q[k] < -q[3], outside[2 * k + 1] += q[k] > q[3];
  }
  for (int k = 0; k < 6; k++)
    if (outside[k] == n) return true;
  return false;
}

/* The cube faces a visible pixel may sample (bit f: face f): those that
 * reach into the camera's slice of seen depths and hold a mesh the camera
 * sees. Conservative: a seen point lies in a seen mesh's box and one face. */
static int cube_faces_seen(const lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam, const vec3 pos,
                           float range) {
  vec3 slice[8], lo, hi;
  slice_corners(cam, plan->seen[0], plan->seen[1], slice);
  int mask = 0;
  for (int f = 0; f < 6; f++) {
    mat4 vp;
    perspective_view_proj(pos, cube_faces[f], GLM_PI_2f, range, vp);
    if (points_outside(vp, (const vec3 *)slice, 8)) continue;
    for (int i = 0; i < s->node_count && !(mask & 1 << f); i++)
      if (lm_scene_node_bounds(s, i, lo, hi) && !lm_box_outside_frustum(cam->view_proj, lo, hi) &&
          !lm_box_outside_frustum((float *)vp, lo, hi))
        mask |= 1 << f;
  }
  return mask;
}

enum { MIN_TILE = 32 };

/* How many times a local light's tiles halve the resolution: about one
 * texel a pixel over the disc that its reach (a sphere of `range` around
 * pos) covers on screen, a cube face about half of it, never below
 * MIN_TILE texels; a light whose reach holds the camera keeps the full
 * resolution, one whose reach lies outside the view gets the least; `last`
 * (the last frame's level, -1: none) stays while it is near enough
 * (lm_shadow_settings.last_levels). The measure is in pixels, so a scene's
 * unit changes nothing. */
static int pixels_level(const lm_shadow_plan *plan, float pixels) {
  int level = 0;
  while (tile_size(plan->tile, level + 1) >= MIN_TILE && (float)tile_size(plan->tile, level + 1) >= pixels) level++;
  return level;
}

static int coverage_level(const lm_shadow_plan *plan, const lm_frame_data *cam, const vec3 pos, float range,
                          bool cube, int last) {
  if (!plan->settings.coverage) return 0;
  float d = glm_vec3_distance((float *)cam->camera_pos, (float *)pos), pixels = 0;
  if (!(d > range)) return 0; /* inside, or not a number */
  vec3 lo = {pos[0] - range, pos[1] - range, pos[2] - range}, hi = {pos[0] + range, pos[1] + range, pos[2] + range};
  if (!lm_box_outside_frustum(cam->view_proj, lo, hi)) {
    /* The disc's diameter: 2 tan(angular radius) over 2 tan(fov_y / 2), in pixels of the height. */
    float sin_a = range / d;
    pixels = cam->output_size[1] * sin_a / sqrtf(fmaxf(1.0f - sin_a * sin_a, 1e-12f)) / fmaxf(cam->clip[3], 1e-6f);
    if (cube) pixels *= 0.5f;
  }
  /* The last level, while it lies between those for a little more and a little less. */
  if (last >= pixels_level(plan, pixels * LM_SHADOW_LEVEL_SLACK) && last <= pixels_level(plan, pixels / LM_SHADOW_LEVEL_SLACK))
    return last;
  return pixels_level(plan, pixels);
}

static void plan_light(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam, int i,
                       const lm_light_data *ld) {
  const lm_light *l = &s->lights[i];
  lm_shadow_light_data *out = &plan->lights[i];
  int faces = out->cube[0]; /* chosen when the plan was made; a fit keeps them */
  memset(out, 0, sizeof *out);
  out->info[3] = plan->settings.technique;
  out->params[0] = plan->settings.c;
  out->params[1] = plan->settings.bias;
  out->params[2] = plan->settings.blend;
  out->params[3] = plan->settings.radius;
  out->soft[1] = plan->settings.penumbra;
  float size = plan->settings.size > 0 ? plan->settings.size : l->size;
  if (!l->casts_shadows) return;
  if (l->type == LM_LIGHT_DIRECTIONAL) {
    out->soft[0] = size > 0 ? size : LM_LIGHT_SUN_SIZE;
    plan_cascades(plan, s, cam, ld, out);
    return;
  }
  vec3 pos = {ld->position[0], ld->position[1], ld->position[2]};
  vec3 dir = {ld->direction[0], ld->direction[1], ld->direction[2]};
  float range = light_range(s, l, pos);
  out->soft[0] = size > 0 ? size : LM_LIGHT_SIZE_SHARE * range;
  out->info[0] = plan->view_count;
  int tile = tile_size(plan->tile, plan->levels[i]);
  if (l->type == LM_LIGHT_SPOT) {
    out->info[1] = 1;
    out->info[2] = KIND_SPOT;
    if (plan->settings.rsm > 0) out->cube[1] = plan->view_count, out->cube[2] = 1;
    float fov = fminf(2.0f * l->outer_cone * 1.05f + 0.02f, glm_rad(170.0f));
    plan_perspective(plan, tile, pos, dir, fov, range);
    return;
  }
  /* Point light: the faces a visible pixel may sample, in face order. */
  out->info[1] = __builtin_popcount((unsigned)faces);
  out->info[2] = KIND_POINT;
  out->cube[0] = faces;
  if (plan->settings.rsm > 0) out->cube[1] = plan->view_count, out->cube[2] = out->info[1];
  for (int f = 0; f < 6; f++)
    if (faces & 1 << f) plan_perspective(plan, tile, pos, cube_faces[f], GLM_PI_2f, range);
}

/* Places n tiles of size[v] texels a side in cells of `tile` texels: largest first, each in a free square of its size, else in the
 * smallest larger one split into quadrants (the three it does not take stay
 * free), else in a new cell. Sizes are the cell halved whole times, so the
 * quadrants fit exactly and only the last cell has room to spare. Writes
 * cell[v] and the place x, y in it; returns the cells used. */
static int pack_tiles(int tile, const int *size, int n, int *cell, int *x, int *y) {
  typedef struct { int cell, x, y, size; } square;
  int cells = 0, nfree = 0;
  int *order = lm_alloc(sizeof *order * (size_t)(n + 1));
  square *free_squares = lm_alloc(sizeof *free_squares * (size_t)(3 * 16 * n + 1)); /* 3 a halving, <= 13 halvings */
  for (int v = 0; v < n; v++) { /* insertion sort, largest first, views in order among equals */
    int k = v;
    for (; k > 0 && size[order[k - 1]] < size[v]; k--) order[k] = order[k - 1];
    order[k] = v;
  }
  for (int i = 0; i < n; i++) {
    int v = order[i], best = -1;
    for (int f = 0; f < nfree; f++)
      if (free_squares[f].size >= size[v] && (best < 0 || free_squares[f].size < free_squares[best].size)) best = f;
    square q = {cells, 0, 0, tile};
    if (best >= 0) q = free_squares[best], free_squares[best] = free_squares[--nfree];
    else cells++;
    while (q.size / 2 >= size[v]) {
      int h = q.size / 2;
      free_squares[nfree++] = (square){q.cell, q.x + h, q.y, h};
      free_squares[nfree++] = (square){q.cell, q.x, q.y + h, h};
      free_squares[nfree++] = (square){q.cell, q.x + h, q.y + h, h};
      q.size = h;
    }
    cell[v] = q.cell, x[v] = q.x, y[v] = q.y;
  }
  free(order);
  free(free_squares);
  return cells;
}

/* Into best (x, y, size; size 0: none yet): the smallest square of at least `need` texels within
 * square x, y, s that none of the n tiles at p (where placed[v]) overlaps, if smaller than best's.
 * Tiles lie on multiples of their size in a cell (pack_tiles' quadrants), so a tile that overlaps
 * a square no smaller than it lies inside it: its other quadrants may still be free. */
static void free_square(const lm_shadow_place *p, const bool *placed, int n, int x, int y, int s, int need,
                        int best[3]) {
  if (s < need || best[2] == need) return; /* none fits, or none can be smaller */
  bool partly = false;
  for (int v = 0; v < n; v++) {
    if (!placed[v] || p[v].x >= x + s || x >= p[v].x + p[v].size || p[v].y >= y + s || y >= p[v].y + p[v].size)
      continue;
    if (p[v].size >= s) return; /* it covers the square */
    partly = true;
  }
  if (!partly) {
    if (best[2] == 0 || s < best[2]) best[0] = x, best[1] = y, best[2] = s;
    return;
  }
  int h = s / 2;
  if (h < need) return;
  free_square(p, placed, n, x, y, h, need, best);
  free_square(p, placed, n, x + h, y, h, need, best);
  free_square(p, placed, n, x, y + h, h, need, best);
  free_square(p, placed, n, x + h, y + h, h, need, best);
}

/* Places the n tiles p in the last frame's grid: a tile of the same light, view and size keeps its
 * place; the others, largest first, take the smallest free square that holds them (pack_tiles'
 * best fit). False when one finds none. */
static bool keep_places(const lm_shadow_plan *plan, const lm_shadow_layout *last, lm_shadow_place *p, int n) {
  int width = plan->tile * plan->columns, height = plan->tile * plan->rows, left = 0;
  int *order = lm_alloc(sizeof *order * (size_t)(n + 1));
  bool *placed = lm_alloc(sizeof *placed * (size_t)(n + 1)), ok = true;
  for (int v = 0; v < n; v++) {
    placed[v] = false;
    for (int u = 0; u < last->count && !placed[v]; u++) {
      const lm_shadow_place *q = &last->places[u];
      if (q->light == p[v].light && q->view == p[v].view && q->size == p[v].size && q->x + q->size <= width &&
          q->y + q->size <= height)
        p[v].x = q->x, p[v].y = q->y, placed[v] = true;
    }
    if (placed[v]) continue;
    int k = left++; /* insertion sort, largest first, views in order among equals */
    for (; k > 0 && p[order[k - 1]].size < p[v].size; k--) order[k] = order[k - 1];
    order[k] = v;
  }
  for (int i = 0; i < left && ok; i++) {
    int v = order[i], best[3] = {0, 0, 0};
    for (int c = 0; c < plan->columns * plan->rows; c++)
      free_square(p, placed, n, c % plan->columns * plan->tile, c / plan->columns * plan->tile, plan->tile, p[v].size,
                  best);
    ok = best[2] > 0;
    p[v].x = best[0], p[v].y = best[1], placed[v] = ok;
  }
  free(order);
  free(placed);
  return ok;
}

enum { MAX_ATLAS = 16384 }; /* texels a side: the GL limit assumed */

/* The atlas' grid and the n tiles' places in it (p: light, view and the size at plan->tile;
 * plan->layout takes p). The last frame's grid stays while a fresh packing needs its cells but
 * more than half of them (a fresh grid always holds that: hysteresis for a camera walking to and
 * fro); its tiles keep their places (keep_places), or all are packed afresh in it when free
 * squares are too scattered. Otherwise a near-square grid of the fresh packing's cells, its
 * cells halved while the atlas would pass the GL limit. */
static void plan_layout(lm_shadow_plan *plan, const lm_shadow_layout *last, lm_shadow_place *p, int n) {
  int *size = lm_alloc(sizeof *size * (size_t)(4 * n + 1)), *cell = size + n, *x = cell + n, *y = x + n;
  for (int v = 0; v < n; v++) size[v] = p[v].size;
  int cells = pack_tiles(plan->tile, size, n, cell, x, y), grid = last ? last->columns * last->rows : 0;
  bool keep = n > 0 && last && last->tile == plan->tile && cells <= grid && 2 * cells > grid;
  if (keep) {
    plan->columns = last->columns, plan->rows = last->rows;
  } else {
    plan->columns = cells ? (int)ceil(sqrt((double)cells)) : 0;
    plan->rows = cells ? (cells + plan->columns - 1) / plan->columns : 0;
    int tile = plan->tile;
    while (cells && plan->tile > 1 && (plan->tile * plan->columns > MAX_ATLAS || plan->tile * plan->rows > MAX_ATLAS))
      plan->tile /= 2;
    if (plan->tile != tile) { /* the same packing, in halved cells */
      for (int v = 0; v < n; v++) size[v] = p[v].size = tile_size(plan->tile, plan->levels[p[v].light]);
      pack_tiles(plan->tile, size, n, cell, x, y);
    }
  }
  if (!keep || !keep_places(plan, last, p, n))
    for (int v = 0; v < n; v++)
      p[v].x = cell[v] % plan->columns * plan->tile + x[v], p[v].y = cell[v] / plan->columns * plan->tile + y[v];
  free(size);
  plan->layout = (lm_shadow_layout){p, n, plan->columns, plan->rows, plan->tile};
}

/* Where the box lo .. hi projects in view_proj's tile coordinates (0..1, clamped): min xy, max xy;
 * the whole tile where a corner lies at or behind the eye plane (a perspective view inside the box). */
static void tile_bounds(const float view_proj[16], const float lo[3], const float hi[3], float out[4]) {
  float b[4] = {1, 1, 0, 0};
  for (int c = 0; c < 8; c++) {
    vec4 p = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2], 1}, q;
    glm_mat4_mulv((vec4 *)view_proj, p, q);
    if (!(q[3] > 1e-12f)) {
      memcpy(out, (float[4]){0, 0, 1, 1}, 16);
      return;
    }
    for (int k = 0; k < 2; k++) {
      float t = glm_clamp(q[k] / q[3] * 0.5f + 0.5f, 0.0f, 1.0f);
      b[k] = fminf(b[k], t), b[k + 2] = fmaxf(b[k + 2], t);
    }
  }
  memcpy(out, b, 16);
}

/* The RSM views, out of the views planned (a directional light's wide tile
 * after the shadow views, a spot or point light's shadow views): each
 * light's (cube y, z) in turn, rsm_tile texels a side, in rows of the RSM
 * atlas; their records follow the shadow views' in view_data, where cube y
 * then points. A perspective view's texel size follows its new size, and
 * each view's bounds are where the scene's box (s) projects into it. The
 * shadow pass keeps the shadow views alone. */
static void plan_rsm_views(lm_shadow_plan *plan, const lm_scene *s) {
  float lo[3], hi[3];
  bool bounded = lm_scene_bounds(s, lo, hi);
  int n = 0, shadows = plan->shadow_views;
  for (int i = 0; i < plan->light_count; i++) n += plan->lights[i].cube[2];
  plan->rsm_view_count = n;
  plan->rsm_columns = n > 0 ? (int)ceil(sqrt((double)n)) : 1;
  plan->rsm_width = plan->rsm_tile * plan->rsm_columns;
  plan->rsm_height = plan->rsm_tile * (n > 0 ? (n + plan->rsm_columns - 1) / plan->rsm_columns : 1);
  plan->rsm_views = lm_realloc(plan->rsm_views, sizeof *plan->rsm_views * (size_t)(n + 1));
  lm_shadow_view_data *data = lm_alloc(sizeof *data * (size_t)(shadows + n + 1));
  if (shadows > 0) memcpy(data, plan->view_data, sizeof *data * (size_t)shadows);
  for (int i = 0, k = 0; i < plan->light_count; i++) {
    int32_t *cube = plan->lights[i].cube, first = cube[1];
    cube[1] = shadows + k;
    for (int j = 0; j < cube[2]; j++, k++) {
      lm_pass_view *w = &plan->rsm_views[k];
      lm_shadow_view_data *d = &data[shadows + k];
      *w = plan->views[first + j], *d = plan->view_data[first + j];
      if (d->depth[3] > 0) d->texel[0] *= (float)w->width / (float)plan->rsm_tile;
      w->width = w->height = plan->rsm_tile;
      w->x = k % plan->rsm_columns * plan->rsm_tile, w->y = k / plan->rsm_columns * plan->rsm_tile;
      d->rect[0] = (float)w->x / (float)plan->rsm_width, d->rect[1] = (float)w->y / (float)plan->rsm_height;
      d->rect[2] = (float)w->width / (float)plan->rsm_width, d->rect[3] = (float)w->height / (float)plan->rsm_height;
      if (bounded) { /* a texel more each side: the texels the box's edges cross are whole senders */
        tile_bounds(d->view_proj, lo, hi, d->bounds);
        for (int e = 0; e < 4; e++)
          d->bounds[e] = glm_clamp(d->bounds[e] + (e < 2 ? -1.0f : 1.0f) / (float)plan->rsm_tile, 0.0f, 1.0f);
      }
    }
  }
  free(plan->view_data);
  plan->view_data = data;
  plan->view_count = shadows;
}

/* Every light's views for the camera; then the tiles' places in the atlas. */
static void plan_views(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam) {
  plan->view_count = 0;
  lm_light_data *ld = lm_alloc(sizeof *ld * (size_t)(s->light_count + 1));
  lm_scene_light_data(s, ld, s->light_count);
  for (int i = 0; i < s->light_count; i++) plan_light(plan, s, cam, i, &ld[i]);
  plan->shadow_views = plan->view_count;
  for (int i = 0; i < s->light_count; i++)
    if (plan->settings.rsm > 0 && s->lights[i].casts_shadows && s->lights[i].type == LM_LIGHT_DIRECTIONAL)
      plan_wide_tile(plan, s, cam, &ld[i], &plan->lights[i]);
  free(ld);
  for (int v = 0; v < plan->shadow_views && v < plan->layout.count; v++) {
    lm_pass_view *w = &plan->views[v];
    w->x = plan->layout.places[v].x, w->y = plan->layout.places[v].y;
    float *rect = plan->view_data[v].rect;
    rect[0] = (float)w->x / (float)plan->atlas_width;
    rect[1] = (float)w->y / (float)plan->atlas_height;
    rect[2] = (float)w->width / (float)plan->atlas_width;
    rect[3] = (float)w->height / (float)plan->atlas_height;
  }
  plan_rsm_views(plan, s);
}

bool lm_shadow_plan_make(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam,
                         const lm_shadow_settings *settings, lm_error *err) {
  *plan = (lm_shadow_plan){.settings = *settings};
  plan->settings.last_layout = NULL; /* the caller's, read while the plan is made */
  const lm_shadow_settings *st = settings;
  if (st->resolution < 16 || st->resolution > 8192 || st->cascades < 1 || st->cascades > LM_SHADOW_MAX_CASCADES ||
      !(st->c > 0 && st->c <= 10000) || st->blur < 0 || st->blur > 32 || !(st->lambda >= 0 && st->lambda <= 1) ||
      !(st->bias >= 0 && st->bias <= 64) || !(st->distance >= 0) || !(st->blend >= 0 && st->blend <= 1) ||
      !(st->radius >= 0 && st->radius <= 32) || !(st->rsm >= 0 && st->rsm <= 64) ||
      st->rsm_resolution < 16 || st->rsm_resolution > 8192 ||
      (unsigned)st->technique > LM_SHADOW_PCSS ||
      !(st->size < 0 || st->size <= 1e30f) || !(st->penumbra >= 1 && st->penumbra <= 64)) {
    lm_error_set(err, "shadow settings out of range");
    return false;
  }
  plan->light_count = s->light_count;
  plan->lights = lm_alloc(sizeof *plan->lights * (size_t)(s->light_count + 1));
  size_t rows = sizeof *plan->depths * LM_SHADOW_MAX_CASCADES * (size_t)(s->light_count + 1);
  plan->depths = lm_alloc(rows);
  if (st->last_depths && st->last_light_count == s->light_count) {
    plan->last_depths = lm_alloc(rows);
    memcpy(plan->last_depths, st->last_depths, sizeof *plan->depths * LM_SHADOW_MAX_CASCADES * (size_t)s->light_count);
  }
  plan->settings.last_depths = NULL; /* the caller's: plan->last_depths holds them */
  visible_depth(s, cam, plan->seen);
  /* Each light's tiles and their sizes (a point light's faces chosen now,
   * for the whole frame), then a near-square grid of cells that holds them,
   * shrunk to fit the GL limit if needed; the views depend on the tile size
   * (texel snapping). */
  plan->levels = lm_alloc(sizeof *plan->levels * (size_t)(s->light_count + 1));
  plan->tile = st->resolution;
  /* Relative to the cell, so that a tile halved to fit the GL limit below halves it too. */
  while (tile_size(plan->tile, plan->rsm_level + 1) >= st->rsm_resolution) plan->rsm_level++;
  lm_light_data *ld = lm_alloc(sizeof *ld * (size_t)(s->light_count + 1));
  lm_scene_light_data(s, ld, s->light_count);
  int count = 0, rsm_count = 0;
  lm_shadow_place *places = lm_alloc(sizeof *places * (size_t)(6 * s->light_count + 1));
  for (int i = 0; i < s->light_count; i++) {
    const lm_light *l = &s->lights[i];
    plan->levels[i] = 0;
    if (!l->casts_shadows) continue;
    int views = st->cascades, mask = (1 << views) - 1; /* the views by cascade, cube face or 0 (spot) */
    if (l->type != LM_LIGHT_DIRECTIONAL) {
      vec3 pos = {ld[i].position[0], ld[i].position[1], ld[i].position[2]};
      float range = light_range(s, l, pos);
      int last = st->last_levels && st->last_light_count == s->light_count ? st->last_levels[i] : -1;
      plan->levels[i] = coverage_level(plan, cam, pos, range, l->type == LM_LIGHT_POINT, last);
      /* An RSM needs every face: a sender off screen lights what is seen. */
      if (l->type == LM_LIGHT_POINT) plan->lights[i].cube[0] = st->rsm > 0 ? 63 : cube_faces_seen(plan, s, cam, pos, range);
      mask = l->type == LM_LIGHT_SPOT ? 1 : plan->lights[i].cube[0];
      views = __builtin_popcount((unsigned)mask);
    }
    for (int k = 0; k < 6; k++) /* in plan_light's order */
      if (mask >> k & 1)
        places[count++] = (lm_shadow_place){.light = i, .view = k, .size = tile_size(plan->tile, plan->levels[i])};
    if (st->rsm > 0) rsm_count += l->type == LM_LIGHT_DIRECTIONAL ? 1 : views; /* plan_rsm_views */
  }
  free(ld);
  plan_layout(plan, st->last_layout, places, count);
  plan->atlas_width = plan->tile * plan->columns;
  plan->atlas_height = plan->tile * plan->rows;
  plan->rsm_tile = tile_size(plan->tile, plan->rsm_level);
  int rsm_columns = rsm_count > 0 ? (int)ceil(sqrt((double)rsm_count)) : 1; /* as plan_rsm_views lays them */
  while (plan->rsm_tile > 1 && plan->rsm_tile * rsm_columns > MAX_ATLAS) plan->rsm_tile /= 2;
  plan_views(plan, s, cam);
  return true;
}

void lm_shadow_plan_fit(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam, float zmin, float zmax) {
  if (plan->view_count == 0 || !(zmin > 0 && zmin < zmax && isfinite(zmax))) return;
  plan->seen[0] = fmaxf(zmin, cam->clip[0]);
  plan->seen[1] = fminf(zmax, cam->clip[1]);
  if (!(plan->seen[0] < plan->seen[1])) return;
  plan_views(plan, s, cam);
}

bool lm_shadow_view_moved_across(const float a[16], const float b[16]) {
  for (int row = 0; row < 4; row++) {
    float scale = 0;
    for (int col = 0; col < 4; col++) scale = fmaxf(scale, fabsf(a[col * 4 + row]));
    for (int col = 0; col < 4; col++) {
      int i = col * 4 + row;
      if (i != 12 && i != 13 && !(fabsf(a[i] - b[i]) <= 1e-6f * scale)) return false;
    }
  }
  return true;
}

void lm_shadow_plan_free(lm_shadow_plan *plan) {
  free(plan->levels);
  free(plan->layout.places);
  free(plan->views);
  free(plan->rsm_views);
  free(plan->view_data);
  free(plan->lights);
  free(plan->depths);
  free(plan->last_depths);
  *plan = (lm_shadow_plan){0};
}

/* The storage block the general light loop reads and its first `records`
 * as the uniform block a scene of few lights reads (LM_LIGHT_SET_VIEWS). */
static void upload(int binding, const void *data, size_t bytes, size_t record, int records) {
  lm_storage_upload(binding, data, bytes);
  lm_uniform_upload(binding, data, bytes, record * (size_t)records);
}

/* For light-set variants, each light's shadow views again at fixed places
 * (uniform block 5, shadow.glsl's shadow_slots, SHADOW_SLOTS the same): light
 * i's view j at SHADOW_SLOTS i + j, j its cube face (+X -X +Y -Y +Z -Z), its
 * cascade or 0 for a spot. A variant's light index is a constant, so what a
 * light's views share is read at a constant offset (once for all lanes on
 * llvmpipe), not at the offset a pixel's cube face gives in the records'
 * order (lane by lane). A cube's faces not drawn hold its first view (their
 * centre; never sampled); no plan: zeros. */
enum { SHADOW_SLOTS = 6 };
static void upload_slots(const lm_shadow_plan *plan) {
  lm_shadow_view_data slots[LM_LIGHT_SET_MAX * SHADOW_SLOTS];
  memset(slots, 0, sizeof slots);
  int lights = plan ? plan->light_count < LM_LIGHT_SET_MAX ? plan->light_count : LM_LIGHT_SET_MAX : 0;
  for (int i = 0; i < lights; i++) {
    const int32_t *info = plan->lights[i].info;
    unsigned faces = (unsigned)plan->lights[i].cube[0];
    bool cube = info[2] == KIND_POINT;
    for (int j = 0; j < SHADOW_SLOTS; j++) {
      int v = cube ? info[0] + (faces >> j & 1 ? __builtin_popcount(faces & ((1u << j) - 1)) : 0)
                   : j < info[1] ? info[0] + j : -1;
      if (info[1] > 0 && v >= 0 && v < plan->view_count) slots[i * SHADOW_SLOTS + j] = plan->view_data[v];
    }
  }
  lm_uniform_upload(5, slots, sizeof slots, sizeof slots);
}

void lm_shadow_plan_upload(const lm_shadow_plan *plan, int light_count) {
  upload_slots(plan && plan->lights ? plan : NULL);
  if (plan && plan->lights) {
    upload(2, plan->lights, sizeof *plan->lights * (size_t)plan->light_count, sizeof *plan->lights,
           LM_LIGHT_SET_MAX);
    upload(3, plan->view_data, sizeof *plan->view_data * (size_t)(plan->view_count + plan->rsm_view_count),
           sizeof *plan->view_data, LM_LIGHT_SET_VIEWS);
    return;
  }
  lm_shadow_light_data *none = lm_alloc(sizeof *none * (size_t)(light_count + 1));
  upload(2, none, sizeof *none * (size_t)light_count, sizeof *none, LM_LIGHT_SET_MAX);
  upload(3, NULL, 0, sizeof(lm_shadow_view_data), LM_LIGHT_SET_VIEWS);
  free(none);
}

/* ---- lights whose tiles hold no back face (lm_shadow_front_lit) -------- */

/* A mesh as its draws give it: positions (8 floats a vertex, xyz first) and
 * every index its draws read, its own then its copies' (lm_mesh_lod ranges). */
typedef struct drawn_mesh {
  float *vertices;
  uint32_t *indices;
  int index_count;
  int *shell;     /* per vertex: its shell (vertices welded by position, joined by triangles) */
  int shells;
  bool closed;    /* the mesh's and its caster copies' ranges closed and consistently wound */
  bool deforms;   /* a deformed mesh's pose (read again each time) */
  bool valid;     /* every index names a vertex (else no face is taken to face any light) */
  /* The mesh's own indices, then its caster copies' (what an opaque node draws in a tile: closed_ranges
   * of them), then the camera's (a caster cut by its texture's alpha may draw them: lm_scene_draw). */
  lm_mesh_lod ranges[1 + 2 * LM_LOD_LEVELS];
  int range_count, closed_ranges;
} drawn_mesh;

static int shell_root(int *parent, int v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

static void drawn_mesh_read(const lm_scene_mesh *m, drawn_mesh *d) {
  *d = (drawn_mesh){0};
  int n = m->index_count;
  d->ranges[d->range_count++] = (lm_mesh_lod){.first = 0, .count = m->index_count};
  for (int k = 0; k < m->caster_levels; k++) d->ranges[d->range_count++] = m->casters[k];
  d->closed_ranges = d->range_count;
  for (int k = 0; k < m->lod_levels; k++) d->ranges[d->range_count++] = m->lods[k];
  for (int k = 0; k < d->range_count; k++) n = n > d->ranges[k].first + d->ranges[k].count ? n : d->ranges[k].first + d->ranges[k].count;
  d->index_count = n;
  d->vertices = lm_alloc(sizeof(float) * 8 * (size_t)(m->vertex_count + 1));
  d->indices = lm_alloc(sizeof(uint32_t) * (size_t)(n + 1));
  if (m->gpu.vao && !m->rest) /* what the GPU draws, copies included */
    lm_mesh_read(&m->gpu, d->vertices, m->vertex_count, d->indices, n);
  else {
    memcpy(d->vertices, m->vertices, sizeof(float) * 8 * (size_t)m->vertex_count);
    memcpy(d->indices, m->indices, sizeof(uint32_t) * (size_t)m->index_count);
  }
  d->deforms = m->rest != NULL;
  d->valid = true;
  for (int t = 0; t < n; t++) d->valid = d->valid && d->indices[t] < (uint32_t)m->vertex_count;
  if (d->deforms || !d->valid) return; /* a pose (this time's): its triangles alone, not taken for closed */
  int nv = m->vertex_count;
  int *weld = lm_alloc(sizeof *weld * (size_t)(nv + 1)), *parent = lm_alloc(sizeof *parent * (size_t)(nv + 1));
  lm_weld_positions(d->vertices, nv, weld);
  d->closed = n >= 3;
  for (int k = 0; k < d->closed_ranges && d->closed; k++)
    d->closed = lm_indices_closed(d->indices + d->ranges[k].first, d->ranges[k].count, weld);
  /* Shells: welded vertices joined by the triangles of every range (a copy's triangles join what the mesh's do). */
  for (int i = 0; i < nv; i++) parent[i] = weld[i];
  for (int t = 0; t + 2 < n; t += 3)
    for (int k = 1; k < 3; k++) {
      int a = shell_root(parent, weld[d->indices[t]]), b = shell_root(parent, weld[d->indices[t + k]]);
      if (a != b) parent[a < b ? b : a] = a < b ? a : b;
    }
  d->shell = lm_alloc(sizeof *d->shell * (size_t)(nv + 1));
  for (int i = 0; i < nv; i++) d->shell[i] = -1;
  for (int i = 0; i < nv; i++) {
    int r = shell_root(parent, i);
    if (d->shell[r] < 0) d->shell[r] = d->shells++;
    d->shell[i] = d->shell[r];
  }
  free(weld), free(parent);
}

static void drawn_mesh_free(drawn_mesh *d) {
  free(d->vertices), free(d->indices), free(d->shell);
}

/* Whether every face of mesh d, drawn by a node whose world matrix is m,
 * that light `l` (lm_light_data) sees nearest faces it. In the node's own
 * space: an affine map keeps which side of a plane the light is on (times
 * its determinant's sign, which a mirrored node's clockwise front faces
 * undo: engine/scene, lm_set_front_face_clockwise) and the order along a
 * ray. `solid`: the node's material is opaque (a mask's holes open it). */
static bool node_front_lit(const drawn_mesh *d, const float m[16], const lm_light_data *l, bool solid) {
  mat4 world, inv; /* aligned copies: cglm's vector loads */
  memcpy(world, m, sizeof world);
  glm_mat4_inv(world, inv);
  bool sun = l->position[3] == 2.0f;
  vec4 at = {l->position[0], l->position[1], l->position[2], 1.0f};
  if (sun) glm_vec4_copy((vec4){-l->direction[0], -l->direction[1], -l->direction[2], 0.0f}, at);
  vec4 local;
  glm_mat4_mulv(inv, at, local); /* the light's place, or the way toward it (w 0), in the node's space */
  for (int c = 0; c < 4; c++)
    if (!isfinite(local[c]) || !d->valid) return false;
  double L[3] = {local[0], local[1], local[2]};
  bool behind = false; /* a triangle faces away from the light, or edge on (either way, rounded) */
  /* An opaque node draws its mesh or a caster copy; one cut by its texture's alpha may draw a camera copy. */
  const lm_mesh_lod *last = &d->ranges[(solid ? d->closed_ranges : d->range_count) - 1];
  int end = last->first + last->count;
  for (int t = 0; t + 2 < end && !behind; t += 3) {
    const float *a = d->vertices + 8 * (size_t)d->indices[t], *b = d->vertices + 8 * (size_t)d->indices[t + 1],
                *c = d->vertices + 8 * (size_t)d->indices[t + 2];
    double u[3], v[3], n[3], w[3];
    for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = sun ? L[k] : L[k] - a[k];
    n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), ww = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (nn == 0.0) continue; /* no area */
    behind = n[0] * w[0] + n[1] * w[1] + n[2] * w[2] <= 1e-4 * nn * ww;
  }
  if (!behind) return true;
  if (!solid || !d->closed) return false;
  /* Closed: the nearest face along a ray from the light enters a shell
   * where the light lies at the shell's least winding number, outside one
   * whose faces point outward (0), inside one whose faces point inward (-1);
   * a sun, at infinity, outside all: each shell's faces must point outward.
   * Each range on its own: a node draws one of them in a tile. */
  double *wind = lm_alloc(sizeof *wind * 2 * (size_t)(d->shells + 1)), *volume = wind + d->shells + 1;
  bool front = true;
  for (int r = 0; r < d->closed_ranges && front; r++) {
    memset(wind, 0, sizeof *wind * 2 * (size_t)(d->shells + 1));
    for (int t = d->ranges[r].first; t + 2 < d->ranges[r].first + d->ranges[r].count; t += 3) {
      double p[3][3], len[3];
      for (int j = 0; j < 3; j++) {
        const float *q = d->vertices + 8 * (size_t)d->indices[t + j];
        for (int k = 0; k < 3; k++) p[j][k] = q[k] - (sun ? 0.0 : L[k]);
        len[j] = sqrt(p[j][0] * p[j][0] + p[j][1] * p[j][1] + p[j][2] * p[j][2]);
      }
      /* Six times the signed volume of the tetrahedron the triangle spans
       * with the light (summed: the shell's, with the sun at the origin),
       * and the triangle's solid angle from the light (Van Oosterom and
       * Strackee): positive where the light is behind it. */
      double triple = p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) +
                      p[0][1] * (p[1][2] * p[2][0] - p[1][0] * p[2][2]) +
                      p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
      double dot01 = p[0][0] * p[1][0] + p[0][1] * p[1][1] + p[0][2] * p[1][2];
      double dot02 = p[0][0] * p[2][0] + p[0][1] * p[2][1] + p[0][2] * p[2][2];
      double dot12 = p[1][0] * p[2][0] + p[1][1] * p[2][1] + p[1][2] * p[2][2];
      double den = len[0] * len[1] * len[2] + dot01 * len[2] + dot02 * len[1] + dot12 * len[0];
      int shell = d->shell[d->indices[t]];
      volume[shell] += triple;
      wind[shell] += sun ? 0.0 : 2.0 * atan2(triple, den);
    }
    for (int k = 0; k < d->shells && front; k++) {
      if (volume[k] == 0.0 && wind[k] == 0.0) continue; /* none of this range's triangles */
      double least = volume[k] > 0.0 ? 0.0 : -1.0, w = wind[k] / (4.0 * GLM_PI);
      front = volume[k] != 0.0 && (sun ? volume[k] > 0.0 : fabs(w - least) < 0.25);
    }
  }
  free(wind);
  return front;
}

struct lm_shadow_casters {
  drawn_mesh *meshes; /* per scene mesh, read when first needed (vertices NULL before) */
  int count;
};

void lm_shadow_casters_free(lm_shadow_casters *c) {
  for (int i = 0; c && i < c->count; i++) drawn_mesh_free(&c->meshes[i]);
  if (c) free(c->meshes);
  free(c);
}

unsigned lm_shadow_front_lit(const lm_scene *s, lm_shadow_casters **casters) {
  lm_light_data ld[LM_LIGHT_SET_MAX];
  int n = lm_scene_light_data(s, ld, LM_LIGHT_SET_MAX);
  unsigned lit = 0;
  for (int i = 0; i < n && s->light_count <= LM_LIGHT_SET_MAX; i++) lit |= (unsigned)s->lights[i].casts_shadows << i;
  lm_shadow_casters *c = *casters;
  if (lit && (!c || c->count != s->mesh_count)) {
    lm_shadow_casters_free(c);
    c = *casters = lm_alloc(sizeof *c);
    c->count = s->mesh_count;
    c->meshes = lm_alloc(sizeof *c->meshes * (size_t)(c->count + 1));
    memset(c->meshes, 0, sizeof *c->meshes * (size_t)(c->count + 1));
  }
  for (int mi = 0; mi < s->mesh_count && lit; mi++) {
    bool drawn = false;
    for (int i = 0; i < s->node_count && !drawn; i++) drawn = s->nodes[i].mesh == mi;
    if (!drawn || s->meshes[mi].vertex_count <= 0) continue;
    drawn_mesh *d = &c->meshes[mi];
    if (d->deforms) drawn_mesh_free(d), d->vertices = NULL;
    if (!d->vertices) drawn_mesh_read(&s->meshes[mi], d);
    for (int i = 0; i < s->node_count && lit; i++) {
      const lm_node *node = &s->nodes[i];
      if (node->mesh != mi) continue;
      int mat = node->material;
      bool solid = mat < 0 || mat >= s->material_count || !s->material_pbr ||
                   s->material_pbr[mat].alpha_mode == LM_ALPHA_OPAQUE;
      for (int k = 0; k < n; k++)
        if (lit >> k & 1 && !node_front_lit(d, node->world, &ld[k], solid)) lit &= ~(1u << k);
    }
  }
  return lit;
}
