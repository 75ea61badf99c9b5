// The exposure meter (engine/render's frame_exposure): how bright the lit
// image is, read back without a stall for the next frame's pre-exposure.
// Each texel of a SIDE x SIDE target covers a block of the image (pre-exposed
// radiance) and reads at most SAMPLES x SAMPLES of its pixels, evenly
// strided (a meter, not a sum: a few thousand reads at any output size):
//   r  the largest channel of the brightest finite pixel read
//   g  how many read were Inf or at half floats' ceiling (an overflow; effects
//      clamp to post.glsl's HALF_MAX, 65000)
// NaN counts in neither: a pass's fault, not the exposure's.
#include "common.glsl"

uniform sampler2D src;

out vec4 meter;

void main() {
  ivec2 size = textureSize(src, 0), cell = ivec2(gl_FragCoord.xy);
  ivec2 lo = cell * size / SIDE, hi = max((cell + 1) * size / SIDE, lo + 1);
  ivec2 stride = max((hi - lo) / SAMPLES, ivec2(1));
  float peak = 0.0, over = 0.0;
  for (int y = lo.y; y < hi.y; y += stride.y)
    for (int x = lo.x; x < hi.x; x += stride.x) {
      vec3 c = texelFetch(src, ivec2(x, y), 0).rgb;
      float m = max(c.r, max(c.g, c.b));
      if (isnan(m)) continue;
      if (isinf(m) || m >= 65000.0) over += 1.0;
      else peak = max(peak, m);
    }
  meter = vec4(peak, over, 0.0, 1.0);
}
