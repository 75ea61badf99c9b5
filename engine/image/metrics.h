/* metrics: how far apart two images are, in the terms of seed 000 chapter
 * 3.3 (difference image eq 18, mean error eq 19, Pearson eq 20) plus RMSE,
 * PSNR and SSIM. Pure C on float pixels; no GL, no files.
 *
 * Images are compared value by value over their colour channels: the first
 * min(channels, 3) of each pixel (a fourth, alpha, is left out). Both images
 * must have the same width, height and channel count. Values are taken as
 * stored (linear for EXR, sRGB-encoded / 255 for PNG), never clamped. */
#ifndef LIMN_METRICS_H
#define LIMN_METRICS_H

#include "image/image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lm_metrics {
  int width, height, channels; /* channels compared: 1..3 */
  /* Seed eq 19: sum over pixels and compared channels of |a - b|, divided by
   * channels * w * h (3wh for RGB). */
  double mean_error;
  double max_error; /* largest |a - b| of any value */
  double rmse;      /* sqrt(mean (a - b)^2) over the same values */
  /* 10 log10(1 / mse), peak 1. INFINITY when the images are identical
   * (identical is then true): callers print it as "inf" or JSON null. */
  double psnr;
  bool identical;
  /* Seed eq 20 with population statistics, every compared value one sample
   * (n = channels * w * h): mean of the product of standard scores. Where a
   * standard deviation is 0 (a constant image) the score is undefined; the
   * result is then defined as 1 when both images are constant and equal, and
   * 0 otherwise (a constant image predicts nothing about the other). */
  double pearson;
  /* SSIM (Wang et al. 2004) per channel on a Gaussian window of 11x11 taps,
   * sigma 1.5, cut at the borders and renormalized there; C1 = (0.01 L)^2,
   * C2 = (0.03 L)^2 with L = 1; the mean over every pixel and channel. */
  double ssim;
  /* With a reference R (lm_metrics_closer): share of pixels where a is
   * strictly closer to R than b (sum over channels of |a - R| against
   * |b - R|), and share where both are equally far. -1 without a reference. */
  double closer, ties;
} lm_metrics;

/* SSIM window and constants (see above). */
#define LM_SSIM_RADIUS 5
#define LM_SSIM_SIGMA 1.5
#define LM_SSIM_K1 0.01
#define LM_SSIM_K2 0.03

/* False with a message when the images differ in size or channel count, are
 * empty, or hold a NaN or Inf among their compared values (no metric of
 * them would mean anything). `a_name` and `b_name` name them in the message. */
bool lm_metrics_check(const lm_image *a, const char *a_name, const lm_image *b, const char *b_name,
                      lm_error *err);
/* Every metric but closer/ties (set to -1). The images must pass lm_metrics_check. */
void lm_metrics_compute(const lm_image *a, const lm_image *b, lm_metrics *m);
/* The same but SSIM (set to -1), whose window costs tens of times the rest:
 * cheap enough for every frame of a viewer. */
void lm_metrics_compute_fast(const lm_image *a, const lm_image *b, lm_metrics *m);
/* Fills m->closer and m->ties against reference r (all three must match). */
void lm_metrics_closer(const lm_image *a, const lm_image *b, const lm_image *r, lm_metrics *m);

/* Difference heat map: per pixel the mean over compared channels of
 * |a - b|, divided by `scale` (> 0) and mapped through a black - blue - red
 * - yellow - white ramp. `rgb8` holds w * h * 3 bytes, top row first. */
void lm_metrics_heatmap(const lm_image *a, const lm_image *b, double scale, unsigned char *rgb8);
/* The largest per-pixel mean |a - b| (the heat map's natural scale). */
double lm_metrics_max_pixel_error(const lm_image *a, const lm_image *b);

/* ---- error over time (shared/design/motion.md) --------------------------
 * Limn's own measures of a sequence against a reference sequence, both
 * linear, frame t of one at the same view and time as frame t of the other. */

/* Flicker of one pair of consecutive frames: the mean over pixels and
 * compared channels of |(a - a_prev) - (r - r_prev)|, the frame-to-frame
 * change of Limn's frames (a_prev, a) that the reference's (r_prev, r) does
 * not have. Per RGB channel and divided by 3wh like eq 19, not on
 * luminance: a change of hue at one luminance flickers too. A constant bias
 * (a = r + c in both frames) cancels, and a still sequence (a_prev = a,
 * r_prev = r) gives exactly 0. A sequence's flicker is the mean of this over
 * its pairs t >= 1 (none for one frame). All four images must pass
 * lm_metrics_check against a (same size, finite). */
double lm_metrics_flicker(const lm_image *a_prev, const lm_image *a, const lm_image *r_prev, const lm_image *r);

/* Lag after an event (a light switched, a door opened, an object stopped)
 * at frame `event`, from per-frame errors (eq 19) error[event .. end - 1],
 * end being the next event or the sequence's end.
 * - settled: the error the technique settles to after the event: `settled`
 *   when it is >= 0 (limn report renders the window's last pose as a still
 *   frame until it has converged: a history that fades out slowly, as
 *   1 / frames, never looks settled against its own tail), else the median
 *   of the window's last LM_LAG_SETTLED_FRAMES frames (all of them in a
 *   shorter window). After the event, not before: the change alters the
 *   image, so the error before it is no target.
 * - frames: the smallest d >= 0 such that every frame from event + d to
 *   end - 1 is within LM_LAG_TOLERANCE of settled (|e - settled| <=
 *   0.1 settled): frames event .. event + d - 1 were off. Every frame to the
 *   end, not the first one back, so that an error swinging through the
 *   settled value on its way does not count as settled.
 * - returned: false when even the window's last frame is off (noise wider
 *   than 10%); frames is then the window's frame count, end - event.
 * A settled error of 0 allows no deviation at all. */
#define LM_LAG_SETTLED_FRAMES 5
#define LM_LAG_TOLERANCE 0.1
typedef struct lm_lag {
  int frames;
  bool returned;
  double settled;
} lm_lag;
/* False with a message when event is not in 0 .. end - 1 or an error of the
 * window (or a given settled error) is NaN or Inf, or negative (naming its frame). */
bool lm_metrics_lag(const double *error, int event, int end, double settled, lm_lag *out, lm_error *err);

/* Eq 19's mean error over a band of pixels only: mask[i] != 0 marks pixel i
 * (w * h bytes, top row first). Ghosting is this error in the band a moving
 * object disoccluded, set against the same band's in a frame where nothing
 * moved (motion.md): a trail the history left there raises the first only.
 * a and b must pass lm_metrics_check. False when the band is empty (no mean);
 * *pixels (may be NULL) gets the band's pixel count. */
bool lm_metrics_band_error(const lm_image *a, const lm_image *b, const unsigned char *mask, double *out,
                           size_t *pixels);

#ifdef __cplusplus
}
#endif
#endif
