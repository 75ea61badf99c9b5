#include "scene/scene_internal.h"

#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lm_scene *lm_scene_create(const char *name) {
  lm_scene *s = lm_alloc(sizeof *s);
  snprintf(s->name, sizeof s->name, "%s", name);
  s->animation = LM_ANIM_NONE;
  return s;
}

/* The animation data's memory and node references (scene_internal.h): the
 * scene owns them; anim.c only evaluates them. */
void lm_scene_mesh_free_deform(lm_scene_mesh *m) {
  free(m->rest);
  free(m->prev_positions);
  free(m->target_positions);
  free(m->target_normals);
  free(m->default_weights);
  free(m->joints);
  free(m->joint_weights);
}

void lm_scene_free_animations(lm_scene *s) {
  for (int a = 0; a < s->animation_count; a++) {
    for (int c = 0; c < s->animations[a].channel_count; c++) {
      free(s->animations[a].channels[c].times);
      free(s->animations[a].channels[c].values);
    }
    free(s->animations[a].channels);
  }
  free(s->animations);
  for (int k = 0; k < s->skin_count; k++) {
    free(s->skins[k].joints);
    free(s->skins[k].inverse_bind);
  }
  free(s->skins);
}

void lm_scene_shift_animation_nodes(lm_scene *s, int from, int by) {
  for (int a = 0; a < s->animation_count; a++)
    for (int c = 0; c < s->animations[a].channel_count; c++)
      if (s->animations[a].channels[c].node >= from) s->animations[a].channels[c].node += by;
  for (int k = 0; k < s->skin_count; k++)
    for (int j = 0; j < s->skins[k].joint_count; j++)
      if (s->skins[k].joints[j] >= from) s->skins[k].joints[j] += by;
}

/* Frees each array the scene owns, one by one: destroy functions read alike. */
void lm_scene_destroy(lm_scene *s) {
  if (!s) return;
  lm_scene_drop_meshes(s); /* its threads read the meshes */
  for (int i = 0; i < s->mesh_count; i++) {
    lm_mesh_destroy(&s->meshes[i].gpu); /* none made: nothing to do */
    free(s->meshes[i].vertices);
    free(s->meshes[i].tangents);
    free(s->meshes[i].indices);
    free(s->meshes[i].chunks);
    lm_scene_mesh_free_deform(&s->meshes[i]);
  }
  for (int i = 0; i < s->node_count; i++) free(s->nodes[i].weights);
  lm_scene_free_animations(s);
  for (int i = 0; i < s->texture_count; i++) {
    lm_texture_destroy(&s->textures[i].gpu);
    free(s->textures[i].rgba);
  }
  free(s->textures);
  free(s->nodes);
  free(s->meshes);
  free(s->materials);
  free(s->material_pbr);
  free(s->lights);
  free(s->cameras);
  free(s);
}

int lm_scene_add_material(lm_scene *s, const lm_material *m) {
  int cap = s->material_cap; /* material_pbr keeps material_cap entries, zeroed when new */
  *LM_PUSH(s->materials, s->material_count, s->material_cap) = *m;
  s->material_pbr = lm_grow(s->material_pbr, &cap, s->material_cap, sizeof *s->material_pbr);
  return s->material_count - 1;
}

int lm_scene_add_mesh(lm_scene *s, const char *name, const float *vertices, int vertex_count,
                      const uint32_t *indices, int index_count) {
  lm_scene_mesh *m = LM_PUSH(s->meshes, s->mesh_count, s->mesh_cap);
  snprintf(m->name, sizeof m->name, "%s", name);
  m->vertices = memcpy(lm_alloc(sizeof(float) * 8 * (size_t)vertex_count), vertices,
                       sizeof(float) * 8 * (size_t)vertex_count);
  m->indices = memcpy(lm_alloc(sizeof(uint32_t) * (size_t)index_count), indices,
                      sizeof(uint32_t) * (size_t)index_count);
  m->vertex_count = vertex_count;
  m->index_count = index_count;
  glm_vec3_fill(m->bounds[0], vertex_count ? FLT_MAX : 0);
  glm_vec3_fill(m->bounds[1], vertex_count ? -FLT_MAX : 0);
  for (int i = 0; i < vertex_count; i++) {
    const float *p = vertices + (size_t)i * 8;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
    glm_vec3_minv(m->bounds[0], (float *)p, m->bounds[0]);
    glm_vec3_maxv(m->bounds[1], (float *)p, m->bounds[1]);
  }
  return s->mesh_count - 1;
}

void lm_scene_mesh_set_tangents(lm_scene *s, int mesh, const float *tangents) {
  lm_scene_mesh *m = &s->meshes[mesh];
  size_t size = sizeof(float) * 4 * (size_t)m->vertex_count;
  free(m->tangents);
  m->tangents = memcpy(lm_alloc(size + 1), tangents, size);
}

int lm_scene_add_texture(lm_scene *s, const char *name, int width, int height, unsigned char *rgba) {
  lm_scene_texture *t = LM_PUSH(s->textures, s->texture_count, s->texture_cap);
  snprintf(t->name, sizeof t->name, "%s", name);
  t->width = width, t->height = height, t->rgba = rgba;
  return s->texture_count - 1;
}

int lm_scene_find_material(const lm_scene *s, const char *name) {
  for (int i = 0; i < s->material_count; i++)
    if (!strcmp(s->materials[i].name, name)) return i;
  return -1;
}

int lm_scene_find_node(const lm_scene *s, const char *name) {
  for (int i = 0; i < s->node_count; i++)
    if (!strcmp(s->nodes[i].name, name)) return i;
  return -1;
}

int lm_scene_add_node(lm_scene *s, const char *name, int parent, const float local[16], int mesh,
                      int material) {
  lm_node *n = LM_PUSH(s->nodes, s->node_count, s->node_cap);
  snprintf(n->name, sizeof n->name, "%s", name);
  n->parent = parent;
  memcpy(n->local, local, sizeof n->local);
  n->mesh = mesh;
  n->material = material;
  n->skin = -1;
  n->rotation[3] = n->scale[0] = n->scale[1] = n->scale[2] = 1; /* an identity T * R * S (trs stays false) */
  return s->node_count - 1;
}

int lm_scene_add_light(lm_scene *s, const lm_light *l) {
  *LM_PUSH(s->lights, s->light_count, s->light_cap) = *l;
  return s->light_count - 1;
}

int lm_scene_add_camera(lm_scene *s, const lm_camera *c) {
  *LM_PUSH(s->cameras, s->camera_count, s->camera_cap) = *c;
  return s->camera_count - 1;
}

int lm_scene_add_root(lm_scene *s, const char *name, const float local[16]) {
  LM_PUSH(s->nodes, s->node_count, s->node_cap);
  memmove(s->nodes + 1, s->nodes, sizeof *s->nodes * (size_t)(s->node_count - 1));
  for (int i = 1; i < s->node_count; i++) s->nodes[i].parent = s->nodes[i].parent >= 0 ? s->nodes[i].parent + 1 : 0;
  for (int i = 0; i < s->light_count; i++) s->lights[i].node += s->lights[i].node >= 0;
  for (int i = 0; i < s->camera_count; i++) s->cameras[i].node += s->cameras[i].node >= 0;
  lm_scene_shift_animation_nodes(s, 0, 1);
  lm_node *n = &s->nodes[0];
  memset(n, 0, sizeof *n);
  snprintf(n->name, sizeof n->name, "%s", name);
  n->parent = -1;
  memcpy(n->local, local, sizeof n->local);
  n->mesh = n->material = n->skin = -1;
  n->rotation[3] = n->scale[0] = n->scale[1] = n->scale[2] = 1;
  lm_scene_update(s);
  return 0;
}

/* The node's matrices are plain float[16] at any alignment; cglm's SIMD
 * product loads aligned, so it works on aligned copies. */
void lm_scene_node_set_world(lm_scene *s, int node, const float world[16]) {
  if (node < 0 || node >= s->node_count) return;
  lm_node *n = &s->nodes[node];
  if (n->parent >= 0 && n->parent < node) {
    mat4 parent, inv, w, local; /* aligned copies: cglm's SSE loads need them */
    memcpy(parent, s->nodes[n->parent].world, sizeof parent);
    memcpy(w, world, sizeof w);
    glm_mat4_inv(parent, inv);
    glm_mat4_mul(inv, w, local);
    memcpy(n->local, local, sizeof n->local);
  } else {
    memcpy(n->local, world, sizeof n->local);
  }
  lm_scene_update(s);
}

void lm_scene_update(lm_scene *s) {
  for (int i = 0; i < s->node_count; i++) {
    lm_node *n = &s->nodes[i];
    if (n->parent >= 0 && n->parent < i) {
      mat4 parent, local, world;
      memcpy(parent, s->nodes[n->parent].world, sizeof parent);
      memcpy(local, n->local, sizeof local);
      glm_mat4_mul(parent, local, world);
      memcpy(n->world, world, sizeof n->world);
    } else {
      memcpy(n->world, n->local, sizeof n->world);
    }
  }
}

bool lm_scene_bounds(const lm_scene *s, float min[3], float max[3]) {
  glm_vec3_fill(min, FLT_MAX);
  glm_vec3_fill(max, -FLT_MAX);
  for (int i = 0; i < s->node_count; i++) { /* scripts and shadow plans ask each frame: one product a node */
    float lo[3], hi[3];
    if (!lm_scene_node_bounds(s, i, lo, hi)) continue; /* no mesh, or no finite box */
    glm_vec3_minv(min, lo, min);
    glm_vec3_maxv(max, hi, max);
  }
  if (min[0] > max[0]) {
    glm_vec3_fill(min, -1);
    glm_vec3_fill(max, 1);
    return false;
  }
  return true;
}

int lm_scene_add_framing_camera(lm_scene *s, const char *name, float aspect) {
  vec3 lo, hi, c;
  lm_scene_bounds(s, lo, hi);
  glm_vec3_center(lo, hi, c);
  const float fov = glm_rad(45.0f), pitch = glm_rad(20.0f), margin = 1.05f;
  vec3 fwd = {0, -sinf(pitch), -cosf(pitch)}, right = {1, 0, 0}, up = {0, cosf(pitch), -sinf(pitch)};
  float ty = tanf(fov / 2), tx = ty * (aspect > 0 && isfinite(aspect) ? aspect : 1.0f);
  /* Eye at c - D fwd: a corner q (from c) lies at depth D + q.fwd; it is in
   * view when |q.right| <= tx depth and |q.up| <= ty depth. */
  float dist = 0, zmin = FLT_MAX, zmax = -FLT_MAX, extent = glm_vec3_distance(lo, hi);
  for (int k = 0; k < 8; k++) {
    vec3 q = {(k & 1 ? hi : lo)[0] - c[0], (k & 2 ? hi : lo)[1] - c[1], (k & 4 ? hi : lo)[2] - c[2]};
    float x = glm_vec3_dot(q, right), y = glm_vec3_dot(q, up), z = glm_vec3_dot(q, fwd);
    dist = fmaxf(dist, fmaxf(margin * fabsf(x) / tx, margin * fabsf(y) / ty) - z);
    zmin = fminf(zmin, z), zmax = fmaxf(zmax, z);
  }
  /* In front of the eye even when flat, and never at the centre itself. */
  dist = fmaxf(dist, fmaxf(-zmin, 0) + 1e-3f * fmaxf(extent, 1e-3f));
  float world[16] = {0};
  for (int i = 0; i < 3; i++) {
    world[i] = right[i], world[4 + i] = up[i], world[8 + i] = -fwd[i];
    world[12 + i] = c[i] - fwd[i] * dist;
  }
  world[15] = 1;
  lm_camera cam = {.fov_y = fov, .znear = fmaxf(0.5f * (dist + zmin), 1e-4f * dist), .zfar = 1.5f * (dist + zmax)};
  snprintf(cam.name, sizeof cam.name, "%s", name);
  cam.node = lm_scene_add_node(s, name, -1, world, -1, -1);
  lm_scene_update(s);
  return lm_scene_add_camera(s, &cam);
}

/* The determinant of a world transform's 3 x 3 part (column-major; the
 * nodes' world arrays are not aligned for cglm's mat3). */
static double world_det3(const float w[16]) {
  return (double)w[0] * ((double)w[5] * w[10] - (double)w[9] * w[6]) -
         (double)w[4] * ((double)w[1] * w[10] - (double)w[9] * w[2]) +
         (double)w[8] * ((double)w[1] * w[6] - (double)w[5] * w[2]);
}

bool lm_scene_camera_invertible(const lm_scene *s, int cam) {
  if (cam < 0 || cam >= s->camera_count || s->cameras[cam].node < 0) return true;
  return fabs(world_det3(s->nodes[s->cameras[cam].node].world)) > 1e-24;
}

bool lm_scene_camera_check(const lm_scene *s, int cam, lm_error *err) {
  if (cam < 0 || cam >= s->camera_count) return true;
  const lm_camera *c = &s->cameras[cam];
  if (c->ortho[0] > 0 || c->ortho[1] > 0) {
    lm_error_set(err, "camera '%s' (%d) is orthographic (xmag %g, ymag %g): the passes rebuild positions "
                 "from depth along rays from one eye and cannot take it; give the view a perspective camera "
                 "(or --camera auto)", c->name, cam, (double)c->ortho[0], (double)c->ortho[1]);
    return false;
  }
  if (!lm_scene_camera_invertible(s, cam)) { /* the view, its inverse, would be inf or NaN: an empty frame */
    lm_error_set(err, "camera '%s' (%d) on node '%s': posed with (near) zero scale (an animation scales it or a "
                 "node above it to zero), its world transform cannot be inverted into a view", c->name, cam,
                 s->nodes[c->node].name);
    return false;
  }
  return true;
}

bool lm_scene_upload_texture(lm_scene *s, int i, lm_error *err) {
  lm_scene_texture *t = &s->textures[i];
  if (t->gpu.id) return true;
  if (!lm_texture_upload_rgba8(&t->gpu, t->width, t->height, t->rgba, !t->linear, t->name, err)) return false;
  if (s->gpu_only) free(t->rgba), t->rgba = NULL;
  return true;
}

void lm_scene_upload_mesh(lm_scene *s, int i) {
  lm_scene_mesh *m = &s->meshes[i];
  if (m->gpu.vao || m->simplifying) return;
  m->caster_levels = m->lod_levels = 0;
  if (!m->rest && m->index_count / 3 >= LM_LOD_MIN_TRIANGLES) { /* a deformed mesh moves its vertices */
    m->simplifying = true;
    lm_scene_simplify_mesh(s, i);
    return;
  }
  float *welded = m->rest ? NULL : lm_welded_vertices(m->vertices, m->vertex_count);
  lm_mesh_create(&m->gpu, welded ? welded : m->vertices, m->vertex_count, m->tangents, m->indices, m->index_count,
                 m->rest != NULL);
  free(welded);
  lm_scene_mesh_uploaded(s, i);
}

bool lm_scene_upload(lm_scene *s, lm_error *err) {
  if (s->uploaded) return true;
  for (int i = 0; i < s->texture_count; i++) {
    lm_scene_texture *t = &s->textures[i];
    if (t->gpu.id) continue; /* uploaded as the file was read (lm_scene_load_gpu) */
    if (!lm_texture_upload_rgba8(&t->gpu, t->width, t->height, t->rgba, !t->linear, t->name, err)) {
      for (int k = 0; k < i; k++)
        if (s->textures[k].rgba) lm_texture_destroy(&s->textures[k].gpu);
      lm_error_prefix(err, "scene '%s'", s->name);
      return false;
    }
  }
  for (int i = 0; s->gpu_only && i < s->texture_count; i++) { /* after all: a failed upload keeps them */
    free(s->textures[i].rgba);
    s->textures[i].rgba = NULL;
  }
  double t0 = lm_now_ms();
  long whole = 0, casters = 0, camera = 0;
  int simplified = 0;
  for (int i = 0; i < s->mesh_count; i++) lm_scene_upload_mesh(s, i);
  lm_scene_finish_meshes(s);
  for (int i = 0; i < s->mesh_count; i++) {
    const lm_scene_mesh *m = &s->meshes[i];
    if (m->caster_levels || m->lod_levels) {
      simplified++, whole += m->index_count / 3;
      casters += m->caster_levels ? m->casters[m->caster_levels - 1].count / 3 : m->index_count / 3;
      camera += m->lod_levels ? m->lods[m->lod_levels - 1].count / 3 : m->index_count / 3;
    }
  }
  if (simplified)
    lm_debug("scene '%s': %d meshes simplified, %ld triangles to %ld at the coarsest caster level, %ld at the "
             "camera's (%.0f ms)", s->name, simplified, whole, casters, camera, lm_now_ms() - t0);
  s->uploaded = true;
  return true;
}

void lm_scene_restore_geometry(lm_scene *s) {
  for (int i = 0; s->uploaded && i < s->mesh_count; i++) {
    lm_scene_mesh *m = &s->meshes[i];
    if (m->vertices) continue;
    m->vertices = lm_alloc(sizeof(float) * 8 * (size_t)m->vertex_count);
    m->indices = lm_alloc(sizeof(uint32_t) * (size_t)m->index_count);
    lm_mesh_read(&m->gpu, m->vertices, m->vertex_count, m->indices, m->index_count);
  }
}

int lm_scene_upload_deformed(lm_scene *s) {
  if (!s->uploaded) return 0;
  int changed = 0;
  for (int i = 0; i < s->mesh_count; i++) {
    lm_scene_mesh *m = &s->meshes[i];
    if (!m->dirty) {
      lm_mesh_set_prev_positions(&m->gpu, NULL, m->vertex_count);
      continue;
    }
    lm_mesh_update_vertices(&m->gpu, m->vertices, m->vertex_count);
    lm_mesh_set_prev_positions(&m->gpu, m->prev_positions, m->vertex_count);
    m->dirty = false;
    changed++;
  }
  return changed;
}

bool lm_scene_reload_materials(lm_scene *s, const lm_scene *from, lm_error *err) {
  bool same = s->node_count == from->node_count;
  for (int i = 0; i < s->node_count && same; i++) same = s->nodes[i].mesh == from->nodes[i].mesh;
  if (!same) {
    lm_error_set(err, "scene '%s': the file's nodes changed (%d now, %d before): reload the whole scene",
                 s->name, from->node_count, s->node_count);
    return false;
  }
  lm_scene_texture *textures = lm_alloc(sizeof *textures * (size_t)(from->texture_count + 1));
  for (int i = 0; i < from->texture_count; i++) {
    const lm_scene_texture *t = &from->textures[i];
    size_t bytes = (size_t)t->width * t->height * 4;
    textures[i] = (lm_scene_texture){.width = t->width, .height = t->height, .linear = t->linear,
                                     .rgba = memcpy(lm_alloc(bytes), t->rgba, bytes)};
    memcpy(textures[i].name, t->name, sizeof t->name);
    if (s->uploaded &&
        !lm_texture_upload_rgba8(&textures[i].gpu, t->width, t->height, t->rgba, !t->linear, t->name, err)) {
      for (int k = 0; k <= i; k++) {
        if (k < i) lm_texture_destroy(&textures[k].gpu);
        free(textures[k].rgba);
      }
      free(textures);
      return false;
    }
  }
  for (int i = 0; i < s->texture_count; i++) {
    if (s->uploaded) lm_texture_destroy(&s->textures[i].gpu);
    free(s->textures[i].rgba);
  }
  free(s->textures);
  s->textures = textures;
  s->texture_count = from->texture_count;
  s->texture_cap = from->texture_count + 1;
  free(s->materials);
  free(s->material_pbr);
  s->material_pbr = memcpy(lm_alloc(sizeof *s->material_pbr * (size_t)(from->material_count + 1)),
                           from->material_pbr, sizeof *s->material_pbr * (size_t)from->material_count);
  s->materials = memcpy(lm_alloc(sizeof *s->materials * (size_t)(from->material_count + 1)), from->materials,
                        sizeof *s->materials * (size_t)from->material_count);
  s->material_count = from->material_count;
  s->material_cap = from->material_count + 1;
  for (int i = 0; i < s->node_count; i++) s->nodes[i].material = from->nodes[i].material;
  return true;
}

static void node_position(const lm_scene *s, int node, vec3 out) {
  const float *w = s->nodes[node].world;
  out[0] = w[12], out[1] = w[13], out[2] = w[14];
}

/* The node's -Z axis in world space, normalized (unit Z fallback for a degenerate matrix). */
static void node_forward(const lm_scene *s, int node, vec3 out) {
  const float *w = s->nodes[node].world;
  vec3 f = {-w[8], -w[9], -w[10]};
  float len = glm_vec3_norm(f);
  if (len > 1e-20f) {
    glm_vec3_scale(f, 1.0f / len, out);
  } else {
    out[0] = 0, out[1] = 0, out[2] = -1;
  }
}

void lm_scene_frame_data(const lm_scene *s, int cam, int width, int height, lm_frame_data *out) {
  memset(out, 0, sizeof *out);
  lm_camera c = {.fov_y = glm_rad(45.0f), .znear = 0.1f, .zfar = 100.0f, .node = -1};
  if (cam >= 0 && cam < s->camera_count) c = s->cameras[cam];
  mat4 world = GLM_MAT4_IDENTITY_INIT, view, proj, vp, inv_view;
  if (c.node >= 0) memcpy(world, s->nodes[c.node].world, sizeof world);
  /* A camera under a scaled node (a scene exported in another unit) keeps a
   * rigid view; near and far are in its node's units, so they scale with it.
   * Under a mirrored node (negative determinant) it keeps its eye, direction
   * and up and sees the scene unmirrored, its x axis y cross z again: a
   * mirrored view would flip the image and turn every triangle's winding. */
  float det = glm_mat4_det(world), scale = cbrtf(fabsf(det));
  if (isfinite(scale) && scale > 0 && (fabsf(scale - 1.0f) > 1e-6f || det < 0)) {
    for (int k = 0; k < 3; k++) glm_vec3_normalize(world[k]);
    if (det < 0) glm_vec3_cross(world[1], world[2], world[0]);
    c.znear *= scale, c.zfar *= scale;
  }
  /* Keep the projection invertible whatever a scene file says; any unit and
   * any near/far ratio up to 1e12 (reversed float depth keeps them apart). */
  c.fov_y = isfinite(c.fov_y) ? glm_clamp(c.fov_y, 1e-4f, GLM_PIf - 1e-3f) : glm_rad(45.0f);
  bool far_ok = isfinite(c.zfar) && c.zfar > 0 && c.zfar < 1e30f;
  if (!(isfinite(c.znear) && c.znear > 0 && c.znear < 1e30f)) c.znear = far_ok ? c.zfar * 1e-4f : 0.1f;
  c.znear = fmaxf(c.znear, far_ok ? c.zfar * 1e-12f : 1e-30f);
  c.zfar = far_ok && c.zfar > c.znear * 1.001f ? c.zfar : c.znear * 1.001f;
  /* The output's aspect, whatever the camera's aspectRatio says: glTF's is
   * the camera's own, and an output of another shape keeps fov_y and sees
   * more or less at the sides, as Blender (and so a Cycles reference) does,
   * rather than stretching the image. */
  float aspect = (float)(width > 0 ? width : 1) / (float)(height > 0 ? height : 1);
  glm_mat4_inv(world, view);
  /* Reversed depth (near 1, far 0, with glClipControl's 0..1 range: gfx
   * lm_set_scene_state): float depth then keeps the same relative precision
   * at every distance, where the usual mapping rounds far depths together. */
  glm_perspective(c.fov_y, aspect, c.znear, c.zfar, proj);
  proj[2][2] = c.znear / (c.zfar - c.znear);
  proj[3][2] = c.znear * c.zfar / (c.zfar - c.znear);
  glm_mat4_mul(proj, view, vp);
  glm_mat4_inv(view, inv_view);
  memcpy(out->view, view, 64);
  memcpy(out->proj, proj, 64);
  memcpy(out->view_proj, vp, 64);
  memcpy(out->inv_view, inv_view, 64);
  vec3 pos = {inv_view[3][0], inv_view[3][1], inv_view[3][2]};
  memcpy(out->camera_pos, pos, 12);
  out->camera_pos[3] = 1;
  /* Rays from the eye to the far plane's corners (seed 000, eq 23-24): a
   * pixel's position is camera_pos + (o + u*x + v*y) * (linear depth / far). */
  float t = tanf(c.fov_y * 0.5f), fy = c.zfar * t, fx = fy * aspect;
  vec3 right = {inv_view[0][0], inv_view[0][1], inv_view[0][2]};
  vec3 up = {inv_view[1][0], inv_view[1][1], inv_view[1][2]};
  vec3 back = {inv_view[2][0], inv_view[2][1], inv_view[2][2]};
  for (int i = 0; i < 3; i++) {
    out->frustum_o[i] = -back[i] * c.zfar - right[i] * fx - up[i] * fy;
    out->frustum_u[i] = right[i] * 2 * fx;
    out->frustum_v[i] = up[i] * 2 * fy;
  }
  out->exposure[0] = out->exposure[1] = out->exposure[2] = out->exposure[3] = 1; /* none: the renderer's */
  out->clip[0] = c.znear;
  out->clip[1] = c.zfar;
  out->clip[2] = 1.0f / c.zfar;
  out->clip[3] = t;
  out->output_size[0] = (float)width;
  out->output_size[1] = (float)height;
  out->output_size[2] = 1.0f / (float)(width > 0 ? width : 1);
  out->output_size[3] = 1.0f / (float)(height > 0 ? height : 1);
  out->counts[0] = s->light_count;
}

float lm_light_falloff(lm_falloff f, float d, float radius) {
  if (f == LM_FALLOFF_NONE) return 1.0f;
  float inv_d2 = 1.0f / fmaxf(d * d, 1e-8f);
  if (f == LM_FALLOFF_INVERSE_SQUARE) return inv_d2;
  if (f == LM_FALLOFF_RANGE) {
    if (!(radius > 0)) return inv_d2;
    float q = d / radius;
    q *= q;
    return glm_clamp(1.0f - q * q, 0.0f, 1.0f) * inv_d2;
  }
  float r = fmaxf(radius, 1e-12f), q = d / r;
  return glm_clamp(1.0f - q * q, 0.0f, 1.0f);
}

float lm_light_reach(const lm_light *l) {
  if (l->type == LM_LIGHT_DIRECTIONAL) return INFINITY;
  switch (l->falloff) {
  case LM_FALLOFF_WINDOW: return fmaxf(l->radius, 0.0f);
  case LM_FALLOFF_RANGE: return l->radius > 0 ? l->radius : INFINITY;
  default: return INFINITY;
  }
}

int lm_scene_light_data(const lm_scene *s, lm_light_data *out, int max) {
  int n = s->light_count < max ? s->light_count : max;
  for (int i = 0; i < n; i++) {
    const lm_light *l = &s->lights[i];
    lm_light_data *d = &out[i];
    memset(d, 0, sizeof *d);
    vec3 pos = {0, 0, 0}, dir = {0, 0, -1};
    if (l->node >= 0) {
      node_position(s, l->node, pos);
      node_forward(s, l->node, dir);
    }
    memcpy(d->position, pos, 12);
    d->position[3] = (float)l->type;
    memcpy(d->direction, dir, 12);
    d->direction[3] = cosf(l->outer_cone);
    for (int c = 0; c < 3; c++) d->color[c] = l->color[c] * l->power;
    d->color[3] = l->radius;
    d->params[0] = cosf(l->inner_cone);
    d->params[1] = (float)l->falloff;
  }
  return n;
}

/* Per slot (lm_texture_slot): the sampler, its KHR_texture_transform and the
 * define that turns its use on in a material technique. */
static const char *const slot_sampler[LM_TEX_SLOTS] = {"base_color_tex", "mr_tex", "normal_tex", "occlusion_tex",
                                                        "emissive_tex"};
static const char *const slot_xform[LM_TEX_SLOTS] = {"base_color_xform", "mr_xform", "normal_xform",
                                                      "occlusion_xform", "emissive_xform"};
static const char *const slot_define[LM_TEX_SLOTS] = {"BASE_COLOR_TEXTURE", "MR_TEXTURE", "NORMAL_TEXTURE",
                                                       "OCCLUSION_TEXTURE", "EMISSIVE_TEXTURE"};

static const char *scene_uniforms[] = {"material_color", "material_rho", "material_k",
                                       "material_reflectivity", "material_pbr", "material_emissive", "material_alpha",
                                       "material_glass", "material_attenuation", "base_color_tex",
                                       "mr_tex", "normal_tex", "occlusion_tex", "emissive_tex", "base_color_xform",
                                       "mr_xform", "normal_xform", "occlusion_xform", "emissive_xform"};

bool lm_scene_owns_uniform(const char *name) {
  for (size_t i = 0; i < sizeof scene_uniforms / sizeof *scene_uniforms; i++)
    if (!strcmp(scene_uniforms[i], name)) return true;
  return false;
}

static bool material_blends(const lm_scene *s, int material) {
  return material >= 0 && material < s->material_count && s->material_pbr[material].set &&
         s->material_pbr[material].alpha_mode == LM_ALPHA_BLEND;
}

bool lm_scene_has_blend(const lm_scene *s) {
  for (int i = 0; i < s->node_count; i++)
    if (s->nodes[i].mesh >= 0 && material_blends(s, s->nodes[i].material)) return true;
  return false;
}

bool lm_scene_reflective(const lm_scene *s) {
  for (int i = 0; i < s->node_count; i++)
    if (s->nodes[i].mesh >= 0 && lm_scene_node_material(s, &s->nodes[i])->reflectivity > 0) return true;
  return false;
}

const lm_material *lm_scene_node_material(const lm_scene *s, const lm_node *n) {
  static const lm_material fallback = {"default", {0.8f, 0.8f, 0.8f}, 0.8f, 0.1f, 0.9f, 0.0f, 16.0f, 0, 0};
  return n->material >= 0 && n->material < s->material_count ? &s->materials[n->material] : &fallback;
}

/* ---- material parameters ------------------------------------------------ */
static const struct {
  const char *name;
  int count;
} material_params[] = {{"color", 3}, {"rho", 1}, {"ka", 1}, {"kd", 1}, {"ks", 1}, {"shininess", 1},
                       {"reflectivity", 1}};
enum { MATERIAL_PARAM_COUNT = sizeof material_params / sizeof *material_params };

const char *lm_material_param_list(void) { return "color, rho, ka, kd, ks, shininess, reflectivity"; }

static int material_param_index(const char *name) {
  for (int i = 0; i < MATERIAL_PARAM_COUNT; i++)
    if (!strcmp(material_params[i].name, name)) return i;
  return -1;
}

bool lm_scene_check_params(const lm_scene *s, const lm_material_param *params, int count, lm_error *err) {
  for (int i = 0; i < count; i++) {
    const lm_material_param *p = &params[i];
    if (lm_scene_find_material(s, p->material) < 0) {
      lm_buf names = {0};
      for (int k = 0; k < s->material_count && k < 24; k++)
        lm_buf_printf(&names, "%s%s", k ? ", " : "", s->materials[k].name);
      if (s->material_count > 24) lm_buf_printf(&names, ", ...");
      lm_error_set(err, "material '%s': scene '%s' has no material of that name (it has: %s)", p->material,
                   s->name, names.data ? names.data : "none");
      lm_buf_free(&names);
      return false;
    }
    int k = material_param_index(p->name);
    if (k < 0) {
      lm_error_set(err, "material '%s': unknown parameter '%s' (known: %s)", p->material, p->name,
                   lm_material_param_list());
      return false;
    }
    if (p->count != material_params[k].count) {
      lm_error_set(err, "material '%s': parameter '%s' takes %d number%s, not %d", p->material, p->name,
                   material_params[k].count, material_params[k].count == 1 ? "" : "s", p->count);
      return false;
    }
    for (int c = 0; c < p->count; c++)
      if (!isfinite(p->v[c])) {
        lm_error_set(err, "material '%s': parameter '%s' is not finite", p->material, p->name);
        return false;
      }
  }
  return true;
}

static void apply_param(lm_material *m, const lm_material_param *p) {
  switch (material_param_index(p->name)) {
  case 0: memcpy(m->color, p->v, sizeof m->color); break;
  case 1: m->rho = p->v[0]; break;
  case 2: m->ka = p->v[0]; break;
  case 3: m->kd = p->v[0]; break;
  case 4: m->ks = p->v[0]; break;
  case 5: m->shininess = p->v[0]; break;
  case 6: m->reflectivity = p->v[0]; break;
  default: break;
  }
}

/* ---- drawing ------------------------------------------------------------ */
/* All 8 corners beyond the same clip plane (x, y, z against +-w); with
 * `pancake`, z < -w (before an orthographic tile's near plane) does not count.
 * Plane k of clip row r is w + r or w - r (row r of view_proj: its elements r,
 * 4 + r, 8 + r, 12 + r); its greatest value over the box is at its centre
 * plus the half extents weighed by the plane's |coefficients|, so one dot
 * product a plane says what the eight corners' transforms would (the cull
 * of every node for every shadow tile and draw: 2444 nodes on outdoor). */
static bool box_outside(const float view_proj[16], const float lo[3], const float hi[3], bool pancake) {
  const float *m = view_proj;
  float c[3], e[3];
  for (int j = 0; j < 3; j++) c[j] = (lo[j] + hi[j]) / 2, e[j] = (hi[j] - lo[j]) / 2;
  for (int k = 0; k < 6; k++) {
    if (pancake && k == 4) continue;
    int r = k / 2;
    float sign = k % 2 ? -1.0f : 1.0f, most = m[15] + sign * m[12 + r];
    for (int j = 0; j < 3; j++) {
      float a = m[4 * j + 3] + sign * m[4 * j + r];
      most += a * c[j] + fabsf(a) * e[j];
    }
    if (most < 0) return true;
  }
  return false;
}

bool lm_box_outside_frustum(const float view_proj[16], const float lo[3], const float hi[3]) {
  return box_outside(view_proj, lo, hi, false);
}

/* World bounds of a mesh under a node's transform (the box of the moved box). */
void lm_box_transform(const float m[16], const float lo[3], const float hi[3], float out_lo[3], float out_hi[3]) {
  for (int r = 0; r < 3; r++) {
    out_lo[r] = out_hi[r] = m[12 + r];
    for (int k = 0; k < 3; k++) {
      float a = m[4 * k + r] * lo[k], c = m[4 * k + r] * hi[k];
      out_lo[r] += a < c ? a : c;
      out_hi[r] += a < c ? c : a;
    }
  }
}

lm_material_pbr lm_scene_material_pbr(const lm_scene *s, int material, const lm_material *m) {
  if (material >= 0 && material < s->material_count && s->material_pbr[material].set)
    return s->material_pbr[material];
  lm_material_pbr p = {.metallic = glm_clamp(1.0f - m->kd, 0.0f, 1.0f),
                       .roughness = powf(2.0f / (fmaxf(m->shininess, 0.0f) + 2.0f), 0.25f),
                       .normal_scale = 1, .occlusion_strength = 1, .alpha = 1};
  return p;
}

/* The index (or -1) of the texture in `slot`. */
static int slot_texture(const lm_scene *s, const lm_material *m, const lm_material_pbr *p, int slot) {
  int t = (slot == LM_TEX_BASE_COLOR ? m->base_color_texture : p->textures[slot]) - 1;
  return t >= 0 && t < s->texture_count ? t : -1;
}

/* The variant's defines: a define per texture the technique reads (every
 * slot for a pbr one, the base colour for the others), and ALPHA_MASK for a
 * glTF alphaMode MASK material in the others (std.frag, shadow.frag: a masked
 * hole is no surface and casts no shadow; pbr.frag reads material_alpha
 * always); ALPHA_BLEND for a BLEND material drawn into a shadow pass's
 * transmittance output. */
static void material_defines(const lm_scene *s, const lm_material *m, const lm_material_pbr *p, bool pbr,
                             bool translucent, char *out, size_t cap) {
  out[0] = '\0';
  for (int slot = 0; slot < LM_TEX_SLOTS; slot++) {
    if (slot_texture(s, m, p, slot) < 0 || (slot != LM_TEX_BASE_COLOR && !pbr)) continue;
    size_t len = strlen(out);
    snprintf(out + len, cap - len, "%s%s", len ? ";" : "", slot_define[slot]);
  }
  if (!pbr && p->alpha_mode == LM_ALPHA_MASK) {
    size_t len = strlen(out);
    snprintf(out + len, cap - len, "%sALPHA_MASK", len ? ";" : "");
  }
  if (translucent) {
    size_t len = strlen(out);
    snprintf(out + len, cap - len, "%sALPHA_BLEND", len ? ";" : "");
  }
}

/* KHR_texture_transform as GLSL's column-major mat3 (identity when unset). */
static void uv_matrix(const float t[6], float out[9]) {
  bool set = false;
  for (int i = 0; i < 6; i++) set |= t[i] != 0;
  const float id[6] = {1, 0, 0, 0, 1, 0}, *a = set ? t : id;
  float m[9] = {a[0], a[3], 0, a[1], a[4], 0, a[2], a[5], 1};
  memcpy(out, m, sizeof m);
}

bool lm_scene_node_bounds(const lm_scene *s, int node, float lo[3], float hi[3]) {
  if (node < 0 || node >= s->node_count) return false;
  const lm_node *n = &s->nodes[node];
  if (n->mesh < 0 || n->mesh >= s->mesh_count) return false;
  const lm_scene_mesh *m = &s->meshes[n->mesh];
  if (!(m->bounds[0][0] <= m->bounds[1][0])) return false;
  lm_box_transform(n->world, m->bounds[0], m->bounds[1], lo, hi);
  return isfinite(lo[0] + lo[1] + lo[2] + hi[0] + hi[1] + hi[2]);
}

bool lm_scene_node_culled(const lm_scene *s, int node, const float view_proj[16], bool pancake) {
  float lo[3], hi[3];
  return lm_scene_node_bounds(s, node, lo, hi) && box_outside(view_proj, lo, hi, pancake);
}

/* A visible mesh node, sorted so that nodes of one mesh, material and
 * simplification (lod: 1 + the level of its simplified copy) lie together, those seen in
 * part (part: some chunk of what they draw out of view) after the whole ones, mirrored ones
 * (a world matrix of negative determinant: their front faces wind clockwise) after the others,
 * translucent casters
 * (into a transmittance output) after the others; in a camera pass the draws then by their
 * nearest node (order_draws_nearest_first); blended ones in the
 * forward pass by the camera's depth of their bounds' centre, farthest first.
 * outside: where a node seen in part has its chunks' frustum tests (one byte a
 * chunk, 1: left out), so that each chunk is tested once a draw. */
typedef struct drawn_node { int translucent, material, mesh, lod, part, mirrored, node; float depth; int outside; } drawn_node;

static int back_to_front(const void *pa, const void *pb) {
  const drawn_node *a = pa, *b = pb;
  if (a->depth != b->depth) return a->depth > b->depth ? -1 : 1;
  return (a->node > b->node) - (a->node < b->node);
}

static int drawn_node_order(const void *pa, const void *pb) {
  const drawn_node *a = pa, *b = pb;
  if (a->translucent != b->translucent) return a->translucent - b->translucent;
  if (a->material != b->material) return a->material < b->material ? -1 : 1;
  if (a->mesh != b->mesh) return a->mesh < b->mesh ? -1 : 1;
  if (a->lod != b->lod) return a->lod - b->lod;
  if (a->part != b->part) return a->part - b->part;
  if (a->mirrored != b->mirrored) return a->mirrored - b->mirrored;
  if (a->depth != b->depth) return a->depth < b->depth ? -1 : 1; /* nearest first: the depth test then
                                                                    spares the shading of what they hide */
  return (a->node > b->node) - (a->node < b->node);
}

/* Do two sorted nodes share one instanced draw (one mesh, material, copy, chunk
 * handling and winding)? */
static bool same_draw(const drawn_node *a, const drawn_node *b) {
  return a->material == b->material && a->mesh == b->mesh && a->lod == b->lod && a->part == b->part &&
         a->mirrored == b->mirrored;
}

/* One instanced draw's nodes (nodes[first..last), nearest first) and the
 * camera's depth of its nearest. */
typedef struct node_run { int translucent; float depth; int first, last; } node_run;

static int nearest_run_first(const void *pa, const void *pb) {
  const node_run *a = pa, *b = pb;
  if (a->translucent != b->translucent) return a->translucent - b->translucent;
  if (a->depth != b->depth) return a->depth < b->depth ? -1 : 1;
  return a->first - b->first;
}

/* Puts a camera pass's draws in the order of their nearest node, keeping
 * each draw's nodes together: the depth test (before the fragment shader
 * where that writes no depth, llvmpipe's too) then spares the shading of
 * most of what they hide, one draw behind another as within a draw. Drawn by
 * material instead, outdoor's G-buffer shaded 1.76-1.84 fragments a covered
 * pixel, in this order 1.15-1.18 (docs/benchmarks.md). */
static void order_draws_nearest_first(drawn_node *nodes, int count) {
  node_run *runs = lm_alloc(sizeof *runs * (size_t)(count > 0 ? count : 1));
  int run_count = 0;
  for (int first = 0, last; first < count; first = last) {
    for (last = first + 1; last < count && same_draw(&nodes[last], &nodes[first]);) last++;
    runs[run_count++] = (node_run){nodes[first].translucent, nodes[first].depth, first, last};
  }
  qsort(runs, (size_t)run_count, sizeof *runs, nearest_run_first);
  drawn_node *ordered = lm_alloc(sizeof *ordered * (size_t)(count > 0 ? count : 1));
  int n = 0;
  for (int r = 0; r < run_count; r++)
    for (int i = runs[r].first; i < runs[r].last; i++) ordered[n++] = nodes[i];
  memcpy(nodes, ordered, sizeof *nodes * (size_t)count);
  free(ordered);
  free(runs);
}

/* The chain of simplified copies a node draws from. */
typedef enum copy_chain { COPIES_NONE, COPIES_CASTERS, COPIES_CAMERA } copy_chain;

/* Does `material` read uvs in d's pass: a texture in a camera pass or an RSM
 * view, a texture whose alpha cuts (a mask or a blend) in a shadow tile? */
static bool reads_uvs(const lm_scene *s, const lm_scene_draw_desc *d, int material) {
  if (material < 0 || material >= s->material_count) return false;
  const lm_material *m = &s->materials[material];
  const lm_material_pbr *p = &s->material_pbr[material];
  if (!d->lod_camera) return p->set && p->alpha_mode != LM_ALPHA_OPAQUE && slot_texture(s, m, p, LM_TEX_BASE_COLOR) >= 0;
  for (int slot = 0; slot < LM_TEX_SLOTS; slot++)
    if (slot_texture(s, m, p, slot) >= 0) return true;
  return false;
}

/* The camera's copies (`lods`, which keep normals and uvs) in camera passes
 * and RSM views, the casters' (over positions alone) in shadow tiles; where
 * the material reads uvs, only copies whose uvs are the mesh's (a caster cut
 * by its texture's alpha draws the camera's), else none. */
static copy_chain node_copies(const lm_scene *s, const lm_scene_draw_desc *d, const lm_scene_mesh *m, int material) {
  bool uvs = reads_uvs(s, d, material);
  if (!d->lod_camera && !(uvs && m->casters_mix_uvs)) return COPIES_CASTERS;
  return uvs && m->lods_mix_uvs ? COPIES_NONE : COPIES_CAMERA;
}

/* The simplified copy node n (world bounds lo..hi) draws in d's view: 1 +
 * the coarsest level whose error times the node's largest axis scale is at
 * most d->lod_texels of the view's finer texel (pixel) where the bounds come
 * nearest its eye: 2 w / (|row| * texels) for the x and y rows of
 * lod_view_proj, w its clip w there (1 for an orthographic tile; in a
 * perspective view texels grow with distance, and a node reaching behind
 * the eye is drawn whole); 0: the mesh whole. */
static int node_lod(const lm_scene_draw_desc *d, const lm_node *n, const lm_scene_mesh *m, copy_chain chain,
                    const float lo[3], const float hi[3]) {
  int levels = chain == COPIES_CAMERA ? m->lod_levels : chain == COPIES_CASTERS ? m->caster_levels : 0;
  if (!d->lod_view_proj || !(d->lod_texels > 0) || levels <= 0) return 0;
  const float *v = d->lod_view_proj, *w = n->world;
  float scale = 0, w_near = v[15], radius = 0;
  for (int c = 0; c < 3; c++) {
    scale = fmaxf(scale, sqrtf(w[4 * c] * w[4 * c] + w[4 * c + 1] * w[4 * c + 1] + w[4 * c + 2] * w[4 * c + 2]));
    w_near += v[4 * c + 3] * (lo[c] + hi[c]) / 2;
    radius += (hi[c] - lo[c]) * (hi[c] - lo[c]) / 4;
  }
  w_near -= sqrtf(v[3] * v[3] + v[7] * v[7] + v[11] * v[11]) * sqrtf(radius);
  float rows = fmaxf(sqrtf(v[0] * v[0] + v[4] * v[4] + v[8] * v[8]) * (float)d->lod_size[0],
                     sqrtf(v[1] * v[1] + v[5] * v[5] + v[9] * v[9]) * (float)d->lod_size[1]);
  if (!(w_near > 0) || !(rows > 0)) return 0;
  float texel = 2 * w_near / rows, allowed = d->lod_texels * texel;
  if (!isfinite(allowed)) return 0;
  const lm_mesh_lod *lods = chain == COPIES_CAMERA ? m->lods : m->casters;
  int level = 0;
  while (level < levels && lods[level].error * scale <= allowed) level++;
  return level;
}

/* Sets the material uniforms and textures of material m for program p. */
static void bind_material(const lm_scene *s, const lm_program *p, const lm_material *m, const lm_material_pbr *mp,
                          const char *defines) {
  float k[4] = {m->ka, m->kd, m->ks, m->shininess};
  float params[4] = {mp->metallic, mp->roughness, mp->normal_scale, mp->occlusion_strength};
  float alpha[2] = {mp->alpha, mp->alpha_mode == LM_ALPHA_MASK ? mp->alpha_cutoff : -1.0f};
  float glass[4] = {mp->transmission, mp->ior > 0 ? mp->ior : 1.5f, mp->attenuation_distance, mp->thickness};
  const lm_uniform *u;
  if ((u = lm_program_uniform(p, "material_color"))) lm_program_set(p, u, m->color);
  if ((u = lm_program_uniform(p, "material_rho"))) lm_program_set(p, u, &m->rho);
  if ((u = lm_program_uniform(p, "material_k"))) lm_program_set(p, u, k);
  if ((u = lm_program_uniform(p, "material_reflectivity"))) lm_program_set(p, u, &m->reflectivity);
  if ((u = lm_program_uniform(p, "material_pbr"))) lm_program_set(p, u, params);
  if ((u = lm_program_uniform(p, "material_emissive"))) lm_program_set(p, u, mp->emissive);
  if ((u = lm_program_uniform(p, "material_alpha"))) lm_program_set(p, u, alpha);
  if ((u = lm_program_uniform(p, "material_glass"))) lm_program_set(p, u, glass);
  if ((u = lm_program_uniform(p, "material_attenuation"))) lm_program_set(p, u, mp->attenuation_color);
  for (int slot = 0; slot < LM_TEX_SLOTS && defines[0]; slot++) {
    if (!strstr(defines, slot_define[slot])) continue;
    if ((u = lm_program_uniform(p, slot_sampler[slot])))
      lm_program_bind_texture(u, s->textures[slot_texture(s, m, mp, slot)].gpu);
    float xf[9];
    uv_matrix(mp->uv_transform[slot], xf);
    if ((u = lm_program_uniform(p, slot_xform[slot]))) lm_program_set(p, u, xf);
  }
}

/* A node's model matrix, normal matrix (the inverse transpose's 3x3) and
 * model matrix in the previous frame (`prev`, NULL: the current one); the
 * model matrices take the quantized positions of its mesh (lm_mesh_dequantize). */
static void node_instance(const lm_node *n, const lm_mesh *mesh, const float *prev, lm_instance *out) {
  mat4 model, inv;
  mat3 normal;
  memcpy(model, n->world, sizeof model);
  lm_mesh_dequantize(mesh, prev ? prev : n->world, out->prev_model);
  glm_mat4_inv(model, inv);
  glm_mat4_transpose(inv);
  glm_mat4_pick3(inv, normal);
  lm_mesh_dequantize(mesh, n->world, out->model);
  memcpy(out->normal, normal, sizeof out->normal);
}

/* The chunks of the index range a node of mesh m draws at `lod` (1 + a
 * copy's level; 0: the mesh whole), *count of them (0: none, NULL). */
static const lm_mesh_chunk *lod_chunks(const lm_scene_mesh *m, copy_chain chain, int lod, int *count) {
  lm_chunk_span span = lod ? (chain == COPIES_CAMERA ? m->lod_chunks : m->caster_chunks)[lod - 1] : m->whole_chunks;
  *count = span.count;
  return span.count ? m->chunks + span.first : NULL;
}

/* Does d's cull volume leave out chunk c of node n's mesh? */
static bool chunk_outside(const lm_scene_draw_desc *d, const lm_node *n, const lm_mesh_chunk *c) {
  float lo[3], hi[3];
  lm_box_transform(n->world, c->bounds[0], c->bounds[1], lo, hi);
  return box_outside(d->view_proj, lo, hi, d->pancake);
}

/* Draws the chunks of a node's range (instance `instance`) that its view
 * keeps (outside[k]: chunk k left out), each run of adjacent ones (adjacent
 * in the index buffer) in one draw; returns the triangles drawn. */
static long draw_chunks(const lm_mesh *gpu, const lm_mesh_chunk *c, int chunks, const unsigned char *outside,
                        int instance, lm_scene_draw_stats *stats) {
  long triangles = 0;
  for (int k = 0; k < chunks; k++) {
    if (outside[k]) {
      if (stats) stats->chunks_culled++;
      continue;
    }
    int end = k + 1; /* the run of kept chunks from k */
    while (end < chunks && !outside[end]) end++;
    int from = c[k].first, count = c[end - 1].first + c[end - 1].count - from;
    lm_mesh_draw_instances(gpu, from, count, instance, 1);
    triangles += count / 3;
    if (stats) stats->calls++;
    k = end - 1;
  }
  return triangles;
}

bool lm_scene_draw(const lm_scene *s, const lm_scene_draw_desc *d, lm_scene_draw_stats *stats, lm_error *err) {
  const lm_program *p = d->program;
  if (lm_program_uniform(p, "model") || lm_program_uniform(p, "normal_matrix")) {
    lm_error_set(err, "technique %s: the uniforms model and normal_matrix are no longer set; its vertex shader "
                 "reads the instance attributes instance_model (location 3) and instance_normal (7), as std.vert does",
                 p->label);
    return false;
  }
  /* A technique that reads material_pbr (shaders/pbr.frag) takes every texture slot. */
  bool pbr = lm_program_uniform(d->program, "material_pbr") != NULL;
  /* The nodes in view, then one instanced draw for each run of one mesh and
   * material: a scene of many copies costs a few draw calls, not one a copy. */
  drawn_node *nodes = lm_alloc(sizeof *nodes * (size_t)(s->node_count > 0 ? s->node_count : 1));
  int count = 0;
  unsigned char *outside = NULL; /* the chunk tests of the nodes seen in part (drawn_node.outside) */
  int outside_len = 0, outside_cap = 0;
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0 || n->mesh >= s->mesh_count) continue;
    if (d->dynamic && d->layer && d->dynamic[i] != (d->layer == 2)) continue;
    if (material_blends(s, n->material) ? d->blend == LM_BLEND_SKIP : d->blend == LM_BLEND_ONLY) continue;
    float lo[3] = {0}, hi[3] = {0};
    const float(*b)[3] = s->meshes[n->mesh].bounds;
    if (d->view_proj || d->lod_view_proj || d->eye_view_proj) lm_box_transform(n->world, b[0], b[1], lo, hi);
    if (d->view_proj && box_outside(d->view_proj, lo, hi, d->pancake)) {
      if (stats) stats->culled++;
      continue;
    }
    float depth = 0; /* the camera's clip w of the bounds' centre: its view depth */
    for (int k = 0; k < 3 && d->eye_view_proj; k++) depth += d->eye_view_proj[4 * k + 3] * (lo[k] + hi[k]) / 2;
    int translucent = d->blend == LM_BLEND_CAST && d->transmit > 0 && material_blends(s, n->material);
    copy_chain chain = node_copies(s, d, &s->meshes[n->mesh], n->material);
    int lod = node_lod(d, n, &s->meshes[n->mesh], chain, lo, hi), part = 0, chunks;
    const lm_mesh_chunk *c = lod_chunks(&s->meshes[n->mesh], chain, lod, &chunks);
    if (d->view_proj && chunks) { /* kept only when some chunk is left out: a node seen whole is one draw */
      outside = lm_grow(outside, &outside_cap, outside_len + chunks, 1);
      for (int k = 0; k < chunks; k++) {
        outside[outside_len + k] = chunk_outside(d, n, &c[k]);
        part |= outside[outside_len + k];
      }
    }
    int mirrored = world_det3(n->world) < 0;
    nodes[count++] = (drawn_node){translucent, n->material, n->mesh, lod, part, mirrored, i, depth, outside_len};
    if (part) outside_len += chunks;
  }
  bool sorted = d->blend == LM_BLEND_ONLY; /* blending needs the order, one node a draw */
  qsort(nodes, (size_t)count, sizeof *nodes, sorted ? back_to_front : drawn_node_order);
  if (!sorted && d->eye_view_proj) order_draws_nearest_first(nodes, count);
  lm_instance *instances = lm_alloc(sizeof *instances * (size_t)(count > 0 ? count : 1));
  for (int i = 0; i < count; i++) {
    int k = nodes[i].node;
    node_instance(&s->nodes[k], &s->meshes[s->nodes[k].mesh].gpu, d->prev_world ? d->prev_world + (size_t)k * 16 : NULL, &instances[i]);
  }
  lm_instances_upload(instances, count);
  free(instances);
  char bound[160] = ""; /* the defines of the variant that is bound */
  bool ok = true, translucent = false; /* drawing into the transmittance output */
  for (int first = 0, last; first < count && ok; first = last) {
    for (last = first + 1; !sorted && last < count && same_draw(&nodes[last], &nodes[first]);) last++;
    const lm_node *n = &s->nodes[nodes[first].node];
    const lm_scene_mesh *mesh = &s->meshes[n->mesh];
    lm_material m = *lm_scene_node_material(s, n);
    for (int k = 0; k < d->param_count; k++)
      if (!strcmp(d->params[k].material, m.name)) apply_param(&m, &d->params[k]);
    lm_material_pbr mp = lm_scene_material_pbr(s, n->material, &m);
    char defines[160] = "";
    if (nodes[first].translucent && !translucent) { /* after every opaque caster */
      translucent = true;
      lm_set_caster_layer(d->transmit - 1, d->outputs, true);
    }
    if (d->variant) material_defines(s, &m, &mp, pbr, translucent, defines, sizeof defines);
    if (strcmp(defines, bound)) { /* switch programs only when the variant changes */
      p = d->variant(d->ctx, defines, err);
      if (!p) {
        ok = false;
        break;
      }
      snprintf(bound, sizeof bound, "%s", defines);
    }
    bind_material(s, p, &m, &mp, defines);
    /* A mirrored node's triangles wind the other way (glTF: its front faces are clockwise):
     * culled, and gl_FrontFacing (the shadow pass's back-face sign, two-sided normals), as its
     * normals (the inverse transpose) say. */
    lm_set_front_face_clockwise(nodes[first].mirrored);
    int lod = nodes[first].lod;
    copy_chain chain = node_copies(s, d, mesh, n->material); /* alike for the group: one material and mesh */
    const lm_mesh_lod *copy = lod ? &(chain == COPIES_CAMERA ? mesh->lods : mesh->casters)[lod - 1] : NULL;
    int index_count = copy ? copy->count : mesh->index_count;
    long triangles = 0;
    if (nodes[first].part) { /* node by node, the chunks in view */
      int chunks;
      const lm_mesh_chunk *c = lod_chunks(mesh, chain, lod, &chunks);
      for (int i = first; i < last; i++) triangles += draw_chunks(&mesh->gpu, c, chunks, outside + nodes[i].outside, i, stats);
    } else {
      lm_mesh_draw_instances(&mesh->gpu, copy ? copy->first : 0, index_count, first, last - first);
      triangles = (long)(last - first) * (index_count / 3);
      if (stats) stats->calls++;
    }
    if (stats) {
      stats->drawn += last - first, stats->triangles += triangles;
      stats->simplified += lod ? last - first : 0;
    }
  }
  if (translucent) lm_set_caster_layer(-1, d->outputs, false);
  lm_set_front_face_clockwise(false);
  free(nodes);
  free(outside);
  return ok;
}
