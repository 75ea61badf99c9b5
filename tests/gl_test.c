#include "gl_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int gl_test_setup(void **state) {
  (void)state;
  lm_log_set_level(LM_LOG_WARN);
  lm_error err;
  if (!lm_context_create_headless(&(lm_context_desc){0}, &err)) {
    fprintf(stderr, "no OpenGL context: %s\n", err.msg);
    return -1;
  }
  return 0;
}

int gl_test_teardown(void **state) {
  (void)state;
  lm_programs_clear();
  lm_context_destroy();
  return 0;
}

static bool read_output(gl_result *r) {
  return lm_renderer_read(r->renderer, true, r->rgb, &r->err) &&
         lm_renderer_read(r->renderer, false, r->srgb, &r->err);
}

gl_result gl_render(const gl_run *run) {
  gl_result r = {.width = run->width ? run->width : 256, .height = run->height ? run->height : 192};
  char path[1024];
  snprintf(path, sizeof path, "%s/scripts/pp.lua", lm_root_dir());
  r.pipeline = lm_pipeline_load(&(lm_pipeline_desc){.path = run->script ? run->script : path}, &r.err);
  if (!r.pipeline) return r;
  if (run->tech && !lm_pipeline_set_technique(r.pipeline, run->tech, &r.err)) return r;
  for (const char *const *s = run->sets; s && *s; s++) {
    char name[128];
    const char *eq = strchr(*s, '=');
    snprintf(name, sizeof name, "%.*s", eq ? (int)(eq - *s) : 0, *s);
    if (!eq || !lm_pipeline_set_option(r.pipeline, name, eq + 1, &r.err)) return r;
  }
  r.renderer = lm_renderer_create(&(lm_renderer_desc){.scene = run->scene, .pipeline = r.pipeline,
                                                      .width = r.width, .height = r.height,
                                                      .linear_output = true,
                                                      .check_finite = run->check_finite}, &r.err);
  if (!r.renderer) return r;
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

void gl_region(const gl_result *r, int x0, int y0, int x1, int y1, float out[3]) {
  double sum[3] = {0};
  int n = 0;
  for (int y = y0; y <= y1; y++)
    for (int x = x0; x <= x1; x++, n++)
      for (int c = 0; c < 3; c++) sum[c] += r->rgb[((size_t)y * r->width + x) * 3 + c];
  for (int c = 0; c < 3; c++) out[c] = n ? (float)(sum[c] / n) : 0.0f;
}

float gl_luminance(const float c[3]) { return 0.27f * c[0] + 0.67f * c[1] + 0.06f * c[2]; }

bool gl_all_finite(const gl_result *r) {
  for (size_t i = 0; i < (size_t)r->width * r->height * 3; i++)
    if (!isfinite(r->rgb[i]) || r->rgb[i] < 0) return false;
  return true;
}

float *gl_read_target(gl_result *r, const char *name, int *width, int *height) {
  lm_graph *g = lm_renderer_graph(r->renderer);
  int id = lm_graph_find_target(g, name);
  if (id < 0) return NULL;
  lm_graph_target_info t = lm_graph_target(g, id);
  if (!t.texture.id) return NULL;
  float *px = malloc(sizeof(float) * 4 * (size_t)t.width * (size_t)t.height);
  lm_texture_read(t.texture, t.width, t.height, true, px);
  *width = t.width;
  *height = t.height;
  return px;
}
