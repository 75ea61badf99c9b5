/* Rendering a view and writing its images: the one path that `limn capture`
 * (cli/capture.c), capture jobs (cli/job.c), `limn report` and the viewer
 * share. It calls none of them. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "image/image.h"
#include "capture_render.h"
#include "tools.h"

bool capture_known_extension(const char *path, bool *linear) {
  const char *dot = strrchr(path, '.');
  if (!dot || strchr(dot, '/')) return false;
  *linear = !strcasecmp(dot, ".exr") || !strcasecmp(dot, ".hdr");
  return *linear || !strcasecmp(dot, ".png") || !strcasecmp(dot, ".jpg") || !strcasecmp(dot, ".tif");
}

/* A relative script path that does not exist here is looked up under the root. */
void capture_resolve(const char *given, char *out, size_t cap) {
  if (!given) {
    snprintf(out, cap, "%s/scripts/pp.lua", lm_root_dir());
  } else if (given[0] != '/' && !lm_file_exists(given)) {
    snprintf(out, cap, "%s/%s", lm_root_dir(), given);
    if (!lm_file_exists(out)) snprintf(out, cap, "%s", given);
  } else {
    snprintf(out, cap, "%s", given);
  }
}

typedef struct pass_samples {
  const char *name, *kind;
  double *ms;
  int count;
} pass_samples;

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  if (n == 0) return 0;
  qsort(v, (size_t)n, sizeof *v, compare_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void collect_times(lm_graph *g, pass_samples **times, int *count, int frames) {
  for (int i = 0; i < lm_graph_pass_count(g); i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    if (p.culled || p.ms < 0) continue;
    pass_samples *t = NULL;
    for (int k = 0; k < *count && !t; k++)
      if (!strcmp((*times)[k].name, p.name)) t = &(*times)[k];
    if (!t) {
      *times = lm_realloc(*times, sizeof **times * (size_t)(*count + 1));
      t = &(*times)[(*count)++];
      *t = (pass_samples){lm_strdup(p.name), lm_pass_kind_name(p.kind),
                          lm_alloc(sizeof(double) * (size_t)frames), 0};
    }
    if (t->count < frames) t->ms[t->count++] = p.ms;
  }
}

/* A frame's outputs are written all or none: when one fails, those written
 * before it are removed, so that no failed frame is left half there (its
 * PNG without its EXR) to pass for a rendered one. */
static bool write_outputs(lm_renderer *r, int width, int height, const char *const *outputs, int count,
                          bool quiet, lm_error *err) {
  size_t px = (size_t)width * height;
  unsigned char *srgb = NULL;
  float *linear = NULL;
  bool ok = true;
  int written = 0;
  for (int i = 0; i < count && ok; i++, written += ok) {
    bool want_linear = false;
    capture_known_extension(outputs[i], &want_linear);
    if (want_linear && !linear) {
      linear = lm_alloc(px * 3 * sizeof(float));
      ok = lm_renderer_read(r, true, linear, err);
    } else if (!want_linear && !srgb) {
      srgb = lm_alloc(px * 3);
      ok = lm_renderer_read(r, false, srgb, err);
    }
    if (ok)
      ok = lm_image_write(outputs[i], width, height, 3, want_linear,
                          want_linear ? (void *)linear : (void *)srgb, err);
    if (ok && !quiet) lm_info("wrote %s", outputs[i]);
  }
  for (int i = 0; i < written && !ok; i++) remove(outputs[i]);
  free(srgb);
  free(linear);
  return ok;
}

bool capture_render_write(lm_renderer *r, const capture_view *v, capture_result *res, lm_error *err) {
  *res = (capture_result){0};
  pass_samples *samples = NULL;
  int n = 0;
  if (!v->continues) lm_renderer_set_view(r, v->camera, v->width, v->height);
  bool ok = true;
  for (int f = 0; f < v->warmup + v->frames && ok; f++) {
    if (v->stop && *v->stop) {
      lm_error_set(err, "stopped by signal %d", (int)*v->stop);
      ok = false;
      break;
    }
    ok = lm_renderer_frame(r, err);
    if (ok && f >= v->warmup) collect_times(lm_renderer_graph(r), &samples, &n, v->frames);
  }
  if (ok) ok = write_outputs(r, v->width, v->height, v->outputs, v->output_count, v->quiet, err);
  res->passes = lm_alloc(sizeof *res->passes * (size_t)(n + 1));
  for (int i = 0; i < n; i++) {
    res->passes[i] = (capture_pass_time){samples[i].name, samples[i].kind, median(samples[i].ms, samples[i].count)};
    res->total_ms += res->passes[i].ms;
    free(samples[i].ms);
  }
  res->pass_count = n;
  res->stats = lm_renderer_draw_stats(r);
  free(samples);
  return ok;
}

void capture_result_free(capture_result *res) {
  for (int i = 0; i < res->pass_count; i++) free((char *)res->passes[i].name);
  free(res->passes);
  *res = (capture_result){0};
}

bool capture_set_option(lm_pipeline *p, const char *name_value, lm_error *err) {
  char name[256];
  const char *eq = strchr(name_value, '=');
  if (!eq) {
    lm_error_set(err, "'%s' is not NAME=VALUE", name_value);
    return false;
  }
  snprintf(name, sizeof name, "%.*s", (int)(eq - name_value), name_value);
  return lm_pipeline_set_option(p, name, eq + 1, err);
}

lm_pipeline *capture_load_pipeline(const limn_common_args *a, int *rc, lm_error *err) {
  char script[2048];
  capture_resolve(a->script, script, sizeof script);
  *rc = 1;
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = script}, err);
  if (!p) return NULL;
  bool ok = !a->tech || lm_pipeline_set_technique(p, a->tech, err);
  for (int i = 0; i < a->set_count && ok; i++) ok = capture_set_option(p, a->sets[i], err);
  if (!ok) {
    lm_pipeline_destroy(p);
    *rc = 2;
    return NULL;
  }
  *rc = 0;
  return p;
}

bool capture_parse_clock(const char *s, lm_clock *out) {
  static const char *const names[] = {[LM_CLOCK_AUTO] = "auto", [LM_CLOCK_GPU] = "gpu", [LM_CLOCK_CPU] = "cpu",
                                      [LM_CLOCK_PROCESS] = "process"};
  for (int i = 0; i < (int)(sizeof names / sizeof *names); i++)
    if (!strcmp(s, names[i])) {
      *out = (lm_clock)i;
      return true;
    }
  return false;
}
