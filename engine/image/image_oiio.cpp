// Bridge to OpenImageIO; the engine sees only image/image.h.
#include "image/image.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>
#include <string>
#include <unistd.h>

using namespace OIIO;

static std::string temp_name(const std::string &path) {
  size_t slash = path.rfind('/');
  size_t dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) dot = path.size();
  return path.substr(0, dot) + ".tmp-" + std::to_string(getpid()) + path.substr(dot);
}

extern "C" bool lm_image_write(const char *path, int width, int height, int channels, bool floats,
                               const void *pixels, lm_error *err) {
  std::string tmp = temp_name(path);
  auto out = ImageOutput::create(path);
  if (!out) {
    lm_error_set(err, "%s: cannot write this format: %s", path, geterror().c_str());
    return false;
  }
  ImageSpec spec(width, height, channels, floats ? TypeDesc::FLOAT : TypeDesc::UINT8);
  if (!out->open(tmp, spec)) {
    lm_error_set(err, "%s: %s", path, out->geterror().c_str());
    return false;
  }
  bool ok = out->write_image(floats ? TypeDesc::FLOAT : TypeDesc::UINT8, pixels);
  std::string why = ok ? "" : out->geterror();
  ok = out->close() && ok;
  if (ok && std::rename(tmp.c_str(), path) != 0) {
    why = "cannot rename the finished file into place";
    ok = false;
  }
  if (!ok) {
    std::remove(tmp.c_str());
    lm_error_set(err, "%s: %s", path, why.empty() ? out->geterror().c_str() : why.c_str());
  }
  return ok;
}

extern "C" bool lm_image_read(const char *path, lm_image *img, lm_error *err) {
  *img = lm_image{};
  auto in = ImageInput::open(path);
  if (!in) {
    lm_error_set(err, "%s: %s", path, geterror().c_str());
    return false;
  }
  const ImageSpec &spec = in->spec();
  size_t count = (size_t)spec.width * spec.height * spec.nchannels;
  float *pixels = (float *)lm_alloc(count * sizeof(float));
  if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, pixels)) {
    lm_error_set(err, "%s: %s", path, in->geterror().c_str());
    free(pixels);
    return false;
  }
  img->width = spec.width;
  img->height = spec.height;
  img->channels = spec.nchannels;
  img->pixels = pixels;
  return true;
}

// OpenImageIO picks the reader by the name's extension, then by content:
// give it a neutral name and let the bytes decide.
static std::unique_ptr<ImageInput> open_memory(const void *data, size_t size, const char *name,
                                               Filesystem::IOMemReader *proxy, lm_error *err) {
  static const char *const kinds[] = {"png", "jpg", "tga", "bmp", "exr", "hdr", "tif"};
  const unsigned char *b = (const unsigned char *)data;
  const char *ext = "png";
  if (size >= 3 && b[0] == 0xff && b[1] == 0xd8) ext = "jpg";
  for (const char *k : kinds) {
    if (strcmp(k, ext)) continue;
    ImageSpec config;
    config.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy);
    auto in = ImageInput::open(std::string("memory.") + k, &config);
    if (in) return in;
  }
  lm_error_set(err, "%s: not an image OpenImageIO can read (%zu bytes): %s", name, size,
               geterror().c_str());
  return nullptr;
}

// A PNG's chunks must all lie inside the bytes and end in IEND. OpenImageIO
// (2.4) leaks when libpng runs off the end of a memory stream, and a cut
// file deserves its own message anyway.
static bool png_whole(const unsigned char *b, size_t size, const char *name, lm_error *err) {
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', 13, 10, 26, 10};
  if (size < 8 || memcmp(b, sig, 8)) return true; /* not a PNG: not ours to judge */
  for (size_t at = 8; at + 12 <= size;) {
    size_t len = (size_t)b[at] << 24 | (size_t)b[at + 1] << 16 | (size_t)b[at + 2] << 8 | b[at + 3];
    if (len > size - at - 12) break;
    if (!memcmp(b + at + 4, "IEND", 4)) return true;
    at += 12 + len;
  }
  lm_error_set(err, "%s: PNG cut short or damaged (%zu bytes, no whole chunk sequence ending in IEND)", name, size);
  return false;
}

static bool read_memory(const void *data, size_t size, const char *name, TypeDesc type, int *w, int *h,
                        int *channels, std::vector<unsigned char> &out, lm_error *err) {
  if (!data || size < 8) {
    lm_error_set(err, "%s: %zu bytes are not an image", name, size);
    return false;
  }
  if (!png_whole((const unsigned char *)data, size, name, err)) return false;
  Filesystem::IOMemReader proxy(data, size);
  auto in = open_memory(data, size, name, &proxy, err);
  if (!in) return false;
  const ImageSpec &spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.width > 16384 || spec.height > 16384 || spec.nchannels < 1) {
    lm_error_set(err, "%s: size %dx%d with %d channels is outside 1x1 .. 16384x16384", name, spec.width,
                 spec.height, spec.nchannels);
    return false;
  }
  *w = spec.width, *h = spec.height, *channels = spec.nchannels;
  out.resize((size_t)spec.width * spec.height * spec.nchannels * type.size());
  if (!in->read_image(0, 0, 0, spec.nchannels, type, out.data())) {
    lm_error_set(err, "%s: %s", name, in->geterror().c_str());
    return false;
  }
  return true;
}

extern "C" bool lm_image_read_memory(const void *data, size_t size, const char *name, lm_image *img,
                                     lm_error *err) {
  *img = lm_image{};
  std::vector<unsigned char> px;
  int w, h, c;
  if (!read_memory(data, size, name, TypeDesc::FLOAT, &w, &h, &c, px, err)) return false;
  img->pixels = (float *)lm_alloc(px.size());
  memcpy(img->pixels, px.data(), px.size());
  img->width = w, img->height = h, img->channels = c;
  return true;
}

extern "C" bool lm_image_decode_rgba8(const void *data, size_t size, const char *name, int *width,
                                      int *height, unsigned char **rgba, lm_error *err) {
  std::vector<unsigned char> px;
  int w, h, c;
  *rgba = nullptr;
  if (!read_memory(data, size, name, TypeDesc::UINT8, &w, &h, &c, px, err)) return false;
  size_t n = (size_t)w * h;
  unsigned char *out = (unsigned char *)lm_alloc(n * 4);
  for (size_t i = 0; i < n; i++) {
    const unsigned char *p = &px[i * c];
    unsigned char *o = out + i * 4;
    o[0] = p[0];
    o[1] = c >= 3 ? p[1] : p[0];
    o[2] = c >= 3 ? p[2] : p[0];
    o[3] = c == 4 ? p[3] : c == 2 ? p[1] : 255;
  }
  *width = w, *height = h, *rgba = out;
  return true;
}

extern "C" void lm_image_free(lm_image *img) {
  free(img->pixels);
  *img = lm_image{};
}
