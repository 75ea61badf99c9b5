/* limn compare: how far apart two images are (engine/image/metrics.h). */
#define _GNU_SOURCE
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "image/metrics.h"
#include "tools.h"

static const char compare_usage[] =
    "usage: limn compare A B [--ref R] [--mask M] [--json] [--diff FILE [--diff-scale X]]\n"
    "\n"
    "Compares images A and B (PNG, EXR or anything OpenImageIO reads) value by\n"
    "value over their colour channels (alpha left out), as stored: linear for\n"
    "EXR, sRGB-encoded for PNG. Both must have the same size and channel count.\n"
    "\n"
    "  mean error  sum of |dR| + |dG| + |dB| over 3wh (seed 000 eq 19)\n"
    "  max error   the largest |d| of any value\n"
    "  RMSE        root of the mean squared difference\n"
    "  PSNR        10 log10(1 / MSE) dB, peak 1; inf (JSON null) when identical\n"
    "  Pearson     eq 20, population statistics over every value; 1 when both\n"
    "              images are constant and equal, 0 when either is constant else\n"
    "  SSIM        per channel, Gaussian window 11x11 sigma 1.5 (cut at borders),\n"
    "              C1 = 0.01^2, C2 = 0.03^2 (L = 1), mean over pixels and channels\n"
    "\n"
    "options:\n"
    "  --ref R           reference: the share of pixels where A is closer to R than\n"
    "                    B is (sum over channels of absolute differences), and ties\n"
    "  --mask M          also the mean error over the pixels whose first channel\n"
    "                    in image M (the same size) exceeds 0.5, and their count\n"
    "                    (say, a material's pixels: scripts/examples/mask.lua)\n"
    "  --json            one JSON object on stdout instead of the table\n"
    "  --diff FILE       difference image: .png is a heat map of the per-pixel mean\n"
    "                    |A - B| (black, blue, red, yellow, white); .exr holds |A - B|\n"
    "                    per channel (eq 18) as float\n"
    "  --diff-scale X    the error the heat map shows as white (default: the largest\n"
    "                    per-pixel error of the pair)\n"
    "  --help            this text\n"
    "\n"
    "exit codes: 0 compared, 1 the difference image could not be written,\n"
    "2 bad usage, an unreadable file, images that differ in size or channels, or a\n"
    "NaN or Inf among the values (named by pixel and channel), a mask of another\n"
    "size or with no pixel in it.\n";

typedef struct compare_args {
  const char *a, *b, *ref, *diff, *mask;
  double diff_scale;
  double masked_error; /* over the mask's pixels, with mask */
  size_t masked_pixels;
  bool json;
} compare_args;

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("compare", fmt, arg); }

static bool has_extension(const char *path, const char *ext) {
  const char *dot = strrchr(path, '.');
  return dot && !strchr(dot, '/') && !strcasecmp(dot, ext);
}

static int parse_args(int argc, char **argv, compare_args *a) {
  *a = (compare_args){.diff_scale = -1};
  static const struct option opts[] = {{"ref", required_argument, 0, 'r'},   {"json", no_argument, 0, 'j'},
                                       {"mask", required_argument, 0, 'm'},
                                       {"diff", required_argument, 0, 'd'},  {"diff-scale", required_argument, 0, 's'},
                                       {"help", no_argument, 0, 'h'},        {0, 0, 0, 0}};
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    switch (c) {
    case 'r': a->ref = optarg; break;
    case 'j': a->json = true; break;
    case 'm': a->mask = optarg; break;
    case 'd':
      if (!has_extension(optarg, ".png") && !has_extension(optarg, ".exr"))
        return usage_error("--diff '%s': use a .png (heat map) or .exr (|A - B|) file", optarg);
      a->diff = optarg;
      break;
    case 's':
      if (!limn_parse_double(optarg, &a->diff_scale) || a->diff_scale <= 0)
        return usage_error("--diff-scale wants a number > 0, not '%s'", optarg);
      break;
    case 'h': fputs(compare_usage, stdout); return -1;
    case ':': return usage_error("%s needs a value", argv[optind - 1]);
    default: return usage_error("unknown flag '%s'", argv[optind - 1]);
    }
  }
  if (argc - optind != 2) return usage_error("%s", "wants two images, A and B");
  a->a = argv[optind];
  a->b = argv[optind + 1];
  return 0;
}

static void print_json(const compare_args *a, const lm_metrics *m, double scale) {
  printf("{\"a\": ");
  limn_json_string(a->a);
  printf(", \"b\": ");
  limn_json_string(a->b);
  printf(", \"ref\": ");
  if (a->ref) limn_json_string(a->ref);
  else printf("null");
  printf(", \"width\": %d, \"height\": %d, \"channels\": %d", m->width, m->height, m->channels);
  printf(", \"mean_error\": %.9g, \"max_error\": %.9g, \"rmse\": %.9g", m->mean_error, m->max_error, m->rmse);
  if (m->identical) printf(", \"psnr\": null, \"identical\": true");
  else printf(", \"psnr\": %.9g, \"identical\": false", m->psnr);
  printf(", \"pearson\": %.9g, \"ssim\": %.9g", m->pearson, m->ssim);
  if (a->mask) printf(", \"masked_error\": %.9g, \"masked_pixels\": %zu", a->masked_error, a->masked_pixels);
  if (a->ref) printf(", \"closer\": %.9g, \"ties\": %.9g", m->closer, m->ties);
  else printf(", \"closer\": null, \"ties\": null");
  if (a->diff) {
    printf(", \"diff\": ");
    limn_json_string(a->diff);
    printf(", \"diff_scale\": %.9g", scale);
  }
  printf("}\n");
}

static void print_table(const compare_args *a, const lm_metrics *m, double scale) {
  printf("A: %s\nB: %s\n", a->a, a->b);
  printf("size: %dx%d, %d channel%s compared\n", m->width, m->height, m->channels, m->channels == 1 ? "" : "s");
  printf("  mean error (eq 19)  %.6f\n", m->mean_error);
  printf("  max error           %.6f\n", m->max_error);
  printf("  RMSE                %.6f\n", m->rmse);
  if (m->identical) printf("  PSNR                inf (identical)\n");
  else printf("  PSNR                %.3f dB\n", m->psnr);
  printf("  Pearson (eq 20)     %.6f\n", m->pearson);
  printf("  SSIM                %.6f\n", m->ssim);
  if (a->mask) printf("  masked mean error   %.6f over %zu pixels of %s\n", a->masked_error, a->masked_pixels, a->mask);
  if (a->ref)
    printf("  closer to %s: A on %.2f%% of pixels, B on %.2f%%, ties %.2f%%\n", a->ref, 100 * m->closer,
           100 * (1 - m->closer - m->ties), 100 * m->ties);
  if (a->diff) printf("wrote %s (heat map white at %.6g)\n", a->diff, scale);
}

static bool write_diff(const compare_args *a, const lm_image *ia, const lm_image *ib, double scale, lm_error *err) {
  size_t px = (size_t)ia->width * ia->height;
  if (has_extension(a->diff, ".png")) {
    unsigned char *rgb = lm_alloc(px * 3);
    lm_metrics_heatmap(ia, ib, scale, rgb);
    bool ok = lm_image_write(a->diff, ia->width, ia->height, 3, false, rgb, err);
    free(rgb);
    return ok;
  }
  int nc = ia->channels < 3 ? ia->channels : 3;
  float *d = lm_alloc(px * (size_t)nc * sizeof(float));
  for (size_t i = 0; i < px; i++)
    for (int k = 0; k < nc; k++)
      d[i * nc + k] = fabsf(ia->pixels[i * ia->channels + k] - ib->pixels[i * ib->channels + k]);
  bool ok = lm_image_write(a->diff, ia->width, ia->height, nc, true, d, err);
  free(d);
  return ok;
}

/* The mean error of A against B over the pixels whose first channel in the
 * mask image exceeds 0.5 (lm_metrics_band_error). */
static bool masked_error(compare_args *a, const lm_image *ia, const lm_image *ib, lm_error *err) {
  lm_image im = {0};
  if (!lm_image_read(a->mask, &im, err)) return false;
  bool ok = im.width == ia->width && im.height == ia->height;
  if (!ok) lm_error_set(err, "%s is %dx%d, %s %dx%d: a mask must be the images' size", a->mask, im.width,
                        im.height, a->a, ia->width, ia->height);
  size_t px = (size_t)ia->width * ia->height;
  unsigned char *band = lm_alloc(px + 1);
  for (size_t i = 0; ok && i < px; i++) band[i] = im.pixels[i * im.channels] > 0.5f;
  if (ok && !lm_metrics_band_error(ia, ib, band, &a->masked_error, &a->masked_pixels))
    ok = false, lm_error_set(err, "%s: no pixel of the mask exceeds 0.5", a->mask);
  free(band);
  lm_image_free(&im);
  return ok;
}

int limn_compare(int argc, char **argv) {
  compare_args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc < 0 ? 0 : rc;
  lm_image ia = {0}, ib = {0}, ir = {0};
  lm_error err;
  rc = 0;
  if (!lm_image_read(a.a, &ia, &err) || !lm_image_read(a.b, &ib, &err) ||
      (a.ref && !lm_image_read(a.ref, &ir, &err)) || !lm_metrics_check(&ia, a.a, &ib, a.b, &err) ||
      (a.ref && !lm_metrics_check(&ia, a.a, &ir, a.ref, &err)))
    rc = 2;
  lm_metrics m;
  double scale = 0;
  if (!rc) {
    lm_metrics_compute(&ia, &ib, &m);
    if (a.ref) lm_metrics_closer(&ia, &ib, &ir, &m);
    if (a.mask && !masked_error(&a, &ia, &ib, &err)) rc = 2;
    if (!rc && a.diff) {
      scale = a.diff_scale > 0 ? a.diff_scale : lm_metrics_max_pixel_error(&ia, &ib);
      if (!(scale > 0) || !isfinite(scale)) scale = 1; /* identical images: any scale shows black */
      if (!write_diff(&a, &ia, &ib, scale, &err)) rc = 1;
    }
  }
  if (!rc) {
    if (a.json) print_json(&a, &m, scale);
    else print_table(&a, &m, scale);
  } else {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
  }
  lm_image_free(&ia);
  lm_image_free(&ib);
  lm_image_free(&ir);
  return rc;
}
