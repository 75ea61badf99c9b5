#define _POSIX_C_SOURCE 200809L
#include <cglm/cglm.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"
#include "scene/gltf.h"

static lm_scene *cornell;
static char scratch[256];

static bool scratch_create(void) {
  char real_root[1024], cmd[4096];
  snprintf(real_root, sizeof real_root, "%s", lm_root_dir());
  snprintf(scratch, sizeof scratch, "/tmp/limn-test-XXXXXX");
  if (!mkdtemp(scratch)) return false;
  snprintf(cmd, sizeof cmd, "mkdir -p %s/shaders && ln -s %s/shaders/* %s/shaders/ && ln -s %s/scripts %s/scripts",
           scratch, real_root, scratch, real_root, scratch);
  if (system(cmd) != 0) return false;
  setenv("LIMN_ROOT", scratch, 1);
  return true;
}

int gl_test_setup(void **state) {
  (void)state;
  lm_log_set_level(LM_LOG_WARN);
  lm_error err;
  if (!scratch_create()) {
    fprintf(stderr, "no scratch root in /tmp\n");
    return -1;
  }
  if (!(cornell = lm_scene_builtin("cornell", &err))) {
    fprintf(stderr, "%s\n", err.msg);
    return -1;
  }
  if (!lm_context_create_headless(&(lm_context_desc){0}, &err)) {
    fprintf(stderr, "no OpenGL context: %s\n", err.msg);
    return -1;
  }
  return 0;
}

int gl_test_teardown(void **state) {
  (void)state;
  lm_scene_destroy(cornell); /* its GL buffers go before the context */
  cornell = NULL;
  lm_programs_clear();
  lm_context_destroy();
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", scratch);
  return system(cmd) == 0 ? 0 : -1;
}

lm_scene *gl_cornell(void) { return cornell; }
const char *gl_root(void) { return scratch; }

bool gl_write_file(const char *rel, const char *text) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", scratch, rel);
  FILE *f = fopen(path, "w");
  if (!f) return false;
  bool ok = fputs(text, f) >= 0;
  return fclose(f) == 0 && ok;
}

static bool read_output(gl_result *r) {
  return lm_renderer_read(r->renderer, true, r->rgb, &r->err) &&
         lm_renderer_read(r->renderer, false, r->srgb, &r->err);
}

gl_result gl_render_ok(const gl_run *run) {
  gl_result r = gl_render(run);
  const char *tech = run->tech ? run->tech : "(default)";
  if (!r.ok) fail_msg("%s: %s", tech, r.err.msg);
  if (!gl_all_finite(&r)) fail_msg("%s: a pixel is NaN, Inf or negative", tech);
  return r;
}

bool gl_set(gl_result *r, const char *assignment) {
  char name[128];
  const char *eq = strchr(assignment, '=');
  if (!eq) {
    lm_error_set(&r->err, "option '%s': expected name=value", assignment);
    return false;
  }
  snprintf(name, sizeof name, "%.*s", (int)(eq - assignment), assignment);
  return lm_pipeline_set_option(r->pipeline, name, eq + 1, &r->err);
}

gl_result gl_render(const gl_run *run) {
  gl_result r = {.width = run->width ? run->width : 256, .height = run->height ? run->height : 192};
  const char *script = run->script ? run->script : "scripts/pp.lua";
  char path[1024];
  if (script[0] == '/') snprintf(path, sizeof path, "%s", script);
  else snprintf(path, sizeof path, "%s/%s", lm_root_dir(), script);
  r.pipeline = lm_pipeline_load(&(lm_pipeline_desc){.path = path}, &r.err);
  if (!r.pipeline) return r;
  if (run->tech && !lm_pipeline_set_technique(r.pipeline, run->tech, &r.err)) return r;
  for (const char *const *s = run->sets; s && *s; s++)
    if (!gl_set(&r, *s)) return r;
  r.renderer = lm_renderer_create(&(lm_renderer_desc){.scene = run->scene ? run->scene : cornell,
                                                      .pipeline = r.pipeline, .width = r.width,
                                                      .height = r.height, .linear_output = true,
                                                      .check_finite = run->check_finite,
                                                      .no_light_culling = run->no_light_culling,
                                                      .exposure = run->exposure,
                                                      .no_culling = run->no_culling}, &r.err);
  if (!r.renderer) return r;
  if (run->keep_targets) lm_renderer_set_sharing(r.renderer, false);
  r.rgb = malloc(sizeof(float) * 3 * (size_t)r.width * (size_t)r.height);
  r.srgb = malloc(3 * (size_t)r.width * (size_t)r.height);
  r.ok = true;
  for (int f = 0; f < (run->frames ? run->frames : 1) && r.ok; f++) r.ok = lm_renderer_frame(r.renderer, &r.err);
  if (r.ok) r.ok = read_output(&r);
  return r;
}

bool gl_render_again(gl_result *r) {
  r->ok = lm_renderer_frame(r->renderer, &r->err) && read_output(r);
  return r->ok;
}

double gl_mean_abs_diff(const float *a, const float *b, int n) {
  double sum = 0;
  for (int i = 0; i < n; i++) sum += fabs(a[i] - b[i]);
  return n > 0 ? sum / n : 0;
}

gl_convergence gl_temporal_convergence(gl_run run, const char *const *on, const char *const *off,
                                       const char *const *ref, int last, const char *label) {
  gl_convergence c = {0};
  run.sets = on;
  run.frames = 2;
  gl_result r = gl_render(&run);
  if (!r.ok) fail_msg("%s: %s", label, r.err.msg);
  int n = r.width * r.height * 3;
  float *before = malloc(sizeof(float) * (size_t)n);
  for (int f = 3; f <= last; f++) {
    memcpy(before, r.rgb, sizeof(float) * (size_t)n);
    if (!gl_render_again(&r)) fail_msg("%s, frame %d: %s", label, f, r.err.msg);
    c.late = gl_mean_abs_diff(before, r.rgb, n);
    if (f == 3) c.early = c.late;
  }
  free(before);
  if (!gl_all_finite(&r)) fail_msg("%s: a value is not finite or is negative", label);
  run.frames = 1;
  run.sets = off;
  gl_result one = gl_render_ok(&run);
  run.sets = ref;
  gl_result best = gl_render_ok(&run);
  c.e_acc = gl_mean_abs_diff(r.rgb, best.rgb, n);
  c.e_one = gl_mean_abs_diff(one.rgb, best.rgb, n);
  float all[3];
  gl_region(&r, 0, 0, r.width - 1, r.height - 1, all);
  c.mean = (all[0] + all[1] + all[2]) / 3.0;
  print_message("%s: change %.2e (frame 3) -> %.2e (frame %d) of a mean %.3f; error to the reference %.2e "
                "(one frame without reuse: %.2e)\n", label, c.early, c.late, last, c.mean, c.e_acc, c.e_one);
  gl_result_free(&r);
  gl_result_free(&one);
  gl_result_free(&best);
  return c;
}

void gl_result_free(gl_result *r) {
  lm_renderer_destroy(r->renderer);
  lm_pipeline_destroy(r->pipeline);
  free(r->rgb);
  free(r->srgb);
  *r = (gl_result){0};
}

void gl_pass_names(const gl_result *r, char *out, size_t cap) {
  lm_graph *g = lm_renderer_graph(r->renderer);
  out[0] = '\0';
  for (int i = 0; i < lm_graph_pass_count(g); i++) {
    if (lm_graph_pass(g, i).culled) continue;
    size_t n = strlen(out);
    snprintf(out + n, cap - n, "%s ", lm_graph_pass(g, i).name);
  }
}

bool gl_has_pass(const gl_result *r, const char *prefix) {
  lm_graph *g = lm_renderer_graph(r->renderer);
  for (int i = 0; i < lm_graph_pass_count(g); i++)
    if (!strncmp(lm_graph_pass(g, i).name, prefix, strlen(prefix))) return true;
  return false;
}

int gl_culled(const gl_result *r, const char *prefix) {
  lm_graph *g = lm_renderer_graph(r->renderer);
  int n = 0;
  for (int i = 0; i < lm_graph_pass_count(g); i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    n += p.culled && !strncmp(p.name, prefix, strlen(prefix));
  }
  return n;
}

void gl_region(const gl_result *r, int x0, int y0, int x1, int y1, float out[3]) {
  double sum[3] = {0};
  int n = 0;
  for (int y = y0; y <= y1; y++)
    for (int x = x0; x <= x1; x++, n++)
      for (int c = 0; c < 3; c++) sum[c] += r->rgb[((size_t)y * r->width + x) * 3 + c];
  for (int c = 0; c < 3; c++) out[c] = n ? (float)(sum[c] / n) : 0.0f;
}

float gl_luminance(const float c[3]) { return 0.27f * c[0] + 0.67f * c[1] + 0.06f * c[2]; }

static bool finite_not_negative(const float *v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i]) || v[i] < 0) return false;
  return true;
}

bool gl_all_finite(const gl_result *r) { return finite_not_negative(r->rgb, (size_t)r->width * r->height * 3); }

/* Whether pass i (run, not culled) writes target `id`. */
static bool pass_writes(lm_graph *g, int i, int id) {
  lm_graph_pass_info p = lm_graph_pass(g, i);
  if (p.culled) return false;
  for (int k = 0; k < p.desc->output_count; k++)
    if (p.desc->outputs[k] == id) return true;
  return p.desc->depth == id;
}

/* The target sharing `id`'s texture that a pass wrote after `id`'s last
 * writer (what a read after the frame would hold instead), or NULL. */
static const char *overwritten_by(lm_graph *g, int id) {
  int slot = lm_graph_target(g, id).slot, last = -1;
  if (slot < 0) return NULL;
  for (int i = 0; i < lm_graph_pass_count(g); i++)
    if (pass_writes(g, i, id)) last = i;
  for (int i = last + 1; i < lm_graph_pass_count(g); i++)
    for (int t = 0; t < lm_graph_target_count(g); t++)
      if (t != id && lm_graph_target(g, t).slot == slot && pass_writes(g, i, t)) return lm_graph_target(g, t).name;
  return NULL;
}

float *gl_read_target(gl_result *r, const char *name, int *width, int *height) {
  lm_graph *g = lm_renderer_graph(r->renderer);
  int id = lm_graph_find_target(g, name);
  if (id < 0) return NULL;
  lm_graph_target_info t = lm_graph_target(g, id);
  if (!t.used || !t.texture.id) return NULL; /* an unused target's slot holds another's texels */
  const char *other = overwritten_by(g, id);
  if (other) { /* a test would judge another target's texels */
    fprintf(stderr, "gl_read_target: %s shares its texture with %s, written after it: render with sharing off\n", name,
            other);
    return NULL;
  }
  float *px = malloc(sizeof(float) * 4 * (size_t)t.width * (size_t)t.height);
  lm_texture_read(t.texture, t.width, t.height, true, px);
  *width = t.width;
  *height = t.height;
  return px;
}

float *gl_read_normals(gl_result *r, const char *name, int *width, int *height) {
  float *px = gl_read_target(r, name, width, height);
  for (size_t i = 0; px && i < (size_t)*width * *height; i++) {
    float *t = px + i * 4;
    unsigned b[4];
    for (int k = 0; k < 4; k++) b[k] = (unsigned)lroundf(fminf(fmaxf(t[k], 0.0f), 1.0f) * 255.0f);
    unsigned qx = b[0] << 4 | b[1] >> 4, qy = (b[1] & 15u) << 8 | b[2];
    float n[3] = {0, 1, 0};
    if (qx) { /* octahedral coordinates (2048 + 2047 o): common.glsl's oct_decode */
      float ox = (qx - 2048.0f) / 2047.0f, oy = (qy - 2048.0f) / 2047.0f;
      n[0] = ox, n[1] = oy, n[2] = 1.0f - fabsf(ox) - fabsf(oy);
      if (n[2] < 0) n[0] = (1.0f - fabsf(oy)) * (ox >= 0 ? 1.0f : -1.0f), n[1] = (1.0f - fabsf(ox)) * (oy >= 0 ? 1.0f : -1.0f);
      float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]); /* >= 1 / sqrt(3) */
      for (int k = 0; k < 3; k++) n[k] /= len;
    }
    t[0] = n[0], t[1] = n[1], t[2] = n[2], t[3] = exp2f(b[3] / 16.0f) - 1.0f;
  }
  return px;
}

bool gl_target_finite(gl_result *r, const char *name) {
  int w, h;
  float *px = gl_read_target(r, name, &w, &h);
  bool ok = px && finite_not_negative(px, (size_t)w * h * 4);
  free(px);
  return ok;
}

void gl_quad(lm_scene *s, const char *name, int material, const float c[4][3], const float n[3]) {
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  float v[4 * 8];
  for (int i = 0; i < 4; i++) {
    float *o = v + 8 * i;
    o[0] = c[i][0], o[1] = c[i][1], o[2] = c[i][2], o[3] = n[0], o[4] = n[1], o[5] = n[2];
    o[6] = (float)(i == 1 || i == 2), o[7] = (float)(i >= 2);
  }
  mat4 id = GLM_MAT4_IDENTITY_INIT;
  lm_scene_add_node(s, name, -1, (float *)id, lm_scene_add_mesh(s, name, v, 4, idx, 6), material);
}

int gl_uv_sphere(lm_scene *s, const char *name, float r) {
  enum { SEG = 32, RINGS = 16 };
  static float v[(SEG + 1) * (RINGS + 1) * 8];
  static uint32_t idx[SEG * RINGS * 6];
  int nv = 0, ni = 0;
  for (int j = 0; j <= RINGS; j++)
    for (int i = 0; i <= SEG; i++) {
      float th = GLM_PIf * (float)j / RINGS, ph = 2 * GLM_PIf * (float)i / SEG;
      float n[3] = {sinf(th) * cosf(ph), cosf(th), -sinf(th) * sinf(ph)};
      float *o = v + nv++ * 8;
      for (int k = 0; k < 3; k++) o[k] = r * n[k], o[3 + k] = n[k];
      o[6] = (float)i / SEG, o[7] = (float)j / RINGS;
    }
  for (int j = 0; j < RINGS; j++)
    for (int i = 0; i < SEG; i++) {
      uint32_t a = (uint32_t)(j * (SEG + 1) + i), b = a + SEG + 1;
      uint32_t q[6] = {a, b, a + 1, a + 1, b, b + 1};
      memcpy(idx + ni, q, sizeof q), ni += 6;
    }
  return lm_scene_add_mesh(s, name, v, nv, idx, ni);
}

int gl_material(lm_scene *s, const char *name, float r, float g, float b) {
  lm_material m = {.color = {r, g, b}, .rho = 0.5f, .ka = 1, .kd = 1, .shininess = 1};
  snprintf(m.name, sizeof m.name, "%s", name);
  return lm_scene_add_material(s, &m);
}

void gl_camera_up(lm_scene *s, float y) {
  mat4 m;
  glm_translate_make(m, (vec3){0, y, 0});
  glm_rotate(m, glm_rad(90.0f), (vec3){1, 0, 0}); /* -Z of the node points up */
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "up", .fov_y = glm_rad(45.0f), .znear = 0.01f, .zfar = 100, .node = cam});
}

lm_scene *gl_reference_scene(const char *name) {
  lm_error err;
  char path[1024];
  snprintf(path, sizeof path, "%s/../data/scenes/reference/%s.glb", LIMN_TEST_DIR, name);
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  snprintf(path, sizeof path, "%s/../data/scenes/reference/%s.cams", LIMN_TEST_DIR, name);
  int n, first = lm_scene_add_camera_list(s, path, &n, &err);
  if (first < 0) fail_msg("%s", err.msg);
  lm_camera c = s->cameras[0];
  s->cameras[0] = s->cameras[first], s->cameras[first] = c;
  return s;
}

lm_scene *gl_sunlit_corner(int width, int height, float view_proj[16]) {
  lm_scene *s = lm_scene_create("yard");
  int grey = gl_material(s, "grey", 0.5f, 0.5f, 0.5f);
  gl_quad(s, "ground", grey, (const float[4][3]){{-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, {-10, 0, -10}},
          (const float[3]){0, 1, 0});
  gl_quad(s, "wall x", grey, (const float[4][3]){{0, 0, 8}, {0, 0, 0}, {0, 4, 0}, {0, 4, 8}}, (const float[3]){1, 0, 0});
  gl_quad(s, "wall z", grey, (const float[4][3]){{0, 0, 0}, {8, 0, 0}, {8, 4, 0}, {0, 4, 0}}, (const float[3]){0, 0, 1});
  mat4 view, m;
  glm_lookat((vec3){0, 0, 0}, (vec3){-0.3f, -1, -0.2f}, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, m);
  int sun = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1);
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 0,
                                     .casts_shadows = true, .node = sun});
  gl_look_camera(s, "yard", (const float[3]){9, 6, 9}, (const float[3]){3, 0, 3}, 60, width, height, view_proj);
  return s;
}

void gl_look_camera(lm_scene *s, const char *name, const float eye[3], const float target[3], float fov_y, int width,
                    int height, float view_proj[16]) {
  mat4 view, m, proj, vp;
  glm_lookat((float *)eye, (float *)target, (vec3){0, 1, 0}, view);
  glm_mat4_inv(view, m);
  int cam = lm_scene_add_node(s, "camera", -1, (float *)m, -1, -1);
  lm_camera c = {.fov_y = glm_rad(fov_y), .znear = 0.01f, .zfar = 100, .node = cam};
  snprintf(c.name, sizeof c.name, "%s", name);
  lm_scene_add_camera(s, &c);
  lm_scene_update(s);
  glm_perspective(glm_rad(fov_y), (float)width / (float)height, 0.01f, 100, proj);
  glm_mat4_mul(proj, view, vp);
  memcpy(view_proj, vp, sizeof vp);
}

void gl_rescale(lm_scene *s, float unit) {
  float m[16] = {unit, 0, 0, 0, 0, unit, 0, 0, 0, 0, unit, 0, 0, 0, 0, 1};
  lm_scene_add_root(s, "unit", m);
  for (int i = 0; i < s->light_count; i++) {
    lm_light *l = &s->lights[i];
    l->radius *= unit;
    /* An inverse-square light's intensity is per unit of distance squared. */
    bool inverse_square = l->falloff == LM_FALLOFF_INVERSE_SQUARE || l->falloff == LM_FALLOFF_RANGE;
    if (inverse_square && l->type != LM_LIGHT_DIRECTIONAL) l->power *= unit * unit;
  }
}

void gl_project(int width, int height, float x, float y, float z, int *col, int *row) {
  float depth = 3.4f - z, t = tanf(0.5f * 45.0f * 3.14159265f / 180.0f), aspect = (float)width / height;
  *col = (int)((x / (depth * t * aspect) + 1) * 0.5f * width);
  *row = (int)((1 - (y - 1) / (depth * t)) * 0.5f * height);
}

void gl_mean_around(const gl_result *r, float x, float y, float z, int radius, float out[3]) {
  int col, row;
  gl_project(r->width, r->height, x, y, z, &col, &row);
  gl_region(r, col - radius, row - radius, col + radius, row + radius, out);
}

void gl_assert_bad_options(const gl_bad_option *cases, size_t n, const char *where) {
  for (size_t i = 0; i < n; i++) {
    const char *sets[] = {cases[i].set, NULL};
    gl_result r = gl_render(&(gl_run){.tech = cases[i].tech, .sets = sets});
    if (r.ok) fail_msg("%s: rendered", cases[i].set);
    if (!strstr(r.err.msg, cases[i].expect) || !strstr(r.err.msg, where))
      fail_msg("%s: '%s'", cases[i].set, r.err.msg);
    gl_result_free(&r);
  }
}
