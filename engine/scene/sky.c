#include "scene/sky.h"

#include <cglm/cglm.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"

void lm_sky_radiance(const lm_sky *sky, const float d[3], float out[3]) {
  float t = d[1] > 0.0f ? fminf(d[1], 1.0f) : 0.0f;
  for (int c = 0; c < 3; c++) out[c] = sky->intensity * (sky->horizon[c] + (sky->zenith[c] - sky->horizon[c]) * t);
}

/* The 9 real basis functions at unit direction d. */
static void sh_basis(const double d[3], double y[9]) {
  double x = d[0], yy = d[1], z = d[2];
  y[0] = 0.282094792;
  y[1] = 0.488602512 * yy;
  y[2] = 0.488602512 * z;
  y[3] = 0.488602512 * x;
  y[4] = 1.092548431 * x * yy;
  y[5] = 1.092548431 * yy * z;
  y[6] = 0.315391565 * (3.0 * z * z - 1.0);
  y[7] = 1.092548431 * x * z;
  y[8] = 0.546274215 * (x * x - yy * yy);
}

/* Projects radiance given on a w x h equirectangular grid (rows from the
 * zenith, see lm_sky_sh_map) with `channels` floats a texel, then convolves
 * with the clamped cosine and divides by pi. */
static void project(const float *texels, int w, int h, int channels, float scale, float out[LM_SKY_SH]) {
  static const double band[9] = {1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25};
  double sum[3][9] = {{0}};
  for (int r = 0; r < h; r++) {
    double theta = GLM_PI * (r + 0.5) / h, st = sin(theta);
    double dw = (2.0 * GLM_PI / w) * (GLM_PI / h) * st;
    for (int c = 0; c < w; c++) {
      double phi = 2.0 * GLM_PI * ((c + 0.5) / w - 0.5);
      double d[3] = {st * sin(phi), cos(theta), -st * cos(phi)}, y[9];
      sh_basis(d, y);
      const float *t = texels + ((size_t)r * (size_t)w + (size_t)c) * (size_t)channels;
      for (int k = 0; k < 3; k++) {
        double L = t[channels >= 3 ? k : 0] * dw;
        for (int i = 0; i < 9; i++) sum[k][i] += L * y[i];
      }
    }
  }
  for (int k = 0; k < 3; k++)
    for (int i = 0; i < 9; i++) out[k * 9 + i] = (float)(scale * band[i] * sum[k][i]);
}

void lm_sky_sh_gradient(const lm_sky *sky, float out[LM_SKY_SH]) {
  enum { W = 64, H = 256 }; /* the gradient varies with elevation only: rows matter */
  float *texels = malloc(sizeof *texels * W * H * 3);
  for (int r = 0; r < H; r++) {
    double theta = GLM_PI * (r + 0.5) / H;
    float d[3] = {0.0f, (float)cos(theta), 0.0f}, L[3];
    lm_sky_radiance(sky, d, L);
    for (int c = 0; c < W; c++) memcpy(texels + ((size_t)r * W + (size_t)c) * 3, L, sizeof L);
  }
  project(texels, W, H, 3, 1.0f, out);
  free(texels);
}

bool lm_sky_sh_map(const char *path, float intensity, float out[LM_SKY_SH], lm_error *err) {
  lm_image img;
  if (!lm_image_read(path, &img, err)) return false;
  size_t n = (size_t)img.width * (size_t)img.height * (size_t)img.channels;
  for (size_t i = 0; i < n; i++)
    if (!(img.pixels[i] >= 0.0f && img.pixels[i] < INFINITY)) {
      lm_error_set(err, "sky map %s: texel %zu holds %g (radiance must be finite and not negative)", path,
                   i / (size_t)img.channels, (double)img.pixels[i]);
      lm_image_free(&img);
      return false;
    }
  project(img.pixels, img.width, img.height, img.channels, intensity, out);
  lm_image_free(&img);
  return true;
}
