/* Image files (engine/image): PNGs built here byte by byte (zlib, not
 * libpng) and JPEGs encoded by libjpeg, decoded to values as stored; cut and
 * damaged data refused by name; PNGs written whole; OpenImageIO's module
 * left unloaded until a format that needs it (an EXR) is read or written.
 * The tests run in order: oiio_not_loaded_yet must come before the module's. */
#define _XOPEN_SOURCE 700 /* mkdtemp */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <jpeglib.h>
#include <zlib.h>

#include "image/image.h"

static char dir[64];

static const char *in_dir(const char *name) {
  static char path[128];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return path;
}

static void put_chunk(unsigned char **at, const char *type, const unsigned char *data, uint32_t n) {
  unsigned char *p = *at;
  p[0] = n >> 24, p[1] = n >> 16, p[2] = n >> 8, p[3] = n;
  memcpy(p + 4, type, 4);
  if (n) memcpy(p + 8, data, n);
  uLong crc = crc32(0, p + 4, n + 4);
  p[8 + n] = crc >> 24, p[9 + n] = crc >> 16, p[10 + n] = crc >> 8, p[11 + n] = crc;
  *at = p + 12 + n;
}

/* A PNG of `rows` (each row's bytes as stored, without its filter byte),
 * with an optional PLTE and tRNS; *size gets its length. */
static unsigned char *png_bytes(int w, int h, int depth, int type, const unsigned char *rows, size_t row_bytes,
                                const unsigned char *plte, int plte_n, const unsigned char *trns, int trns_n,
                                size_t *size) {
  size_t raw_n = (row_bytes + 1) * (size_t)h;
  unsigned char *raw = calloc(1, raw_n);
  for (int y = 0; y < h; y++) memcpy(raw + y * (row_bytes + 1) + 1, rows + y * row_bytes, row_bytes);
  uLongf z_n = compressBound(raw_n);
  unsigned char *z = malloc(z_n);
  assert_int_equal(compress(z, &z_n, raw, raw_n), Z_OK);
  unsigned char *png = malloc(8 + 25 + 12 + plte_n + 12 + trns_n + 12 + z_n + 12), *at = png;
  memcpy(at, "\x89PNG\r\n\x1a\n", 8), at += 8;
  unsigned char ihdr[13] = {w >> 24, w >> 16, w >> 8, w, h >> 24, h >> 16, h >> 8, h, depth, type, 0, 0, 0};
  put_chunk(&at, "IHDR", ihdr, 13);
  if (plte) put_chunk(&at, "PLTE", plte, plte_n);
  if (trns) put_chunk(&at, "tRNS", trns, trns_n);
  put_chunk(&at, "IDAT", z, z_n);
  put_chunk(&at, "IEND", NULL, 0);
  free(raw), free(z);
  *size = at - png;
  return png;
}

static void write_file(const char *path, const void *data, size_t size) {
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(data, 1, size, f), size);
  fclose(f);
}

/* Decodes with lm_image_decode_rgba8 and, through a file, lm_image_read. */
static void decode_both(const unsigned char *data, size_t size, unsigned char **rgba, int *w, int *h, lm_image *img) {
  lm_error err = {""};
  if (!lm_image_decode_rgba8(data, size, "test", w, h, rgba, &err)) fail_msg("%s", err.msg);
  write_file(in_dir("decoded"), data, size);
  if (!lm_image_read(in_dir("decoded"), img, &err)) fail_msg("%s", err.msg);
  assert_int_equal(img->width, *w);
  assert_int_equal(img->height, *h);
}

/* Alpha 128 leaves the colour as stored (not premultiplied): glTF's
 * base colour and a PNG both keep it apart. */
static void png_rgba_as_stored(void **state) {
  (void)state;
  const unsigned char px[] = {200, 100, 50, 128, 10, 20, 30, 255};
  size_t size;
  unsigned char *png = png_bytes(2, 1, 8, 6, px, 8, NULL, 0, NULL, 0, &size), *rgba;
  int w, h;
  lm_image img;
  decode_both(png, size, &rgba, &w, &h, &img);
  assert_int_equal(w, 2);
  assert_memory_equal(rgba, px, 8);
  assert_int_equal(img.channels, 4);
  for (int i = 0; i < 8; i++) assert_float_equal(img.pixels[i], px[i] / 255.0f, 1e-7);
  free(png), free(rgba), lm_image_free(&img);
}

/* 16 bits: lm_image_read divides by 65535, the texture rounds to 8 bits.
 * (Reads alike png_rgba_as_stored: each case builds its own PNG and checks
 * both decoders' values, so a failure names the format.) */
static void png_16_bit(void **state) {
  (void)state;
  const uint16_t v[] = {50000, 1000, 65535};
  unsigned char px[6];
  for (int i = 0; i < 3; i++) px[2 * i] = v[i] >> 8, px[2 * i + 1] = v[i] & 0xff;
  size_t size;
  unsigned char *png = png_bytes(1, 1, 16, 2, px, 6, NULL, 0, NULL, 0, &size), *rgba;
  int w, h;
  lm_image img;
  decode_both(png, size, &rgba, &w, &h, &img);
  const unsigned char want[] = {195, 4, 255, 255}; /* 50000 / 257 = 194.6, 1000 / 257 = 3.9 */
  assert_memory_equal(rgba, want, 4);
  assert_int_equal(img.channels, 3);
  for (int i = 0; i < 3; i++) assert_float_equal(img.pixels[i], v[i] / 65535.0f, 1e-7);
  free(png), free(rgba), lm_image_free(&img);
}

/* Grey spreads to RGB (one channel read), 1-bit grey reaches 255, a palette
 * with transparency gives RGBA. */
static void png_grey_and_palette(void **state) {
  (void)state;
  size_t size;
  int w, h;
  unsigned char *rgba;
  lm_image img;
  const unsigned char grey[] = {77, 200};
  unsigned char *png = png_bytes(2, 1, 8, 0, grey, 2, NULL, 0, NULL, 0, &size);
  decode_both(png, size, &rgba, &w, &h, &img);
  const unsigned char grey_rgba[] = {77, 77, 77, 255, 200, 200, 200, 255};
  assert_memory_equal(rgba, grey_rgba, 8);
  assert_int_equal(img.channels, 1);
  assert_float_equal(img.pixels[1], 200 / 255.0f, 1e-7);
  free(png), free(rgba), lm_image_free(&img);

  const unsigned char bits[] = {0x80}; /* 1 bit a pixel: white, black */
  png = png_bytes(2, 1, 1, 0, bits, 1, NULL, 0, NULL, 0, &size);
  decode_both(png, size, &rgba, &w, &h, &img);
  assert_int_equal(rgba[0], 255);
  assert_int_equal(rgba[4], 0);
  assert_float_equal(img.pixels[0], 1.0f, 0);
  free(png), free(rgba), lm_image_free(&img);

  const unsigned char plte[] = {255, 0, 0, 0, 0, 255}, trns[] = {64}, index[] = {0, 1};
  png = png_bytes(2, 1, 8, 3, index, 2, plte, 6, trns, 1, &size);
  decode_both(png, size, &rgba, &w, &h, &img);
  const unsigned char pal_rgba[] = {255, 0, 0, 64, 0, 0, 255, 255};
  assert_memory_equal(rgba, pal_rgba, 8);
  assert_int_equal(img.channels, 4);
  assert_float_equal(img.pixels[3], 64 / 255.0f, 1e-7);
  free(png), free(rgba), lm_image_free(&img);
}

/* A flat w x h JPEG of `channels` (1 or 3) of `colour`, at quality 95. */
static unsigned char *jpeg_bytes(int w, int h, int channels, const unsigned char *colour, size_t *size) {
  struct jpeg_compress_struct c;
  struct jpeg_error_mgr jerr;
  c.err = jpeg_std_error(&jerr);
  jpeg_create_compress(&c);
  unsigned char *out = NULL;
  unsigned long n = 0;
  jpeg_mem_dest(&c, &out, &n);
  c.image_width = w, c.image_height = h, c.input_components = channels;
  c.in_color_space = channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 95, TRUE);
  jpeg_start_compress(&c, TRUE);
  unsigned char *row = malloc((size_t)w * channels);
  for (int x = 0; x < w; x++) memcpy(row + x * channels, colour, channels);
  while (c.next_scanline < c.image_height) jpeg_write_scanlines(&c, &row, 1);
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  free(row);
  *size = n;
  return out;
}

static void jpeg_rgb_and_grey(void **state) {
  (void)state;
  const unsigned char colour[] = {180, 60, 20};
  size_t size;
  int w, h;
  unsigned char *rgba;
  lm_image img;
  unsigned char *jpeg = jpeg_bytes(16, 8, 3, colour, &size);
  decode_both(jpeg, size, &rgba, &w, &h, &img);
  assert_int_equal(w, 16);
  assert_int_equal(h, 8);
  assert_int_equal(img.channels, 3);
  for (int i = 0; i < 16 * 8; i++) {
    for (int c = 0; c < 3; c++) {
      assert_in_range(rgba[i * 4 + c], colour[c] - 3, colour[c] + 3);
      assert_float_equal(img.pixels[i * 3 + c], rgba[i * 4 + c] / 255.0f, 1e-7);
    }
    assert_int_equal(rgba[i * 4 + 3], 255);
  }
  free(jpeg), free(rgba), lm_image_free(&img);

  const unsigned char grey = 128;
  jpeg = jpeg_bytes(8, 8, 1, &grey, &size);
  decode_both(jpeg, size, &rgba, &w, &h, &img);
  assert_int_equal(img.channels, 1);
  assert_float_equal(img.pixels[0], 128 / 255.0f, 2 / 255.0f);
  assert_int_equal(rgba[0], rgba[2]);
  free(jpeg), free(rgba), lm_image_free(&img);
}

static void refused(const void *data, size_t size, const char *why) {
  lm_error err = {""};
  int w = -1, h = -1;
  unsigned char *rgba = (unsigned char *)"not touched";
  assert_false(lm_image_decode_rgba8(data, size, "image 3 ('wall')", &w, &h, &rgba, &err));
  assert_null(rgba);
  assert_int_equal(w, 0);
  if (!strstr(err.msg, "image 3 ('wall'): ") || !strstr(err.msg, why)) fail_msg("'%s' lacks '%s'", err.msg, why);
}

static void damaged_data_refused(void **state) {
  (void)state;
  unsigned char px[64 * 3];
  for (int i = 0; i < (int)sizeof px; i++) px[i] = (unsigned char)(i * 37);
  size_t size;
  unsigned char *png = png_bytes(8, 8, 8, 2, px, 24, NULL, 0, NULL, 0, &size);
  refused(png, 40, "PNG cut short (40 bytes)");
  refused(png, size - 20, "PNG cut short");
  png[size - 20] ^= 0x55; /* inside IDAT: its CRC no longer matches */
  refused(png, size, "PNG: ");
  free(png);
  unsigned char wide[] = {0};
  png = png_bytes(20000, 1, 1, 0, wide, 1, NULL, 0, NULL, 0, &size);
  refused(png, size, "size 20000x1 is outside 1x1 .. 16384x16384");
  free(png);
  const unsigned char colour[] = {1, 2, 3};
  unsigned char *jpeg = jpeg_bytes(64, 64, 3, colour, &size);
  refused(jpeg, size - 8, "JPEG cut short"); /* inside the scan, before its end marker */
  refused(jpeg, 40, "JPEG");
  free(jpeg);
  refused("GIF89a and so on", 16, "neither a PNG nor a JPEG (16 bytes)");
  refused(NULL, 0, "neither a PNG nor a JPEG (0 bytes)");
}

static bool temp_files_left(void) {
  DIR *d = opendir(dir);
  struct dirent *e;
  bool left = false;
  while ((e = readdir(d))) left |= strstr(e->d_name, ".tmp-") != NULL;
  closedir(d);
  return left;
}

/* Bytes as given, floats clamped and rounded to 8 bits (NaN to 0). */
static void png_written_and_read_back(void **state) {
  (void)state;
  lm_error err = {""};
  const unsigned char rgba[] = {200, 100, 50, 128, 0, 255, 7, 0};
  lm_image img;
  assert_true(lm_image_write(in_dir("rgba.png"), 2, 1, 4, false, rgba, &err));
  assert_true(lm_image_read(in_dir("rgba.png"), &img, &err));
  assert_int_equal(img.channels, 4);
  for (int i = 0; i < 8; i++) assert_float_equal(img.pixels[i], rgba[i] / 255.0f, 1e-7);
  lm_image_free(&img);
  const float f[] = {-0.5f, 0.5f, 1.5f, 0.2f, 0.00196f, 0.998f, 0.0f / 0.0f, 1.0f, 0.0f};
  const unsigned char want[] = {0, 128, 255, 51, 0, 254, 0, 255, 0};
  assert_true(lm_image_write(in_dir("floats.PNG"), 3, 1, 3, true, f, &err));
  assert_true(lm_image_read(in_dir("floats.PNG"), &img, &err));
  assert_int_equal(img.width, 3);
  assert_int_equal(img.channels, 3);
  for (int i = 0; i < 9; i++) assert_float_equal(img.pixels[i], want[i] / 255.0f, 1e-7);
  lm_image_free(&img);
  assert_false(temp_files_left());

  assert_false(lm_image_write("/nonexistent-dir/a.png", 2, 1, 4, false, rgba, &err));
  assert_non_null(strstr(err.msg, "/nonexistent-dir/a.png: cannot write: No such file"));
  assert_false(lm_image_write(in_dir("five.png"), 1, 1, 5, false, rgba, &err));
  assert_non_null(strstr(err.msg, "a PNG holds 1 to 4 channels, not 5"));
  assert_false(lm_file_exists(in_dir("five.png")));
  assert_false(lm_image_read(in_dir("missing.exr"), &img, &err));
  assert_non_null(strstr(err.msg, "missing.exr: cannot open: No such file"));
  assert_null(img.pixels);
}

static bool mapped(const char *name) {
  char *maps = lm_read_file("/proc/self/maps", NULL, NULL);
  assert_non_null(maps);
  bool found = strstr(maps, name) != NULL;
  free(maps);
  return found;
}

/* Everything above read and wrote PNG and JPEG: OpenImageIO is not mapped. */
static void oiio_not_loaded_yet(void **state) {
  (void)state;
  assert_true(mapped("libpng16")); /* the check reads the maps */
  assert_false(mapped("limn_image_oiio"));
  assert_false(mapped("libOpenImageIO"));
}

/* An EXR keeps floats beyond 1 and a TIFF its alpha as given, through the module. */
static void exr_and_tiff_through_the_module(void **state) {
  (void)state;
  lm_error err = {""};
  const float px[] = {1e5f, 1e-6f, 0.25f, 0.5f, 2.0f, 0.0f, 3.5f, 1.0f};
  lm_image img;
  if (!lm_image_write(in_dir("a.exr"), 2, 1, 4, true, px, &err)) fail_msg("%s", err.msg);
  if (!lm_image_read(in_dir("a.exr"), &img, &err)) fail_msg("%s", err.msg);
  assert_int_equal(img.channels, 4);
  assert_memory_equal(img.pixels, px, sizeof px);
  lm_image_free(&img);
  const unsigned char rgba[] = {200, 100, 50, 128};
  assert_true(lm_image_write(in_dir("a.tif"), 1, 1, 4, false, rgba, &err));
  assert_true(lm_image_read(in_dir("a.tif"), &img, &err));
  for (int i = 0; i < 4; i++) assert_float_equal(img.pixels[i], rgba[i] / 255.0f, 1e-7);
  lm_image_free(&img);
  assert_false(temp_files_left());
  assert_true(mapped("limn_image_oiio"));
  assert_true(mapped("libOpenImageIO"));
  assert_false(lm_image_write(in_dir("a.nosuchformat"), 1, 1, 4, false, rgba, &err));
  assert_non_null(strstr(err.msg, "a.nosuchformat: cannot write this format"));
}

static int remove_dir(void **state) {
  (void)state;
  DIR *d = opendir(dir);
  struct dirent *e;
  while ((e = readdir(d)))
    if (e->d_name[0] != '.') unlink(in_dir(e->d_name));
  closedir(d);
  return rmdir(dir);
}

int main(void) {
  snprintf(dir, sizeof dir, "/tmp/limn-test-image-XXXXXX");
  if (!mkdtemp(dir)) return 1;
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(png_rgba_as_stored),
      cmocka_unit_test(png_16_bit),
      cmocka_unit_test(png_grey_and_palette),
      cmocka_unit_test(jpeg_rgb_and_grey),
      cmocka_unit_test(damaged_data_refused),
      cmocka_unit_test(png_written_and_read_back),
      cmocka_unit_test(oiio_not_loaded_yet),
      cmocka_unit_test(exr_and_tiff_through_the_module),
  };
  return cmocka_run_group_tests(tests, NULL, remove_dir);
}
