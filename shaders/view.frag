// The viewer's display: the frame as rendered, or a target of the frame graph
// (exposure, one channel, false colour), under the text overlay. With PROBE
// defined it writes the target's raw values instead (for EXR and ranges).
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;     // the frame (sRGB-encoded bytes) or a target (linear values)
uniform sampler2D overlay; // text, premultiplied alpha
uniform sampler2D panel;   // the panel (cli/view_panel.cpp), premultiplied alpha, when show_panel
uniform int show_panel = 0;
uniform sampler2D other;   // the wipe's other side (sRGB-encoded bytes), right of split
uniform int other_linear = 0; // other holds linear radiance (a reference): encoded as the output stage does
uniform float split = -1.0; // the wipe's line, window pixels from the left; < 0: no wipe
uniform int mode = 0;      // 0: the frame; 1: a target; 2: a target in false colour; 3: black;
                           // 4: a one-channel or depth target, grey over its range
uniform int channel = 4;   // 0 r, 1 g, 2 b, 3 a, 4 rgb
uniform float exposure = 0.0;          // stops
uniform vec2 range = vec2(0.0, 1.0);   // false colour and grey: min and max shown

out vec4 color;

vec3 srgb_encode(vec3 c) {
  c = saturate(c);
  vec3 lo = c * 12.92, hi = 1.055 * pow(max(c, vec3(1e-8)), vec3(1.0 / 2.4)) - 0.055;
  return mix(lo, hi, step(vec3(0.0031308), c));
}

// Blue (low) through cyan, green, yellow to red (high).
vec3 false_colour(float t) {
  t = saturate(t);
  return saturate(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)));
}

// NaN and Inf become 0; negative values (normals) stay.
float finite(float x) { return isnan(x) || isinf(x) ? 0.0 : x; }

void main() {
  vec4 v = texture(src, uv);
  v = vec4(finite(v.r), finite(v.g), finite(v.b), finite(v.a));
#ifdef PROBE
  color = v;
#else
  vec3 c = v.rgb;
  if (split >= 0.0 && gl_FragCoord.x >= split)
    c = other_linear != 0 ? srgb_encode(finite_or_zero(texture(other, uv).rgb)) : texture(other, uv).rgb;
  if (split >= 0.0 && abs(gl_FragCoord.x - split) < 1.0) c = vec3(1.0); // the line to drag
  if (mode == 3) {
    c = vec3(0.0);
  } else if (mode > 0) {
    float one = channel < 4 ? v[channel] : v.r;
    float span = range.y - range.x, t = span > 1e-20 ? (one - range.x) / span : 0.5;
    if (mode == 2) {
      c = false_colour(t);
    } else if (mode == 4) {
      c = vec3(saturate(t));
    } else {
      c = (channel < 4 ? vec3(one) : v.rgb) * exp2(clamp(exposure, -40.0, 40.0));
      c = srgb_encode(c);
    }
  }
  vec4 o = texture(overlay, uv);
  c = c * (1.0 - o.a) + o.rgb;
  if (show_panel != 0) {
    vec4 q = texture(panel, uv);
    c = c * (1.0 - q.a) + q.rgb;
  }
  color = vec4(c, 1.0);
#endif
}
