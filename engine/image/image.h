/* image: reading and writing image files (PNG, EXR and whatever else
 * OpenImageIO knows) behind a C interface. */
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
 * follows the extension. The file appears whole or not at all: it is written
 * under a temporary name in the same directory and renamed. */
bool lm_image_write(const char *path, int width, int height, int channels, bool floats,
                    const void *pixels, lm_error *err);
/* Reads any file OpenImageIO knows into float pixels (8-bit values / 255). */
bool lm_image_read(const char *path, lm_image *img, lm_error *err);
/* Decodes an encoded file held in memory (PNG, JPEG, ... as OpenImageIO
 * reads from memory). `name` is what messages call it. */
bool lm_image_read_memory(const void *data, size_t size, const char *name, lm_image *img, lm_error *err);
/* Decodes to 8-bit RGBA as stored (a PNG's sRGB values stay sRGB): grey
 * spreads to RGB, a missing alpha is 255. *rgba is malloc'd. */
bool lm_image_decode_rgba8(const void *data, size_t size, const char *name, int *width, int *height,
                           unsigned char **rgba, lm_error *err);
void lm_image_free(lm_image *img);

#ifdef __cplusplus
}
#endif
#endif
