// Tone mapping (seed 001 eq 2.2-2.4, Reinhard): scale by the key over the
// adapted log-average luminance, times 2^exposure, and map with a white point:
//   L = 2^exposure * a / L_avg * L_w,   L_d = L (1 + L / L_white^2) / (1 + L)
// Colour keeps its hue: rgb * L_d / L_w. The result is linear display values
// in [0, 1] (the output stage encodes sRGB). 2^exposure * a / L_avg comes
// from hdr_adapt.frag (its alpha), with AUTO_KEY's key. With BLOOM it adds
// bloom's blurred bright pass first (hdr_reduce.frag). With OUTPUT_STAGE
// (scripts/hdr.lua's fold_output) it is the frame's output stage too: the
// mapped image goes to output.glsl's outputs, not written and read again.
// With DOF (scripts/post.lua: depth of field at half size before it) src is
// the image under depth of field and the pass lays the gather's light over
// it as it reads (dof.glsl's dof_composite): the composite is not written.
#include "post.glsl"
#include "output.glsl"
#ifdef DOF
#include "dof.glsl"
uniform sampler2D foreign, small_coc; // dof_gather.frag's, dof_reduce.frag's (dpt: dof.glsl's)
#endif

in vec2 uv;
uniform sampler2D src;
uniform sampler2D adapted;     // hdr_adapt.frag (1x1): a = 2^exposure * key / adapted luminance
uniform float white = 4.0;     // L_white in scaled units, > 0
#ifdef BLOOM
uniform sampler2D bloom;
uniform float strength = 1.0;
#endif

#ifndef OUTPUT_STAGE
out vec4 dst;
#endif

void main() {
#ifdef DOF
  vec3 c = dof_composite(src, foreign, small_coc, ivec2(gl_FragCoord.xy)); // in [0, HALF_MAX]
#else
  vec3 c = hdr_clamp(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb, 1e30);
#endif
#ifdef BLOOM
  c = bloom_sum(c, texture(bloom, uv).rgb, strength);
#endif
  float scale = texelFetch(adapted, ivec2(0), 0).a;
  float lw = luminance(c); // pre-exposed (exposed()); the adapted luminance is radiance
  // lw in radiance is clamped and scale <= 0.9e30 (hdr_adapt.frag), so L is
  // finite up to ~1e38 and is then capped.
  float l = min(scale * min(lw * frame.exposure.y, 1e30), 1e30);
  float w = max(white, 1e-3);
  float ld = l / (1.0 + l) * (1.0 + min(l / (w * w), 1e30));
  // rgb * ld / lw; where lw is ~0 the colour is ~0 too.
  vec3 mapped = lw > 1e-30 ? c * (min(ld, 1e4) / lw) : vec3(0.0);
#ifdef OUTPUT_STAGE
  output_write(saturate(mapped));
#else
  dst = vec4(saturate(mapped), 1.0);
#endif
}
