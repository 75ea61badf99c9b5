// The adaptive sample count of SSDO (seed 001, lines 840-870): an edge map
// at 1/16 of the output a side. Each texel looks at a 5 x 5 grid of
// G-buffer points spread over its 16 x 16 block and half a block around
// it, and takes the largest change of normal (1 - cos) and the largest
// distance off the centre's tangent plane (relative to its depth, so a
// floor seen at a grazing angle is no edge), with coverage changes counting
// as edges. Flat regions get 10 samples, gentle ones 20, edges 30.
#include "common.glsl"

uniform sampler2D nrm, dpt, mat; // full-size G-buffer
uniform float normal_edge = 0.1; // 1 - cos at which a region is an edge
uniform float depth_edge = 0.05; // off-plane distance / depth at which it is

out float count;

void main() {
  ivec2 size = textureSize(dpt, 0), centre = ivec2(gl_FragCoord.xy) * 16 + 8;
  ivec2 c = clamp(centre, ivec2(0), size - 1);
  vec3 n0 = gbuffer_normal_decode(texelFetch(nrm, c, 0)).xyz;
  float z0 = texelFetch(dpt, c, 0).r;
  vec3 p0 = position_from_depth((vec2(c) + 0.5) / vec2(size), z0);
  bool cov0 = texelFetch(mat, c, 0).a >= 0.5;
  float edge = 0.0;
  for (int y = -2; y <= 2; y++)
    for (int x = -2; x <= 2; x++) {
      ivec2 q = clamp(centre + ivec2(x, y) * 6, ivec2(0), size - 1);
      bool cov = texelFetch(mat, q, 0).a >= 0.5;
      if (cov != cov0) {
        edge = 1.0;
        continue;
      }
      if (!cov) continue;
      vec3 n = gbuffer_normal_decode(texelFetch(nrm, q, 0)).xyz;
      vec3 p = position_from_depth((vec2(q) + 0.5) / vec2(size), texelFetch(dpt, q, 0).r);
      float dz = abs(dot(n0, p - p0)) / max(z0 * frame.clip.y, 1e-12);
      edge = max(edge, max((1.0 - dot(n, n0)) / normal_edge, dz / depth_edge));
    }
  count = edge >= 1.0 ? 30.0 : (edge >= 0.25 ? 20.0 : 10.0);
}
