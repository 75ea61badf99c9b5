// The coarse G-buffer for ISR (seed 000, Listing 3 step 2: CLR_4, NRM_4,
// DPT_4) and the frame's direct light (the senders' radiance): each coarse
// texel averages its FACTOR x FACTOR block. Only covered
// texels are averaged, so background (depth 0) cannot pull a depth toward the
// eye; the normal is renormalized; mat.a becomes the covered fraction.
#include "common.glsl"

#ifndef FACTOR
#define FACTOR 2
#endif

uniform sampler2D clr, nrm, dpt, mat, direct;

layout(location = 0) out vec4 out_clr;
layout(location = 1) out vec4 out_nrm;
layout(location = 2) out float out_dpt;
layout(location = 3) out vec4 out_mat;
layout(location = 4) out vec4 out_direct;

void main() {
  ivec2 last = textureSize(dpt, 0) - 1;
  ivec2 base = ivec2(gl_FragCoord.xy) * FACTOR;
  vec4 c = vec4(0.0), n = vec4(0.0), l = vec4(0.0);
  vec3 k = vec3(0.0);
  float d = 0.0, covered = 0.0;
  for (int y = 0; y < FACTOR; y++)
    for (int x = 0; x < FACTOR; x++) {
      ivec2 q = min(base + ivec2(x, y), last);
      vec4 m = texelFetch(mat, q, 0);
      float w = step(0.5, m.a);
      c += w * texelFetch(clr, q, 0);
      n += w * gbuffer_normal_decode(texelFetch(nrm, q, 0));
      l += w * texelFetch(direct, q, 0);
      d += w * texelFetch(dpt, q, 0).r;
      k += w * m.xyz;
      covered += w;
    }
  float inv = covered > 0.0 ? 1.0 / covered : 0.0;
  out_clr = c * inv;
  out_nrm = gbuffer_normal_encode(safe_normalize(n.xyz, vec3(0.0, 1.0, 0.0)), n.w * inv);
  out_dpt = d * inv;
  out_mat = vec4(k * inv, covered / float(FACTOR * FACTOR));
  out_direct = l * inv;
}
