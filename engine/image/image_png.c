/* image without OpenImageIO (LIMN_IMAGE_IO=OFF): image files are refused by
 * name, and PNG textures embedded in glTF files decode through libpng, so a
 * benchmark runs on a machine that lacks OpenImageIO's libraries. */
#include "image/image.h"

#include <png.h>
#include <stdlib.h>
#include <string.h>

static bool refuse(const char *path, lm_error *err) {
  lm_error_set(err, "%s: this build reads PNG textures only (built with LIMN_IMAGE_IO=OFF)", path);
  return false;
}

bool lm_image_write(const char *path, int width, int height, int channels, bool floats, const void *pixels,
                    lm_error *err) {
  (void)width, (void)height, (void)channels, (void)floats, (void)pixels;
  return refuse(path, err);
}

bool lm_image_read(const char *path, lm_image *img, lm_error *err) {
  memset(img, 0, sizeof *img);
  return refuse(path, err);
}

bool lm_image_decode_rgba8(const void *data, size_t size, const char *name, int *width, int *height,
                           unsigned char **rgba, lm_error *err) {
  *width = *height = 0;
  *rgba = NULL;
  png_image png = {.version = PNG_IMAGE_VERSION};
  if (!png_image_begin_read_from_memory(&png, data, size)) return refuse(name, err);
  png.format = PNG_FORMAT_RGBA;
  unsigned char *px = lm_alloc(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, NULL, px, 0, NULL)) {
    lm_error_set(err, "%s: %s", name, png.message);
    free(px);
    return false;
  }
  *width = (int)png.width;
  *height = (int)png.height;
  *rgba = px;
  return true;
}

bool lm_image_read_memory(const void *data, size_t size, const char *name, lm_image *img, lm_error *err) {
  memset(img, 0, sizeof *img);
  unsigned char *rgba;
  int w, h;
  if (!lm_image_decode_rgba8(data, size, name, &w, &h, &rgba, err)) return false;
  size_t n = (size_t)w * (size_t)h * 4;
  img->pixels = lm_alloc(n * sizeof(float));
  for (size_t i = 0; i < n; i++) img->pixels[i] = rgba[i] / 255.0f;
  img->width = w, img->height = h, img->channels = 4;
  free(rgba);
  return true;
}

void lm_image_free(lm_image *img) {
  free(img->pixels);
  memset(img, 0, sizeof *img);
}
