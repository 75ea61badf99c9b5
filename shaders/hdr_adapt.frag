// Eye adaptation (seed 003, "Eye adaptation"): the luminance the eye is
// adapted to moves each frame the fraction `rate` of the way to this frame's
// log-average, so the gap shrinks by (1 - rate) a frame and a sudden change
// of view fades in instead of flickering. The first frame (nothing adapted
// yet: the persistent target starts cleared, g = 0) takes the average as is.
// Output: r = adapted luminance, g = 1 (valid), b = this frame's average, in
// radiance (the average of the pre-exposed image over the exposure), so that
// a history kept under another pre-exposure holds as it is.
#include "post.glsl"

uniform sampler2D average;   // hdr_reduce.frag's last level (1x1)
uniform sampler2D previous;  // last frame's output of this pass (persistent)
uniform float rate = 0.1;    // 0..1 of the gap a frame; 1: no adaptation

out vec4 adapted;

void main() {
  float mean_log = texelFetch(average, ivec2(0), 0).r;
  float avg = exp(clamp(mean_log + log(frame.exposure.y), -80.0, 80.0)); // exp(+-80) is finite in fp32
  vec4 prev = texelFetch(previous, ivec2(0), 0);
  bool valid = prev.g > 0.5 && !isnan(prev.r) && !isinf(prev.r) && prev.r > 0.0;
  float a = valid ? prev.r + (avg - prev.r) * saturate(rate) : avg;
  adapted = vec4(max(a, 1e-30), 1.0, avg, 0.0);
}
