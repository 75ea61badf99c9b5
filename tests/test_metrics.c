/* Image metrics (engine/image/metrics.h) against values worked out by hand
 * on tiny images, and their defined results where a formula has none
 * (identical images, constant images). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "image/metrics.h"

static lm_image img(int w, int h, int c, float *px) { return (lm_image){w, h, c, px}; }

/* A = (0,0,0) (1,1,1); B = (0.5,0,0) (1,1,0.5): differences 0.5 0 0 0 0 0.5. */
static void two_pixels_by_hand(void **state) {
  (void)state;
  float pa[] = {0, 0, 0, 1, 1, 1}, pb[] = {0.5f, 0, 0, 1, 1, 0.5f};
  lm_image a = img(2, 1, 3, pa), b = img(2, 1, 3, pb);
  lm_metrics m;
  lm_metrics_compute(&a, &b, &m);
  assert_int_equal(m.channels, 3);
  assert_float_equal(m.mean_error, 1.0 / 6.0, 1e-12);        /* eq 19: (0.5 + 0.5) / (3 * 2) */
  assert_float_equal(m.max_error, 0.5, 1e-12);
  assert_float_equal(m.rmse, sqrt(0.5 / 6.0), 1e-12);         /* sqrt((0.25 + 0.25) / 6) */
  assert_float_equal(m.psnr, 10.0 * log10(12.0), 1e-9);       /* mse 1/12 */
  assert_false(m.identical);
  /* eq 20: means 0.5 and 0.5; sum xy = 1, sum xx = 1.5, sum yy = 1 */
  assert_float_equal(m.pearson, 1.0 / sqrt(1.5), 1e-12);
  assert_true(m.ssim > 0 && m.ssim < 1);
  assert_float_equal(m.closer, -1, 0);
}

/* One pixel, one channel: the window is the pixel itself, so both variances
 * and the covariance are 0 and SSIM = (2xy + C1) / (x^2 + y^2 + C1). */
static void ssim_of_one_pixel_by_hand(void **state) {
  (void)state;
  float pa[] = {0.5f}, pb[] = {0.25f};
  lm_image a = img(1, 1, 1, pa), b = img(1, 1, 1, pb);
  lm_metrics m;
  lm_metrics_compute(&a, &b, &m);
  double c1 = 0.01 * 0.01;
  assert_float_equal(m.ssim, (2 * 0.5 * 0.25 + c1) / (0.25 + 0.0625 + c1), 1e-12);
  assert_float_equal(m.mean_error, 0.25, 1e-12);
  assert_int_equal(m.channels, 1);
}

static void ssim_is_symmetric_and_one_for_identical(void **state) {
  (void)state;
  float pa[4 * 4 * 3], pb[4 * 4 * 3];
  for (int i = 0; i < 48; i++) pa[i] = (float)((i * 7) % 11) / 10.0f, pb[i] = (float)((i * 5) % 13) / 12.0f;
  lm_image a = img(4, 4, 3, pa), b = img(4, 4, 3, pb);
  lm_metrics ab, ba, aa;
  lm_metrics_compute(&a, &b, &ab);
  lm_metrics_compute(&b, &a, &ba);
  lm_metrics_compute(&a, &a, &aa);
  assert_float_equal(ab.ssim, ba.ssim, 1e-12);
  assert_float_equal(ab.pearson, ba.pearson, 1e-12);
  assert_true(ab.ssim < 0.9);
  assert_float_equal(aa.ssim, 1.0, 1e-12);
  assert_float_equal(aa.pearson, 1.0, 1e-12);
  assert_true(aa.identical);
  assert_true(isinf(aa.psnr) && aa.psnr > 0);
  assert_float_equal(aa.mean_error, 0, 0);
  assert_float_equal(aa.rmse, 0, 0);
}

/* Pearson of a constant image is 0/0 by the formula: defined as 1 when both
 * are constant and equal, else 0 - never NaN. */
static void constant_images_have_a_defined_pearson(void **state) {
  (void)state;
  float k1[] = {0.3f, 0.3f, 0.3f, 0.3f, 0.3f, 0.3f}, k2[] = {0.7f, 0.7f, 0.7f, 0.7f, 0.7f, 0.7f};
  float v[] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  lm_image c1 = img(2, 1, 3, k1), c2 = img(2, 1, 3, k2), var = img(2, 1, 3, v);
  lm_metrics m;
  lm_metrics_compute(&c1, &c1, &m);
  assert_float_equal(m.pearson, 1.0, 0);
  lm_metrics_compute(&c1, &c2, &m);
  assert_float_equal(m.pearson, 0.0, 0);
  assert_float_equal(m.mean_error, 0.4, 1e-6);
  lm_metrics_compute(&c1, &var, &m);
  assert_float_equal(m.pearson, 0.0, 0);
  lm_metrics_compute(&var, &c2, &m);
  assert_float_equal(m.pearson, 0.0, 0);
  assert_false(isnan(m.ssim));
  /* a linear map of an image correlates perfectly; a negated one at -1 */
  float lin[6], neg[6];
  for (int i = 0; i < 6; i++) lin[i] = 2 * v[i] + 0.1f, neg[i] = 1 - v[i];
  lm_image l = img(2, 1, 3, lin), n = img(2, 1, 3, neg);
  lm_metrics_compute(&var, &l, &m);
  assert_float_equal(m.pearson, 1.0, 1e-6);
  lm_metrics_compute(&var, &n, &m);
  assert_float_equal(m.pearson, -1.0, 1e-6);
}

/* Alpha is left out: two RGBA images that differ only in alpha are identical. */
static void alpha_is_not_compared(void **state) {
  (void)state;
  float pa[] = {0.1f, 0.2f, 0.3f, 1.0f}, pb[] = {0.1f, 0.2f, 0.3f, 0.0f};
  lm_image a = img(1, 1, 4, pa), b = img(1, 1, 4, pb);
  lm_metrics m;
  lm_metrics_compute(&a, &b, &m);
  assert_int_equal(m.channels, 3);
  assert_true(m.identical);
}

/* Pixel 0: A off by 0.1, B by 0.3 (A closer); pixel 1: both off by 0.2
 * (tie); pixel 2: A off by 0.5, B exact (B closer); pixel 3: A exact. */
static void closer_share_by_hand(void **state) {
  (void)state;
  float pr[] = {0.5f, 0.5f, 0.5f, 0.5f}, pa[] = {0.6f, 0.7f, 0.0f, 0.5f}, pb[] = {0.2f, 0.3f, 0.5f, 0.9f};
  lm_image r = img(4, 1, 1, pr), a = img(4, 1, 1, pa), b = img(4, 1, 1, pb);
  lm_metrics m;
  lm_metrics_compute(&a, &b, &m);
  lm_metrics_closer(&a, &b, &r, &m);
  assert_float_equal(m.closer, 0.5, 1e-12);
  assert_float_equal(m.ties, 0.25, 1e-12);
}

static void mismatched_images_are_refused_by_name(void **state) {
  (void)state;
  float p[12] = {0};
  lm_image a = img(2, 2, 3, p), b = img(2, 1, 3, p), c = img(2, 2, 1, p), e = img(0, 0, 3, NULL);
  lm_error err;
  assert_true(lm_metrics_check(&a, "a.exr", &a, "b.exr", &err));
  assert_false(lm_metrics_check(&a, "a.exr", &b, "b.png", &err));
  assert_string_equal(err.msg, "sizes differ: a.exr is 2x2, b.png is 2x1");
  assert_false(lm_metrics_check(&a, "a.exr", &c, "c.png", &err));
  assert_string_equal(err.msg, "channel counts differ: a.exr has 3, c.png has 1");
  assert_false(lm_metrics_check(&a, "a.exr", &e, "e.exr", &err));
  assert_string_equal(err.msg, "e.exr: empty image");
  float bad[12] = {0};
  bad[3 * 3 + 1] = NAN; /* pixel (1, 1), green */
  lm_image n = img(2, 2, 3, bad);
  assert_false(lm_metrics_check(&a, "a.exr", &n, "n.exr", &err));
  assert_string_equal(err.msg, "n.exr: pixel (1, 1) channel 1 is not finite (NaN or Inf)");
  bad[3 * 3 + 1] = 0;
  bad[3] = INFINITY;
  assert_false(lm_metrics_check(&n, "n.exr", &a, "a.exr", &err));
  assert_string_equal(err.msg, "n.exr: pixel (1, 0) channel 0 is not finite (NaN or Inf)");
  bad[3] = 0;
  assert_true(lm_metrics_check(&n, "n.exr", &a, "a.exr", &err));
}

/* The heat map's ramp: 0 black, half the scale red, the scale and beyond white. */
static void heatmap_ramp(void **state) {
  (void)state;
  float pa[] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, pb[] = {0, 0, 0, 0.5f, 0.5f, 0.5f, 2, 2, 2};
  lm_image a = img(3, 1, 3, pa), b = img(3, 1, 3, pb);
  unsigned char rgb[9];
  lm_metrics_heatmap(&a, &b, 1.0, rgb);
  static const unsigned char want[9] = {0, 0, 0, 255, 0, 0, 255, 255, 255};
  assert_memory_equal(rgb, want, 9);
  assert_float_equal(lm_metrics_max_pixel_error(&a, &b), 2.0, 1e-12);
}

/* A still sequence, Limn's frames identical and the reference's too (but
 * not Limn's): no pair changes, so flicker is exactly 0 however far apart
 * Limn and the reference are. */
static void flicker_of_a_still_sequence_is_zero(void **state) {
  (void)state;
  float pl[] = {0.1f, 0.2f, 0.3f, 0.9f, 0.8f, 0.7f}, pr[] = {0.5f, 0.5f, 0.5f, 0.0f, 1.0f, 0.25f};
  float frames[4][2][6]; /* four frames, each its own copy of Limn's and the reference's */
  lm_image l[4], r[4];
  for (int t = 0; t < 4; t++) {
    memcpy(frames[t][0], pl, sizeof pl);
    memcpy(frames[t][1], pr, sizeof pr);
    l[t] = img(2, 1, 3, frames[t][0]), r[t] = img(2, 1, 3, frames[t][1]);
  }
  lm_metrics m;
  lm_metrics_compute(&l[3], &r[3], &m);
  assert_true(m.mean_error > 0.2);
  for (int t = 1; t < 4; t++) assert_float_equal(lm_metrics_flicker(&l[t - 1], &l[t], &r[t - 1], &r[t]), 0.0, 0);
}

/* Limn's red alternates between 0.25 and 0.75 every frame, green and blue
 * hold: each pair changes one of 3 values by 0.5, so against a still
 * reference the flicker is 0.5 / 3; against a reference alternating the
 * other way (change -0.5 where Limn's is +0.5) it is 1 / 3. */
static void flicker_of_an_alternating_pattern_by_hand(void **state) {
  (void)state;
  float lo[] = {0.25f, 0.5f, 0.5f, 0.25f, 0.5f, 0.5f}, hi[] = {0.75f, 0.5f, 0.5f, 0.75f, 0.5f, 0.5f};
  float still[] = {0.3f, 0.3f, 0.3f, 0.6f, 0.6f, 0.6f};
  lm_image l[2] = {img(2, 1, 3, lo), img(2, 1, 3, hi)}, r = img(2, 1, 3, still);
  double still_ref = 0, opposite_ref = 0;
  for (int t = 1; t < 5; t++) {
    still_ref += lm_metrics_flicker(&l[(t - 1) % 2], &l[t % 2], &r, &r);
    opposite_ref += lm_metrics_flicker(&l[(t - 1) % 2], &l[t % 2], &l[t % 2], &l[(t - 1) % 2]);
  }
  assert_float_equal(still_ref / 4, 0.5 / 3, 1e-12);
  assert_float_equal(opposite_ref / 4, 1.0 / 3, 1e-12);
  /* In phase with the reference it is 0 again. */
  assert_float_equal(lm_metrics_flicker(&l[0], &l[1], &l[0], &l[1]), 0.0, 0);
}

/* Limn's frames are the reference's plus a constant 0.25 (values exact in
 * float): its change equals the reference's, so flicker is 0 while the
 * mean error is the bias. */
static void flicker_ignores_a_constant_bias(void **state) {
  (void)state;
  float r0[] = {0.125f, 0.5f, 0.0f}, r1[] = {0.625f, 0.25f, 0.375f}, l0[3], l1[3];
  for (int i = 0; i < 3; i++) l0[i] = r0[i] + 0.25f, l1[i] = r1[i] + 0.25f;
  lm_image a0 = img(1, 1, 3, l0), a1 = img(1, 1, 3, l1), b0 = img(1, 1, 3, r0), b1 = img(1, 1, 3, r1);
  assert_float_equal(lm_metrics_flicker(&a0, &a1, &b0, &b1), 0.0, 0);
  lm_metrics m;
  lm_metrics_compute(&a1, &b1, &m);
  assert_float_equal(m.mean_error, 0.25, 0);
  /* Without the bias in the second frame the change differs by 0.25 in each channel. */
  assert_float_equal(lm_metrics_flicker(&a0, &b1, &b0, &b1), 0.25, 1e-12);
}

/* A step at the event (frame 5) from 0.1 to 0.5, then back halving the
 * excess each frame: error(5 + d) = 0.1 + 0.4 / 2^d. Settled is the median
 * of frames 15 .. 19, 0.1 + 0.4 / 2^12; 10% of it is 0.0100098, so d = 5
 * (excess 0.0125 - 0.0001) is still off and d = 6 (0.00625 - 0.0001) is
 * back: the lag is 6 frames. */
static void lag_of_an_exponential_return_by_hand(void **state) {
  (void)state;
  double e[20];
  for (int t = 0; t < 20; t++) e[t] = t < 5 ? 0.1 : 0.1 + 0.4 / pow(2, t - 5);
  lm_lag lag;
  lm_error err;
  assert_true(lm_metrics_lag(e, 5, 20, -1, &lag, &err));
  assert_int_equal(lag.frames, 6);
  assert_true(lag.returned);
  assert_float_equal(lag.settled, 0.1 + 0.4 / 4096, 1e-15);
  /* A window cut at the next event (frame 12) while the error still falls:
   * settled is the median of frames 7 .. 11, 0.1 + 0.4 / 2^4 = 0.125, and
   * the last frame, 0.10625, is 0.01875 below it, past the tolerance
   * 0.0125: never settled, the lag is the window's 7 frames. */
  assert_true(lm_metrics_lag(e, 5, 12, -1, &lag, &err));
  assert_false(lag.returned);
  assert_int_equal(lag.frames, 7);
  assert_float_equal(lag.settled, 0.125, 1e-15);
  /* The same cut window against the converged value 0.1 (a still frame
   * rendered until it settled): the error falls within 0.01 of it only at
   * frame 11 (0.1 + 0.4 / 2^6 = 0.10625 is 0.00625 off; frame 10's
   * 0.1125 is 0.0125 off): the tail alone hid a lag of 6 frames. */
  assert_true(lm_metrics_lag(e, 5, 12, 0.1, &lag, &err));
  assert_true(lag.returned);
  assert_int_equal(lag.frames, 6);
  assert_float_equal(lag.settled, 0.1, 0);
  /* A settled error that is not finite is refused. */
  assert_false(lm_metrics_lag(e, 5, 12, NAN, &lag, &err));
  assert_non_null(strstr(err.msg, "settled"));
  /* No change at all: lag 0. */
  assert_true(lm_metrics_lag(e, 0, 5, -1, &lag, &err));
  assert_int_equal(lag.frames, 0);
  assert_true(lag.returned);
}

/* An error swinging through its settled value counts from where it stays;
 * one whose last frame is off never returned, and the lag is the window. */
static void lag_that_swings_or_never_settles(void **state) {
  (void)state;
  /* last 5: 0.2 0.2 0.3 0.2 0.2, median 0.2; frame 1 passes 0.2 on the way */
  double swing[] = {0.5, 0.2, 0.05, 0.2, 0.2, 0.3, 0.2, 0.2};
  lm_lag lag;
  lm_error err;
  assert_true(lm_metrics_lag(swing, 0, 8, -1, &lag, &err));
  assert_int_equal(lag.frames, 6); /* frame 5 (0.3) is off */
  assert_true(lag.returned);
  /* last 5: 0.2 0.1 0.2 0.2 0.1, median 0.2, the last frame 0.1 is off */
  double noisy[] = {0.9, 0.5, 0.2, 0.1, 0.2, 0.2, 0.1};
  assert_true(lm_metrics_lag(noisy, 1, 7, -1, &lag, &err));
  assert_false(lag.returned);
  assert_int_equal(lag.frames, 6);
  assert_float_equal(lag.settled, 0.2, 0);
  /* a settled error of 0 tolerates nothing, and never divides */
  double zero[] = {0.3, 0, 0, 0, 0, 0};
  assert_true(lm_metrics_lag(zero, 0, 6, -1, &lag, &err));
  assert_int_equal(lag.frames, 1);
  assert_float_equal(lag.settled, 0, 0);
  /* Bad input is refused by name. */
  assert_false(lm_metrics_lag(zero, 6, 6, -1, &lag, &err));
  assert_string_equal(err.msg, "event at frame 6: not among the sequence's frames 0 .. 5");
  assert_false(lm_metrics_lag(zero, -1, 6, -1, &lag, &err));
  zero[3] = NAN;
  assert_false(lm_metrics_lag(zero, 0, 6, -1, &lag, &err));
  assert_string_equal(err.msg, "frame 3: error nan is not a finite value >= 0");
  zero[3] = -0.5;
  assert_false(lm_metrics_lag(zero, 2, 6, -1, &lag, &err));
  assert_string_equal(err.msg, "frame 3: error -0.5 is not a finite value >= 0");
  assert_true(lm_metrics_lag(zero, 4, 6, -1, &lag, &err)); /* frame 3 is outside that window */
}

/* Band error: pixels 0 and 2 of 4 are in the band, off by 0.3 in every
 * channel and by 0.6 in one of three; pixels outside (off by 1) do not count. */
static void band_error_by_hand(void **state) {
  (void)state;
  float pa[12] = {0}, pb[12] = {0.3f, 0.3f, 0.3f, 1, 1, 1, 0.6f, 0, 0, 1, 1, 1};
  lm_image a = img(4, 1, 3, pa), b = img(4, 1, 3, pb);
  unsigned char band[] = {1, 0, 255, 0}, none[4] = {0};
  double e = -1;
  size_t px = 0;
  assert_true(lm_metrics_band_error(&a, &b, band, &e, &px));
  assert_int_equal(px, 2);
  assert_float_equal(e, (0.9 + 0.6) / 6, 1e-7);
  e = -1;
  assert_false(lm_metrics_band_error(&a, &b, none, &e, &px)); /* empty: no mean, no 0/0 */
  assert_int_equal(px, 0);
  assert_float_equal(e, -1, 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(two_pixels_by_hand),
      cmocka_unit_test(ssim_of_one_pixel_by_hand),
      cmocka_unit_test(ssim_is_symmetric_and_one_for_identical),
      cmocka_unit_test(constant_images_have_a_defined_pearson),
      cmocka_unit_test(alpha_is_not_compared),
      cmocka_unit_test(closer_share_by_hand),
      cmocka_unit_test(mismatched_images_are_refused_by_name),
      cmocka_unit_test(heatmap_ramp),
      cmocka_unit_test(flicker_of_a_still_sequence_is_zero),
      cmocka_unit_test(flicker_of_an_alternating_pattern_by_hand),
      cmocka_unit_test(flicker_ignores_a_constant_bias),
      cmocka_unit_test(lag_of_an_exponential_return_by_hand),
      cmocka_unit_test(lag_that_swings_or_never_settles),
      cmocka_unit_test(band_error_by_hand),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
