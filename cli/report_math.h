/* What `limn report` computes that needs no GL or files, kept apart so that
 * unit tests check it against hand values: the sweep syntax, the Pareto
 * front, the gains over the baseline (seed 000 chapter 5.3.2), the share
 * of its indirect error removed, and a sequence's error over time
 * (shared/design/motion.md). */
#ifndef LIMN_REPORT_MATH_H
#define LIMN_REPORT_MATH_H

#include "image/metrics.h"
#include "job.h"

#define REPORT_MAX_OPTIONS 8
#define REPORT_MAX_SETTINGS 256

/* One technique with one value for each swept option. */
typedef struct report_setting {
  char technique[64];
  char names[REPORT_MAX_OPTIONS][128], values[REPORT_MAX_OPTIONS][64];
  int option_count;
  char label[512]; /* "isr samples=8 coarse=2" */
} report_setting;

/* Adds the settings of one --sweep SPEC to list[*count]:
 *   TECH                          the technique as the job sets it
 *   TECH:OPT=V1,V2,...[;OPT=...]  every combination of the values
 * e.g. "isr:isr.samples=8,16;isr.coarse=1,2" gives four settings. False with
 * a message naming SPEC and what is wrong (no technique, an option without
 * values, an empty value, more than REPORT_MAX_SETTINGS in all). */
bool report_sweep_parse(const char *spec, report_setting *list, int *count, lm_error *err);

/* front[i] = no point j is at least as good in both x and y and better in
 * one (lower is better: milliseconds, error). Equal points are all on it. */
void report_pareto(const double *x, const double *y, int n, bool *front);

/* Seed 000 chapter 5.3.2: gain = 100 (e_base - e) / e_base percent; 0 when
 * e_base is 0 (nothing to gain). */
double report_gain(double base_error, double error);

/* The share of the baseline's indirect error a setting removes, percent:
 * 100 (e_base - e) / (e_base - floor), floor being the baseline's error
 * against the direct-only reference (what is left when indirect light is
 * perfect). False (n/a) when floor is not below e_base: no indirect error
 * to remove. */
bool report_indirect_removed(double base_error, double floor, double error, double *out);

typedef struct report_summary {
  int views;
  double mean_gain, median_gain;  /* percent, over views */
  double views_improved;          /* share of views with gain > 0 */
  double pixels_closer;           /* share of all pixels closer than the baseline's */
  double pearson_before, pearson_after; /* means over views */
  double views_pearson_rose;      /* share of views whose Pearson is above the baseline's */
  double indirect_removed;        /* percent, mean over the views where it is defined */
  int indirect_views;             /* those views (0: n/a) */
  double floor;                   /* mean direct-only floor over views */
} report_summary;

/* Over n views: the baseline's and the setting's mean errors, the direct-only
 * floor (report_indirect_removed), the share of each view's pixels closer to
 * the reference than the baseline's, its pixel count (weights the pixel
 * share) and both Pearson coefficients. */
void report_summarize(int n, const double *base_error, const double *floor, const double *error,
                      const double *closer, const double *pixels, const double *pearson_base,
                      const double *pearson, report_summary *out);

/* ---- sequences ----------------------------------------------------------- */

#define REPORT_MAX_EVENTS 64

/* Splits n views, in the job's order, into runs: view i continues view
 * i - 1's run when both show the same scene, camera, size and technique and
 * its frame is greater; any other view starts a run. first[k] is run k's
 * first view and first[runs] = n (first holds n + 1). Returns the run
 * count: n for a still job (every run one view), fewer when it has sequences. */
int report_sequences(const job_view *views, int n, int *first);

/* A job's `events`: frame indices, strictly increasing, each in
 * 0 .. frames - 1 (frames: its sequences' length). False with a message
 * naming the job file (path) and the event otherwise. */
bool report_events_check(const char *path, const int *events, int count, int frames, lm_error *err);

/* One setting's error over one sequence. */
typedef struct report_sequence {
  int frames;
  double mean_error; /* eq 19, the mean over frames */
  double flicker;    /* lm_metrics_flicker's mean over the pairs t >= 1; 0 with one frame */
  lm_lag lags[REPORT_MAX_EVENTS]; /* after each event, the window ending at the next */
  int event_count;
} report_sequence;

/* From per-frame errors error[t] and flickers flicker[t] (of frames t - 1
 * and t; flicker[0] is not read) over `frames` frames, and the job's events
 * (checked by report_events_check) with the error each settles to (settled[e]:
 * lm_metrics_lag's; NULL or < 0: the window's tail). False with a message naming the frame
 * whose error or flicker is not a finite value >= 0. */
bool report_sequence_summarize(int frames, const double *error, const double *flicker, const int *events,
                               const double *settled, int event_count, report_sequence *out, lm_error *err);

/* The error-against-frame curve of one setting over several sequences:
 * curve[t] is the mean of frame t's error over the runs that have a frame t
 * (errors[r][t] for t < frames[r]); returns the longest run's length. */
int report_frame_curve(const double *const *errors, const int *frames, int runs, double *curve);

#endif
