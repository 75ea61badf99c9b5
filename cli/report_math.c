/* The report's arithmetic (cli/report_math.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "report_math.h"

static void trim(char *s) {
  size_t n = strlen(s), i = 0;
  while (n && (s[n - 1] == ' ' || s[n - 1] == '\t')) s[--n] = '\0';
  while (s[i] == ' ' || s[i] == '\t') i++;
  memmove(s, s + i, n - i + 1);
}

/* Splits s in place at sep into at most max parts; returns how many. */
static int split(char *s, char sep, char **parts, int max) {
  int n = 0;
  for (char *p = s;; n++) {
    if (n == max) return max + 1;
    parts[n] = p;
    char *q = strchr(p, sep);
    if (!q) return n + 1;
    *q = '\0';
    p = q + 1;
  }
}

static bool same_setting(const report_setting *a, const report_setting *b) {
  if (strcmp(a->technique, b->technique) || a->option_count != b->option_count) return false;
  for (int i = 0; i < a->option_count; i++)
    if (strcmp(a->names[i], b->names[i]) || strcmp(a->values[i], b->values[i])) return false;
  return true;
}

bool report_sweep_parse(const char *spec, report_setting *list, int *count, lm_error *err) {
  char buf[2048];
  if (strlen(spec) >= sizeof buf) {
    lm_error_set(err, "--sweep '%.40s...': too long", spec);
    return false;
  }
  snprintf(buf, sizeof buf, "%s", spec);
  char *colon = strchr(buf, ':');
  if (colon) *colon = '\0';
  report_setting base = {0};
  snprintf(base.technique, sizeof base.technique, "%s", buf);
  trim(base.technique);
  if (!base.technique[0] || strchr(base.technique, '=') || strchr(base.technique, ',')) {
    lm_error_set(err, "--sweep '%s': want TECH or TECH:OPTION=V1,V2;OPTION=V1,V2 (a technique name first)", spec);
    return false;
  }
  char *opts[REPORT_MAX_OPTIONS + 1];
  char *values[REPORT_MAX_OPTIONS][64];
  int value_counts[REPORT_MAX_OPTIONS], option_count = 0;
  if (colon) {
    option_count = split(colon + 1, ';', opts, REPORT_MAX_OPTIONS);
    if (option_count > REPORT_MAX_OPTIONS) {
      lm_error_set(err, "--sweep '%s': at most %d options", spec, REPORT_MAX_OPTIONS);
      return false;
    }
    for (int i = 0; i < option_count; i++) {
      char *eq = strchr(opts[i], '=');
      if (!eq) {
        lm_error_set(err, "--sweep '%s': '%s' wants OPTION=V1,V2,...", spec, opts[i]);
        return false;
      }
      *eq = '\0';
      trim(opts[i]);
      if (!opts[i][0] || strlen(opts[i]) >= sizeof base.names[0]) {
        lm_error_set(err, "--sweep '%s': option %d has no name (or too long a one)", spec, i + 1);
        return false;
      }
      value_counts[i] = split(eq + 1, ',', values[i], 64);
      for (int k = 0; k < value_counts[i] && value_counts[i] <= 64; k++) {
        trim(values[i][k]);
        if (!values[i][k][0] || strlen(values[i][k]) >= sizeof base.values[0]) {
          lm_error_set(err, "--sweep '%s': %s: value %d is empty (or too long)", spec, opts[i], k + 1);
          return false;
        }
      }
      if (value_counts[i] > 64) {
        lm_error_set(err, "--sweep '%s': %s: at most 64 values", spec, opts[i]);
        return false;
      }
    }
  }
  long total = 1;
  for (int i = 0; i < option_count; i++) total *= value_counts[i];
  if (*count + total > REPORT_MAX_SETTINGS) {
    lm_error_set(err, "--sweep '%s': %ld settings, more than the %d a report holds", spec, total,
                 REPORT_MAX_SETTINGS);
    return false;
  }
  /* Every combination, the last option varying fastest. */
  int first = *count;
  for (long c = 0; c < total; c++) {
    report_setting *s = &list[(*count)++];
    *s = base;
    s->option_count = option_count;
    int len = snprintf(s->label, sizeof s->label, "%s", s->technique);
    long rest = c;
    for (int i = option_count - 1; i >= 0; i--) {
      snprintf(s->names[i], sizeof s->names[i], "%s", opts[i]);
      snprintf(s->values[i], sizeof s->values[i], "%s", values[i][rest % value_counts[i]]);
      rest /= value_counts[i];
    }
    for (int i = 0; i < option_count && len < (int)sizeof s->label; i++) {
      /* "isr.samples" labels as "samples" under technique isr */
      const char *name = s->names[i];
      size_t tl = strlen(s->technique);
      if (!strncmp(name, s->technique, tl) && name[tl] == '.') name += tl + 1;
      len += snprintf(s->label + len, sizeof s->label - (size_t)len, " %s=%s", name, s->values[i]);
    }
  }
  /* A setting given twice (isr.samples=8,8, or a --sweep repeated) would be two rows of one image. */
  for (int k = first; k < *count; k++)
    for (int e = 0; e < k; e++)
      if (same_setting(&list[e], &list[k])) {
        lm_error_set(err, "--sweep '%s': setting '%s' is there twice (settings %d and %d)", spec, list[k].label, e, k);
        *count = first;
        return false;
      }
  return true;
}

void report_pareto(const double *x, const double *y, int n, bool *front) {
  for (int i = 0; i < n; i++) {
    front[i] = true;
    for (int j = 0; j < n && front[i]; j++)
      if (j != i && x[j] <= x[i] && y[j] <= y[i] && (x[j] < x[i] || y[j] < y[i])) front[i] = false;
  }
}

double report_gain(double base_error, double error) {
  return base_error > 0 ? 100.0 * (base_error - error) / base_error : 0.0;
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

bool report_indirect_removed(double base_error, double floor, double error, double *out) {
  if (!(floor < base_error)) return false;
  *out = 100.0 * (base_error - error) / (base_error - floor);
  return true;
}

void report_summarize(int n, const double *base_error, const double *floor, const double *error,
                      const double *closer, const double *pixels, const double *pearson_base,
                      const double *pearson, report_summary *out) {
  *out = (report_summary){.views = n};
  if (n <= 0) return;
  double *gains = lm_alloc(sizeof *gains * (size_t)n);
  double improved = 0, closer_px = 0, all_px = 0;
  for (int i = 0; i < n; i++) {
    gains[i] = report_gain(base_error[i], error[i]);
    out->mean_gain += gains[i] / n;
    improved += gains[i] > 0;
    closer_px += closer[i] * pixels[i];
    all_px += pixels[i];
    out->pearson_before += pearson_base[i] / n;
    out->pearson_after += pearson[i] / n;
    out->views_pearson_rose += (double)(pearson[i] > pearson_base[i]) / n;
    out->floor += floor[i] / n;
    double share;
    if (report_indirect_removed(base_error[i], floor[i], error[i], &share))
      out->indirect_removed += share, out->indirect_views++;
  }
  if (out->indirect_views) out->indirect_removed /= out->indirect_views;
  qsort(gains, (size_t)n, sizeof *gains, compare_double);
  out->median_gain = n % 2 ? gains[n / 2] : 0.5 * (gains[n / 2 - 1] + gains[n / 2]);
  out->views_improved = improved / n;
  out->pixels_closer = all_px > 0 ? closer_px / all_px : 0;
  free(gains);
}

int report_sequences(const job_view *views, int n, int *first) {
  int runs = 0;
  for (int i = 0; i < n; i++) {
    const job_view *v = &views[i], *u = &views[i > 0 ? i - 1 : 0];
    bool continues = i > 0 && v->scene == u->scene && v->camera == u->camera && v->size == u->size &&
                     v->technique == u->technique && v->frame > u->frame;
    if (!continues) first[runs++] = i;
  }
  first[runs] = n;
  return runs;
}

bool report_events_check(const char *path, const int *events, int count, int frames, lm_error *err) {
  for (int i = 0; i < count; i++) {
    if (events[i] < 0 || events[i] >= frames) {
      lm_error_set(err, "%s: events[%d]: frame %d is not among the sequence's frames 0 .. %d", path, i + 1,
                   events[i], frames - 1);
      return false;
    }
    if (i > 0 && events[i] <= events[i - 1]) {
      lm_error_set(err, "%s: events[%d]: frame %d does not come after frame %d (events go in order)", path, i + 1,
                   events[i], events[i - 1]);
      return false;
    }
  }
  return true;
}

bool report_sequence_summarize(int frames, const double *error, const double *flicker, const int *events,
                               const double *settled, int event_count, report_sequence *out, lm_error *err) {
  *out = (report_sequence){.frames = frames, .event_count = event_count};
  for (int t = 0; t < frames; t++)
    if (!(isfinite(error[t]) && error[t] >= 0) || (t > 0 && !(isfinite(flicker[t]) && flicker[t] >= 0))) {
      lm_error_set(err, "frame %d: error %g, flicker %g: not finite values >= 0", t, error[t],
                   t > 0 ? flicker[t] : 0.0);
      return false;
    }
  for (int t = 0; t < frames; t++) out->mean_error += error[t] / frames;
  for (int t = 1; t < frames; t++) out->flicker += flicker[t] / (frames - 1);
  for (int e = 0; e < event_count; e++) {
    int end = e + 1 < event_count ? events[e + 1] : frames;
    if (!lm_metrics_lag(error, events[e], end, settled ? settled[e] : -1, &out->lags[e], err)) return false;
  }
  return true;
}

int report_frame_curve(const double *const *errors, const int *frames, int runs, double *curve) {
  int longest = 0;
  for (int r = 0; r < runs; r++) longest = frames[r] > longest ? frames[r] : longest;
  for (int t = 0; t < longest; t++) {
    int count = 0;
    curve[t] = 0;
    for (int r = 0; r < runs; r++)
      if (t < frames[r]) curve[t] += errors[r][t], count++;
    curve[t] /= count; /* t < longest: some run has frame t */
  }
  return longest;
}
