#include "image/metrics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int compared_channels(const lm_image *img) { return img->channels < 3 ? img->channels : 3; }
static bool finite_values(const lm_image *img, const char *name, lm_error *err);

bool lm_metrics_check(const lm_image *a, const char *a_name, const lm_image *b, const char *b_name,
                      lm_error *err) {
  if (a->width <= 0 || a->height <= 0 || a->channels <= 0 || !a->pixels) {
    lm_error_set(err, "%s: empty image", a_name);
    return false;
  }
  if (b->width <= 0 || b->height <= 0 || b->channels <= 0 || !b->pixels) {
    lm_error_set(err, "%s: empty image", b_name);
    return false;
  }
  if (a->width != b->width || a->height != b->height) {
    lm_error_set(err, "sizes differ: %s is %dx%d, %s is %dx%d", a_name, a->width, a->height, b_name,
                 b->width, b->height);
    return false;
  }
  if (a->channels != b->channels) {
    lm_error_set(err, "channel counts differ: %s has %d, %s has %d", a_name, a->channels, b_name,
                 b->channels);
    return false;
  }
  return finite_values(a, a_name, err) && finite_values(b, b_name, err);
}

/* False with a message naming the first value that is NaN or Inf. */
static bool finite_values(const lm_image *img, const char *name, lm_error *err) {
  int nc = compared_channels(img);
  size_t px = (size_t)img->width * img->height;
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++)
      if (!isfinite(img->pixels[i * (size_t)img->channels + (size_t)k])) {
        lm_error_set(err, "%s: pixel (%d, %d) channel %d is not finite (NaN or Inf)", name,
                     (int)(i % (size_t)img->width), (int)(i / (size_t)img->width), k);
        return false;
      }
  return true;
}

/* Value k (0 .. channels-1) of pixel i. */
static double at(const lm_image *img, size_t i, int k) {
  return img->pixels[i * (size_t)img->channels + (size_t)k];
}

/* True when every compared value of the image is the same number. */
static bool constant(const lm_image *img, size_t px, int nc) {
  float first = img->pixels[0];
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++)
      if (img->pixels[i * (size_t)img->channels + (size_t)k] != first) return false;
  return true;
}

/* Seed eq 20: mean of the product of standard scores, population statistics. */
static double pearson(const lm_image *a, const lm_image *b, size_t px, int nc) {
  bool ca = constant(a, px, nc), cb = constant(b, px, nc);
  if (ca || cb) return ca && cb && a->pixels[0] == b->pixels[0] ? 1.0 : 0.0;
  double n = (double)px * nc, sa = 0, sb = 0;
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++) sa += at(a, i, k), sb += at(b, i, k);
  double ma = sa / n, mb = sb / n, vaa = 0, vbb = 0, vab = 0;
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++) {
      double x = at(a, i, k) - ma, y = at(b, i, k) - mb;
      vaa += x * x, vbb += y * y, vab += x * y;
    }
  /* Not constant, so both sums of squares are positive; rounding could still
   * push the quotient a hair past +-1. */
  double den = sqrt(vaa) * sqrt(vbb);
  if (!(den > 0)) return 0.0;
  double r = vab / den;
  return r > 1 ? 1 : r < -1 ? -1 : r;
}

/* The 1-D Gaussian taps of the SSIM window. */
static void ssim_taps(double taps[2 * LM_SSIM_RADIUS + 1]) {
  for (int t = -LM_SSIM_RADIUS; t <= LM_SSIM_RADIUS; t++)
    taps[t + LM_SSIM_RADIUS] = exp(-(double)(t * t) / (2.0 * LM_SSIM_SIGMA * LM_SSIM_SIGMA));
}

/* One pass of the separable Gaussian blur: `lines` lines of n values, value
 * k of line l at l * across + k * along, the window cut at the line's ends
 * and its weights renormalized there. */
static void blur_lines(const double *src, double *dst, int lines, int n, size_t along, size_t across,
                       const double *taps) {
  for (int l = 0; l < lines; l++)
    for (int k = 0; k < n; k++) {
      double s = 0, wsum = 0;
      for (int t = -LM_SSIM_RADIUS; t <= LM_SSIM_RADIUS; t++) {
        int kk = k + t;
        if (kk < 0 || kk >= n) continue;
        s += taps[t + LM_SSIM_RADIUS] * src[l * across + kk * along];
        wsum += taps[t + LM_SSIM_RADIUS];
      }
      dst[l * across + k * along] = s / wsum;
    }
}

/* Separable Gaussian blur of a w x h plane: rows into tmp, then its columns
 * (the 2-D window is a product, so its cut at the borders is too). */
static void blur(const double *src, double *dst, double *tmp, int w, int h, const double *taps) {
  blur_lines(src, tmp, h, w, 1, (size_t)w, taps);
  blur_lines(tmp, dst, w, h, (size_t)w, 1, taps);
}

static double ssim(const lm_image *a, const lm_image *b, int nc) {
  int w = a->width, h = a->height;
  size_t px = (size_t)w * h;
  double taps[2 * LM_SSIM_RADIUS + 1];
  ssim_taps(taps);
  /* planes: a, b, a^2, b^2, ab, then their blurs, plus scratch */
  double *buf = lm_alloc(px * 11 * sizeof(double));
  double *in[5], *mu[5], *tmp = buf + 10 * px;
  for (int p = 0; p < 5; p++) in[p] = buf + p * px, mu[p] = buf + (5 + p) * px;
  const double c1 = (LM_SSIM_K1 * 1.0) * (LM_SSIM_K1 * 1.0), c2 = (LM_SSIM_K2 * 1.0) * (LM_SSIM_K2 * 1.0);
  double total = 0;
  for (int k = 0; k < nc; k++) {
    for (size_t i = 0; i < px; i++) {
      double x = at(a, i, k), y = at(b, i, k);
      in[0][i] = x, in[1][i] = y, in[2][i] = x * x, in[3][i] = y * y, in[4][i] = x * y;
    }
    for (int p = 0; p < 5; p++) blur(in[p], mu[p], tmp, w, h, taps);
    for (size_t i = 0; i < px; i++) {
      double ma = mu[0][i], mb = mu[1][i];
      /* Variances may come out a rounding error below 0. */
      double va = fmax(mu[2][i] - ma * ma, 0), vb = fmax(mu[3][i] - mb * mb, 0);
      double cov = mu[4][i] - ma * mb;
      /* c1, c2 > 0 keep the denominator positive. */
      total += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
    }
  }
  free(buf);
  return total / ((double)px * nc);
}

void lm_metrics_compute_fast(const lm_image *a, const lm_image *b, lm_metrics *m) {
  memset(m, 0, sizeof *m);
  int nc = compared_channels(a);
  size_t px = (size_t)a->width * a->height;
  m->width = a->width, m->height = a->height, m->channels = nc;
  double sum_abs = 0, sum_sq = 0, max_abs = 0;
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++) {
      double d = at(a, i, k) - at(b, i, k);
      sum_abs += fabs(d);
      sum_sq += d * d;
      if (fabs(d) > max_abs) max_abs = fabs(d);
    }
  double n = (double)px * nc, mse = sum_sq / n;
  m->mean_error = sum_abs / n;
  m->max_error = max_abs;
  m->rmse = sqrt(mse);
  m->identical = sum_sq == 0;
  m->psnr = m->identical ? INFINITY : 10.0 * log10(1.0 / mse);
  m->pearson = pearson(a, b, px, nc);
  m->ssim = m->closer = m->ties = -1;
}

void lm_metrics_compute(const lm_image *a, const lm_image *b, lm_metrics *m) {
  lm_metrics_compute_fast(a, b, m);
  m->ssim = ssim(a, b, m->channels);
}

void lm_metrics_closer(const lm_image *a, const lm_image *b, const lm_image *r, lm_metrics *m) {
  int nc = compared_channels(a);
  size_t px = (size_t)a->width * a->height, closer = 0, ties = 0;
  for (size_t i = 0; i < px; i++) {
    double da = 0, db = 0;
    for (int k = 0; k < nc; k++) {
      da += fabs(at(a, i, k) - at(r, i, k));
      db += fabs(at(b, i, k) - at(r, i, k));
    }
    closer += da < db;
    ties += da == db;
  }
  m->closer = (double)closer / (double)px;
  m->ties = (double)ties / (double)px;
}

static double pixel_error(const lm_image *a, const lm_image *b, size_t i, int nc) {
  double d = 0;
  for (int k = 0; k < nc; k++) d += fabs(at(a, i, k) - at(b, i, k));
  return d / nc;
}

double lm_metrics_max_pixel_error(const lm_image *a, const lm_image *b) {
  int nc = compared_channels(a);
  size_t px = (size_t)a->width * a->height;
  double mx = 0;
  for (size_t i = 0; i < px; i++) mx = fmax(mx, pixel_error(a, b, i, nc));
  return mx;
}

void lm_metrics_heatmap(const lm_image *a, const lm_image *b, double scale, unsigned char *rgb8) {
  /* black, blue, red, yellow, white at 0, 1/4, 1/2, 3/4, 1 */
  static const double ramp[5][3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
  int nc = compared_channels(a);
  size_t px = (size_t)a->width * a->height;
  double inv = scale > 0 && isfinite(scale) ? 1.0 / scale : 0.0;
  for (size_t i = 0; i < px; i++) {
    double t = pixel_error(a, b, i, nc) * inv;
    t = isfinite(t) ? fmin(fmax(t, 0), 1) : 1; /* Inf or NaN in a file: full scale */
    double f = t * 4;
    int lo = f >= 4 ? 3 : (int)f;
    double u = f - lo;
    for (int c = 0; c < 3; c++) {
      double v = ramp[lo][c] + (ramp[lo + 1][c] - ramp[lo][c]) * u;
      rgb8[i * 3 + (size_t)c] = (unsigned char)lround(v * 255.0);
    }
  }
}

double lm_metrics_flicker(const lm_image *a_prev, const lm_image *a, const lm_image *r_prev, const lm_image *r) {
  int nc = compared_channels(a);
  size_t px = (size_t)a->width * a->height;
  double sum = 0;
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++)
      sum += fabs((at(a, i, k) - at(a_prev, i, k)) - (at(r, i, k) - at(r_prev, i, k)));
  return sum / ((double)px * nc); /* checked images: px, nc > 0 */
}

bool lm_metrics_lag(const double *error, int event, int end, double settled, lm_lag *out, lm_error *err) {
  if (event < 0 || event >= end) {
    lm_error_set(err, "event at frame %d: not among the sequence's frames 0 .. %d", event, end - 1);
    return false;
  }
  for (int t = event; t < end; t++)
    if (!isfinite(error[t]) || error[t] < 0) {
      lm_error_set(err, "frame %d: error %g is not a finite value >= 0", t, error[t]);
      return false;
    }
  if (isnan(settled) || isinf(settled)) {
    lm_error_set(err, "event at frame %d: settled error %g is not finite", event, settled);
    return false;
  }
  if (settled < 0) { /* the median of the last k frames: a sorted copy, k is small */
    int k = end - event < LM_LAG_SETTLED_FRAMES ? end - event : LM_LAG_SETTLED_FRAMES;
    double last[LM_LAG_SETTLED_FRAMES];
    for (int i = 0; i < k; i++) {
      double v = error[end - k + i];
      int j = i;
      for (; j > 0 && last[j - 1] > v; j--) last[j] = last[j - 1];
      last[j] = v;
    }
    settled = k % 2 ? last[k / 2] : 0.5 * (last[k / 2 - 1] + last[k / 2]);
  }
  /* Walk back from the end while the error stays within the tolerance. */
  int first = end;
  while (first > event && fabs(error[first - 1] - settled) <= LM_LAG_TOLERANCE * settled) first--;
  /* first == end: even the last frame is off, and frames is the window's count. */
  *out = (lm_lag){.frames = first - event, .returned = first < end, .settled = settled};
  return true;
}

bool lm_metrics_band_error(const lm_image *a, const lm_image *b, const unsigned char *mask, double *out,
                           size_t *pixels) {
  int nc = compared_channels(a);
  size_t px = (size_t)a->width * a->height, band = 0;
  double sum = 0;
  for (size_t i = 0; i < px; i++)
    if (mask[i]) {
      for (int k = 0; k < nc; k++) sum += fabs(at(a, i, k) - at(b, i, k));
      band++;
    }
  if (pixels) *pixels = band;
  if (!band) return false;
  *out = sum / ((double)band * nc);
  return true;
}
