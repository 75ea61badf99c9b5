// Bloom's bright pass (seed 001, lines 1355-1400): at a lower resolution,
// keep what exceeds `threshold`, with a soft knee of width `knee` so that the
// cut does not show as an edge. Each output texel averages the FACTOR x FACTOR
// source texels under it, so no bright pixel falls between the taps.
// With DOF (scripts/post.lua: depth of field at half size before it, its
// composite not written) the source is that composite, read at the reduced
// size where FACTOR allows (dof.glsl's dof_composite_small), else computed.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
#ifdef DOF
#include "dof.glsl"
uniform sampler2D small, foreign, small_coc; // dof_reduce.frag's image and (coc, depth), dof_gather.frag's
#endif
uniform float threshold = 1.0; // luminance-like brightness where bloom starts
uniform float knee = 0.5;      // soft transition width, >= 0

#ifndef FACTOR
#define FACTOR 2
#endif

out vec4 dst;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * FACTOR;
#if defined(DOF) && FACTOR == 1
  vec3 c = dof_composite(src, foreign, small_coc, base);
#elif defined(DOF)
  // The FACTOR / 2 x FACTOR / 2 reduced texels under the output texel, each
  // its own (1 - a) small + foreign (a mean of products: no filtered read).
  vec3 c = vec3(0.0);
  for (int y = 0; y < FACTOR / 2; y++)
    for (int x = 0; x < FACTOR / 2; x++) c += dof_composite_small(small, foreign, base / 2 + ivec2(x, y));
  c = hdr_clamp(c / float(FACTOR * FACTOR / 4), HALF_MAX);
#elif FACTOR == 1
  vec3 c = hdr_clamp(texelFetch(src, base, 0).rgb, HALF_MAX);
#else
  // Each 2 x 2 of the source texels in one filtered read (block_mean).
  vec3 c = vec3(0.0);
  for (int y = 0; y < FACTOR; y += 2)
    for (int x = 0; x < FACTOR; x += 2) c += block_mean(src, base + ivec2(x, y)).rgb;
  c = hdr_clamp(c / float(FACTOR * FACTOR / 4), HALF_MAX);
#endif
  // Quadratic soft knee: the kept fraction rises smoothly from
  // threshold - knee to threshold + knee, then follows brightness - threshold.
  float t = max(threshold, 0.0), k = max(knee, 0.0);
  float b = max(c.r, max(c.g, c.b)) * frame.exposure.y; // in radiance, as the threshold (c is pre-exposed)
  float soft = clamp(b - t + k, 0.0, 2.0 * k);
  soft = soft * soft / (4.0 * k + 1e-4);
  float kept = max(soft, b - t) / max(b, 1e-4);
  dst = vec4(hdr_clamp(c * saturate(kept), HALF_MAX), 1.0);
}
