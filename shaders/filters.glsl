// Geometry-aware filter weights shared by bilateral.frag and upsample.frag
// (seed 001, lines 684-713 and 990-1000): a tap counts by how far it lies
// off the centre's tangent plane (relative to the centre's depth, so the
// same at any distance) and by the angle between the normals. Measuring
// off the plane rather than in depth lets a floor seen at a grazing angle
// blur along its length while a step in depth stops it.
#ifndef LIMN_FILTERS_GLSL
#define LIMN_FILTERS_GLSL
#include "common.glsl"

struct Geometry {
  vec3 n, p;   // unit normal, world position
  float z;     // linear depth / far
  bool covered;
};

// The geometry of a filtered texel: texel q of an image `factor` times
// coarser than the G-buffer takes the G-buffer texel at its block's centre.
Geometry geometry_at(sampler2D nrm, sampler2D dpt, sampler2D mat, ivec2 q, int factor) {
  ivec2 size = textureSize(dpt, 0);
  ivec2 g = block_centre(q, factor, size);
  Geometry o;
  o.n = gbuffer_normal_decode(texelFetch(nrm, g, 0)).xyz;
  o.z = max(texelFetch(dpt, g, 0).r, 0.0);
  o.p = position_from_depth((vec2(g) + 0.5) / vec2(size), o.z);
  o.covered = texelFetch(mat, g, 0).a >= 0.5;
  return o;
}

// Range weight of tap t for centre c: Gaussian in the distance off c's
// plane over (z_c * far * sigma_depth) and in (1 - n_c.n_t) over
// sigma_normal. Background taps weigh 0.
float geometry_weight(Geometry c, Geometry t, float sigma_depth, float sigma_normal) {
  if (!t.covered) return 0.0;
  float scale = max(dpt_view_depth(c.z) * sigma_depth, 1e-30);
  float off = dot(c.n, t.p - c.p) / scale;
  float bend = (1.0 - dot(c.n, t.n)) / max(sigma_normal, 1e-6);
  return exp(-0.5 * (off * off + bend * bend));
}
#endif
