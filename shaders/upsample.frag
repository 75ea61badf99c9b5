// Joint bilateral upsampling (Kopf et al., seed 001 eq 3.12, lines 700-713,
// 1300-1307): each full-size pixel averages the 3 x 3 coarse texels around
// it, weighted by a spatial Gaussian in coarse texels and by the geometry
// range weight of filters.glsl between the full-size pixel and each coarse
// texel's G-buffer sample. Not separable, as the seed keeps it. Where every
// weight vanishes (a sliver the coarse image missed) the coarse texel
// nearest in depth is taken. With PAIR, src2 goes the same way.
#include "filters.glsl"

in vec2 uv;
uniform sampler2D src; // coarse, 1/factor of the output
#ifdef PAIR
uniform sampler2D src2;
#endif
uniform sampler2D nrm, dpt, mat; // full-size G-buffer
uniform int factor = 2;
uniform float sigma_space = 1.0;  // coarse texels
uniform float sigma_depth = 0.02;
uniform float sigma_normal = 0.2;

layout(location = 0) out vec4 dst;
#ifdef PAIR
layout(location = 1) out vec4 dst2;
#endif

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  int f = max(factor, 1);
  Geometry c = geometry_at(nrm, dpt, mat, p, 1);
  vec2 pc = (vec2(p) + 0.5) / float(f) - 0.5; // p in coarse texel coordinates
  ivec2 base = clamp(ivec2(floor(pc + 0.5)), ivec2(0), last);
  vec4 sum = vec4(0.0), nearest = texelFetch(src, base, 0);
#ifdef PAIR
  vec4 sum2 = vec4(0.0), nearest2 = texelFetch(src2, base, 0);
#endif
  float wsum = 0.0, nearest_dz = 1e30, inv2s2 = 0.5 / max(sigma_space * sigma_space, 1e-6);
  for (int y = -1; y <= 1; y++)
    for (int x = -1; x <= 1; x++) {
      ivec2 q = clamp(base + ivec2(x, y), ivec2(0), last);
      Geometry t = geometry_at(nrm, dpt, mat, q, f);
      vec2 d = vec2(q) - pc;
      float w = exp(-dot(d, d) * inv2s2) * geometry_weight(c, t, sigma_depth, sigma_normal);
      vec4 v = texelFetch(src, q, 0);
      sum += w * v;
#ifdef PAIR
      vec4 v2 = texelFetch(src2, q, 0);
      sum2 += w * v2;
#endif
      wsum += w;
      float dz = t.covered ? abs(t.z - c.z) : 1e20;
      if (dz < nearest_dz) {
        nearest_dz = dz;
        nearest = v;
#ifdef PAIR
        nearest2 = v2;
#endif
      }
    }
  bool ok = c.covered && wsum > 1e-6;
  dst = ok ? sum / wsum : nearest;
#ifdef PAIR
  dst2 = ok ? sum2 / wsum : nearest2;
#endif
}
