// Deferred direct light over the G-buffer: position rebuilt from linear depth.
// INDIRECT: indirect light that needs no direct light of this frame (RSM,
// LPV; vpl.frag's refinement does the same for VPLs) is added here, a
// coarse result upsampled (coarse.glsl), rather than in a composite pass of
// its own: L = D + k_a L_a albedo A + k k_d albedo E (the physical composite
// of isr_light.frag; A = 1 from the RSM, the share of open sky from the LPV's
// geometry volume: lpv_lookup.frag's SKY_OCCLUSION).
#include "gbuffer.glsl"
#ifdef INDIRECT
#include "coarse.glsl"
uniform float k = 1.0;
#endif

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat;
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);

out vec4 lit;

void main() {
  // Unfiltered: a pass at the G-buffer's size reads each texel at its centre,
  // where filtering changes nothing but costs four texels a read on a software
  // rasterizer (office moving, 640x480, llvmpipe: direct 1.04-1.33x faster over
  // four alternated runs on a shared machine).
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, ivec2(uv * vec2(textureSize(dpt, 0))));
  if (!s.covered) {
    lit = vec4(background_seen(background, uv), 1.0);
    return;
  }
  vec3 l = direct_light(s, ambient);
#ifdef INDIRECT
  vec4 e = coarse_upsample(uv, s.depth01);
  l += gi_reflected(s, k, e.rgb) - (1.0 - saturate(e.a)) * ambient_light(s, ambient);
#endif
  lit = vec4(l, 1.0);
}
