// The log-average luminance (seed 001 eq 2.1), one level of a reduction:
//   L_avg = exp( (1/N) sum ln(delta + L_w(x, y)) )
// Each output texel covers a BLOCK x BLOCK square of its source. The first
// level (FIRST) reads the HDR image, one pixel of each STEP x STEP (a meter:
// the log-average of a regular sixteenth of the pixels at STEP 4, for a
// sixteenth of the reads), and writes per block the mean of
// ln(delta + luminance) and how many pixels it read; later levels take the
// count-weighted mean of the level below. Blocks cut by the image's edge
// count only the pixels they hold, so the result is the exact mean of the
// pixels read for any size (glGenerateMipmap's box filter drops or blends
// edge texels of odd sizes). Output: r = mean ln, g = pixel count. The image is pre-exposed
// (common.glsl's exposed()) and delta is added to it as it is: the mean is of
// ln(delta + E L_w), hdr_adapt.frag takes ln E away, and an image lit 1e10
// times more adapts to the same picture. With BLOOM the first level reads
// the image plus `strength` of bloom's blurred bright pass (scripts/hdr.lua:
// bloom's sum is never written). With DOF (scripts/post.lua: depth of field
// at half size before it, its composite not written) the first level
// computes the composite at the pixels it reads (dof.glsl's dof_composite):
// the reduced composite's texel in their place, or each pixel with its
// texel's gather, moved the Cornell box's tone mapped image by 0.0067 a
// channel (test_hdr; near-black pixels, which the log weighs most, took the
// blurred box's light without the depth-aware upsampling).
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
#ifdef DOF
#include "dof.glsl"
uniform sampler2D foreign, small_coc; // dof_gather.frag's, dof_reduce.frag's (dpt: dof.glsl's)
#endif
#ifdef FIRST
uniform float delta = 1e-4; // against ln(0) (seed 001: "a small constant")
#endif
#ifdef BLOOM
uniform sampler2D bloom;
uniform float strength = 1.0;
#endif

#ifndef BLOCK
#define BLOCK 8
#endif
#ifndef STEP
#define STEP 1
#endif

out vec4 dst;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * (BLOCK * STEP), size = textureSize(src, 0);
  float sum = 0.0, count = 0.0;
  for (int y = 0; y < BLOCK; y++) {
    for (int x = 0; x < BLOCK; x++) {
      ivec2 q = base + ivec2(x, y) * STEP;
      if (any(greaterThanEqual(q, size))) continue;
#if defined(FIRST) && defined(DOF)
      vec4 t = vec4(dof_composite(src, foreign, small_coc, q), 1.0);
#else
      vec4 t = texelFetch(src, q, 0);
#endif
#ifdef FIRST
#ifdef BLOOM
      // The glow as tone mapping adds it (its bilinear enlargement): at one
      // pixel of 16 the filtered read costs little, and a texel under the
      // pixel moved the meter by 0.001 from the written sum's.
      t.rgb = bloom_sum(t.rgb, texture(bloom, (vec2(q) + 0.5) / vec2(size)).rgb, strength);
#endif
      // Up to 1e30 (an fp32 input may hold far more than a half float).
      float l = luminance(hdr_clamp(t.rgb, 1e30));
      sum += log(max(delta, 1e-30) + l);
      count += 1.0;
#else
      sum += t.r * t.g;
      count += t.g;
#endif
    }
  }
  dst = vec4(count > 0.0 ? sum / count : 0.0, count, 0.0, 0.0);
}
