// The OpenImageIO module: EXR, HDR, TIFF and the other formats that
// image.c leaves to OpenImageIO, built as a shared module of its own and
// opened on first use (image.c says why). It calls nothing of the engine's,
// which the executable does not export: errors are written into err->msg
// and pixels allocated with malloc.
#include "image/image.h"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
#include <string>

using namespace OIIO;

static bool fail(lm_error *err, const char *path, const std::string &why) {
  snprintf(err->msg, sizeof err->msg, "%s: %s", path, why.c_str());
  return false;
}

extern "C" bool lm_image_oiio_write(const char *file, const char *path, int width, int height, int channels,
                                    bool floats, const void *pixels, lm_error *err) {
  auto out = ImageOutput::create(file);
  if (!out) return fail(err, path, "cannot write this format: " + geterror());
  TypeDesc type = floats ? TypeDesc::FLOAT : TypeDesc::UINT8;
  ImageSpec spec(width, height, channels, type);
  spec.attribute("oiio:UnassociatedAlpha", 1); // alpha as given: PNG, TIFF... store it so
  if (!out->open(file, spec)) return fail(err, path, out->geterror());
  bool ok = out->write_image(type, pixels);
  std::string why = ok ? "" : out->geterror();
  ok = out->close() && ok;
  return ok || fail(err, path, why.empty() ? out->geterror() : why);
}

extern "C" bool lm_image_oiio_read(const char *path, lm_image *img, lm_error *err) {
  *img = lm_image{};
  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1); // alpha as stored, as image.c reads a PNG
  auto in = ImageInput::open(path, &config);
  if (!in) return fail(err, path, geterror());
  const ImageSpec &spec = in->spec();
  size_t count = (size_t)spec.width * spec.height * spec.nchannels;
  float *pixels = (float *)malloc(count * sizeof(float));
  if (!pixels) return fail(err, path, "out of memory for " + std::to_string(count) + " floats");
  if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, pixels)) {
    free(pixels);
    return fail(err, path, in->geterror());
  }
  *img = lm_image{spec.width, spec.height, spec.nchannels, pixels};
  return true;
}
