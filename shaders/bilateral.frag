// Geometry-aware separable bilateral blur (seed 001, lines 684-713, 940-
// 959): one axis a pass, vertical then horizontal as Reinbothe et al. A tap
// weighs by a spatial Gaussian (sigma_space texels) times the geometry
// range weight of filters.glsl. Background texels pass through unchanged.
// With PAIR a second image (src2) is blurred with the same weights (SSDO's
// modulation factor and bounce, blurred together as the seed suggests).
// The pass may run at 1/factor of the G-buffer's size. With AGE (temporal
// reuse's history state at this size), a pixel of n frames takes
// aged_radius(radius, n, narrow) taps each side (common.glsl; blur.frag's AGE).
#include "filters.glsl"

uniform sampler2D src;
#ifdef PAIR
uniform sampler2D src2;
#endif
uniform sampler2D nrm, dpt, mat;
uniform ivec2 axis = ivec2(1, 0);
uniform int radius = 5;            // taps each side: 5 is the seed's 11 x 11
uniform float sigma_space = 3.0;   // texels
uniform float sigma_depth = 0.02;  // off-plane distance, fraction of the depth
uniform float sigma_normal = 0.2;  // 1 - cos of the angle between normals
uniform int factor = 1;
#ifdef AGE
uniform sampler2D age;
uniform float narrow = 0.25; // temporal.narrow
#endif

layout(location = 0) out vec4 dst;
#ifdef PAIR
layout(location = 1) out vec4 dst2;
#endif

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  vec4 sum = texelFetch(src, p, 0);
#ifdef PAIR
  vec4 sum2 = texelFetch(src2, p, 0);
#endif
  Geometry c = geometry_at(nrm, dpt, mat, p, factor);
#ifdef AGE
  int r = clamp(aged_radius(radius, texelFetch(age, p, 0).g, narrow), 0, 32);
#else
  int r = clamp(radius, 0, 32);
#endif
  if (c.covered && r > 0) {
    float inv2s2 = 0.5 / max(sigma_space * sigma_space, 1e-6), wsum = 1.0; // the centre weighs 1
    for (int i = -r; i <= r; i++) {
      ivec2 q = p + axis * i;
      if (i == 0 || any(lessThan(q, ivec2(0))) || any(greaterThan(q, last))) continue;
      float w = exp(-float(i * i) * inv2s2) *
                geometry_weight(c, geometry_at(nrm, dpt, mat, q, factor), sigma_depth, sigma_normal);
      sum += w * texelFetch(src, q, 0);
#ifdef PAIR
      sum2 += w * texelFetch(src2, q, 0);
#endif
      wsum += w;
    }
    sum /= wsum; // >= 1
#ifdef PAIR
    sum2 /= wsum;
#endif
  }
  dst = sum;
#ifdef PAIR
  dst2 = sum2;
#endif
}
