/* image: reading and writing image files behind a C interface. PNG and
 * JPEG go through libpng and libjpeg; EXR, HDR, TIFF and whatever else
 * OpenImageIO knows through a module of its own (image_oiio.cpp), opened
 * on the first such file (image.c says why). */
#ifndef LIMN_IMAGE_H
#define LIMN_IMAGE_H

#include "core/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lm_image {
  int width, height, channels;
  float *pixels; /* rows top first, channels interleaved, values as stored */
} lm_image;

/* Writes `pixels` (uint8 when !floats, else float32) to `path`; the format
 * follows the extension (floats to a PNG are clamped and rounded to 8 bits).
 * The file appears whole or not at all: it is written under a temporary name
 * in the same directory and renamed. */
bool lm_image_write(const char *path, int width, int height, int channels, bool floats,
                    const void *pixels, lm_error *err);
/* Reads an image file into float pixels, channels as stored (a palette
 * expanded to RGB, or RGBA with its transparency), alpha not premultiplied:
 * 8-bit values / 255, 16-bit / 65535, float formats as they are. */
bool lm_image_read(const char *path, lm_image *img, lm_error *err);
/* Decodes a PNG or JPEG held in memory (a glTF texture) to 8-bit RGBA as
 * stored (a PNG's sRGB values stay sRGB, 16 bits are rounded to 8): grey
 * spreads to RGB, a missing alpha is 255. *rgba is malloc'd. `name` is what
 * messages call it. Safe to call from several threads at once. */
bool lm_image_decode_rgba8(const void *data, size_t size, const char *name, int *width, int *height,
                           unsigned char **rgba, lm_error *err);
void lm_image_free(lm_image *img);

/* The OpenImageIO module's entry points, found with dlsym: lm_image_read
 * and lm_image_write for the formats libpng and libjpeg do not cover.
 * lm_image_oiio_write writes `file` (lm_image_write's temporary name) in the
 * format of its extension; messages name `path`. */
typedef bool lm_image_read_fn(const char *path, lm_image *img, lm_error *err);
typedef bool lm_image_write_fn(const char *file, const char *path, int width, int height, int channels,
                               bool floats, const void *pixels, lm_error *err);
lm_image_read_fn lm_image_oiio_read;
lm_image_write_fn lm_image_oiio_write;

#ifdef __cplusplus
}
#endif
#endif
