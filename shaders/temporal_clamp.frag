// Neighbourhood clamping of a temporal history (temporal.clamp; the pass
// after a GI pass that wrote, with TEMPORAL_CLAMP, its accumulation `raw`
// and `fresh`: this frame's own estimate in rgb and the weight w its history
// took in a (temporal.glsl's temporal_accumulate: raw = mix(fresh, h, w);
// w < 0 where the pixel took no fresh samples: converged or nothing drawn).
// The history h is recovered from the two, its luminance held within
// mean +- k sigma of the log luminance of the fresh estimates in the pixel's
// 3 x 3 neighbourhood (its colour kept), and blended again: after a change
// of light (a door, a light, a moving object) the history cannot stay
// further from what the frame sees than the noise allows, so it follows
// within a frame or two instead of fading out as 1 / frames, or staying once
// converged. Log luminance because GI is noisy and spans decades: a few rays
// a texel give estimates from 0 to many times their mean, whose linear sigma
// would reach below 0 and clamp nothing, while a light 1e4 times brighter
// is a shift in log; and a box in log scales with the light, so every
// exposure clamps alike. delta, a thousandth of the neighbourhood's mean,
// keeps a black estimate's log finite. Output: the clamped value, to E and
// to the history.
#include "common.glsl"

in vec2 uv;
uniform sampler2D raw, fresh;
uniform float k = 1.0; // the box's half width in standard deviations (temporal.clamp)

layout(location = 0) out vec4 result;
layout(location = 1) out vec4 value;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy), size = textureSize(raw, 0);
  vec4 v = texelFetch(raw, px, 0), c = texelFetch(fresh, px, 0);
  float w = c.a;
  if (w > 0.0 && w <= 1.0) {
    float y[9], sum = 0.0, count = 0.0;
    for (int i = 0; i < 9; i++) {
      vec4 f = texelFetch(fresh, clamp(px + ivec2(i % 3 - 1, i / 3 - 1), ivec2(0), size - 1), 0);
      y[i] = f.a >= 0.0 ? luminance(f.rgb) : -1.0; // -1: no fresh estimate there
      if (y[i] >= 0.0 && y[i] < 1e30) {
        sum += y[i];
        count += 1.0;
      } else {
        y[i] = -1.0;
      }
    }
    // Four fresh neighbours at least (a refreshed 4 x 4 tile's corner has four): fewer say nothing of
    // the noise. No light at all around: nothing to clamp to.
    if (count >= 4.0 && sum > 0.0) {
      float delta = 1e-3 * sum / count, m1 = 0.0, m2 = 0.0;
      for (int i = 0; i < 9; i++) {
        if (y[i] < 0.0) continue;
        float l = log(y[i] + delta); // delta > 0
        m1 += l;
        m2 += l * l;
      }
      m1 /= count;
      float sigma = sqrt(max(m2 / count - m1 * m1, 0.0));
      vec3 h = (v.rgb - (1.0 - w) * c.rgb) / w; // w > 0
      float yh = max(luminance(h), 0.0);
      float want = exp(clamp(log(yh + delta), m1 - k * sigma, m1 + k * sigma)) - delta;
      if (want != yh) {
        // A history with no light takes the fresh estimate's colour.
        vec3 tint = yh > 1e-30 ? h / yh : c.rgb / max(luminance(c.rgb), 1e-30);
        h = tint * max(want, 0.0);
        v.rgb = mix(c.rgb, h, w);
      }
    }
  }
  result = value = finite_or_zero(v);
}
