/* image: PNG and JPEG through libpng and libjpeg, every other format
 * through the OpenImageIO module (image_oiio.cpp), opened on first use.
 *
 * OpenImageIO could read and write PNG and JPEG too, but its libraries (and
 * what they load: OpenVDB, GDAL, ...) add about 110 MiB to the resident
 * memory of every process that maps them, as much as a 100 MB scene needs
 * besides. glTF textures are PNG or JPEG and captures mostly PNG, so those
 * go through the two small libraries directly and OpenImageIO stays out of
 * the process until an EXR, HDR, TIFF... file is read or written. */
#define _XOPEN_SOURCE 700 /* readlink */
#include "image/image.h"

#include <dlfcn.h>
#include <errno.h>
#include <jerror.h>
#include <png.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include <jpeglib.h> /* after stdio.h, which it needs */

/* A decoded image: 8- or 16-bit (native byte order) samples as stored. */
typedef struct decoded {
  int width, height, channels, depth;
  unsigned char *pixels;
} decoded;

/* Textures larger than this are refused (a GL implementation's limit). */
enum { TEXTURE_MAX = 16384 };

static const unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', 13, 10, 26, 10};

static bool is_png(const unsigned char *b, size_t size) { return size >= 8 && !memcmp(b, png_signature, 8); }
static bool is_jpeg(const unsigned char *b, size_t size) {
  return size >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff;
}

static bool check_size(const char *name, int width, int height, int limit, lm_error *err) {
  if (width >= 1 && height >= 1 && width <= limit && height <= limit) return true;
  lm_error_set(err, "%s: size %dx%d is outside 1x1 .. %dx%d", name, width, height, limit, limit);
  return false;
}

/* ---- PNG (libpng) ------------------------------------------------------ */

typedef struct png_source {
  const unsigned char *data;
  size_t size, at;
  const char *name;
  lm_error *err;
} png_source;

static void png_on_error(png_structp png, png_const_charp msg) {
  png_source *src = png_get_error_ptr(png);
  lm_error_set(src->err, "%s: PNG: %s", src->name, msg);
  png_longjmp(png, 1);
}

/* Warnings (an sRGB profile's quibbles, a damaged ancillary chunk) are not the user's to fix. */
static void png_on_warning(png_structp png, png_const_charp msg) { (void)png, (void)msg; }

static void png_on_read(png_structp png, png_bytep out, size_t n) {
  png_source *src = png_get_io_ptr(png);
  if (n > src->size - src->at) {
    lm_error_set(src->err, "%s: PNG cut short (%zu bytes)", src->name, src->size);
    png_longjmp(png, 1);
  }
  memcpy(out, src->data + src->at, n);
  src->at += n;
}

/* Values as stored, palettes and bit depths under 8 expanded (a tRNS chunk
 * becomes alpha); `rgba8` asks for 8-bit RGBA instead (16-bit rounded, grey
 * spread, a missing alpha 255). No gamma is applied, alpha is not premultiplied. */
static bool png_decode(const unsigned char *data, size_t size, const char *name, bool rgba8, int limit,
                       decoded *out, lm_error *err) {
  png_source src = {data, size, 0, name, err};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, png_on_error, png_on_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!info) {
    png_destroy_read_struct(&png, NULL, NULL);
    lm_error_set(err, "%s: out of memory for libpng", name);
    return false;
  }
  unsigned char *volatile pixels = NULL;
  png_bytep *volatile rows = NULL;
  if (setjmp(png_jmpbuf(png))) { /* png_on_error or png_on_read said why */
    free(pixels);
    free(rows);
    png_destroy_read_struct(&png, &info, NULL);
    return false;
  }
  png_set_read_fn(png, &src, png_on_read);
  png_read_info(png, info);
  int width = (int)png_get_image_width(png, info), height = (int)png_get_image_height(png, info);
  if (!check_size(name, width, height, limit, err)) png_longjmp(png, 1);
  png_set_expand(png); /* palette to RGB, grey under 8 bits to 8, tRNS to alpha */
  if (rgba8) {
    png_set_scale_16(png);
    png_set_gray_to_rgb(png);
    png_set_filler(png, 0xff, PNG_FILLER_AFTER);
  } else {
    const uint16_t one = 1;
    if (*(const unsigned char *)&one) png_set_swap(png); /* PNG's samples are big-endian */
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  int channels = png_get_channels(png, info), depth = png_get_bit_depth(png, info);
  size_t stride = png_get_rowbytes(png, info);
  pixels = lm_alloc(stride * (size_t)height);
  rows = lm_alloc(sizeof(png_bytep) * (size_t)height);
  for (int y = 0; y < height; y++) rows[y] = pixels + stride * (size_t)y;
  png_read_image(png, rows);
  png_read_end(png, NULL);
  free(rows);
  png_destroy_read_struct(&png, &info, NULL);
  *out = (decoded){width, height, channels, depth, pixels};
  return true;
}

/* 8-bit samples, 1 to 4 channels, written to `file`; messages name `path`. */
static bool png_write(const char *file, const char *path, int width, int height, int channels,
                      const unsigned char *pixels, lm_error *err) {
  static const png_uint_32 formats[] = {PNG_FORMAT_GRAY, PNG_FORMAT_GA, PNG_FORMAT_RGB, PNG_FORMAT_RGBA};
  png_image png = {.version = PNG_IMAGE_VERSION, .width = (png_uint_32)width, .height = (png_uint_32)height,
                   .format = formats[channels - 1]};
  FILE *f = fopen(file, "wb");
  if (!f) {
    lm_error_set(err, "%s: cannot write: %s", path, strerror(errno));
    return false;
  }
  bool ok = png_image_write_to_stdio(&png, f, 0, pixels, 0, NULL);
  ok = fclose(f) == 0 && ok;
  if (!ok) lm_error_set(err, "%s: %s", path, png.message[0] ? png.message : "write error");
  png_image_free(&png);
  return ok;
}

/* ---- JPEG (libjpeg) ---------------------------------------------------- */

typedef struct jpeg_failure {
  struct jpeg_error_mgr mgr;
  jmp_buf jump;
  bool cut; /* the data ended before the image did */
} jpeg_failure;

static void jpeg_on_error(j_common_ptr jpeg) { longjmp(((jpeg_failure *)jpeg->err)->jump, 1); }

/* Warnings (extraneous bytes and the like) pass, as other readers let them;
 * libjpeg fills a cut image with grey, which must not pass for the image. */
static void jpeg_on_message(j_common_ptr jpeg, int level) {
  jpeg_failure *f = (jpeg_failure *)jpeg->err;
  if (level < 0 && f->mgr.msg_code == JWRN_JPEG_EOF) f->cut = true;
}

/* Grey or RGB as stored (CMYK refused); `rgba8` asks for RGBA. */
static bool jpeg_decode(const unsigned char *data, size_t size, const char *name, bool rgba8, int limit,
                        decoded *out, lm_error *err) {
  struct jpeg_decompress_struct jpeg;
  jpeg_failure failure;
  jpeg.err = jpeg_std_error(&failure.mgr);
  failure.mgr.error_exit = jpeg_on_error;
  failure.mgr.emit_message = jpeg_on_message;
  failure.cut = false;
  unsigned char *volatile pixels = NULL;
  int failed = setjmp(failure.jump); /* 1: libjpeg's error, 2: ours, already said */
  if (failed) {
    if (failed == 1) {
      char msg[JMSG_LENGTH_MAX];
      failure.mgr.format_message((j_common_ptr)&jpeg, msg);
      lm_error_set(err, "%s: JPEG: %s", name, msg);
    }
    free(pixels);
    jpeg_destroy_decompress(&jpeg);
    return false;
  }
  jpeg_create_decompress(&jpeg);
  jpeg_mem_src(&jpeg, data, (unsigned long)size);
  jpeg_read_header(&jpeg, TRUE);
  if (!check_size(name, (int)jpeg.image_width, (int)jpeg.image_height, limit, err)) longjmp(failure.jump, 2);
  if (jpeg.jpeg_color_space == JCS_CMYK || jpeg.jpeg_color_space == JCS_YCCK) {
    lm_error_set(err, "%s: a CMYK JPEG (save it as RGB)", name);
    longjmp(failure.jump, 2);
  }
  jpeg.out_color_space = rgba8 ? JCS_EXT_RGBA : jpeg.jpeg_color_space == JCS_GRAYSCALE ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(&jpeg);
  size_t stride = (size_t)jpeg.output_width * (size_t)jpeg.output_components;
  pixels = lm_alloc(stride * jpeg.output_height);
  while (jpeg.output_scanline < jpeg.output_height) {
    JSAMPROW row = pixels + stride * jpeg.output_scanline;
    jpeg_read_scanlines(&jpeg, &row, 1);
  }
  if (failure.cut) {
    lm_error_set(err, "%s: JPEG cut short (%zu bytes)", name, size);
    longjmp(failure.jump, 2);
  }
  jpeg_finish_decompress(&jpeg);
  *out = (decoded){(int)jpeg.output_width, (int)jpeg.output_height, jpeg.output_components, 8, pixels};
  jpeg_destroy_decompress(&jpeg);
  return true;
}

static bool decode(const void *data, size_t size, const char *name, bool rgba8, int limit, decoded *out,
                   lm_error *err) {
  if (is_png(data, size)) return png_decode(data, size, name, rgba8, limit, out, err);
  if (is_jpeg(data, size)) return jpeg_decode(data, size, name, rgba8, limit, out, err);
  lm_error_set(err, "%s: neither a PNG nor a JPEG (%zu bytes)", name, size);
  return false;
}

/* ---- the OpenImageIO module -------------------------------------------- */

static struct {
  pthread_once_t once;
  lm_image_read_fn *read;
  lm_image_write_fn *write;
  char why[1024]; /* why it is not there */
} oiio = {.once = PTHREAD_ONCE_INIT};

/* Next to the executable first (a copied build), then where the build put it.
 * It is never closed: OpenImageIO keeps threads and caches until exit, and
 * LeakSanitizer finds what they hold through the module's globals. */
static void oiio_open(void) {
#ifdef LIMN_IMAGE_MODULE
  const char *built = LIMN_IMAGE_MODULE, *file = strrchr(built, '/') ? strrchr(built, '/') + 1 : built;
  char beside[4096];
  ssize_t n = readlink("/proc/self/exe", beside, sizeof beside - 1);
  beside[n > 0 ? n : 0] = '\0';
  char *slash = strrchr(beside, '/');
  if (slash) snprintf(slash + 1, sizeof beside - (size_t)(slash + 1 - beside), "%s", file);
  void *module = slash ? dlopen(beside, RTLD_NOW | RTLD_LOCAL) : NULL;
  if (!module) module = dlopen(built, RTLD_NOW | RTLD_LOCAL);
  if (!module) {
    const char *why = dlerror();
    snprintf(oiio.why, sizeof oiio.why, "the OpenImageIO module (%s) does not load: %s", file, why ? why : "?");
    return;
  }
  oiio.read = (lm_image_read_fn *)dlsym(module, "lm_image_oiio_read");
  oiio.write = (lm_image_write_fn *)dlsym(module, "lm_image_oiio_write");
  if (!oiio.read || !oiio.write) {
    oiio.read = NULL, oiio.write = NULL;
    snprintf(oiio.why, sizeof oiio.why, "%s lacks lm_image_oiio_read or lm_image_oiio_write", file);
  }
#else
  snprintf(oiio.why, sizeof oiio.why, "this build reads PNG and JPEG and writes PNG, no other format "
           "(built with LIMN_IMAGE_IO=OFF, without OpenImageIO)");
#endif
}

static bool oiio_ready(const char *path, lm_error *err) {
  pthread_once(&oiio.once, oiio_open);
  if (oiio.read) return true;
  lm_error_set(err, "%s: %s", path, oiio.why);
  return false;
}

/* ---- the interface ----------------------------------------------------- */

static bool has_extension(const char *path, const char *ext) {
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  return dot && (!slash || dot > slash) && !strcasecmp(dot + 1, ext);
}

/* "dir/name.tmp-PID.ext": the same extension, so that the format is the same. */
static void temp_name(const char *path, char *out, size_t cap) {
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  if (!dot || (slash && dot < slash)) dot = path + strlen(path);
  snprintf(out, cap, "%.*s.tmp-%ld%s", (int)(dot - path), path, (long)getpid(), dot);
}

bool lm_image_write(const char *path, int width, int height, int channels, bool floats, const void *pixels,
                    lm_error *err) {
  bool png = has_extension(path, "png");
  if (png && (channels < 1 || channels > 4)) {
    lm_error_set(err, "%s: a PNG holds 1 to 4 channels, not %d", path, channels);
    return false;
  }
  if (!png && !oiio_ready(path, err)) return false;
  char tmp[4096];
  temp_name(path, tmp, sizeof tmp);
  bool ok;
  if (png) {
    unsigned char *bytes = (unsigned char *)pixels;
    if (floats) { /* rounded and clamped, as image libraries store floats in 8 bits */
      size_t n = (size_t)width * (size_t)height * (size_t)channels;
      bytes = lm_alloc(n);
      for (size_t i = 0; i < n; i++) {
        float v = ((const float *)pixels)[i];
        bytes[i] = (unsigned char)(v >= 1.0f ? 255 : v > 0.0f ? (int)(v * 255.0f + 0.5f) : 0); /* NaN: 0 */
      }
    }
    ok = png_write(tmp, path, width, height, channels, bytes, err);
    if (bytes != pixels) free(bytes);
  } else {
    ok = oiio.write(tmp, path, width, height, channels, floats, pixels, err);
  }
  if (ok && rename(tmp, path) != 0) {
    lm_error_set(err, "%s: cannot rename the finished file into place: %s", path, strerror(errno));
    ok = false;
  }
  if (!ok) remove(tmp);
  return ok;
}

bool lm_image_read(const char *path, lm_image *img, lm_error *err) {
  memset(img, 0, sizeof *img);
  unsigned char head[8];
  FILE *f = fopen(path, "rb");
  if (!f) {
    lm_error_set(err, "%s: cannot open: %s", path, strerror(errno));
    return false;
  }
  size_t got = fread(head, 1, sizeof head, f);
  fclose(f);
  if (!is_png(head, got) && !is_jpeg(head, got)) return oiio_ready(path, err) && oiio.read(path, img, err);
  size_t size;
  unsigned char *data = (unsigned char *)lm_read_file(path, &size, err);
  decoded d;
  bool ok = data && decode(data, size, path, false, INT32_MAX, &d, err);
  free(data);
  if (!ok) return false;
  size_t n = (size_t)d.width * (size_t)d.height * (size_t)d.channels;
  img->pixels = lm_alloc(n * sizeof(float));
  for (size_t i = 0; i < n; i++)
    img->pixels[i] = d.depth == 16 ? ((const uint16_t *)d.pixels)[i] / 65535.0f : d.pixels[i] / 255.0f;
  img->width = d.width, img->height = d.height, img->channels = d.channels;
  free(d.pixels);
  return true;
}

bool lm_image_decode_rgba8(const void *data, size_t size, const char *name, int *width, int *height,
                           unsigned char **rgba, lm_error *err) {
  *width = *height = 0;
  *rgba = NULL;
  decoded d;
  if (!decode(data, size, name, true, TEXTURE_MAX, &d, err)) return false;
  *width = d.width, *height = d.height, *rgba = d.pixels;
  return true;
}

void lm_image_free(lm_image *img) {
  free(img->pixels);
  memset(img, 0, sizeof *img);
}
