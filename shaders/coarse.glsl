// A coarse GI result brought to full size (seed 000, eq 27-28): depth-aware
// bilateral upsampling over the 2 x 2 coarse texels around a pixel, shared
// by the composites (isr_light.frag, and direct.frag with INDIRECT, which
// adds RSM or LPV light in the direct pass itself). Inputs: the coarse
// result `coarse` (rgb E, a A) and its depth `coarse_dpt`; the coverage is
// coarse_mat's (a coarse copy of the G-buffer) or with Z_MASK the depth's,
// 0 where nothing was drawn (a coarse view's depth, isr.coarse_view).
// QUAD_SHARED (isr.lua's composite, where the factor is a multiple of 4 that
// divides the output): the four pixels of each 2 x 2 quad lie between the
// same four coarse texels, so each reads one and takes the other three from
// its neighbours (quad_values): a quarter of the reads. Only in uniform
// control flow (fine derivatives).
#ifndef LIMN_COARSE_GLSL
#define LIMN_COARSE_GLSL

uniform sampler2D coarse, coarse_dpt;
#ifndef Z_MASK
uniform sampler2D coarse_mat;
#endif

// Eq 27's depth weight 1 / |z_p - z_i|, with |dz| relative to z_p (the same
// at any distance) and offset so that equal depths weigh 1 / EPS_Z, not Inf.
const float COARSE_EPS_Z = 0.01;

#ifdef QUAD_SHARED
// A value of each pixel of a 2 x 2 quad, in every pixel of it: v[i] is the
// pixel's at (i & 1, i >> 1) in the quad (odd: this pixel's place), its own
// value plus or minus fine derivatives (differences across the quad; two
// shuffles and a subtraction on llvmpipe, where a texel read costs about
// 5 ns). a + (b - a) is b bit for bit where b - a is exact: floats within
// a factor 2 of each other (Sterbenz), half floats within 2^13; else within
// a float's rounding.
void quad_values(vec4 own, bvec2 odd, out vec4 v[4]) {
  vec4 dx = dFdxFine(own);
  vec4 r0 = odd.x ? own - dx : own, r1 = odd.x ? own : own + dx; // this pixel's row of the quad
  vec4 d0 = dFdyFine(r0), d1 = dFdyFine(r1);
  v[0] = odd.y ? r0 - d0 : r0;
  v[1] = odd.y ? r1 - d1 : r1;
  v[2] = odd.y ? r0 : r0 + d0;
  v[3] = odd.y ? r1 : r1 + d1;
}
#endif

// Eq 27-28 at uv for a pixel of depth z (depth / far). When the weights are
// all about zero (no covered texel) the texel nearest in depth is taken.
vec4 coarse_upsample(vec2 uv, float z) {
  ivec2 size = textureSize(coarse, 0), last = size - 1;
  vec2 t = uv * vec2(size) - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 f = t - floor(t);
  vec4 sum = vec4(0.0), nearest = vec4(0.0, 0.0, 0.0, 1.0);
  float wsum = 0.0, nearest_dz = 1e30;
  // The four texels' E, depths and coverage, in the order (0, 0), (1, 0),
  // (0, 1), (1, 1) from base (clamped at the border).
  vec4 v[4], zs, cover;
#ifdef QUAD_SHARED
  bvec2 odd = bvec2(ivec2(gl_FragCoord.xy) & 1);
  ivec2 q = clamp(base + ivec2(odd), ivec2(0), last);
  quad_values(texelFetch(coarse, q, 0), odd, v);
  vec4 zc[4]; // depth, and coverage where the depth does not tell it
#ifdef Z_MASK
  quad_values(vec4(texelFetch(coarse_dpt, q, 0).r, 0.0, 0.0, 0.0), odd, zc);
#else
  quad_values(vec4(texelFetch(coarse_dpt, q, 0).r, step(0.5, texelFetch(coarse_mat, q, 0).a), 0.0, 0.0), odd, zc);
  cover = vec4(zc[0].y, zc[1].y, zc[2].y, zc[3].y);
#endif
  zs = vec4(zc[0].x, zc[1].x, zc[2].x, zc[3].x);
#else
  // The depths (and coverage) in one gather each, at the texels' shared
  // corner: x (0, 1), y (1, 1), z (1, 0), w (0, 0) from base.
  vec2 corner = (vec2(base) + 1.0) / vec2(size);
  zs = textureGather(coarse_dpt, corner, 0).wzxy;
#ifndef Z_MASK
  cover = step(0.5, textureGather(coarse_mat, corner, 3).wzxy);
#endif
  for (int i = 0; i < 4; i++) v[i] = texelFetch(coarse, clamp(base + ivec2(i & 1, i >> 1), ivec2(0), last), 0);
#endif
#ifdef Z_MASK
  cover = vec4(greaterThan(zs, vec4(0.0))); // a difference with 0 is exact: 0 stays 0
#endif
  for (int i = 0; i < 4; i++) {
    ivec2 o = ivec2(i & 1, i >> 1);
    vec2 wb2 = mix(1.0 - f, f, vec2(o));
    float dz = abs(z - zs[i]) / max(z, 1e-12);
    float w = wb2.x * wb2.y * cover[i] / (COARSE_EPS_Z + dz);
    sum += w * v[i];
    wsum += w;
    if (dz < nearest_dz) {
      nearest_dz = dz;
      nearest = v[i];
    }
  }
  return wsum > 1e-6 ? sum / wsum : nearest;
}
#endif
