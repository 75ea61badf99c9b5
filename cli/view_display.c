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

/* Held within +-1e15: a time as far out as 1e30 s (--time, time=, a job's
 * time; it poses the animation's end) has a frame number past a long's range,
 * whose conversion is undefined (it read -9223372036854775808). */
long view_frame(const viewer *v) {
  double f = floor((v->time - v->args->frame_zero) * v->args->fps + 1e-6);
  return (long)fmax(-1e15, fmin(f, 1e15));
}

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
    int now[3] = {v->cursor_px[0], v->cursor_px[1], v->inspect};
    if (memcmp(now, v->cursor_logged, sizeof now)) /* what the overlay shows, for tests: once a texel */
      lm_debug("texel %d,%d of the inspected target: %.9g %.9g %.9g %.9g", now[0], now[1], v->cursor_value[0],
               v->cursor_value[1], v->cursor_value[2], v->cursor_value[3]);
    memcpy(v->cursor_logged, now, sizeof now);
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

/* The overlay's lines are recorded (colour, line limit, text) and drawn into
 * its image only when they differ from those it holds: clearing, drawing and
 * uploading a window-sized image every frame cost ~1 ms of the viewer's
 * thread a frame at 640x480, even while it showed nothing (--overlay off). */
static void add_text(viewer *v, const uint8_t color[3], int max_lines, const char *text) {
  const char head[4] = {(char)color[0], (char)color[1], (char)color[2], (char)max_lines};
  lm_buf_append(&v->overlay_lines, head, 4);
  lm_buf_append(&v->overlay_lines, text, (int)strlen(text) + 1);
}

static void add_line(viewer *v, const uint8_t color[3], const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void add_line(viewer *v, const uint8_t color[3], const char *fmt, ...) {
  char text[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  add_text(v, color, 2, text);
}

/* The recorded lines into v->overlay from the top, each wrapped to the window. */
static void paint_overlay(viewer *v) {
  memset(v->overlay, 0, (size_t)v->width * v->height * 4);
  int cols = (v->width - 8) / lm_font_advance(v->font), lh = lm_font_line_height(v->font), y = 2;
  if (cols < 8) cols = 8;
  char line[256];
  for (int at = 0; at < v->overlay_lines.len && y < v->height;) {
    const uint8_t *head = (const uint8_t *)v->overlay_lines.data + at;
    const char *text = v->overlay_lines.data + at + 4;
    at += 4 + (int)strlen(text) + 1;
    int max_lines = head[3];
    for (const char *p = text; *p && max_lines > 0 && y < v->height; max_lines--, y += lh) {
      size_t n = strcspn(p, "\n");
      if (n > (size_t)cols) n = (size_t)cols;
      snprintf(line, sizeof line, "%.*s", (int)n, p);
      lm_font_draw(v->font, v->overlay, v->width, v->height, 4, y, line, head);
      p += n;
      if (*p == '\n') p++;
    }
  }
}

static void draw_overlay(viewer *v) {
  static const uint8_t white[3] = {235, 235, 235}, red[3] = {255, 96, 80}, yellow[3] = {255, 220, 96};
  v->overlay_lines.len = 0;
  const char *error = v->script_error[0]   ? v->script_error
                      : v->scene_error[0]  ? v->scene_error
                      : v->shader_error[0] ? v->shader_error
                      : v->frame_error[0]  ? v->frame_error
                                           : v->compare_error;
  lm_graph *g = lm_renderer_graph(v->renderer);
  /* What matters most first: a small window cuts the list at its bottom. */
  if (v->overlay_on)
    add_line(v, white, "%s | %s | %s | %dx%d", lm_pipeline_technique(v->pipeline), v->scene->name,
              strrchr(v->script, '/') ? strrchr(v->script, '/') + 1 : v->script, v->width, v->height);
  if (v->overlay_on && v->compare_on)
    add_line(v, white, "A/B: left %s | right %s%s (B toggles; drag the line)", lm_pipeline_technique(v->pipeline),
              lm_pipeline_technique(v->compare_pipeline), v->args->compare_set_count ? " with its own options" : "");
  if (v->overlay_on && v->args->job && v->reference_text[0]) add_line(v, white, "%s", v->reference_text);
  char time[LIMN_TIME_TEXT];
  if (v->overlay_on && lm_scene_animated(v->scene))
    add_line(v, white, "time %s s | frame %ld | animation %s (%.3g..%.3g s)%s", limn_time_text(v->time, 3, time),
             view_frame(v), view_animation_name(v), v->anim_range[0], v->anim_range[1], v->paused ? " | paused" : "");
  if (v->overlay_on && v->inspect >= 0 && v->inspect < lm_graph_target_count(g)) {
    lm_graph_target_info t = lm_graph_target(g, v->inspect);
    int *order = lm_alloc(sizeof *order * (size_t)lm_graph_target_count(g));
    int n = inspect_order(v, order, lm_graph_target_count(g)), at = 0;
    while (at < n && order[at] != v->inspect) at++;
    free(order);
    bool used = target_used(v, v->inspect), grey = single_channel(t.format);
    add_line(v, yellow, "target %d/%d '%s' %s %dx%d%s | %s | exposure %+.1f%s", at + 1, n, t.name,
              lm_format_name(t.format), t.width, t.height, used ? "" : " | NOT WRITTEN this frame",
              grey ? "grey" : channel_name(v->channel), v->exposure, v->false_colour ? " | false colour" : "");
    if (used && (v->false_colour || grey)) add_line(v, yellow, "range %g .. %g", v->range[0], v->range[1]);
    if (used && v->cursor_in)
      add_line(v, yellow, "at %d,%d: %g %g %g %g", v->cursor_px[0], v->cursor_px[1], v->cursor_value[0],
                v->cursor_value[1], v->cursor_value[2], v->cursor_value[3]);
  }
  if (*error) {
    char text[2100];
    snprintf(text, sizeof text, "error: %s", error);
    add_text(v, red, 8, text); /* the cause first; a traceback's top lines */
  }
  if (v->message[0] && lm_now_ms() < v->message_until) add_text(v, yellow, 3, v->message);
  if (v->overlay_on) {
    double rec, comp;
    lm_renderer_overhead(v->renderer, &rec, &comp);
    add_line(v, white, "frame %.2f ms, render %.2f (Lua %.2f, graph %.2f)", v->frame_ms, v->render_ms,
              rec, comp);
    add_line(v, white, "clock: %s", lm_clock_name(lm_renderer_clock(v->renderer)));
    if (v->frames_timed[1] > 0) {
      char cost[200];
      panel_cost(v, cost, sizeof cost);
      add_line(v, white, "%s", cost);
    }
    double total = 0;
    for (int i = 0; i < lm_graph_pass_count(g); i++) {
      lm_graph_pass_info p = lm_graph_pass(g, i);
      if (p.culled || p.ms < 0) continue;
      add_line(v, white, "  %-14s %8.3f ms", p.name, p.ms);
      total += p.ms;
    }
    add_line(v, white, "  %-14s %8.3f ms", "passes", total);
    lm_buf opts = {0};
    lm_pipeline_list_options(v->pipeline, &opts);
    add_line(v, white, "options: %s", opts.data ? opts.data : "none");
    lm_buf_free(&opts);
  }
  lm_buf *drawn = &v->overlay_drawn, *lines = &v->overlay_lines;
  if (drawn->len == lines->len && (!lines->len || !memcmp(drawn->data, lines->data, (size_t)lines->len))) return;
  paint_overlay(v);
  lm_texture_upload(v->overlay_tex, v->width, v->height, v->overlay);
  drawn->len = 0;
  lm_buf_append(drawn, lines->data ? lines->data : "", lines->len);
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
  lm_texture_clear(v->overlay_tex);
  v->overlay_drawn.len = 0; /* the cleared image: no lines */
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

/* The median of the last n of a ring of PANEL_TIMES figures. */
static double median(const double *ring, long count) {
  double t[PANEL_TIMES];
  int n = count < PANEL_TIMES ? (int)count : PANEL_TIMES;
  memcpy(t, ring, sizeof *t * (size_t)n);
  qsort(t, (size_t)n, sizeof *t, by_value);
  return n ? t[n / 2] : 0;
}

/* The panel's own time is the median of its last timed frames: on llvmpipe a
 * glFinish now and then waits for the rasterizer threads to be scheduled
 * (milliseconds on a loaded machine), which a mean would count as the
 * panel's. Its CPU time (the process's: llvmpipe's threads too) is steadier
 * on a machine others load; the frame's share of each is against the frames
 * with the panel on. */
void panel_cost(const viewer *v, char *out, size_t cap) {
  double on[2] = {0, 0}, off[2] = {0, 0}, own[2];
  for (int c = 0; c < 2; c++) {
    const double *on_sum = c ? v->frame_cpu_sum : v->frame_ms_sum;
    if (v->frames_timed[1]) on[c] = on_sum[1] / v->frames_timed[1];
    if (v->frames_timed[0]) off[c] = on_sum[0] / v->frames_timed[0];
    own[c] = median(v->panel_times[c], v->panel_timed);
  }
  int n = snprintf(out, cap, "panel %.2f ms, %.1f%% of the frame; CPU %.2f ms, %.1f%%", own[0],
                   on[0] > 0 ? 100.0 * own[0] / on[0] : 0.0, own[1], on[1] > 0 ? 100.0 * own[1] / on[1] : 0.0);
  if (off[0] > 0 && n > 0 && (size_t)n < cap)
    snprintf(out + n, cap - (size_t)n, " (frames %.1f ms on, %.1f off; CPU %.1f, %.1f)", on[0], off[0], on[1], off[1]);
}

static void set_texture(const lm_program *p, const char *name, lm_texture t) {
  const lm_uniform *u = lm_program_uniform(p, name);
  if (u) lm_program_bind_texture(u, t);
}

/* A timed stretch of the panel's work (glFinish on both sides; wall:
 * CLOCK_MONOTONIC, CPU: the process's), in frames PANEL_EVERY apart: the
 * glFinish stalls llvmpipe's pipelining, a cost of the timing the other
 * frames spare. panel_clock() starts one, panel_lap() adds its time since to
 * spent[2] (wall, CPU) with the sign given. */
typedef struct panel_stretch {
  double start[2];
} panel_stretch;

static bool panel_timed_frame(const viewer *v) { return v->frame % PANEL_EVERY == 0; }

static panel_stretch panel_clock(const viewer *v) {
  if (!panel_timed_frame(v)) return (panel_stretch){{0, 0}};
  lm_finish();
  return (panel_stretch){{lm_now_ms(), lm_cpu_ms()}};
}

static void panel_lap(const viewer *v, panel_stretch s, double sign, double spent[2]) {
  if (!panel_timed_frame(v)) return;
  lm_finish();
  spent[0] += sign * (lm_now_ms() - s.start[0]);
  spent[1] += sign * (lm_cpu_ms() - s.start[1]);
}

/* The panel laid out (its model built from the viewer's state, its image
 * drawn again when it changed); its time into v->panel_spent. */
static panel_image lay_out_panel(viewer *v) {
  panel_stretch t0 = panel_clock(v);
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
  /* The cost line changes once in PANEL_EVERY timed frames (after a first
   * figure): a line changing every frame would lay the panel out every frame. */
  if (panel_timed_frame(v) && (v->panel_timed == 3 || v->panel_timed % PANEL_EVERY == 0))
    panel_cost(v, v->panel_cost_text, sizeof v->panel_cost_text);
  /* The frame graph: passes with their targets as indices. */
  lm_graph *g = lm_renderer_graph(v->renderer);
  int pass_count = lm_graph_pass_count(g), target_count = lm_graph_target_count(g), ends = 0;
  for (int i = 0; i < pass_count; i++) {
    const lm_pass_desc *d = lm_graph_pass(g, i).desc;
    ends += d->input_count + d->output_count + 1;
  }
  panel_pass *passes = lm_alloc(sizeof *passes * (size_t)(pass_count + 1));
  int *targets_of = lm_alloc(sizeof *targets_of * (size_t)(2 * ends + 1)), used = 0;
  int *columns = lm_alloc(sizeof *columns * (size_t)(pass_count + 1));
  const char **target_names = lm_alloc(sizeof *target_names * (size_t)(target_count + 1));
  for (int i = 0; i < target_count; i++) target_names[i] = lm_graph_target(g, i).name;
  lm_graph_pass_depths(g, columns);
  for (int i = 0; i < pass_count; i++) {
    lm_graph_pass_info info = lm_graph_pass(g, i);
    panel_pass *pp = &passes[i];
    *pp = (panel_pass){.name = info.name, .culled = info.culled, .ms = info.ms, .inputs = targets_of + used,
                       .column = columns[i]};
    for (int k = 0; k < info.desc->input_count; k++) targets_of[used++] = info.desc->inputs[k].target;
    pp->input_count = info.desc->input_count;
    pp->writers = targets_of + used;
    for (int k = 0; k < info.desc->input_count; k++) targets_of[used++] = lm_graph_input_writer(g, i, k);
    pp->outputs = targets_of + used;
    for (int k = 0; k < info.desc->output_count; k++) targets_of[used++] = info.desc->outputs[k];
    if (info.desc->depth >= 0) targets_of[used++] = info.desc->depth;
    pp->output_count = (int)(targets_of + used - pp->outputs);
  }
  char time_text[LIMN_TIME_TEXT];
  panel_model m = {.options = v->options, .option_count = v->option_count, .techniques = names,
                   .technique_count = count, .technique = current, .animated = lm_scene_animated(v->scene),
                   .time = v->time, .time_lo = v->anim_range[0], .time_hi = v->anim_range[1],
                   .time_text = limn_time_text(v->time, 3, time_text),
                   .paused = v->paused, .status = v->status[0] ? v->status : NULL,
                   .cost = v->frames_timed[1] ? v->panel_cost_text : NULL, .passes = passes,
                   .pass_count = pass_count, .targets = target_names, .target_count = target_count,
                   .compare_technique = compare, .compare_on = v->compare_on, .compare_option = compare_option,
                   .reference = v->args->job ? v->reference_text : NULL, .reference_here = v->place_ready,
                   .error_view = v->error_view};
  panel_image image = panel_frame(v->panel, &m, v->width, v->height, &v->edits);
  free(passes);
  free(targets_of);
  free(columns);
  free(target_names);
  v->panel_spent[0] = v->panel_spent[1] = 0;
  panel_lap(v, t0, 1, v->panel_spent);
  return image;
}

/* The panel's image over the display (the window's framebuffer bound); its
 * time added to v->panel_spent (which the display's draw over the panel's
 * column, the pixels the panel spares it, has lessened), the frame's total
 * into v->panel_times. */
static void composite_panel(viewer *v, const panel_image *image) {
  panel_stretch t0 = panel_clock(v);
  lm_error err;
  lm_program *p = lm_program_get("fullscreen.vert", "view.frag", "PANEL", &err);
  const int *r = image->cover;
  if (image->texture.id && p && r[2] > 0 && r[3] > 0) {
    lm_program_use(p);
    set_texture(p, "panel", image->texture);
    lm_set_scissor(true, r[0], r[1], r[2], r[3]);
    lm_draw_fullscreen_over();
    lm_set_scissor(false, 0, 0, 0, 0);
  }
  panel_lap(v, t0, 1, v->panel_spent);
  if (!panel_timed_frame(v)) return;
  for (int c = 0; c < 2; c++) v->panel_times[c][v->panel_timed % PANEL_TIMES] = v->panel_spent[c];
  v->panel_timed++;
}

/* The display's columns x .. x + w - 1: src copied to the window, or drawn
 * by the program in use. */
static void draw_columns(viewer *v, bool copy, lm_texture src, int x, int w) {
  lm_error err;
  if (copy && !lm_screen_blit(src, x, 0, w, v->height, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    copy = false;
  }
  if (copy) return;
  lm_set_scissor(true, x, 0, w, v->height);
  lm_draw_fullscreen();
  lm_set_scissor(false, 0, 0, 0, 0);
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
  /* The panel first: the display leaves out the column its window covers. */
  panel_image panel = {.column = v->width};
  if (v->panel && v->panel_on) panel = lay_out_panel(v);
  if (!panel.texture.id) panel.column = v->width;
  /* The wipe: the other side right of the split (the frame only, not a
   * target): the reference or its heat map while the error view is on,
   * else the A/B --compare side. view.frag's variant: what this frame shows. */
  bool reference = reference_shown(v), wipe = (v->compare_on || reference) && mode == 0;
  bool linear = wipe && reference && v->error_view == ERROR_VIEW_REFERENCE;
  char defines[64];
  snprintf(defines, sizeof defines, "MODE=%d%s%s%s", mode, wipe ? ";WIPE" : "", linear ? ";OTHER_LINEAR" : "",
           v->overlay_drawn.len ? ";OVERLAY" : "");
  lm_program *p = lm_program_get("fullscreen.vert", "view.frag", defines, &err);
  lm_screen_bind(v->width, v->height);
  if (!p) { /* view.frag itself is broken: show what can be shown */
    set_error(v->shader_error, sizeof v->shader_error, err.msg, "");
  } else {
    lm_program_use(p);
    set_texture(p, "src", src);
    set_texture(p, "overlay", v->overlay_tex);
    set_texture(p, "other", !reference ? v->compare_shown
                            : linear   ? v->reference_tex
                                       : v->heat_tex);
    float split = v->split * (float)v->width;
    set_float(p, "split", &split);
    set_int(p, "channel", v->channel);
    set_float(p, "exposure", &v->exposure);
    set_float(p, "range", v->range);
    /* The frame as it is (no target, wipe or text over it) is copied, not
     * drawn: llvmpipe's blit spares the shader, ~1.4 ms of CPU a frame at 640x480. */
    bool copy = mode == 0 && !wipe && !v->overlay_drawn.len;
    draw_columns(v, copy, src, 0, panel.column);
    if (panel.column < v->width && panel_timed_frame(v)) { /* what the panel spares the display, timed */
      panel_stretch t0 = panel_clock(v);
      draw_columns(v, copy, src, panel.column, v->width - panel.column);
      panel_lap(v, t0, -1, v->panel_spent);
    }
  }
  if (v->panel && v->panel_on) composite_panel(v, &panel);
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
