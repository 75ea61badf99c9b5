// Eye adaptation (seed 003, "Eye adaptation"): the luminance the eye is
// adapted to moves each frame the fraction `rate` of the way to this frame's
// log-average, so the gap shrinks by (1 - rate) a frame and a sudden change
// of view fades in instead of flickering. The first frame (nothing adapted
// yet: the persistent target starts cleared, g = 0) takes the average as is.
// Output: r = adapted luminance, g = 1 (valid), b = this frame's average, in
// radiance (the average of the pre-exposed image over the exposure), so that
// a history kept under another pre-exposure holds as it is; a = the tone
// mapping's scale 2^exposure * key / adapted (hdr_tonemap.frag), worked out
// once here rather than at every pixel (llvmpipe runs a uniform's exp2, log
// and divisions a lane).
#include "post.glsl"

uniform sampler2D average;   // hdr_reduce.frag's last level (1x1)
uniform sampler2D previous;  // last frame's output of this pass (persistent)
uniform float rate = 0.1;    // 0..1 of the gap a frame; 1: no adaptation
uniform float key = 0.18;      // a, 0.045..0.9 typical
uniform float exposure = 0.0;  // bias in stops

out vec4 adapted;

void main() {
  float mean_log = texelFetch(average, ivec2(0), 0).r;
  float avg = exp(clamp(mean_log + log(frame.exposure.y), -80.0, 80.0)); // exp(+-80) is finite in fp32
  vec4 prev = texelFetch(previous, ivec2(0), 0);
  bool valid = prev.g > 0.5 && !isnan(prev.r) && !isinf(prev.r) && prev.r > 0.0;
  float a = valid ? prev.r + (avg - prev.r) * saturate(rate) : avg;
  a = max(a, 1e-30);
  // With AUTO_KEY the key follows the adapted luminance (seed 001 fig 6.17:
  // darker views a lower key): Krawczyk et al. 2005,
  // key = 1.03 - 2 / (2 + log10(L + 1)), in the seed's 0.045..0.9.
  float L = isnan(a) || isinf(a) ? 1.0 : a;
  float k = key;
#ifdef AUTO_KEY
  k = clamp(1.03 - 2.0 / (2.0 + log(L + 1.0) / log(10.0)), 0.045, 0.9);
#endif
  // a / L <= 1e30 * 0.9: finite.
  adapted = vec4(a, 1.0, avg, exp2(clamp(exposure, -40.0, 40.0)) * (k / L));
}
