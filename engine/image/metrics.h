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
/* Fills m->closer and m->ties against reference r (all three must match). */
void lm_metrics_closer(const lm_image *a, const lm_image *b, const lm_image *r, lm_metrics *m);

/* Difference heat map: per pixel the mean over compared channels of
 * |a - b|, divided by `scale` (> 0) and mapped through a black - blue - red
 * - yellow - white ramp. `rgb8` holds w * h * 3 bytes, top row first. */
void lm_metrics_heatmap(const lm_image *a, const lm_image *b, double scale, unsigned char *rgb8);
/* The largest per-pixel mean |a - b| (the heat map's natural scale). */
double lm_metrics_max_pixel_error(const lm_image *a, const lm_image *b);

#ifdef __cplusplus
}
#endif
#endif
