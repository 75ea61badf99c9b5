// A coarse GI result brought to full size (seed 000, eq 27-28): depth-aware
// bilateral upsampling over the 2 x 2 coarse texels around a pixel, shared
// by the composites (isr_light.frag, and direct.frag with INDIRECT, which
// adds RSM or LPV light in the direct pass itself). Inputs: the coarse
// result `coarse` (rgb E, a A) and its depth `coarse_dpt`; the coverage is
// coarse_mat's (a coarse copy of the G-buffer) or with Z_MASK the depth's,
// 0 where nothing was drawn (a coarse view's depth, isr.coarse_view).
#ifndef LIMN_COARSE_GLSL
#define LIMN_COARSE_GLSL

uniform sampler2D coarse, coarse_dpt;
#ifndef Z_MASK
uniform sampler2D coarse_mat;
#endif

// Eq 27's depth weight 1 / |z_p - z_i|, with |dz| relative to z_p (the same
// at any distance) and offset so that equal depths weigh 1 / EPS_Z, not Inf.
const float COARSE_EPS_Z = 0.01;

// Eq 27-28 at uv for a pixel of depth z (depth / far). When the weights are
// all about zero (no covered texel) the texel nearest in depth is taken.
vec4 coarse_upsample(vec2 uv, float z) {
  ivec2 size = textureSize(coarse, 0), last = size - 1;
  vec2 t = uv * vec2(size) - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 f = t - floor(t);
  vec4 sum = vec4(0.0), nearest = vec4(0.0, 0.0, 0.0, 1.0);
  float wsum = 0.0, nearest_dz = 1e30;
  // The four texels' depths (and coverage) in one gather each, at their
  // shared corner (clamped at the border, as q is): x (0, 1), y (1, 1),
  // z (1, 0), w (0, 0) from base.
  vec2 corner = (vec2(base) + 1.0) / vec2(size);
  vec4 zs = textureGather(coarse_dpt, corner, 0).wzxy;
#ifdef Z_MASK
  vec4 cover = vec4(greaterThan(zs, vec4(0.0)));
#else
  vec4 cover = step(0.5, textureGather(coarse_mat, corner, 3).wzxy);
#endif
  for (int i = 0; i < 4; i++) {
    ivec2 o = ivec2(i & 1, i >> 1), q = clamp(base + o, ivec2(0), last);
    vec2 wb2 = mix(1.0 - f, f, vec2(o));
    vec4 v = texelFetch(coarse, q, 0);
    float dz = abs(z - zs[i]) / max(z, 1e-12);
    float w = wb2.x * wb2.y * cover[i] / (COARSE_EPS_Z + dz);
    sum += w * v;
    wsum += w;
    if (dz < nearest_dz) {
      nearest_dz = dz;
      nearest = v;
    }
  }
  return wsum > 1e-6 ? sum / wsum : nearest;
}
#endif
