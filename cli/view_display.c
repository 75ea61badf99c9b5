/* What reaches the viewer's user: messages and errors, the frame or an
 * inspected target of the frame graph (exposure, channel, false colour)
 * under the text overlay in the window; captures and screenshots. */
#define _GNU_SOURCE
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "view.h"

/* ---- messages and the time's names ------------------------------------- */
void say(viewer *v, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(v->message, sizeof v->message, fmt, ap);
  va_end(ap);
  v->message_until = lm_now_ms() + 4000;
  lm_info("%s", v->message);
}

/* An error shows once on stderr when it appears and once more when it clears. */
void set_error(char *slot, size_t cap, const char *msg, const char *cleared) {
  if (!msg) msg = "";
  if (!strcmp(slot, msg)) return;
  if (*msg)
    lm_log(LM_LOG_ERROR, "%s", msg);
  else if (*slot)
    lm_info("%s", cleared);
  snprintf(slot, cap, "%s", msg);
}

long view_frame(const viewer *v) { return (long)floor(v->time * v->args->fps + 1e-6); }

const char *view_animation_name(const viewer *v) {
  return v->anim >= 0 && v->anim < v->scene->animation_count ? v->scene->animations[v->anim].name : "all";
}

/* ---- inspector and overlay --------------------------------------------- */
static const char *channel_name(int c) {
  static const char *names[] = {"r", "g", "b", "a", "rgb"};
  return names[c];
}

/* The inspected target's raw values into v->probe (rgba32f at its size). */
static bool probe_target(viewer *v, lm_graph_target_info t, lm_error *err) {
  if (!t.texture.id) {
    lm_error_set(err, "target '%s' has no texture this frame (not used)", t.name);
    return false;
  }
  if (v->probe_w != t.width || v->probe_h != t.height || !v->probe.id) {
    lm_texture_destroy(&v->probe);
    lm_texture_desc d = {LM_FORMAT_RGBA32F, t.width, t.height, false};
    if (!lm_texture_create(&v->probe, &d, "viewer probe", err)) return false;
    v->probe_w = t.width, v->probe_h = t.height;
  }
  lm_program *p = lm_program_get("fullscreen.vert", "view.frag", "PROBE", err);
  lm_attachments att = {.color = {v->probe}, .color_count = 1, .width = t.width, .height = t.height};
  if (!p || !lm_attachments_bind(&att, err)) return false;
  lm_program_use(p);
  lm_program_bind_texture(lm_program_uniform(p, "src"), t.texture);
  lm_draw_fullscreen();
  return true;
}

/* Depth and one-channel targets show grey over their range (sampled, they
 * fill red alone). */
static bool single_channel(lm_format f) {
  return f == LM_FORMAT_R16F || f == LM_FORMAT_R32F || f == LM_FORMAT_DEPTH32F;
}

/* Reads the probe back: the range of channel c (finite values) and the
 * value of the texel under the cursor. */
static void read_probe(viewer *v, int c) {
  size_t n = (size_t)v->probe_w * v->probe_h;
  float *px = lm_alloc(n * 16), lo = INFINITY, hi = -INFINITY;
  lm_texture_read(v->probe, v->probe_w, v->probe_h, true, px); /* top row first, as the window */
  for (size_t i = 0; i < n; i++) {
    float x = px[i * 4 + c];
    if (isfinite(x)) lo = fminf(lo, x), hi = fmaxf(hi, x);
  }
  v->range[0] = isfinite(lo) ? lo : 0, v->range[1] = isfinite(hi) ? hi : 1;
  double x, y;
  if (v->mouse_scripted)
    x = v->mouse[0], y = v->mouse[1];
  else
    lm_window_cursor(v->window, &x, &y);
  v->cursor_in = x >= 0 && y >= 0 && x < v->width && y < v->height;
  if (v->cursor_in) {
    v->cursor_px[0] = (int)(x * v->probe_w / v->width), v->cursor_px[1] = (int)(y * v->probe_h / v->height);
    memcpy(v->cursor_value, px + ((size_t)v->cursor_px[1] * v->probe_w + v->cursor_px[0]) * 4, sizeof v->cursor_value);
  }
  free(px);
}

bool target_used(viewer *v, int target) {
  lm_graph_target_info t = lm_graph_target(lm_renderer_graph(v->renderer), target);
  return t.used && t.texture.id;
}

int inspect_order(viewer *v, int *order, int cap) {
  lm_graph *g = lm_renderer_graph(v->renderer);
  int count = lm_graph_target_count(g), out = lm_graph_find_target(g, "output.srgb"), n = 0;
  if (out >= 0 && n < cap) order[n++] = out;
  for (int used = 1; used >= 0; used--)
    for (int i = 0; i < count && n < cap; i++)
      if (i != out && target_used(v, i) == used) order[n++] = i;
  return n;
}

/* Writes the inspected target (EXR, raw values) and the frame (PNG). */
void write_captures(viewer *v) {
  lm_error err;
  char path[4096];
  int n = ++v->captures;
  lm_graph *g = lm_renderer_graph(v->renderer);
  if (v->inspect >= 0 && v->inspect < lm_graph_target_count(g)) {
    lm_graph_target_info t = lm_graph_target(g, v->inspect);
    char name[128];
    snprintf(name, sizeof name, "%s", t.name);
    for (char *c = name; *c; c++)
      if (*c == '/' || *c == ' ') *c = '_';
    snprintf(path, sizeof path, "%s/limn-%s-%04d.exr", v->args->capture_dir, name, n);
    if (probe_target(v, t, &err)) {
      float *px = lm_alloc((size_t)t.width * t.height * 16);
      lm_texture_read(v->probe, t.width, t.height, true, px);
      bool ok = lm_image_write(path, t.width, t.height, 4, true, px, &err);
      free(px);
      if (ok) say(v, "wrote %s", path);
    }
    if (err.msg[0] && !lm_file_exists(path)) say(v, "%s", err.msg);
  }
  lm_texture tex;
  int w, h;
  if (!lm_renderer_output(v->renderer, &tex, &w, &h)) return;
  unsigned char *rgba = lm_alloc((size_t)w * h * 4), *rgb = lm_alloc((size_t)w * h * 3);
  lm_texture_read(tex, w, h, false, rgba);
  for (size_t i = 0; i < (size_t)w * h; i++) memcpy(rgb + i * 3, rgba + i * 4, 3);
  snprintf(path, sizeof path, "%s/limn-frame-%04d.png", v->args->capture_dir, n);
  if (lm_image_write(path, w, h, 3, false, rgb, &err))
    say(v, "wrote %s", path);
  else
    say(v, "%s", err.msg);
  free(rgba);
  free(rgb);
}

/* Draws text at *y (wrapped to the window, at most max_lines lines) and moves *y down. */
static void draw_text(viewer *v, int *y, const uint8_t color[3], int max_lines, const char *text) {
  int cols = (v->width - 8) / lm_font_advance(v->font), lh = lm_font_line_height(v->font);
  if (cols < 8) cols = 8;
  char line[256];
  for (const char *p = text; *p && max_lines > 0 && *y < v->height; max_lines--, *y += lh) {
    size_t n = strcspn(p, "\n");
    if (n > (size_t)cols) n = (size_t)cols;
    snprintf(line, sizeof line, "%.*s", (int)n, p);
    lm_font_draw(v->font, v->overlay, v->width, v->height, 4, *y, line, color);
    p += n;
    if (*p == '\n') p++;
  }
}

static void draw_line(viewer *v, int *y, const uint8_t color[3], const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void draw_line(viewer *v, int *y, const uint8_t color[3], const char *fmt, ...) {
  char text[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  draw_text(v, y, color, 2, text);
}

static void draw_overlay(viewer *v) {
  static const uint8_t white[3] = {235, 235, 235}, red[3] = {255, 96, 80}, yellow[3] = {255, 220, 96};
  memset(v->overlay, 0, (size_t)v->width * v->height * 4);
  const char *error = v->script_error[0]   ? v->script_error
                      : v->scene_error[0]  ? v->scene_error
                      : v->shader_error[0] ? v->shader_error
                      : v->frame_error[0]  ? v->frame_error
                                           : v->compare_error;
  lm_graph *g = lm_renderer_graph(v->renderer);
  int y = 2;
  /* What matters most first: a small window cuts the list at its bottom. */
  if (v->overlay_on)
    draw_line(v, &y, white, "%s | %s | %s | %dx%d", lm_pipeline_technique(v->pipeline), v->scene->name,
              strrchr(v->script, '/') ? strrchr(v->script, '/') + 1 : v->script, v->width, v->height);
  if (v->overlay_on && v->compare_on)
    draw_line(v, &y, white, "A/B: left %s | right %s%s (B toggles; drag the line)", lm_pipeline_technique(v->pipeline),
              lm_pipeline_technique(v->compare_pipeline), v->args->compare_set_count ? " with its own options" : "");
  if (v->overlay_on && v->args->job && v->reference_text[0]) draw_line(v, &y, white, "%s", v->reference_text);
  if (v->overlay_on && lm_scene_animated(v->scene))
    draw_line(v, &y, white, "time %.3f s | frame %ld | animation %s (%.3g..%.3g s)%s", v->time, view_frame(v),
              view_animation_name(v), v->anim_range[0], v->anim_range[1], v->paused ? " | paused" : "");
  if (v->overlay_on && v->inspect >= 0 && v->inspect < lm_graph_target_count(g)) {
    lm_graph_target_info t = lm_graph_target(g, v->inspect);
    int *order = lm_alloc(sizeof *order * (size_t)lm_graph_target_count(g));
    int n = inspect_order(v, order, lm_graph_target_count(g)), at = 0;
    while (at < n && order[at] != v->inspect) at++;
    free(order);
    bool used = target_used(v, v->inspect), grey = single_channel(t.format);
    draw_line(v, &y, yellow, "target %d/%d '%s' %s %dx%d%s | %s | exposure %+.1f%s", at + 1, n, t.name,
              lm_format_name(t.format), t.width, t.height, used ? "" : " | NOT WRITTEN this frame",
              grey ? "grey" : channel_name(v->channel), v->exposure, v->false_colour ? " | false colour" : "");
    if (used && (v->false_colour || grey)) draw_line(v, &y, yellow, "range %g .. %g", v->range[0], v->range[1]);
    if (used && v->cursor_in)
      draw_line(v, &y, yellow, "at %d,%d: %g %g %g %g", v->cursor_px[0], v->cursor_px[1], v->cursor_value[0],
                v->cursor_value[1], v->cursor_value[2], v->cursor_value[3]);
  }
  if (*error) {
    char text[2100];
    snprintf(text, sizeof text, "error: %s", error);
    draw_text(v, &y, red, 8, text); /* the cause first; a traceback's top lines */
  }
  if (v->message[0] && lm_now_ms() < v->message_until) draw_text(v, &y, yellow, 3, v->message);
  if (v->overlay_on) {
    double rec, comp;
    lm_renderer_overhead(v->renderer, &rec, &comp);
    draw_line(v, &y, white, "frame %.2f ms, render %.2f (Lua %.2f, graph %.2f)", v->frame_ms, v->render_ms,
              rec, comp);
    draw_line(v, &y, white, "clock: %s", lm_clock_name(lm_renderer_clock(v->renderer)));
    if (v->frames_timed[1] > 0) {
      char cost[200];
      panel_cost(v, cost, sizeof cost);
      draw_line(v, &y, white, "%s", cost);
    }
    double total = 0;
    for (int i = 0; i < lm_graph_pass_count(g); i++) {
      lm_graph_pass_info p = lm_graph_pass(g, i);
      if (p.culled || p.ms < 0) continue;
      draw_line(v, &y, white, "  %-14s %8.3f ms", p.name, p.ms);
      total += p.ms;
    }
    draw_line(v, &y, white, "  %-14s %8.3f ms", "passes", total);
    lm_buf opts = {0};
    lm_pipeline_list_options(v->pipeline, &opts);
    draw_line(v, &y, white, "options: %s", opts.data ? opts.data : "none");
    lm_buf_free(&opts);
  }
  lm_texture_upload(v->overlay_tex, v->width, v->height, v->overlay);
}

/* ---- the window's content ---------------------------------------------- */
bool make_window_textures(viewer *v, lm_error *err) {
  lm_texture_destroy(&v->shown);
  lm_texture_destroy(&v->overlay_tex);
  lm_texture_desc d = {LM_FORMAT_RGBA8, v->width, v->height, false};
  if (!lm_texture_create(&v->shown, &d, "viewer frame", err) ||
      !lm_texture_create(&v->overlay_tex, &d, "viewer overlay", err))
    return false;
  lm_texture_clear(v->shown);
  if (v->compare_renderer) {
    lm_texture_destroy(&v->compare_shown);
    if (!lm_texture_create(&v->compare_shown, &d, "viewer frame (compare)", err)) return false;
    lm_texture_clear(v->compare_shown);
  }
  free(v->overlay);
  v->overlay = lm_alloc((size_t)v->width * v->height * 4);
  return true;
}

static void set_float(const lm_program *p, const char *name, const float *x) {
  const lm_uniform *u = lm_program_uniform(p, name);
  if (u) lm_program_set(p, u, x);
}

static void set_int(const lm_program *p, const char *name, int x) {
  const lm_uniform *u = lm_program_uniform(p, name);
  if (u) lm_program_set_int(p, u, &x);
}

/* ---- the panel --------------------------------------------------------- */
static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The panel's own time is the median of its last frames: on llvmpipe a
 * glFinish now and then waits for the rasterizer threads to be scheduled
 * (milliseconds on a loaded machine), which a mean would count as the panel's. */
void panel_cost(const viewer *v, char *out, size_t cap) {
  double on = v->frames_timed[1] ? v->frame_ms_sum[1] / v->frames_timed[1] : 0;
  double off = v->frames_timed[0] ? v->frame_ms_sum[0] / v->frames_timed[0] : 0;
  double t[PANEL_TIMES], own = 0;
  int n = v->panel_timed < PANEL_TIMES ? (int)v->panel_timed : PANEL_TIMES;
  memcpy(t, v->panel_times, sizeof *t * (size_t)n);
  qsort(t, (size_t)n, sizeof *t, by_value);
  if (n) own = t[n / 2];
  n = snprintf(out, cap, "panel %.2f ms, %.1f%% of the frame", own, on > 0 ? 100.0 * own / on : 0.0);
  if (off > 0 && n > 0 && (size_t)n < cap)
    snprintf(out + n, cap - (size_t)n, " (frames %.1f ms on, %.1f off)", on, off);
}

/* The panel's image; its own time (glFinish on both sides, CLOCK_MONOTONIC) into v->panel_times. */
static lm_texture draw_panel(viewer *v) {
  if (v->options_stale) {
    free(v->options);
    v->option_count = lm_pipeline_options(v->pipeline, &v->options);
    free(v->compare_options);
    v->compare_options = NULL;
    v->compare_option_count = v->compare_pipeline ? lm_pipeline_options(v->compare_pipeline, &v->compare_options) : 0;
    v->options_stale = false;
  }
  enum { MAX_TECHNIQUES = 256 };
  const char *names[MAX_TECHNIQUES];
  int count = lm_pipeline_technique_count(v->pipeline), current = 0, compare = -1;
  if (count > MAX_TECHNIQUES) count = MAX_TECHNIQUES;
  for (int i = 0; i < count; i++) {
    names[i] = lm_pipeline_technique_name(v->pipeline, i);
    if (!strcmp(names[i], lm_pipeline_technique(v->pipeline))) current = i;
    if (v->compare_pipeline && !strcmp(names[i], v->compare_tech)) compare = i;
  }
  const lm_option_info *compare_option = NULL; /* the option the A/B sets apart, as that side has it */
  for (int i = 0; i < v->compare_option_count && v->compare_option[0]; i++)
    if (!strcmp(v->compare_options[i].name, v->compare_option)) compare_option = &v->compare_options[i];
  /* Its own time, one frame in PANEL_EVERY: the glFinish on both sides
   * stalls llvmpipe's pipelining, a cost of the timing the other frames
   * spare. The cost line changes once in PANEL_EVERY timed frames (after a
   * first figure): a line changing every frame would draw the panel's image
   * every frame. */
  bool timed = v->frame % PANEL_EVERY == 0;
  if (timed && (v->panel_timed == 3 || v->panel_timed % PANEL_EVERY == 0))
    panel_cost(v, v->panel_cost_text, sizeof v->panel_cost_text);
  /* The frame graph: passes with their targets as indices. */
  lm_graph *g = lm_renderer_graph(v->renderer);
  int pass_count = lm_graph_pass_count(g), target_count = lm_graph_target_count(g), ends = 0;
  for (int i = 0; i < pass_count; i++) {
    const lm_pass_desc *d = lm_graph_pass(g, i).desc;
    ends += d->input_count + d->output_count + 1;
  }
  panel_pass *passes = lm_alloc(sizeof *passes * (size_t)(pass_count + 1));
  int *targets_of = lm_alloc(sizeof *targets_of * (size_t)(ends + 1)), used = 0;
  const char **target_names = lm_alloc(sizeof *target_names * (size_t)(target_count + 1));
  for (int i = 0; i < target_count; i++) target_names[i] = lm_graph_target(g, i).name;
  for (int i = 0; i < pass_count; i++) {
    lm_graph_pass_info info = lm_graph_pass(g, i);
    panel_pass *pp = &passes[i];
    *pp = (panel_pass){.name = info.name, .culled = info.culled, .ms = info.ms, .inputs = targets_of + used};
    for (int k = 0; k < info.desc->input_count; k++) targets_of[used++] = info.desc->inputs[k].target;
    pp->input_count = info.desc->input_count;
    pp->outputs = targets_of + used;
    for (int k = 0; k < info.desc->output_count; k++) targets_of[used++] = info.desc->outputs[k];
    if (info.desc->depth >= 0) targets_of[used++] = info.desc->depth;
    pp->output_count = (int)(targets_of + used - pp->outputs);
  }
  panel_model m = {.options = v->options, .option_count = v->option_count, .techniques = names,
                   .technique_count = count, .technique = current, .animated = lm_scene_animated(v->scene),
                   .time = v->time, .time_lo = v->anim_range[0], .time_hi = v->anim_range[1],
                   .paused = v->paused, .status = v->status[0] ? v->status : NULL,
                   .cost = v->frames_timed[1] ? v->panel_cost_text : NULL, .passes = passes,
                   .pass_count = pass_count, .targets = target_names, .target_count = target_count,
                   .compare_technique = compare, .compare_on = v->compare_on, .compare_option = compare_option,
                   .reference = v->args->job ? v->reference_text : NULL, .reference_here = v->place_ready,
                   .error_view = v->error_view};
  if (timed) lm_finish();
  double t0 = lm_now_ms();
  lm_texture image = panel_frame(v->panel, &m, v->width, v->height, &v->edits);
  if (timed) {
    lm_finish();
    v->panel_times[v->panel_timed++ % PANEL_TIMES] = lm_now_ms() - t0;
  }
  free(passes);
  free(targets_of);
  free(target_names);
  return image;
}

bool reference_shown(const viewer *v) { return v->error_view != ERROR_VIEW_OFF && v->place_ready; }

void display(viewer *v) {
  lm_error err;
  lm_texture src = v->shown;
  int mode = 0;
  lm_graph *g = lm_renderer_graph(v->renderer);
  if (v->inspect >= 0 && v->inspect < lm_graph_target_count(g)) {
    lm_graph_target_info t = lm_graph_target(g, v->inspect);
    bool grey = single_channel(t.format);
    if (probe_target(v, t, &err)) {
      src = v->probe;
      mode = v->false_colour ? 2 : grey ? 4 : 1;
      read_probe(v, grey || v->channel > 3 ? 0 : v->channel);
    } else {
      mode = 3; /* a target with no texture this frame: black, not the frame */
    }
    if (v->inspect_logged != v->inspect)
      lm_info("inspecting '%s' %s %dx%d%s, range %g .. %g", t.name, lm_format_name(t.format), t.width, t.height,
              mode == 3 ? " (not written this frame)" : grey ? " grey" : "", v->range[0], v->range[1]);
    v->inspect_logged = v->inspect;
  }
  draw_overlay(v);
  lm_texture panel = v->panel && v->panel_on ? draw_panel(v) : (lm_texture){0};
  lm_program *p = lm_program_get("fullscreen.vert", "view.frag", "", &err);
  lm_screen_bind(v->width, v->height);
  if (!p) { /* view.frag itself is broken: show what can be shown */
    set_error(v->shader_error, sizeof v->shader_error, err.msg, "");
    return;
  }
  lm_program_use(p);
  lm_program_bind_texture(lm_program_uniform(p, "src"), src);
  lm_program_bind_texture(lm_program_uniform(p, "overlay"), v->overlay_tex);
  lm_program_bind_texture(lm_program_uniform(p, "panel"), panel.id ? panel : v->overlay_tex);
  set_int(p, "show_panel", panel.id != 0);
  /* The wipe: the other side right of the split (the frame only, not a
   * target): the reference or its heat map while the error view is on,
   * else the A/B --compare side. */
  bool reference = reference_shown(v);
  lm_texture other = !reference                             ? (v->compare_on ? v->compare_shown : src)
                     : v->error_view == ERROR_VIEW_REFERENCE ? v->reference_tex
                                                             : v->heat_tex;
  float split = (v->compare_on || reference) && mode == 0 ? v->split * (float)v->width : -1.0f;
  lm_program_bind_texture(lm_program_uniform(p, "other"), other);
  set_int(p, "other_linear", reference && v->error_view == ERROR_VIEW_REFERENCE);
  set_float(p, "split", &split);
  set_int(p, "mode", mode);
  set_int(p, "channel", v->channel);
  set_float(p, "exposure", &v->exposure);
  set_float(p, "range", v->range);
  lm_draw_fullscreen();
}

bool screenshot(viewer *v, const char *path) {
  uint8_t *rgb = lm_alloc((size_t)v->width * v->height * 3);
  lm_screen_read(v->width, v->height, rgb);
  lm_error err;
  bool ok = lm_image_write(path, v->width, v->height, 3, false, rgb, &err);
  free(rgb);
  if (!ok) lm_log(LM_LOG_ERROR, "%s", err.msg);
  else lm_info("wrote %s (%dx%d)", path, v->width, v->height);
  return ok;
}
