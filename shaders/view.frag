// The viewer's display: the frame as rendered, or a target of the frame graph
// (exposure, one channel, false colour), under the text overlay. With PROBE
// defined it writes the target's raw values instead (for EXR and ranges);
// with PANEL the panel's image alone, drawn over the display (premultiplied).
//
// What a frame needs is chosen by defines, not uniforms: llvmpipe runs both
// sides of a branch on a uniform, and the branches of every mode in one
// program cost 13 of this pass's 16 ms of CPU at 640x480 (measured against a
// program of the frame's path alone). MODE: 0 the frame, 1 a target, 2 a
// target in false colour, 3 black, 4 a one-channel or depth target, grey
// over its range; WIPE: the other side right of the split (OTHER_LINEAR:
// it holds linear radiance); OVERLAY: text to blend over it (none, no fetch).
#include "common.glsl"

#ifndef MODE
#define MODE 0
#endif

in vec2 uv;
uniform sampler2D src;     // the frame (sRGB-encoded bytes) or a target (linear values)
uniform sampler2D overlay; // text, premultiplied alpha
uniform sampler2D panel;   // PANEL: the panel (cli/view_panel.cpp), premultiplied alpha
uniform sampler2D other;   // WIPE: the other side (sRGB-encoded bytes, or linear radiance with OTHER_LINEAR)
uniform float split = 0.0; // WIPE: the line, window pixels from the left
uniform int channel = 4;   // 0 r, 1 g, 2 b, 3 a, 4 rgb
uniform float exposure = 0.0;          // stops
uniform vec2 range = vec2(0.0, 1.0);   // false colour and grey: min and max shown

out vec4 color;

// Blue (low) through cyan, green, yellow to red (high).
vec3 false_colour(float t) {
  t = saturate(t);
  return saturate(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)));
}

// NaN and Inf become 0; negative values (normals) stay.
float finite(float x) { return isnan(x) || isinf(x) ? 0.0 : x; }

// The frame, the overlay and the panel are at the window's size: one texel a pixel.
vec4 at_pixel(sampler2D s) { return texelFetch(s, ivec2(gl_FragCoord.xy), 0); }

void main() {
#if defined(PROBE)
  vec4 v = texture(src, uv);
  color = vec4(finite(v.r), finite(v.g), finite(v.b), finite(v.a));
#elif defined(PANEL)
  color = at_pixel(panel);
#else
#if MODE == 0
  vec3 c = at_pixel(src).rgb;
#else
  vec4 v = texture(src, uv);
  v = vec4(finite(v.r), finite(v.g), finite(v.b), finite(v.a));
  float one = channel < 4 ? v[channel] : v.r;
  float span = range.y - range.x, t = span > 1e-20 ? (one - range.x) / span : 0.5;
#if MODE == 1
  vec3 c = srgb_encode((channel < 4 ? vec3(one) : v.rgb) * exp2(clamp(exposure, -40.0, 40.0)));
#elif MODE == 2
  vec3 c = false_colour(t);
#elif MODE == 3
  vec3 c = vec3(0.0);
#else
  vec3 c = vec3(saturate(t));
#endif
#endif
#if defined(WIPE)
  if (gl_FragCoord.x >= split) {
#if defined(OTHER_LINEAR)
    c = srgb_encode(finite_or_zero(texture(other, uv).rgb));
#else
    c = texture(other, uv).rgb;
#endif
  }
  if (abs(gl_FragCoord.x - split) < 1.0) c = vec3(1.0); // the line to drag
#endif
#if defined(OVERLAY)
  vec4 o = at_pixel(overlay);
  color = vec4(c * (1.0 - o.a) + o.rgb, 1.0);
#else
  color = vec4(c, 1.0);
#endif
#endif
}
