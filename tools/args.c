/* Flag values shared by the limn subcommands. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tools.h"
#include "scene/scene.h"

bool limn_parse_int(const char *s, int lo, int hi, int *out) {
  char *end;
  long v = strtol(s, &end, 10);
  if (end == s || *end || v < lo || v > hi) return false;
  *out = (int)v;
  return true;
}

bool limn_parse_double(const char *s, double *out) {
  char *end;
  double v = strtod(s, &end);
  if (end == s || *end || !isfinite(v)) return false;
  *out = v;
  return true;
}

bool limn_parse_size(const char *s, int *w, int *h) {
  char buf[64];
  snprintf(buf, sizeof buf, "%s", s);
  char *x = strchr(buf, 'x');
  if (!x) return false;
  *x = '\0';
  return limn_parse_int(buf, 1, 65536, w) && limn_parse_int(x + 1, 1, 65536, h);
}

bool limn_parse_camera(const char *s, int *out) {
  if (!strcmp(s, "auto")) {
    *out = LIMN_CAMERA_AUTO;
    return true;
  }
  return limn_parse_int(s, 0, 1 << 20, out);
}

int limn_camera_resolve(lm_scene *s, int camera, int width, int height) {
  if (camera != LIMN_CAMERA_AUTO) return camera;
  return lm_scene_add_framing_camera(s, "auto", (float)width / (float)height);
}

bool limn_parse_on_off(const char *s, bool *out) {
  if (!strcmp(s, "on")) *out = true;
  else if (!strcmp(s, "off")) *out = false;
  else return false;
  return true;
}

void limn_json_append(lm_buf *b, const char *s) {
  lm_buf_append(b, "\"", 1);
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\') lm_buf_printf(b, "\\%c", c);
    else if (c < 0x20) lm_buf_printf(b, "\\u%04x", c);
    else lm_buf_append(b, s, 1);
  }
  lm_buf_append(b, "\"", 1);
}

void limn_json_string(const char *s) {
  lm_buf b = {0};
  limn_json_append(&b, s);
  fputs(b.data, stdout);
  lm_buf_free(&b);
}
