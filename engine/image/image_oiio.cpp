// Bridge to OpenImageIO; the engine sees only image/image.h.
#include "image/image.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
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

extern "C" void lm_image_free(lm_image *img) {
  free(img->pixels);
  *img = lm_image{};
}
