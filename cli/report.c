/* limn report --job FILE --sweep SPEC: error against references (POV-Ray's or Cycles') and
 * run time for every technique and setting of a sweep, on every view of a
 * capture job. Writes report.csv, report.json, report.svg and report.md
 * (seed 000 chapter 5.3: mean error eq 19, Pearson eq 20, gain over direct
 * light, share of pixels closer to the reference). Over a job's sequences
 * also the error over time of shared/design/motion.md: mean error over
 * frames, flicker and lag after the job's events, and error against frame. */
#define _GNU_SOURCE
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/metrics.h"
#include "reference.h"
#include "report_math.h"
#include "tools.h"

#define BASELINE "dl"

static const char report_usage[] =
    "usage: limn report --job FILE --sweep SPEC [--sweep SPEC ...] [options]\n"
    "\n"
    "Renders every view of a capture job (scenes, cameras, sizes; the job's\n"
    "techniques are replaced by the sweep's) with each technique and setting,\n"
    "compares each image with the view's reference (limn reference: POV-Ray's, or\n"
    "Cycles' with --renderer cycles or the job's renderer = \"cycles\";\n"
    "missing ones are rendered first) and writes DIR/report.csv, report.json,\n"
    "report.svg (mean error against milliseconds, Pareto front marked) and\n"
    "report.md (gain over direct light per view, mean and median gain, share\n"
    "of views and pixels improved, Pearson before and after). The baseline\n"
    "(--baseline, default direct light: " BASELINE ") is always rendered.\n"
    "Each view's direct-only reference (POV-Ray without radiosity, Cycles with 0\n"
    "bounces; cached too) gives its floor, the baseline's error against it,\n"
    "and each setting's share of the baseline's indirect error removed:\n"
    "100 (e_base - e) / (e_base - floor), n/a where the floor is not below.\n"
    "Against Cycles each view's reference is rendered again at the next --seed:\n"
    "the mean error between the two is the reference's noise (reference_noise).\n"
    "A job with sequences (time = { start, stop, fps }) renders each setting\n"
    "through each sequence's frames in order, one frame each after the first's\n"
    "warm-up, and adds per setting and sequence: the mean error over frames,\n"
    "flicker (mean |(L_t - L_t-1) - (R_t - R_t-1)|, the change the reference\n"
    "does not have) and the lag after each of the job's events = { frame, ... }\n"
    "(frames until the error stays within 10% of its settled value: the\n"
    "error of the window's last pose rendered still until converged, 48\n"
    "frames), with error against frame plotted under report.svg's scatter.\n"
    "\n"
    "SPEC: TECH, or TECH:OPTION=V1,V2,...;OPTION=V1,... for every combination,\n"
    "  e.g. --sweep \"isr:isr.samples=8,16,32;isr.coarse=1,2\" --sweep ssao\n"
    "  (the last option varies fastest; at most 256 settings). Each setting starts\n"
    "  from the script's defaults and the job's set, inheriting nothing.\n"
    "\n"
    "options:\n"
    "  --job FILE           the capture job (its `set` applies to every setting;\n"
    "                       set ambient = 0 to compare with POV-Ray)\n"
    "  --sweep SPEC         techniques and settings (repeatable)\n"
    "  --out DIR            where the report goes (default out/report)\n"
    "  --baseline TECH      the technique gains are measured against (default " BASELINE ";\n"
    "                       dl+esm when the references have shadows to match)\n"
    "  --frames N           timed frames per image; times are medians (default 5)\n"
    "  --warmup N           frames rendered first, untimed (default 2)\n"
    "  --refs DIR           the references (default out/reference)\n"
    "  --require-refs       fail, naming the command, when a reference is missing,\n"
    "                       instead of rendering it\n"
    "  --cached-refs        render no reference: leave out (and name) the views\n"
    "                       whose reference or direct-only floor is not cached;\n"
    "                       a missing second seed's leaves the noise n/a\n"
    "  --jobs N, --povray PROGRAM, --force: as limn reference, for missing ones\n"
    REFERENCE_OPTIONS_HELP
    "  --radiosity, --count, --error-bound, --pretrace-start, --pretrace-end,\n"
    "  --recursion-limit, --brightness, --shadows, --approximate: as export-pov\n"
    "                       (the references')\n"
    "  --quiet              no progress\n"
    "\n"
    "exit codes: 0 written, 1 a render, reference or file failed, 2 bad usage.\n";

typedef struct report_row {
  int setting, place;
  lm_metrics m;      /* against the reference */
  double floor;      /* the view's direct-only floor: the baseline against the direct-only reference */
  double noise;      /* the reference's own: its mean error against the same render at the next seed; -1: none */
  double closer;     /* share of pixels closer to the reference than the baseline's */
  double flicker;    /* of this frame and the one before in its sequence (lm_metrics_flicker); 0 for a first */
  double total_ms;
  capture_result res;
} report_row;

typedef struct report_args {
  const char *job, *out, *baseline;
  report_setting *settings;
  int setting_count, frames, warmup;
  bool require_refs;
  bool cached_refs; /* leave out the views whose references are not cached */
  reference_args ref;
  reference_args direct; /* the direct-only references' (reference_direct) */
  bool has_floor;        /* the references hold indirect light: the direct-only ones give the floor */
  const char *direct_flags; /* how `limn reference` says direct */
  char against[256];     /* what the references are (reference_describe) */
  bool has_noise;        /* Cycles: the same references at the next seed measure their noise */
  reference_args second; /* those references' */
  char second_flags[96];
  bool sequences; /* the job has a run of two frames or more: views are named with their frame */
  int events[REPORT_MAX_EVENTS], event_count; /* the job's events (job.events) */
} report_args;

/* The places in runs (report_sequences) and, with sequences, each setting's
 * error over each run: summary[run * settings + setting] (frames 0 for a
 * run of one view). */
/* Frames a still pose renders before its error counts as the settled one:
 * more than any temporal history holds by default (temporal.frames 36). */
#define REPORT_SETTLE_FRAMES 48

typedef struct report_runs {
  int *first, count;
  report_sequence *summary;
  /* settled[(run * settings + setting) * REPORT_MAX_EVENTS + event]: the
   * error of the event window's last pose rendered still until converged
   * (settle_pose), what the lag measures the return to; -1: not rendered. */
  double *settled;
} report_runs;

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("report", fmt, arg); }

/* ---- writing ------------------------------------------------------------ */


/* A CSV field: quoted, quotes doubled. */
static void csv_str(lm_buf *b, const char *s) {
  lm_buf_append(b, "\"", 1);
  for (; *s; s++) lm_buf_append(b, *s == '"' ? "\"\"" : s, 1 + (*s == '"'));
  lm_buf_append(b, "\"", 1);
}

/* SVG and Markdown text: <, >, & escaped. */
static void xml_str(lm_buf *b, const char *s) {
  for (; *s; s++) {
    if (*s == '<') lm_buf_append(b, "&lt;", -1);
    else if (*s == '>') lm_buf_append(b, "&gt;", -1);
    else if (*s == '&') lm_buf_append(b, "&amp;", -1);
    else if (*s == '"') lm_buf_append(b, "&quot;", -1);
    else lm_buf_append(b, s, 1);
  }
}

static void place_name(const job *j, const job_view *v, char *out, size_t cap) {
  const job_scene *s = &j->scenes[v->scene];
  snprintf(out, cap, "%s/%s/%dx%d", s->name, s->scene->cameras[v->camera].name, j->sizes[v->size][0],
           j->sizes[v->size][1]);
}

/* A row's view: its place, and "#frame" after it in a job with sequences. */
static void view_name(const report_args *a, const job *j, const job_view *v, char *out, size_t cap) {
  place_name(j, v, out, cap);
  size_t len = strlen(out);
  if (a->sequences) snprintf(out + len, cap - len, "#%d", v->frame);
}

/* PSNR is infinite for identical images: JSON null, CSV "inf". */
static void write_csv(lm_buf *b, const report_args *a, const job *j, const job_view *places,
                      const report_row *rows, int n) {
  lm_buf_append(b, "technique,setting,view,scene,camera,width,height,mean_error,rmse,psnr,pearson,ssim,"
                   "closer_than_baseline,total_ms,passes_ms,direct_floor,indirect_removed,reference,reference_noise\n", -1);
  for (int i = 0; i < n; i++) {
    const report_row *r = &rows[i];
    const report_setting *s = &a->settings[r->setting];
    const job_view *v = &places[r->place];
    const job_scene *sc = &j->scenes[v->scene];
    char view[512];
    view_name(a, j, v, view, sizeof view);
    csv_str(b, s->technique);
    lm_buf_append(b, ",", 1);
    csv_str(b, s->label);
    lm_buf_append(b, ",", 1);
    csv_str(b, view);
    lm_buf_append(b, ",", 1);
    csv_str(b, sc->name);
    lm_buf_append(b, ",", 1);
    csv_str(b, sc->scene->cameras[v->camera].name);
    lm_buf_printf(b, ",%d,%d,%.9g,%.9g,", j->sizes[v->size][0], j->sizes[v->size][1], r->m.mean_error, r->m.rmse);
    if (r->m.identical) lm_buf_append(b, "inf", -1);
    else lm_buf_printf(b, "%.4f", r->m.psnr);
    lm_buf_printf(b, ",%.6f,%.6f,%.6f,%.3f,\"", r->m.pearson, r->m.ssim, r->closer, r->total_ms);
    for (int p = 0; p < r->res.pass_count; p++)
      lm_buf_printf(b, "%s%s=%.3f", p ? ";" : "", r->res.passes[p].name, r->res.passes[p].ms);
    lm_buf_printf(b, "\",%.9g,", r->floor);
    double share;
    if (r->setting > 0 && report_indirect_removed(r[-r->setting].m.mean_error, r->floor, r->m.mean_error, &share))
      lm_buf_printf(b, "%.4f", share);
    else lm_buf_append(b, "n/a", -1);
    lm_buf_append(b, ",", 1);
    csv_str(b, reference_renderer_name(a->ref.renderer));
    if (r->noise >= 0) lm_buf_printf(b, ",%.9g\n", r->noise);
    else lm_buf_append(b, ",n/a\n", -1);
  }
}

/* One setting's error over one sequence, a JSON object (write_json). */
static void json_sequence(lm_buf *b, const report_args *a, const job *j, const job_view *places,
                          const report_row *rows, int first, int setting, const report_sequence *q) {
  char place[512];
  place_name(j, &places[first], place, sizeof place);
  lm_buf_append(b, "    {\"setting\": ", -1);
  limn_json_append(b, a->settings[setting].label);
  lm_buf_append(b, ", \"sequence\": ", -1);
  limn_json_append(b, place);
  lm_buf_printf(b, ", \"frames\": %d, \"mean_error\": %.9g, \"flicker\": %.9g, \"lags\": [", q->frames,
                q->mean_error, q->flicker);
  for (int e = 0; e < q->event_count; e++)
    lm_buf_printf(b, "%s{\"event\": %d, \"frames\": %d, \"returned\": %s, \"settled_error\": %.9g}", e ? ", " : "",
                  a->events[e], q->lags[e].frames, q->lags[e].returned ? "true" : "false", q->lags[e].settled);
  lm_buf_append(b, "], \"errors\": [", -1);
  for (int t = 0; t < q->frames; t++) {
    const report_row *r = &rows[(size_t)(first + t) * (size_t)a->setting_count + (size_t)setting];
    lm_buf_printf(b, "%s%.9g", t ? ", " : "", r->m.mean_error);
  }
  lm_buf_append(b, "]}", -1);
}

/* The rows of write_csv, with the run's settings and sequences, as JSON:
 * the two loops read alike. */
static void write_json(lm_buf *b, const report_args *a, const job *j, const job_view *places,
                       const report_row *rows, int n, const report_runs *runs, const char *clock, int frames,
                       int warmup) {
  lm_buf_append(b, "{\n  \"job\": ", -1);
  limn_json_append(b, j->path);
  lm_buf_printf(b, ",\n  \"clock\": \"%s\",\n  \"renderer\": ", clock);
  limn_json_append(b, lm_gl_renderer());
  lm_buf_append(b, ",\n  \"reference\": ", -1); /* what every error is measured against */
  limn_json_append(b, reference_renderer_name(a->ref.renderer));
  lm_buf_append(b, ",\n  \"reference_settings\": ", -1);
  limn_json_append(b, a->against);
  lm_buf_printf(b, ",\n  \"frames\": %d,\n  \"warmup\": %d,\n  \"baseline\": ", frames, warmup);
  limn_json_append(b, a->baseline);
  lm_buf_append(b, ",\n  \"rows\": [\n", -1);
  for (int i = 0; i < n; i++) {
    const report_row *r = &rows[i];
    const report_setting *s = &a->settings[r->setting];
    const job_view *v = &places[r->place];
    const job_scene *sc = &j->scenes[v->scene];
    char view[512];
    view_name(a, j, v, view, sizeof view);
    lm_buf_append(b, "    {\"technique\": ", -1);
    limn_json_append(b, s->technique);
    lm_buf_append(b, ", \"setting\": ", -1);
    limn_json_append(b, s->label);
    lm_buf_append(b, ", \"options\": {", -1);
    for (int o = 0; o < s->option_count; o++) {
      lm_buf_append(b, o ? ", " : "", -1);
      limn_json_append(b, s->names[o]);
      lm_buf_append(b, ": ", -1);
      limn_json_append(b, s->values[o]);
    }
    lm_buf_append(b, "}, \"view\": ", -1);
    limn_json_append(b, view);
    lm_buf_append(b, ", \"scene\": ", -1);
    limn_json_append(b, sc->path);
    lm_buf_append(b, ", \"camera\": ", -1);
    limn_json_append(b, sc->scene->cameras[v->camera].name);
    if (a->sequences)
      lm_buf_printf(b, ", \"frame\": %d, \"time\": %.9g, \"flicker\": %.9g", v->frame, v->time, r->flicker);
    lm_buf_printf(b, ", \"width\": %d, \"height\": %d, \"mean_error\": %.9g, \"rmse\": %.9g, \"psnr\": ",
                  j->sizes[v->size][0], j->sizes[v->size][1], r->m.mean_error, r->m.rmse);
    if (r->m.identical) lm_buf_append(b, "null", -1);
    else lm_buf_printf(b, "%.4f", r->m.psnr);
    lm_buf_printf(b, ", \"pearson\": %.6f, \"ssim\": %.6f, \"closer_than_baseline\": %.6f, \"direct_floor\": %.9g, "
                  "\"indirect_removed\": ", r->m.pearson, r->m.ssim, r->closer, r->floor);
    double share;
    if (r->setting > 0 && report_indirect_removed(r[-r->setting].m.mean_error, r->floor, r->m.mean_error, &share))
      lm_buf_printf(b, "%.4f", share);
    else lm_buf_append(b, "null", -1);
    if (r->noise >= 0) lm_buf_printf(b, ", \"reference_noise\": %.9g", r->noise);
    else lm_buf_append(b, ", \"reference_noise\": null", -1);
    lm_buf_printf(b, ", \"total_ms\": %.3f, \"passes\": [", r->total_ms);
    for (int p = 0; p < r->res.pass_count; p++) {
      lm_buf_append(b, p ? ", {\"name\": " : "{\"name\": ", -1);
      limn_json_append(b, r->res.passes[p].name);
      lm_buf_printf(b, ", \"ms\": %.3f}", r->res.passes[p].ms);
    }
    lm_buf_printf(b, "]}%s\n", i + 1 < n ? "," : "");
  }
  lm_buf_append(b, "  ]", -1);
  if (runs->summary) {
    lm_buf_append(b, ",\n  \"events\": [", -1);
    for (int e = 0; e < a->event_count; e++) lm_buf_printf(b, "%s%d", e ? ", " : "", a->events[e]);
    lm_buf_append(b, "],\n  \"sequences\": [", -1);
    bool any = false;
    for (int k = 0; k < runs->count; k++)
      for (int s = 0; s < a->setting_count; s++) {
        const report_sequence *q = &runs->summary[k * a->setting_count + s];
        if (q->frames < 2) continue;
        lm_buf_append(b, any ? ",\n" : "\n", -1);
        json_sequence(b, a, j, places, rows, runs->first[k], s, q);
        any = true;
      }
    lm_buf_append(b, "\n  ]", -1);
  }
  lm_buf_append(b, "\n}\n", -1);
}

/* Per setting, over the views: mean error and mean total milliseconds. */
static void setting_means(const report_row *rows, int n, int settings, double *err, double *ms) {
  int *count = calloc((size_t)settings, sizeof *count);
  for (int s = 0; s < settings; s++) err[s] = ms[s] = 0;
  for (int i = 0; i < n; i++) {
    err[rows[i].setting] += rows[i].m.mean_error;
    ms[rows[i].setting] += rows[i].total_ms;
    count[rows[i].setting]++;
  }
  for (int s = 0; s < settings; s++)
    if (count[s]) err[s] /= count[s], ms[s] /= count[s];
  free(count);
}

static const char *const palette[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
                                      "#e377c2", "#17becf"};

/* Under the scatter, in a job with sequences, from `top` down: each
 * setting's error against frame (curve[setting * frames + t], the mean over
 * its sequences: report_frame_curve), one line a setting, the job's events
 * as dashed verticals. The axis starts at 0: a lag is a rise and fall. */
static void write_svg_frames(lm_buf *b, const report_args *a, const double *curve, int frames, double top) {
  int n = a->setting_count;
  const double W = 720, H = 360, L = 80, R = 200, T = 40, B = 50;
  double hi = 0, x1 = frames > 1 ? frames - 1 : 1;
  for (int i = 0; i < n * frames; i++) hi = fmax(hi, curve[i]);
  double y1 = hi > 0 ? 1.1 * hi : 1e-3;
#define PX(v) (L + (v) / x1 * (W - L - R))
#define PY(v) (top + H - B - (v) / y1 * (H - T - B))
  lm_buf_printf(b, "<text x=\"%.0f\" y=\"%.1f\" font-size=\"15\">Mean error (seed eq 19) against frame</text>\n", L,
                top + 24);
  lm_buf_printf(b, "<g stroke=\"black\"><line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/></g>\n",
                L, PY(0), W - R, PY(0), L, PY(0), L, top + T);
  for (int k = 0; k <= 4; k++) {
    double xv = round(x1 * k / 4), yv = y1 * k / 4; /* whole frames */
    lm_buf_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%.0f</text>\n", PX(xv), PY(0) + 18, xv);
    lm_buf_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.4g</text>\n", L - 6, PY(yv) + 4, yv);
  }
  lm_buf_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">frame</text>\n", (L + W - R) / 2, top + H - 14);
  lm_buf_printf(b, "<text x=\"16\" y=\"%.1f\" transform=\"rotate(-90 16 %.1f)\" text-anchor=\"middle\">"
                "mean error against %s</text>\n", top + (T + H - B) / 2, top + (T + H - B) / 2,
                reference_renderer_name(a->ref.renderer));
  for (int e = 0; e < a->event_count; e++)
    lm_buf_printf(b, "<line class=\"event\" x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#888\" "
                  "stroke-dasharray=\"4 3\"><title>event at frame %d</title></line>\n", PX(a->events[e]), PY(0),
                  PX(a->events[e]), PY(y1), a->events[e]);
  /* one colour a setting, dashed past the palette's eight */
  for (int s = 0; s < n; s++) {
    const char *dash = s >= 8 ? " stroke-dasharray=\"6 3\"" : "";
    lm_buf_printf(b, "<polyline class=\"frames\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\"%s points=\"",
                  palette[s % 8], dash);
    for (int t = 0; t < frames; t++) lm_buf_printf(b, "%s%.1f,%.1f", t ? " " : "", PX(t), PY(curve[s * frames + t]));
    lm_buf_append(b, "\"><title>", -1);
    xml_str(b, a->settings[s].label);
    lm_buf_append(b, "</title></polyline>\n", -1);
    lm_buf_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"2\"%s/>"
                  "<text x=\"%.1f\" y=\"%.1f\">", W - R + 12, top + T + 10 + 18.0 * s, W - R + 26,
                  top + T + 10 + 18.0 * s, palette[s % 8], dash, W - R + 30, top + T + 14 + 18.0 * s);
    xml_str(b, a->settings[s].label);
    lm_buf_append(b, "</text>\n", -1);
  }
#undef PX
#undef PY
}

/* Hand-written SVG: a scatter plot needs a few dozen elements, and no
 * Debian C library writes plots without pulling in a toolkit (plplot,
 * cairo), so text is simpler and keeps the output byte-stable. The error
 * axis spans the data and the direct-only floor (floor < 0: none), not 0:
 * settings differ by a few percent of an error that is mostly there. With
 * a curve (NULL in a still job), error against frame goes under the scatter. */
static void write_svg(lm_buf *b, const report_args *a, const double *err, const double *ms, const bool *front,
                      double floor, const char *clock, const double *curve, int curve_frames) {
  int n = a->setting_count;
  const double W = 720, H = 480, L = 80, R = 200, T = 40, B = 60, FRAMES_H = 360;
  double x0 = 0, x1 = 0, lo = floor >= 0 ? floor : err[0], hi = lo;
  for (int i = 0; i < n; i++) {
    if (ms[i] > x1) x1 = ms[i];
    lo = fmin(lo, err[i]);
    hi = fmax(hi, err[i]);
  }
  x1 = x1 > 0 ? x1 * 1.1 : 1;
  double pad = hi > lo ? 0.1 * (hi - lo) : hi > 0 ? 0.1 * hi : 1e-3;
  double y0 = fmax(0, lo - pad), y1 = hi + pad;
#define PX(v) (L + ((v) - x0) / (x1 - x0) * (W - L - R))
#define PY(v) (H - B - ((v) - y0) / (y1 - y0) * (H - T - B))
  lm_buf_printf(b, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"12\">\n"
                "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
                "<text x=\"%.0f\" y=\"24\" font-size=\"15\">Mean error (seed eq 19) against time per frame</text>\n",
                W, H + (curve ? FRAMES_H : 0), W, H + (curve ? FRAMES_H : 0), L);
  /* axes with five ticks each */
  lm_buf_printf(b, "<g stroke=\"black\"><line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/></g>\n",
                L, H - B, W - R, H - B, L, H - B, L, T);
  for (int k = 0; k <= 4; k++) {
    double xv = x0 + (x1 - x0) * k / 4, yv = y0 + (y1 - y0) * k / 4;
    lm_buf_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%.3g</text>\n", PX(xv), H - B + 18, xv);
    lm_buf_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.4g</text>\n", L - 6, PY(yv) + 4, yv);
  }
  lm_buf_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">total ms per frame (median; clock: %s)</text>\n",
                (L + W - R) / 2, H - 16, clock);
  lm_buf_printf(b, "<text x=\"16\" y=\"%.1f\" transform=\"rotate(-90 16 %.1f)\" text-anchor=\"middle\">"
                "mean error against %s</text>\n", (T + H - B) / 2, (T + H - B) / 2,
                reference_renderer_name(a->ref.renderer));
  if (floor >= 0)
    lm_buf_printf(b, "<line class=\"floor\" x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#888\" "
                  "stroke-width=\"2\"><title>direct-only floor: the baseline against %s direct light only, "
                  "mean error %.4g</title></line>\n", L, PY(floor), W - R, PY(floor),
                  reference_renderer_name(a->ref.renderer), floor);
  /* the Pareto front: a step line through its points by time */
  int *order = calloc((size_t)n + 1, sizeof *order), fn = 0;
  for (int i = 0; i < n; i++)
    if (front[i]) order[fn++] = i;
  for (int i = 1; i < fn; i++)
    for (int k = i; k > 0 && ms[order[k]] < ms[order[k - 1]]; k--) {
      int t = order[k];
      order[k] = order[k - 1];
      order[k - 1] = t;
    }
  if (fn > 1) {
    lm_buf_append(b, "<polyline class=\"pareto\" fill=\"none\" stroke=\"#444\" stroke-dasharray=\"4 3\" points=\"", -1);
    for (int i = 0; i < fn; i++) lm_buf_printf(b, "%s%.1f,%.1f", i ? " " : "", PX(ms[order[i]]), PY(err[order[i]]));
    lm_buf_append(b, "\"/>\n", -1);
  }
  free(order);
  /* points, one colour per technique */
  char techs[REPORT_MAX_SETTINGS][64];
  int tech_count = 0;
  for (int i = 0; i < n; i++) {
    int t = 0;
    while (t < tech_count && strcmp(techs[t], a->settings[i].technique)) t++;
    if (t == tech_count) snprintf(techs[tech_count++], sizeof techs[0], "%s", a->settings[i].technique);
    const char *col = palette[t % 8];
    lm_buf_printf(b, "<circle class=\"%s\" cx=\"%.1f\" cy=\"%.1f\" r=\"%d\" fill=\"%s\" stroke=\"%s\" "
                  "stroke-width=\"2\"><title>", front[i] ? "point pareto" : "point", PX(ms[i]), PY(err[i]),
                  front[i] ? 6 : 4, front[i] ? "white" : col, col);
    xml_str(b, a->settings[i].label);
    lm_buf_printf(b, ": %.4g ms, mean error %.4g%s</title></circle>\n", ms[i], err[i],
                  front[i] ? " (Pareto front)" : "");
  }
  for (int t = 0; t < tech_count; t++) {
    lm_buf_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"/><text x=\"%.1f\" y=\"%.1f\">",
                  W - R + 20, T + 10 + 18.0 * t, palette[t % 8], W - R + 30, T + 14 + 18.0 * t);
    xml_str(b, techs[t]);
    lm_buf_append(b, "</text>\n", -1);
  }
  lm_buf_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"6\" fill=\"white\" stroke=\"black\" stroke-width=\"2\"/>"
                "<text x=\"%.1f\" y=\"%.1f\">Pareto front</text>\n",
                W - R + 20, T + 10 + 18.0 * tech_count, W - R + 30, T + 14 + 18.0 * tech_count);
  if (floor >= 0)
    lm_buf_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#888\" stroke-width=\"2\"/>"
                  "<text x=\"%.1f\" y=\"%.1f\">direct-only floor</text>\n", W - R + 12, T + 28 + 18.0 * tech_count,
                  W - R + 26, T + 28 + 18.0 * tech_count, W - R + 30, T + 32 + 18.0 * tech_count);
#undef PX
#undef PY
  if (curve) write_svg_frames(b, a, curve, curve_frames, H);
  lm_buf_append(b, "</svg>\n", -1);
}

/* "12: 3, 30: 7+ (not settled)", or "-" without events. */
static void append_lags(lm_buf *b, const report_args *a, const report_sequence *q) {
  if (!q->event_count) lm_buf_append(b, "-", 1);
  for (int e = 0; e < q->event_count; e++)
    lm_buf_printf(b, "%s%d: %d%s", e ? ", " : "", a->events[e], q->lags[e].frames,
                  q->lags[e].returned ? "" : "+ (not settled)");
}

/* Per setting and sequence: mean error over frames, flicker, lags. */
static void md_sequences(lm_buf *b, const report_args *a, const job *j, const job_view *places,
                         const report_runs *runs) {
  lm_buf_printf(b, "\n## Sequences\n\nError over time against the reference frames. Mean error: eq 19's mean over a "
                "sequence's frames. Flicker: the mean over frames t >= 1 and values of |(L_t - L_t-1) - "
                "(R_t - R_t-1)|, the frame-to-frame change the reference does not have (0 for a still scene). "
                "Lag after each of the job's events (frame: frames): the frames from the event until the error "
                "stays within %g%% of its settled value: the error of the window's last pose (the frame before "
                "the next event, or the last) rendered still for %d frames from no history, so that a history "
                "fading out slowly counts as lag; N+ where even the last is off; - without events. A sequence's frames render once each, "
                "in order (the first after the warm-up), so that temporal reuse sees them as a viewer would: "
                "their times are single frames'.\n\n"
                "| setting | sequence | frames | mean error | flicker | lag |\n|---|---|---|---|---|---|\n",
                100 * LM_LAG_TOLERANCE, REPORT_SETTLE_FRAMES);
  for (int k = 0; k < runs->count; k++)
    for (int s = 0; s < a->setting_count; s++) {
      const report_sequence *q = &runs->summary[k * a->setting_count + s];
      if (q->frames < 2) continue;
      char place[512];
      place_name(j, &places[runs->first[k]], place, sizeof place);
      lm_buf_append(b, "| ", -1);
      xml_str(b, a->settings[s].label);
      lm_buf_append(b, " | ", -1);
      xml_str(b, place);
      lm_buf_printf(b, " | %d | %.5f | %.6f | ", q->frames, q->mean_error, q->flicker);
      append_lags(b, a, q);
      lm_buf_append(b, " |\n", -1);
    }
}

static void write_md(lm_buf *b, const report_args *a, const job *j, const job_view *places, int place_count,
                     const report_row *rows, int n, const report_runs *runs, const double *err, const double *ms,
                     const bool *front, double floor, const char *clock, int frames, int warmup) {
  const char *name = reference_renderer_name(a->ref.renderer);
  lm_buf_printf(b, "# Error against %s and run time\n\nJob `", name);
  xml_str(b, j->path);
  lm_buf_printf(b, "`, %d view%s; renderer ", place_count, place_count == 1 ? "" : "s");
  xml_str(b, lm_gl_renderer());
  lm_buf_printf(b, "; times are medians of %d frame%s after %d warm-up frame%s (clock: %s). Mean error is seed eq "
                "19 (sum of |dR|+|dG|+|dB| over 3wh), against %s references: %s. Gain over the "
                "baseline %s = 100 (e_base - e) / e_base. The direct-only floor of a view is the baseline's "
                "error against %s's direct light only (%s): what is left when indirect light is perfect. Indirect "
                "error removed = 100 (e_base - e) / (e_base - floor), the mean over the views where the floor is "
                "below the baseline (n/a where none is).\n\n",
                frames, frames == 1 ? "" : "s", warmup, warmup == 1 ? "" : "s", clock, name, a->against, a->baseline,
                name, a->direct_flags + 1);
  if (floor >= 0) lm_buf_printf(b, "Direct-only floor, mean over the views: %.5f.\n\n", floor);
  if (a->has_noise) { /* the baseline's rows: one a view; a view without its second seed (-1) is left out */
    double noise = 0, base = 0;
    int measured = 0;
    for (int i = 0; i < n; i++)
      if (rows[i].setting == 0 && rows[i].noise >= 0) noise += rows[i].noise, base += rows[i].m.mean_error, measured++;
    lm_buf_printf(b, "Reference noise (the mean error between the references at seeds %d and %d), mean over the "
                  "views", a->ref.cycles.seed, a->second.cycles.seed);
    if (!measured)
      lm_buf_append(b, ": n/a (no view's second seed is cached).\n\n", -1);
    else
      lm_buf_printf(b, "%s: %.5f, %.1f%% of the baseline's mean error against the reference.\n\n",
                    measured < place_count ? " whose second seed is cached" : "", noise / measured,
                    base > 0 ? 100 * noise / base : 0);
  }
  lm_buf_append(b, "| setting | mean error | ms | mean gain % | median gain % | indirect error removed % | views "
                   "improved | views Pearson rose | pixels closer | Pearson baseline -> setting | Pareto |\n"
                   "|---|---|---|---|---|---|---|---|---|---|---|\n", -1);
  double *be = lm_alloc(sizeof(double) * (size_t)(place_count + 1) * 7);
  double *e = be + place_count, *cl = e + place_count, *px = cl + place_count, *pb = px + place_count,
         *pa = pb + place_count, *fl = pa + place_count;
  for (int s = 0; s < a->setting_count; s++) {
    int k = 0;
    for (int i = 0; i < n; i++) {
      if (rows[i].setting != s) continue;
      const report_row *base = &rows[i - s]; /* rows go place by place, the baseline first */
      be[k] = base->m.mean_error;
      fl[k] = rows[i].floor;
      e[k] = rows[i].m.mean_error;
      cl[k] = rows[i].closer;
      px[k] = (double)rows[i].m.width * rows[i].m.height;
      pb[k] = base->m.pearson;
      pa[k] = rows[i].m.pearson;
      k++;
    }
    report_summary sum;
    report_summarize(k, be, fl, e, cl, px, pb, pa, &sum);
    lm_buf_append(b, "| ", -1);
    xml_str(b, a->settings[s].label);
    if (s == 0) {
      lm_buf_printf(b, " (baseline) | %.5f | %.3f | | | | | | | %.4f | %s |\n", err[s], ms[s], sum.pearson_before,
                    front[s] ? "yes" : "");
      continue;
    }
    lm_buf_printf(b, " | %.5f | %.3f | %.2f | %.2f | ", err[s], ms[s], sum.mean_gain, sum.median_gain);
    if (sum.indirect_views) lm_buf_printf(b, "%.2f", sum.indirect_removed);
    else lm_buf_append(b, "n/a", -1);
    lm_buf_printf(b, " | %.0f%% | %.0f%% | %.2f%% | %.4f -> %.4f | %s |\n", 100 * sum.views_improved,
                  100 * sum.views_pearson_rose, 100 * sum.pixels_closer, sum.pearson_before, sum.pearson_after,
                  front[s] ? "yes" : "");
  }
  if (runs->summary) md_sequences(b, a, j, places, runs);
  lm_buf_append(b, "\n## Per view\n\n| setting | view | error baseline | error | gain % | direct-only floor | "
                   "indirect error removed % | pixels closer | Pearson baseline | Pearson |\n"
                   "|---|---|---|---|---|---|---|---|---|---|\n", -1);
  for (int i = 0; i < n; i++) {
    if (rows[i].setting == 0) continue;
    const report_row *base = &rows[i - rows[i].setting];
    char view[512];
    view_name(a, j, &places[rows[i].place], view, sizeof view);
    lm_buf_append(b, "| ", -1);
    xml_str(b, a->settings[rows[i].setting].label);
    lm_buf_append(b, " | ", -1);
    xml_str(b, view);
    lm_buf_printf(b, " | %.5f | %.5f | %.2f | %.5f | ", base->m.mean_error, rows[i].m.mean_error,
                  report_gain(base->m.mean_error, rows[i].m.mean_error), rows[i].floor);
    double share;
    if (report_indirect_removed(base->m.mean_error, rows[i].floor, rows[i].m.mean_error, &share))
      lm_buf_printf(b, "%.2f", share);
    else lm_buf_append(b, "n/a", -1);
    lm_buf_printf(b, " | %.2f%% | %.4f | %.4f |\n", 100 * rows[i].closer, base->m.pearson, rows[i].m.pearson);
  }
  free(be);
}

/* ---- running ------------------------------------------------------------ */

static bool write_file(const report_args *a, const char *name, lm_buf *b, lm_error *err) {
  char path[1100];
  snprintf(path, sizeof path, "%s/%s", a->out, name);
  bool ok = job_make_parent(path, err) && limn_write_whole(path, b->data ? b->data : "", (size_t)b->len, err);
  if (ok && !a->ref.quiet) printf("wrote %s\n", path);
  lm_buf_free(b);
  return ok;
}

static const char *const report_files[] = {"report.csv", "report.json", "report.svg", "report.md"};

/* A report of an earlier run in --out goes before this one renders: its
 * images are overwritten setting by setting, so a run that fails half-way
 * would leave a report that no longer describes the images beside it. */
static void remove_reports(const report_args *a) {
  for (size_t i = 0; i < sizeof report_files / sizeof *report_files; i++) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", a->out, report_files[i]);
    remove(path);
  }
}

/* The value each swept option has before any setting (the script's default
 * with the job's `set`), so that every setting starts from the same options
 * and none inherits the one before it. */
typedef struct report_base {
  char (*names)[128], (*values)[64];
  int count;
} report_base;

static bool base_has(const report_base *b, const char *name) {
  for (int i = 0; i < b->count; i++)
    if (!strcmp(b->names[i], name)) return true;
  return false;
}

static void base_take(report_base *b, const lm_pipeline *p, const report_setting *settings, int n) {
  int cap = n * REPORT_MAX_OPTIONS;
  b->names = lm_alloc(sizeof *b->names * (size_t)(cap + 1));
  b->values = lm_alloc(sizeof *b->values * (size_t)(cap + 1));
  b->count = 0;
  for (int s = 0; s < n; s++)
    for (int i = 0; i < settings[s].option_count; i++) {
      char name[128], value[64];
      snprintf(name, sizeof name, "%s", settings[s].names[i]);
      if (!lm_pipeline_get_option(p, name, value, sizeof value)) continue; /* set_setting names it */
      if (!strcmp(value, "table")) { /* "bloom=true" sets bloom.enabled */
        snprintf(name, sizeof name, "%.119s.enabled", settings[s].names[i]);
        if (!lm_pipeline_get_option(p, name, value, sizeof value)) continue;
      }
      if (base_has(b, name)) continue;
      memcpy(b->names[b->count], name, sizeof name);
      memcpy(b->values[b->count], value, sizeof value);
      b->count++;
    }
}

static void base_free(report_base *b) {
  free(b->names);
  free(b->values);
}

static bool set_setting(lm_pipeline *p, const report_base *base, const report_setting *s, lm_error *err) {
  if (!lm_pipeline_set_technique(p, s->technique, err)) return false;
  for (int i = 0; i < base->count; i++)
    if (!lm_pipeline_set_option(p, base->names[i], base->values[i], err)) return false;
  for (int i = 0; i < s->option_count; i++)
    if (!lm_pipeline_set_option(p, s->names[i], s->values[i], err)) {
      lm_error_prefix(err, "%s=%s", s->names[i], s->values[i]);
      return false;
    }
  return true;
}

/* Every place's reference with ref's settings (paths into refs): rendered
 * when missing, or with --require-refs named with the command that makes
 * them (flags: what that command needs besides the job and the folder). */
static int get_refs(const report_args *a, const reference_args *ref, const job *j, const job_view *places, int n,
                    char (*refs)[1024], const char *flags) {
  if (!a->require_refs && !a->cached_refs) return reference_run(ref, j, places, n, refs);
  lm_error err;
  int rc = 0;
  for (int i = 0; i < n && !rc; i++) {
    lm_buf sdl = {0};
    if (!reference_export(ref, j, &places[i], &sdl, refs[i], sizeof refs[i], &err)) {
      lm_log(LM_LOG_ERROR, "%s", err.msg);
      rc = 1;
    } else if (!lm_file_exists(refs[i]) && a->cached_refs && ref == &a->second) {
      refs[i][0] = '\0'; /* only the noise is missing: n/a */
    } else if (!lm_file_exists(refs[i])) {
      lm_log(LM_LOG_ERROR, "%s: view %d: no reference %s (make them with: limn reference --job %s --refs %s%s, "
             "with the same export flags)", j->path, i, refs[i], j->path, ref->refs, flags);
      rc = 1;
    }
    lm_buf_free(&sdl);
  }
  return rc;
}

/* Where setting s's image of view v goes: one a place, and in a sequence
 * one a frame. */
static void image_path(const report_args *a, const job *j, const job_view *v, int s, bool sequence, char *out,
                       size_t cap) {
  const job_scene *sc = &j->scenes[v->scene];
  char cam[LM_NAME_MAX];
  snprintf(cam, sizeof cam, "%s", sc->scene->cameras[v->camera].name);
  for (char *c = cam; *c; c++)
    if (*c == '/' || *c == ' ') *c = '_';
  int len = snprintf(out, cap, "%s/images/%s_%s_%dx%d_%d", a->out, sc->name, cam, j->sizes[v->size][0],
                     j->sizes[v->size][1], s);
  if (len >= 0 && (size_t)len < cap)
    snprintf(out + len, cap - (size_t)len, sequence ? "_%04d.exr" : ".exr", v->frame);
}

/* The error that setting s settles to at view v (the last pose of an event's
 * window): v posed and rendered still, from no history, REPORT_SETTLE_FRAMES
 * frames, against the reference ref. Written beside the frames as
 * <image>_settled.exr. -1 (logged) when it fails. */
static double settle_pose(lm_renderer *r, const report_args *a, const job *j, const job_view *v, int s,
                          const char *ref) {
  char out[1400];
  image_path(a, j, v, s, true, out, sizeof out);
  snprintf(out + strlen(out) - strlen(".exr"), sizeof out - strlen(out) + strlen(".exr"), "_settled.exr");
  const char *outs[1] = {out};
  int w = j->sizes[v->size][0], h = j->sizes[v->size][1];
  capture_view cv = {.camera = v->camera, .width = w, .height = h, .frames = 1, .warmup = REPORT_SETTLE_FRAMES,
                     .outputs = outs, .output_count = 1, .quiet = true};
  capture_result res = {0};
  lm_image img = {0}, reference = {0};
  lm_error err;
  job_pose(j, v);
  bool ok = capture_render_write(r, &cv, &res, &err) && lm_image_read(out, &img, &err) &&
            lm_image_read(ref, &reference, &err) && lm_metrics_check(&img, out, &reference, ref, &err);
  lm_metrics m = {0};
  if (ok) lm_metrics_compute(&img, &reference, &m);
  else lm_log(LM_LOG_ERROR, "%s: the settled frame at view %s: %s", j->path, out, err.msg);
  capture_result_free(&res);
  lm_image_free(&img);
  lm_image_free(&reference);
  return ok ? m.mean_error : -1;
}

/* Each setting's error over each sequence (runs of two frames or more) and
 * its error-against-frame curve (curve[setting * curve_frames + t], the
 * longest run's frames); false after logging a frame whose error is not
 * finite. */
static bool summarize_runs(const report_args *a, const report_row *rows, int place_count, report_runs *runs,
                           double **curve, int *curve_frames) {
  int sn = a->setting_count;
  runs->summary = lm_alloc(sizeof *runs->summary * (size_t)(runs->count * sn + 1));
  double *error = lm_alloc(sizeof *error * (size_t)(place_count + 1) * 2), *flicker = error + place_count + 1;
  const double **errors = lm_alloc(sizeof *errors * (size_t)(runs->count + 1));
  int *lengths = lm_alloc(sizeof *lengths * (size_t)(runs->count + 1)), seqs = 0;
  *curve_frames = 0;
  for (int k = 0; k < runs->count; k++)
    if (runs->first[k + 1] - runs->first[k] > *curve_frames) *curve_frames = runs->first[k + 1] - runs->first[k];
  *curve = lm_alloc(sizeof **curve * (size_t)(*curve_frames * sn + 1));
  bool ok = true;
  for (int s = 0; s < sn && ok; s++) {
    seqs = 0;
    for (int p = 0; p < place_count; p++) {
      error[p] = rows[(size_t)p * (size_t)sn + (size_t)s].m.mean_error;
      flicker[p] = rows[(size_t)p * (size_t)sn + (size_t)s].flicker;
    }
    for (int k = 0; k < runs->count && ok; k++) {
      int first = runs->first[k], len = runs->first[k + 1] - first;
      report_sequence *q = &runs->summary[k * sn + s];
      *q = (report_sequence){0};
      if (len < 2) continue;
      lm_error err;
      ok = report_sequence_summarize(len, error + first, flicker + first, a->events,
                                     runs->settled + (size_t)(k * sn + s) * REPORT_MAX_EVENTS, a->event_count, q,
                                     &err);
      if (!ok) lm_log(LM_LOG_ERROR, "%s, sequence from view %d: %s", a->settings[s].label, first, err.msg);
      errors[seqs] = error + first; /* report_frame_curve reads them before the next setting */
      lengths[seqs++] = len;
    }
    if (ok) report_frame_curve(errors, lengths, seqs, *curve + (size_t)s * (size_t)*curve_frames);
  }
  free(error);
  free(errors);
  free(lengths);
  return ok;
}

/* --cached-refs: keeps the places whose reference (and, with a floor, its
 * direct-only one) is cached, naming those left out; their count, 0 when
 * none is (logged with the command that renders them), -1 on an error. */
static int cached_places(const report_args *a, const job *j, job_view *places, int n) {
  int kept = 0;
  for (int i = 0; i < n; i++) {
    char path[1024] = "", direct[1024] = "", place[512];
    lm_buf sdl = {0};
    lm_error err;
    bool ok = reference_export(&a->ref, j, &places[i], &sdl, path, sizeof path, &err);
    lm_buf_free(&sdl);
    if (ok && a->has_floor) {
      ok = reference_export(&a->direct, j, &places[i], &sdl, direct, sizeof direct, &err);
      lm_buf_free(&sdl);
    }
    if (!ok) {
      lm_log(LM_LOG_ERROR, "%s", err.msg);
      return -1;
    }
    const char *missing = !lm_file_exists(path) ? path : direct[0] && !lm_file_exists(direct) ? direct : NULL;
    place_name(j, &places[i], place, sizeof place);
    if (missing) lm_warn("%s: %s left out: no cached reference %s", j->path, place, missing);
    else places[kept++] = places[i];
  }
  if (!kept)
    lm_log(LM_LOG_ERROR, "%s: no view has its references cached in %s (make them with: limn reference --job %s "
           "--refs %s%s%s)", j->path, a->ref.refs, j->path, a->ref.refs,
           a->ref.renderer == REFERENCE_CYCLES ? " --renderer cycles" : "",
           a->has_floor ? ", then again for the direct-only floor" : "");
  return kept;
}

static int run(report_args *a, job *j, lm_pipeline *pipeline) {
  lm_error err;
  job_view *places = NULL;
  int place_count = 0;
  if (!job_views(j, false, &places, &place_count, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 2;
  }
  /* Runs of frames (a still job's places are runs of one) and the job's events in each. */
  report_runs runs = {.first = lm_alloc(sizeof(int) * (size_t)(place_count + 1))};
  runs.count = report_sequences(places, place_count, runs.first);
  size_t settled_count = (size_t)runs.count * (size_t)a->setting_count * REPORT_MAX_EVENTS;
  runs.settled = lm_alloc(sizeof *runs.settled * (settled_count + 1));
  for (size_t i = 0; i < settled_count; i++) runs.settled[i] = -1;
  a->sequences = runs.count < place_count;
  if (a->cached_refs) {
    int kept = a->sequences ? -2 : cached_places(a, j, places, place_count);
    if (kept == -2) lm_log(LM_LOG_ERROR, "%s: --cached-refs: the job has sequences, whose every frame needs its "
                           "reference (--require-refs)", j->path);
    if (kept <= 0) {
      free(runs.first);
      free(runs.settled);
      free(places);
      return kept == -2 ? 2 : 1;
    }
    place_count = kept;
    runs.count = report_sequences(places, place_count, runs.first);
  }
  bool events_ok = j->event_count <= REPORT_MAX_EVENTS;
  a->event_count = events_ok ? j->event_count : 0;
  memcpy(a->events, j->events, sizeof *a->events * (size_t)a->event_count);
  if (events_ok && a->event_count && !a->sequences) {
    lm_error_set(&err, "%s: events: the job has no sequence (time = { start, stop, fps })",
                 j->path);
    events_ok = false;
  }
  for (int k = 0; k < runs.count && events_ok; k++)
    if (runs.first[k + 1] - runs.first[k] > 1)
      events_ok = report_events_check(j->path, a->events, a->event_count, runs.first[k + 1] - runs.first[k], &err);
  if (!events_ok) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    free(runs.first);
    free(runs.settled);
    free(places);
    return 2;
  }
  /* Every setting is checked before anything renders. */
  report_base base_options;
  base_take(&base_options, pipeline, a->settings, a->setting_count);
  for (int s = 0; s < a->setting_count; s++)
    if (!set_setting(pipeline, &base_options, &a->settings[s], &err)) {
      lm_log(LM_LOG_ERROR, "%s %s: %s", s ? "--sweep" : "--baseline", a->settings[s].label, err.msg);
      base_free(&base_options);
      free(runs.first);
      free(runs.settled);
      free(places);
      return 2;
    }
  /* The references, then (with radiosity on) the direct-only ones that give each view's floor. */
  char (*refs)[1024] = lm_alloc(sizeof *refs * (size_t)(place_count + 1) * 3);
  char (*direct)[1024] = refs + place_count + 1, (*second)[1024] = direct + place_count + 1;
  int rc = get_refs(a, &a->ref, j, places, place_count, refs, a->ref.renderer == REFERENCE_CYCLES ? " --renderer cycles" : "");
  if (!rc && a->has_floor) rc = get_refs(a, &a->direct, j, places, place_count, direct, a->direct_flags);
  if (!rc && a->has_noise) rc = get_refs(a, &a->second, j, places, place_count, second, a->second_flags);
  if (rc) {
    free(refs);
    free(runs.first);
    free(runs.settled);
    free(places);
    base_free(&base_options);
    return rc;
  }

  remove_reports(a);
  if (!lm_context_create_headless(&(lm_context_desc){0}, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    free(refs);
    free(runs.first);
    free(runs.settled);
    free(places);
    base_free(&base_options);
    return 1;
  }
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = j->scenes[0].scene, .pipeline = pipeline,
                                                          .width = 1, .height = 1, .linear_output = true}, &err);
  if (!r) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 1;
  }
  int sn = a->setting_count, total = place_count * sn, n = 0;
  /* rows[place * settings + setting]: place by place, the baseline first */
  report_row *rows = lm_alloc(sizeof *rows * (size_t)(total + 1));
  memset(rows, 0, sizeof *rows * (size_t)(total + 1));
  double *floors = lm_alloc(sizeof *floors * (size_t)(place_count + 1) * 2), *noises = floors + place_count + 1;
  bool tty = isatty(STDOUT_FILENO);
  const lm_scene *current = j->scenes[0].scene;
  if (r && !a->ref.quiet) printf("report of %s: %d setting%s x %d view%s on %s\n", j->path, sn,
                                 sn == 1 ? "" : "s", place_count, place_count == 1 ? "" : "s",
                                 lm_gl_renderer());
  /* Run by run, setting by setting, frame by frame: a sequence's frames in
   * order, each rendered once after the first's warm-up and with no reset
   * between them, so that temporal reuse sees them as a viewer would; a
   * still place (a run of one) renders its warm-up and timed frames as it
   * always has. The baseline's image of a frame is read back for the share
   * of pixels closer. */
  for (int k = 0; k < runs.count && !rc; k++) {
    bool sequence = runs.first[k + 1] - runs.first[k] > 1;
    for (int s = 0; s < sn && !rc; s++) {
      lm_image prev = {0}, prev_ref = {0}; /* the frame before, Limn's and the reference's */
      char prev_out[1400] = "";
      for (int p = runs.first[k]; p < runs.first[k + 1] && !rc; p++) {
        const job_view *v = &places[p];
        job_scene *sc = &j->scenes[v->scene];
        int w = j->sizes[v->size][0], h = j->sizes[v->size][1];
        bool first_frame = p == runs.first[k];
        report_row *row = &rows[(size_t)p * (size_t)sn + (size_t)s];
        row->setting = s;
        row->place = p;
        char out[1400], base_out[1400], view[512];
        image_path(a, j, v, s, sequence, out, sizeof out);
        image_path(a, j, v, 0, sequence, base_out, sizeof base_out);
        /* The warm-up, then the timed frames (a still place's) or the first
         * frame (a sequence's, each next frame on from it), in one call: a
         * second would set the view again and drop the histories the warm-up
         * built, so a still place's temporal reuse would start cold. */
        const char *outs[1] = {out};
        capture_view cv = {.camera = v->camera, .width = w, .height = h, .frames = sequence ? 1 : a->frames,
                           .warmup = a->warmup, .outputs = outs, .output_count = 1, .quiet = true};
        lm_image ref = {0}, img = {0}, base = {0}, floor_ref = {0};
        bool ok = lm_image_read(refs[p], &ref, &err);
        if (ok && sc->scene != current) ok = lm_renderer_set_scene(r, sc->scene, &err), current = sc->scene;
        if (ok) job_pose(j, v); /* its time, and the camera a path or turntable moves */
        if (first_frame)
          ok = ok && set_setting(pipeline, &base_options, &a->settings[s], &err) && job_make_parent(out, &err) &&
               capture_render_write(r, &cv, &row->res, &err);
        else ok = ok && capture_render_write(r, &(capture_view){.camera = v->camera, .width = w, .height = h,
                                                                .frames = 1, .outputs = outs, .output_count = 1,
                                                                .quiet = true, .continues = true},
                                             &row->res, &err);
        if (ok) ok = lm_image_read(out, &img, &err) && lm_metrics_check(&img, out, &ref, refs[p], &err);
        if (ok) lm_metrics_compute(&img, &ref, &row->m);
        if (ok && s == 0) {
          floors[p] = row->m.mean_error; /* a direct-only reference: no indirect error */
          if (a->has_floor) {
            ok = lm_image_read(direct[p], &floor_ref, &err) &&
                 lm_metrics_check(&floor_ref, direct[p], &ref, refs[p], &err);
            lm_metrics fm;
            if (ok) lm_metrics_compute(&img, &floor_ref, &fm), floors[p] = fm.mean_error;
          }
          noises[p] = -1;
          lm_image other = {0};
          if (ok && a->has_noise && second[p][0]) {
            ok = lm_image_read(second[p], &other, &err) && lm_metrics_check(&other, second[p], &ref, refs[p], &err);
            lm_metrics nm;
            if (ok) lm_metrics_compute(&other, &ref, &nm), noises[p] = nm.mean_error;
          }
          lm_image_free(&other);
        } else if (ok) {
          ok = lm_image_read(base_out, &base, &err) && lm_metrics_check(&base, base_out, &ref, refs[p], &err);
          lm_metrics closer = row->m;
          if (ok) lm_metrics_closer(&img, &base, &ref, &closer), row->closer = closer.closer;
        }
        if (ok && !first_frame) {
          ok = lm_metrics_check(&prev, prev_out, &img, out, &err) &&
               lm_metrics_check(&prev_ref, refs[p - 1], &ref, refs[p], &err);
          if (ok) row->flicker = lm_metrics_flicker(&prev, &img, &prev_ref, &ref);
        }
        if (ok) {
          row->floor = floors[p];
          row->noise = noises[p];
          row->total_ms = row->res.total_ms;
          n++;
          view_name(a, j, v, view, sizeof view);
          char what[1200];
          snprintf(what, sizeof what, "%s %s: error %.5f against %s, %.2f ms", a->settings[s].label, view,
                   row->m.mean_error, reference_renderer_name(a->ref.renderer), row->total_ms);
          job_progress(a->ref.quiet, tty, n, total, what);
          lm_image_free(&prev);
          lm_image_free(&prev_ref);
          prev = img, prev_ref = ref;
          img = ref = (lm_image){0};
          snprintf(prev_out, sizeof prev_out, "%s", out);
        } else {
          capture_result_free(&row->res);
          if (tty && !a->ref.quiet) printf("\n");
          lm_log(LM_LOG_ERROR, "%s: view %d (%s, camera '%s', %dx%d), %s: %s", j->path, p, sc->name,
                 sc->scene->cameras[v->camera].name, w, h, a->settings[s].label, err.msg);
          rc = 1;
        }
        lm_image_free(&img);
        lm_image_free(&ref);
        lm_image_free(&base);
        lm_image_free(&floor_ref);
      }
      lm_image_free(&prev);
      lm_image_free(&prev_ref);
      /* Each event window's last pose, still until converged: what its lag
       * measures the return to (after the frames: it restarts the history). */
      for (int e = 0; sequence && !rc && e < a->event_count; e++) {
        int end = e + 1 < a->event_count ? a->events[e + 1] : runs.first[k + 1] - runs.first[k];
        int last = runs.first[k] + end - 1;
        double settled = settle_pose(r, a, j, &places[last], s, refs[last]);
        if (settled < 0) rc = 1;
        runs.settled[(size_t)(k * sn + s) * REPORT_MAX_EVENTS + (size_t)e] = settled;
      }
    }
  }
  double *curve = NULL;
  int curve_frames = 0;
  if (!rc && a->sequences && !summarize_runs(a, rows, place_count, &runs, &curve, &curve_frames)) rc = 1;
  if (!rc && a->sequences && !a->ref.quiet)
    for (int k = 0; k < runs.count; k++)
      for (int s = 0; s < sn; s++) {
        const report_sequence *q = &runs.summary[k * sn + s];
        if (q->frames < 2) continue;
        char place[512];
        place_name(j, &places[runs.first[k]], place, sizeof place);
        lm_buf lags = {0};
        append_lags(&lags, a, q);
        printf("%s over %s (%d frames): mean error %.5f, flicker %.6f, lag %s\n", a->settings[s].label, place,
               q->frames, q->mean_error, q->flicker, lags.data);
        lm_buf_free(&lags);
      }
  const char *clock = r ? lm_clock_name(lm_renderer_clock(r)) : "";
  if (!rc) {
    double *err_mean = lm_alloc(sizeof(double) * (size_t)sn * 2), *ms_mean = err_mean + sn;
    bool *front = lm_alloc(sizeof(bool) * (size_t)sn);
    setting_means(rows, n, sn, err_mean, ms_mean);
    double floor = -1; /* none against direct-only references */
    if (a->has_floor && place_count > 0) {
      floor = 0;
      for (int i = 0; i < n; i++) floor += rows[i].setting == 0 ? rows[i].floor / place_count : 0;
    }
    report_pareto(ms_mean, err_mean, sn, front);
    lm_buf csv = {0}, json = {0}, svg = {0}, md = {0};
    write_csv(&csv, a, j, places, rows, n);
    write_json(&json, a, j, places, rows, n, &runs, clock, a->frames, a->warmup);
    write_svg(&svg, a, err_mean, ms_mean, front, floor, clock, curve, curve_frames);
    write_md(&md, a, j, places, place_count, rows, n, &runs, err_mean, ms_mean, front, floor, clock, a->frames,
             a->warmup);
    bool ok = write_file(a, report_files[0], &csv, &err) && write_file(a, report_files[1], &json, &err) &&
              write_file(a, report_files[2], &svg, &err) && write_file(a, report_files[3], &md, &err);
    lm_buf_free(&csv);
    lm_buf_free(&json);
    lm_buf_free(&svg);
    lm_buf_free(&md);
    if (!ok) lm_log(LM_LOG_ERROR, "%s", err.msg), remove_reports(a), rc = 1; /* all four or none */
    free(err_mean);
    free(front);
  }
  for (int i = 0; i < total; i++) capture_result_free(&rows[i].res);
  free(rows);
  free(floors);
  free(curve);
  free(runs.summary);
  free(runs.first);
  free(runs.settled);
  lm_renderer_destroy(r);
  lm_programs_clear();
  job_free_scenes(j); /* GL objects go before the context */
  lm_context_destroy();
  free(refs);
  free(places);
  base_free(&base_options);
  return rc;
}

int limn_report(int argc, char **argv) {
  report_args a = {.out = "out/report", .baseline = BASELINE, .frames = 5, .warmup = 2};
  reference_defaults(&a.ref);
  report_setting *settings = lm_alloc(sizeof *settings * REPORT_MAX_SETTINGS);
  a.settings = settings;
  lm_error err;
  const char *sweeps_given[REPORT_MAX_SETTINGS];
  struct option opts[15 + LIMN_POV_OPTION_COUNT - 1 + REFERENCE_OPTION_COUNT] = {
      {"job", required_argument, 0, 'J'},    {"sweep", required_argument, 0, 'W'},
      {"out", required_argument, 0, 'o'},    {"frames", required_argument, 0, 'f'},
      {"warmup", required_argument, 0, 'u'}, {"refs", required_argument, 0, 'R'},
      {"require-refs", no_argument, 0, 'Q'}, {"jobs", required_argument, 0, 'j'},
      {"povray", required_argument, 0, 'P'}, {"force", no_argument, 0, 'F'},
      {"quiet", no_argument, 0, 'q'},        {"help", no_argument, 0, 'h'},
      {"baseline", required_argument, 0, 'B'}, {"cached-refs", no_argument, 0, 'K'}};
  memcpy(opts + 14, limn_pov_options, sizeof(struct option) * (LIMN_POV_OPTION_COUNT - 1));
  memcpy(opts + 14 + LIMN_POV_OPTION_COUNT - 1, reference_options, sizeof(struct option) * REFERENCE_OPTION_COUNT);
  opterr = 0;
  optind = 1;
  int c, rc = 0, sweeps = 0;
  while (!rc && (c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    int pov = reference_flag("report", c, optarg, &a.ref);
    if (pov == 2) rc = 2;
    if (pov != 1) continue;
    switch (c) {
    case 'J': a.job = optarg; break;
    case 'W':
      if (sweeps == REPORT_MAX_SETTINGS) rc = usage_error("at most %s --sweep flags", "256");
      else sweeps_given[sweeps++] = optarg;
      break;
    case 'B': a.baseline = optarg; break;
    case 'o': a.out = optarg; break;
    case 'f':
      if (!limn_parse_int(optarg, 1, 10000, &a.frames)) rc = usage_error("--frames wants 1..10000, not '%s'", optarg);
      break;
    case 'u':
      if (!limn_parse_int(optarg, 0, 10000, &a.warmup)) rc = usage_error("--warmup wants 0..10000, not '%s'", optarg);
      break;
    case 'R': a.ref.refs = optarg; break;
    case 'Q': a.require_refs = true; break;
    case 'K': a.cached_refs = true; break;
    case 'j':
      if (!limn_parse_int(optarg, 1, 1024, &a.ref.jobs)) rc = usage_error("--jobs wants 1..1024, not '%s'", optarg);
      break;
    case 'P': a.ref.povray = optarg; break;
    case 'F': a.ref.force = true; break;
    case 'q': a.ref.quiet = true; break;
    case 'h': fputs(report_usage, stdout); free(settings); return 0;
    case ':': rc = usage_error("%s needs a value", argv[optind - 1]); break;
    default: rc = usage_error("unknown flag '%s'", argv[optind - 1]); break;
    }
  }
  if (!rc && optind < argc) rc = usage_error("unexpected argument '%s'", argv[optind]);
  if (!rc && !a.job) rc = usage_error("%s", "--job FILE is required");
  if (!rc && !sweeps) rc = usage_error("%s", "--sweep SPEC is required (e.g. --sweep \"isr:isr.samples=8,16\")");
  /* The baseline first (every row's gain refers to it), then the sweeps. */
  if (!rc && !report_sweep_parse(a.baseline, settings, &a.setting_count, &err))
    rc = usage_error("--baseline: %s", err.msg);
  for (int i = 0; i < sweeps && !rc; i++) {
    if (!strcmp(sweeps_given[i], a.baseline)) continue; /* always there */
    if (!report_sweep_parse(sweeps_given[i], settings, &a.setting_count, &err)) {
      fprintf(stderr, "limn report: %s\n", err.msg);
      rc = 2;
    }
  }
  const char *bad = !rc && a.ref.pov.radiosity ? lm_pov_radiosity_check(&a.ref.pov.rad) : NULL;
  if (bad) rc = usage_error("radiosity setting out of range: %s", bad);
  job *j = rc ? NULL : lm_alloc(sizeof *j);
  if (j && !job_read(j, a.job, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 2;
  }
  if (!rc && !reference_prepare(&a.ref, j, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 1;
  }
  if (!rc) {
    a.has_floor = reference_direct(&a.ref, &a.direct, &a.direct_flags);
    reference_describe(&a.ref, a.against, sizeof a.against);
    a.has_noise = a.ref.renderer == REFERENCE_CYCLES;
    a.second = a.ref;
    a.second.cycles.seed = a.ref.cycles.seed + 1;
    snprintf(a.second_flags, sizeof a.second_flags, " --renderer cycles --seed %d", a.second.cycles.seed);
  }
  lm_pipeline *pipeline = rc ? NULL : job_pipeline(j, NULL, 0, false);
  if (!rc && !pipeline) rc = 2;
  if (!rc) rc = run(&a, j, pipeline);
  if (j) job_free_scenes(j);
  lm_pipeline_destroy(pipeline);
  free(j);
  free(settings);
  return rc;
}
