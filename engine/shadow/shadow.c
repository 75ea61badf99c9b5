#include "shadow/shadow.h"

#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { KIND_NONE, KIND_CASCADES, KIND_SPOT, KIND_POINT };

int lm_shadow_technique_parse(const char *name) {
  static const char *names[] = {"esm", "pcf", "poisson", "hard"};
  for (int i = 0; i < 4; i++)
    if (!strcmp(names[i], name)) return i;
  return -1;
}

void lm_shadow_settings_default(lm_shadow_settings *s) {
  *s = (lm_shadow_settings){.technique = LM_SHADOW_ESM, .resolution = 512, .c = 90.0f, .blur = 2,
                            .cascades = 3, .lambda = 0.75f, .distance = 0.0f,
                            .blend = 0.1f, .radius = 2.5f, .stabilize = true};
  s->bias = 0.002f; /* the seed has 0: lit slanted surfaces then lose 1-2% to ESM */
}

/* An up vector that is not parallel to dir. */
static void up_for(const vec3 dir, vec3 up) {
  if (fabsf(dir[1]) < 0.99f)
    glm_vec3_copy((vec3){0, 1, 0}, up);
  else
    glm_vec3_copy((vec3){1, 0, 0}, up);
}

static int add_view(lm_shadow_plan *plan, mat4 view_proj, const float depth[4]) {
  int i = plan->view_count++;
  plan->views = lm_realloc(plan->views, sizeof *plan->views * (size_t)plan->view_count);
  plan->view_data = lm_realloc(plan->view_data, sizeof *plan->view_data * (size_t)plan->view_count);
  memcpy(plan->view_data[i].view_proj, view_proj, 64);
  memcpy(plan->view_data[i].depth, depth, 16);
  memcpy(plan->views[i].view_proj, view_proj, 64);
  memcpy(plan->views[i].depth, depth, 16);
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

static void plan_cascades(lm_shadow_plan *plan, const lm_frame_data *cam,
                          const lm_light_data *light, lm_shadow_light_data *out) {
  const lm_shadow_settings *st = &plan->settings;
  vec3 dir;
  glm_vec3_normalize_to((float *)light->direction, dir);
  float n = cam->clip[0], f = cam->clip[1];
  float reach = st->distance > 0 ? fminf(st->distance, f) : f;
  if (reach <= n) reach = n * 1.001f;
  out->info[0] = plan->view_count;
  out->info[1] = st->cascades;
  out->info[2] = KIND_CASCADES;
  for (int k = 0; k < st->cascades; k++) {
    float z0 = split_depth(n, reach, k, st->cascades, st->lambda);
    float z1 = split_depth(n, reach, k + 1, st->cascades, st->lambda);
    out->splits[k] = z1;
    vec3 corners[8], center = {0, 0, 0};
    slice_corners(cam, z0, z1, corners);
    for (int c = 0; c < 8; c++) glm_vec3_muladds(corners[c], 1.0f / 8.0f, center);
    float l, r, b, t, extent = 0;
    for (int c = 0; c < 8; c++) extent = fmaxf(extent, glm_vec3_distance(corners[c], center));
    extent = ceilf(extent * 16.0f) / 16.0f + 1e-3f;
    /* The eye sits on a plane across the light snapped to steps of extent/16,
     * so a small camera move changes no stored depth. */
    float step = extent / 16.0f, along = glm_vec3_dot(center, dir);
    float behind = along - floorf(along / step) * step; /* in [0, step) */
    vec3 up, eye;
    up_for(dir, up);
    glm_vec3_copy(center, eye);
    glm_vec3_muladds(dir, -(behind + 1.0f), eye);
    mat4 view, proj, vp;
    glm_lookat(eye, center, up, view);
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
    }
    /* Depth spans the slice's sphere only, so ESM's c acts on a short range
     * (no light leaks across a big scene); casters nearer the light than the
     * near plane are clamped onto it by depth clamping in the shadow pass. */
    float zn = 1.0f - extent, zf = 1.0f + step + extent; /* holds the sphere whatever `behind` is */
    glm_ortho(l, r, b, t, zn, zf, proj);
    glm_mat4_mul(proj, view, vp);
    if (st->stabilize) {
      /* Texel snapping: move the projection so the world origin falls on a
       * texel corner; a camera moving by less than a texel moves no edge. */
      vec4 origin = {0, 0, 0, 1}, o;
      glm_mat4_mulv(vp, origin, o);
      float half = (float)plan->tile * 0.5f;
      float dx = (roundf(o[0] * half) - o[0] * half) / half, dy = (roundf(o[1] * half) - o[1] * half) / half;
      proj[3][0] += dx, proj[3][1] += dy;
      glm_mat4_mul(proj, view, vp);
    }
    add_view(plan, vp, (float[4]){0, 0, 0, 0});
  }
}

/* Range of a point or spot light: its radius under the seed's window falloff,
 * else far enough to reach the whole scene. */
static float light_range(const lm_scene *s, const lm_light *l, const vec3 pos) {
  if (l->falloff == LM_FALLOFF_WINDOW && l->radius > 0) return l->radius;
  float bmin[3], bmax[3], range = 1e-3f;
  lm_scene_bounds(s, bmin, bmax);
  for (int c = 0; c < 8; c++) {
    vec3 p = {c & 1 ? bmax[0] : bmin[0], c & 2 ? bmax[1] : bmin[1], c & 4 ? bmax[2] : bmin[2]};
    range = fmaxf(range, glm_vec3_distance(p, (float *)pos));
  }
  return range * 1.01f;
}

static void plan_perspective(lm_shadow_plan *plan, const vec3 pos, const vec3 dir, float fov, float range) {
  vec3 up, target;
  up_for(dir, up);
  glm_vec3_add((float *)pos, (float *)dir, target);
  mat4 view, proj, vp;
  glm_lookat((float *)pos, target, up, view);
  glm_perspective(fov, 1.0f, fmaxf(range * 1e-4f, 1e-5f), range, proj);
  glm_mat4_mul(proj, view, vp);
  add_view(plan, vp, (float[4]){pos[0], pos[1], pos[2], 1.0f / range});
}

static void plan_light(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam, int i,
                       const lm_light_data *ld) {
  const lm_light *l = &s->lights[i];
  lm_shadow_light_data *out = &plan->lights[i];
  memset(out, 0, sizeof *out);
  out->info[3] = plan->settings.technique;
  out->params[0] = plan->settings.c;
  out->params[1] = plan->settings.bias;
  out->params[2] = plan->settings.blend;
  out->params[3] = plan->settings.radius;
  if (!l->casts_shadows) return;
  if (l->type == LM_LIGHT_DIRECTIONAL) {
    plan_cascades(plan, cam, ld, out);
    return;
  }
  vec3 pos = {ld->position[0], ld->position[1], ld->position[2]};
  vec3 dir = {ld->direction[0], ld->direction[1], ld->direction[2]};
  float range = light_range(s, l, pos);
  out->info[0] = plan->view_count;
  if (l->type == LM_LIGHT_SPOT) {
    out->info[1] = 1;
    out->info[2] = KIND_SPOT;
    float fov = fminf(2.0f * l->outer_cone * 1.05f + 0.02f, glm_rad(170.0f));
    plan_perspective(plan, pos, dir, fov, range);
    return;
  }
  /* Point light: cube faces +X -X +Y -Y +Z -Z (shadow.glsl picks by major axis). */
  static const float faces[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  out->info[1] = 6;
  out->info[2] = KIND_POINT;
  for (int f = 0; f < 6; f++) plan_perspective(plan, pos, faces[f], GLM_PI_2f, range);
}

bool lm_shadow_plan_make(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *cam,
                         const lm_shadow_settings *settings, lm_error *err) {
  *plan = (lm_shadow_plan){.settings = *settings};
  const lm_shadow_settings *st = settings;
  if (st->resolution < 16 || st->resolution > 8192 || st->cascades < 1 || st->cascades > 4 ||
      !(st->c > 0 && st->c <= 10000) || st->blur < 0 || st->blur > 32 || !(st->lambda >= 0 && st->lambda <= 1) ||
      !(fabsf(st->bias) < 1) || !(st->distance >= 0) || !(st->blend >= 0 && st->blend <= 1) ||
      !(st->radius >= 0 && st->radius <= 32) || (unsigned)st->technique > LM_SHADOW_HARD) {
    lm_error_set(err, "shadow settings out of range");
    return false;
  }
  plan->tile = st->resolution;
  plan->light_count = s->light_count;
  plan->lights = lm_alloc(sizeof *plan->lights * (size_t)(s->light_count + 1));
  lm_light_data *ld = lm_alloc(sizeof *ld * (size_t)(s->light_count + 1));
  lm_scene_light_data(s, ld, s->light_count);
  for (int i = 0; i < s->light_count; i++) plan_light(plan, s, cam, i, &ld[i]);
  free(ld);
  if (plan->view_count == 0) return true;
  /* Tiles in a near-square grid, shrunk to fit the GL limit if needed. */
  plan->columns = (int)ceil(sqrt((double)plan->view_count));
  plan->rows = (plan->view_count + plan->columns - 1) / plan->columns;
  int max = 16384;
  while (plan->tile * plan->columns > max || plan->tile * plan->rows > max) plan->tile /= 2;
  plan->atlas_width = plan->tile * plan->columns;
  plan->atlas_height = plan->tile * plan->rows;
  for (int v = 0; v < plan->view_count; v++) {
    int cx = v % plan->columns, cy = v / plan->columns;
    plan->views[v].x = cx * plan->tile;
    plan->views[v].y = cy * plan->tile;
    plan->views[v].width = plan->views[v].height = plan->tile;
    float *rect = plan->view_data[v].rect;
    rect[0] = (float)cx / (float)plan->columns;
    rect[1] = (float)cy / (float)plan->rows;
    rect[2] = 1.0f / (float)plan->columns;
    rect[3] = 1.0f / (float)plan->rows;
  }
  return true;
}

void lm_shadow_plan_free(lm_shadow_plan *plan) {
  free(plan->views);
  free(plan->view_data);
  free(plan->lights);
  *plan = (lm_shadow_plan){0};
}

void lm_shadow_plan_upload(const lm_shadow_plan *plan, int light_count) {
  if (plan && plan->lights) {
    lm_storage_upload(2, plan->lights, sizeof *plan->lights * (size_t)plan->light_count);
    lm_storage_upload(3, plan->view_data, sizeof *plan->view_data * (size_t)plan->view_count);
    return;
  }
  lm_shadow_light_data *none = lm_alloc(sizeof *none * (size_t)(light_count + 1));
  lm_storage_upload(2, none, sizeof *none * (size_t)light_count);
  lm_storage_upload(3, NULL, 0);
  free(none);
}
