#include "scene/scene.h"

#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lm_scene *lm_scene_create(const char *name) {
  lm_scene *s = lm_alloc(sizeof *s);
  snprintf(s->name, sizeof s->name, "%s", name);
  return s;
}

void lm_scene_destroy(lm_scene *s) {
  if (!s) return;
  for (int i = 0; i < s->mesh_count; i++) {
    if (s->uploaded) lm_mesh_destroy(&s->meshes[i].gpu);
    free(s->meshes[i].vertices);
    free(s->meshes[i].indices);
  }
  free(s->nodes);
  free(s->meshes);
  free(s->materials);
  free(s->lights);
  free(s->cameras);
  free(s);
}

int lm_scene_add_material(lm_scene *s, const lm_material *m) {
  *LM_PUSH(s->materials, s->material_count, s->material_cap) = *m;
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
  glm_vec3_fill(m->bounds_min, FLT_MAX);
  glm_vec3_fill(m->bounds_max, -FLT_MAX);
  for (int i = 0; i < vertex_count; i++) {
    const float *p = vertices + (size_t)i * 8;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
    glm_vec3_minv(m->bounds_min, (float *)p, m->bounds_min);
    glm_vec3_maxv(m->bounds_max, (float *)p, m->bounds_max);
  }
  return s->mesh_count - 1;
}

int lm_scene_add_node(lm_scene *s, const char *name, int parent, const float local[16], int mesh,
                      int material) {
  lm_node *n = LM_PUSH(s->nodes, s->node_count, s->node_cap);
  snprintf(n->name, sizeof n->name, "%s", name);
  n->parent = parent;
  memcpy(n->local, local, sizeof n->local);
  n->mesh = mesh;
  n->material = material;
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
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0 || n->mesh >= s->mesh_count) continue;
    const lm_scene_mesh *m = &s->meshes[n->mesh];
    if (m->bounds_min[0] > m->bounds_max[0]) continue;
    mat4 w;
    memcpy(w, n->world, sizeof w);
    for (int c = 0; c < 8; c++) {
      vec4 p = {c & 1 ? m->bounds_max[0] : m->bounds_min[0], c & 2 ? m->bounds_max[1] : m->bounds_min[1],
                c & 4 ? m->bounds_max[2] : m->bounds_min[2], 1}, q;
      glm_mat4_mulv(w, p, q);
      if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
      glm_vec3_minv(min, q, min);
      glm_vec3_maxv(max, q, max);
    }
  }
  if (min[0] > max[0]) {
    glm_vec3_fill(min, -1);
    glm_vec3_fill(max, 1);
    return false;
  }
  return true;
}

bool lm_scene_upload(lm_scene *s, lm_error *err) {
  (void)err;
  if (s->uploaded) return true;
  for (int i = 0; i < s->mesh_count; i++) {
    lm_scene_mesh *m = &s->meshes[i];
    lm_mesh_create(&m->gpu, m->vertices, m->vertex_count, m->indices, m->index_count);
  }
  s->uploaded = true;
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
  /* Keep the projection invertible whatever a scene file says. */
  c.fov_y = isfinite(c.fov_y) ? glm_clamp(c.fov_y, 1e-4f, GLM_PIf - 1e-3f) : glm_rad(45.0f);
  c.znear = isfinite(c.znear) && c.znear > 1e-6f ? c.znear : 1e-6f;
  c.zfar = isfinite(c.zfar) && c.zfar > c.znear * 1.001f ? c.zfar : c.znear * 1.001f;
  float aspect = c.aspect > 0 && isfinite(c.aspect) ? c.aspect
                                                   : (float)(width > 0 ? width : 1) / (float)(height > 0 ? height : 1);
  mat4 world = GLM_MAT4_IDENTITY_INIT, view, proj, vp, inv_view;
  if (c.node >= 0) memcpy(world, s->nodes[c.node].world, sizeof world);
  glm_mat4_inv(world, view);
  glm_perspective(c.fov_y, aspect, c.znear, c.zfar, proj);
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

static const char *scene_uniforms[] = {"model", "normal_matrix", "material_color", "material_rho",
                                       "material_k"};

bool lm_scene_owns_uniform(const char *name) {
  for (size_t i = 0; i < sizeof scene_uniforms / sizeof *scene_uniforms; i++)
    if (!strcmp(scene_uniforms[i], name)) return true;
  return false;
}

const lm_material *lm_scene_node_material(const lm_scene *s, const lm_node *n) {
  static const lm_material fallback = {"default", {0.8f, 0.8f, 0.8f}, 0.8f, 0.1f, 0.9f, 0.0f, 16.0f};
  return n->material >= 0 && n->material < s->material_count ? &s->materials[n->material] : &fallback;
}

void lm_scene_draw(const lm_scene *s, const lm_program *p) {
  const lm_uniform *u_model = lm_program_uniform(p, "model");
  const lm_uniform *u_normal = lm_program_uniform(p, "normal_matrix");
  const lm_uniform *u_color = lm_program_uniform(p, "material_color");
  const lm_uniform *u_rho = lm_program_uniform(p, "material_rho");
  const lm_uniform *u_k = lm_program_uniform(p, "material_k");
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0 || n->mesh >= s->mesh_count) continue;
    const lm_material *m = lm_scene_node_material(s, n);
    mat4 model, inv;
    mat3 normal;
    memcpy(model, n->world, sizeof model);
    glm_mat4_inv(model, inv);
    glm_mat4_transpose(inv);
    glm_mat4_pick3(inv, normal);
    float k[4] = {m->ka, m->kd, m->ks, m->shininess};
    if (u_model) lm_program_set(p, u_model, (float *)model);
    if (u_normal) lm_program_set(p, u_normal, (float *)normal);
    if (u_color) lm_program_set(p, u_color, m->color);
    if (u_rho) lm_program_set(p, u_rho, &m->rho);
    if (u_k) lm_program_set(p, u_k, k);
    lm_mesh_draw(&s->meshes[n->mesh].gpu);
  }
}
