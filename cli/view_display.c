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

static void update_range(viewer *v) {
  size_t n = (size_t)v->probe_w * v->probe_h;
  float *px = lm_alloc(n * 16), lo = INFINITY, hi = -INFINITY;
  lm_texture_read(v->probe, v->probe_w, v->probe_h, true, px);
  int c = v->channel < 4 ? v->channel : 0;
  for (size_t i = 0; i < n; i++) {
    float x = px[i * 4 + c];
    if (isfinite(x)) lo = fminf(lo, x), hi = fmaxf(hi, x);
  }
  free(px);
  v->range[0] = isfinite(lo) ? lo : 0, v->range[1] = isfinite(hi) ? hi : 1;
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
                                           : v->frame_error;
  lm_graph *g = lm_renderer_graph(v->renderer);
  int y = 2;
  /* What matters most first: a small window cuts the list at its bottom. */
  if (v->overlay_on)
    draw_line(v, &y, white, "%s | %s | %s | %dx%d", lm_pipeline_technique(v->pipeline), v->scene->name,
              strrchr(v->script, '/') ? strrchr(v->script, '/') + 1 : v->script, v->width, v->height);
  if (v->overlay_on && lm_scene_animated(v->scene))
    draw_line(v, &y, white, "time %.3f s | frame %ld | animation %s (%.3g..%.3g s)%s", v->time, view_frame(v),
              view_animation_name(v), v->anim_range[0], v->anim_range[1], v->paused ? " | paused" : "");
  if (v->overlay_on && v->inspect >= 0 && v->inspect < lm_graph_target_count(g)) {
    lm_graph_target_info t = lm_graph_target(g, v->inspect);
    draw_line(v, &y, yellow, "target %d/%d '%s' %s %dx%d%s | %s | exposure %+.1f%s", v->inspect + 1,
              lm_graph_target_count(g), t.name, lm_format_name(t.format), t.width, t.height,
              t.texture.id ? "" : " (not used this frame)", channel_name(v->channel), v->exposure,
              v->false_colour ? " | false colour" : "");
    if (v->false_colour && t.texture.id) draw_line(v, &y, yellow, "range %g .. %g", v->range[0], v->range[1]);
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

void display(viewer *v) {
  lm_error err;
  lm_texture src = v->shown;
  int mode = 0;
  lm_graph *g = lm_renderer_graph(v->renderer);
  if (v->inspect >= 0 && v->inspect < lm_graph_target_count(g)) {
    lm_graph_target_info t = lm_graph_target(g, v->inspect);
    if (probe_target(v, t, &err)) {
      src = v->probe;
      mode = v->false_colour ? 2 : 1;
      if (v->false_colour) update_range(v);
    } else {
      mode = 3; /* a target with no texture this frame: black, not the frame */
    }
  }
  draw_overlay(v);
  lm_program *p = lm_program_get("fullscreen.vert", "view.frag", "", &err);
  lm_screen_bind(v->width, v->height);
  if (!p) { /* view.frag itself is broken: show what can be shown */
    set_error(v->shader_error, sizeof v->shader_error, err.msg, "");
    return;
  }
  lm_program_use(p);
  lm_program_bind_texture(lm_program_uniform(p, "src"), src);
  lm_program_bind_texture(lm_program_uniform(p, "overlay"), v->overlay_tex);
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
