/* The viewer's live error against the reference: at a view of the --job
 * whose reference `limn reference` cached, the frame's mean error, Pearson
 * and share of the baseline's indirect error removed, as `limn report`
 * measures them (the same files, the same metrics), and a wipe between the
 * frame and the reference or its error heat map. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "job.h"
#include "reference.h"
#include "report_math.h"
#include "view.h"

/* The technique each place's share of indirect error removed is measured
 * against, as `limn report --baseline dl+esm` (the references have shadows),
 * rendered with the job's `set` and limn report's default frames. */
#define BASELINE "dl+esm"
enum { BASELINE_WARMUP = 2, BASELINE_FRAMES = 5 };

void find_places(view_args *a, job *j, const job_view *views, int count, int scene) {
  for (int i = 0; i < j->set_count && i < MAX_SETS; i++) {
    a->job_sets[i] = lm_alloc(strlen(j->set_names[i]) + strlen(j->set_values[i]) + 2);
    sprintf(a->job_sets[i], "%s=%s", j->set_names[i], j->set_values[i]);
    a->job_set_count = i + 1;
  }
  reference_args ref, direct;
  reference_defaults(&ref);
  if (a->refs) ref.refs = a->refs;
  lm_error err;
  if (!reference_prepare(&ref, j, &err)) {
    lm_warn("--job %s: no reference error here: %s", a->job, err.msg);
    return;
  }
  const char *flags;
  bool has_direct = reference_direct(&ref, &direct, &flags);
  snprintf(a->against, sizeof a->against, "%s", reference_renderer_name(ref.renderer));
  a->job_timed = j->timed;
  a->places = lm_alloc(sizeof *a->places * (size_t)(count + 1));
  for (int i = 0; i < count; i++) {
    const job_view *jv = &views[i];
    /* One place per camera, size and frame: the job's first technique's views. */
    if (jv->scene != scene || jv->technique != 0) continue;
    view_place *p = &a->places[a->place_count];
    *p = (view_place){.view = i, .camera = jv->camera, .width = j->sizes[jv->size][0],
                      .height = j->sizes[jv->size][1], .time = jv->time};
    lm_buf input = {0};
    bool found = reference_export(&ref, j, jv, &input, p->reference, sizeof p->reference, &err) &&
                 lm_file_exists(p->reference);
    lm_buf_free(&input);
    if (found && has_direct && (!reference_export(&direct, j, jv, &input, p->direct, sizeof p->direct, &err) ||
                                !lm_file_exists(p->direct)))
      p->direct[0] = '\0';
    lm_buf_free(&input);
    if (found) a->place_count++;
  }
  lm_info("--job %s: %d of its views of this scene have a %s reference under %s", a->job, a->place_count,
          a->against, ref.refs);
}

/* The place the camera is at: a place's camera, not moved by the user, at
 * the place's size (and time, in a timed job); -1 when none. */
static int place_here(const viewer *v) {
  const view_args *a = v->args;
  if (v->camera_user) return -1;
  for (int i = 0; i < a->place_count; i++) {
    const view_place *p = &a->places[i];
    if (p->camera == v->camera && p->width == v->width && p->height == v->height &&
        (!a->job_timed || fabs(p->time - v->time) < 1e-6))
      return i;
  }
  return -1;
}

static void leave_place(viewer *v) {
  lm_image_free(&v->reference);
  lm_texture_destroy(&v->reference_tex);
  lm_texture_destroy(&v->heat_tex);
  v->place_ready = v->live_ok = false;
}

/* Renders the baseline at the place as limn report does and reads its
 * linear output into *img (3 channels). */
static bool render_baseline(viewer *v, const view_place *p, lm_image *img, lm_error *err) {
  const view_args *a = v->args;
  lm_pipeline *pipe = lm_pipeline_load(&(lm_pipeline_desc){.path = v->script}, err);
  bool ok = pipe && lm_pipeline_set_technique(pipe, BASELINE, err);
  for (int i = 0; i < a->job_set_count && ok; i++) ok = capture_set_option(pipe, a->job_sets[i], err);
  lm_renderer *r = NULL;
  if (ok)
    ok = (r = lm_renderer_create(&(lm_renderer_desc){.scene = v->scene, .pipeline = pipe, .width = p->width,
                                                     .height = p->height, .camera = p->camera,
                                                     .linear_output = true}, err)) != NULL;
  capture_view cv = {.camera = p->camera, .width = p->width, .height = p->height, .frames = BASELINE_FRAMES,
                     .warmup = BASELINE_WARMUP, .quiet = true};
  capture_result res = {0};
  *img = (lm_image){p->width, p->height, 3, lm_alloc(sizeof(float) * 3 * (size_t)p->width * p->height)};
  ok = ok && capture_render_write(r, &cv, &res, err) && lm_renderer_read(r, true, img->pixels, err);
  capture_result_free(&res);
  lm_renderer_destroy(r);
  lm_pipeline_destroy(pipe);
  return ok;
}

/* Arriving at place i: its reference, the baseline's errors against it and
 * against the direct-only reference, and the textures the wipe shows. */
static bool arrive(viewer *v, int i, lm_error *err) {
  const view_place *p = &v->args->places[i];
  lm_image base = {0}, direct = {0};
  bool ok = lm_image_read(p->reference, &v->reference, err) &&
            render_baseline(v, p, &base, err) &&
            lm_metrics_check(&base, BASELINE, &v->reference, p->reference, err);
  lm_metrics m;
  v->floor = -1;
  if (ok) {
    lm_metrics_compute_fast(&base, &v->reference, &m);
    v->base_error = m.mean_error;
    v->heat_scale = lm_metrics_max_pixel_error(&base, &v->reference);
  }
  if (ok && p->direct[0]) {
    ok = lm_image_read(p->direct, &direct, err) && lm_metrics_check(&base, BASELINE, &direct, p->direct, err);
    if (ok) lm_metrics_compute_fast(&base, &direct, &m), v->floor = m.mean_error;
  }
  /* The wipe samples the reference as rgba32f (view.frag encodes it as the output stage does). */
  lm_texture_desc d = {LM_FORMAT_RGBA32F, p->width, p->height, false};
  ok = ok && lm_texture_create(&v->reference_tex, &d, "viewer reference", err);
  d.format = LM_FORMAT_RGBA8;
  ok = ok && lm_texture_create(&v->heat_tex, &d, "viewer error heat map", err);
  if (ok) {
    size_t n = (size_t)p->width * p->height;
    float *rgba = lm_alloc(n * 4 * sizeof *rgba);
    for (size_t k = 0; k < n; k++) {
      for (int c = 0; c < 3; c++)
        rgba[k * 4 + c] = v->reference.pixels[k * v->reference.channels + (size_t)(c < v->reference.channels ? c : 0)];
      rgba[k * 4 + 3] = 1;
    }
    lm_texture_upload_floats(v->reference_tex, p->width, p->height, rgba);
    free(rgba);
  }
  if (ok) {
    lm_texture_clear(v->heat_tex);
    lm_info("job view %d: reference %s, direct-only %s", p->view, p->reference, p->direct[0] ? p->direct : "none");
  }
  lm_image_free(&base);
  lm_image_free(&direct);
  return ok;
}

/* The panel's and the overlay's line, and one a test can parse. */
void describe_reference(viewer *v, bool log) {
  const view_place *p = &v->args->places[v->place];
  int n = snprintf(v->reference_text, sizeof v->reference_text, "%s reference of job view %d", v->args->against,
                   p->view);
  double removed;
  bool has_removed = v->floor >= 0 && report_indirect_removed(v->base_error, v->floor, v->live.mean_error, &removed);
  if (v->live_ok && n > 0 && (size_t)n < sizeof v->reference_text) {
    char share[32] = "n/a";
    if (has_removed) snprintf(share, sizeof share, "%.1f%%", removed);
    snprintf(v->reference_text + n, sizeof v->reference_text - (size_t)n,
             ": mean error %.5f, Pearson %.4f, indirect error removed %s of %s's (its error %.5f, floor %.5f;"
             " limn report --baseline %s)",
             v->live.mean_error, v->live.pearson, share, BASELINE, v->base_error, v->floor, BASELINE);
  } else if (n > 0 && (size_t)n < sizeof v->reference_text) {
    snprintf(v->reference_text + n, sizeof v->reference_text - (size_t)n, " here (E: the error against it)");
  }
  if (log && v->live_ok)
    lm_info("reference error: view %d, mean %.9g, pearson %.9g, indirect removed %s%.6g, baseline %.9g, floor %.9g",
            p->view, v->live.mean_error, v->live.pearson, has_removed ? "" : "n/a ", has_removed ? removed : 0.0,
            v->base_error, v->floor);
}

/* This frame's linear output against the reference, and its heat map. */
static void measure(viewer *v) {
  lm_image img = {v->width, v->height, 3, lm_alloc(sizeof(float) * 3 * (size_t)v->width * v->height)};
  lm_error err;
  bool ok = lm_renderer_read(v->renderer, true, img.pixels, &err) &&
            lm_metrics_check(&img, "the frame", &v->reference, v->args->places[v->place].reference, &err);
  if (ok) {
    lm_metrics_compute_fast(&img, &v->reference, &v->live);
    bool first = !v->live_ok;
    v->live_ok = true;
    describe_reference(v, first);
    if (v->error_view == ERROR_VIEW_HEAT) {
      size_t n = (size_t)v->width * v->height;
      unsigned char *rgb = lm_alloc(n * 3), *rgba = lm_alloc(n * 4);
      lm_metrics_heatmap(&img, &v->reference, v->heat_scale, rgb);
      for (size_t k = 0; k < n; k++) memcpy(rgba + k * 4, rgb + k * 3, 3), rgba[k * 4 + 3] = 255;
      lm_texture_upload(v->heat_tex, v->width, v->height, rgba);
      free(rgb);
      free(rgba);
    }
  }
  free(img.pixels);
}

void update_reference(viewer *v) {
  int here = place_here(v);
  if (here != v->place) {
    if (v->place >= 0 && here < 0) say(v, "%s", "no reference here (the camera left the job's view)");
    leave_place(v);
    v->place = here;
    v->reference_text[0] = '\0';
    lm_error err;
    if (here >= 0 && arrive(v, here, &err)) {
      v->place_ready = true;
      describe_reference(v, false);
      say(v, "%s", v->reference_text);
    } else if (here >= 0) {
      snprintf(v->reference_text, sizeof v->reference_text, "reference of job view %d: %s",
               v->args->places[here].view, err.msg);
      lm_log(LM_LOG_ERROR, "%s", v->reference_text);
    }
  }
  if (v->place < 0)
    snprintf(v->reference_text, sizeof v->reference_text, "%s",
             v->args->place_count ? "no reference here (a job view's camera, unmoved, at its size has one)"
                                  : "no reference here (--job FILE with references cached: limn reference)");
  bool on = reference_shown(v);
  /* The frame just rendered kept a linear output only if the last call asked for it. */
  if (on) measure(v);
  lm_renderer_set_linear_output(v->renderer, on);
}

void reference_free(viewer *v) { leave_place(v); }
