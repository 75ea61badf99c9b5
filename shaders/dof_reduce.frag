// Depth of field at reduced resolution, step 1: each texel of the 1/FACTOR
// image takes the mean colour of the FACTOR x FACTOR pixels under it and the
// circle of confusion of the nearest of them (scaled to the reduced pixels),
// so a foreground's blur still spreads and a sharp foreground still shields
// what lies behind it.
#include "post.glsl"

uniform sampler2D src, coc;

layout(location = 0) out vec4 dst;
layout(location = 1) out vec4 dst_coc;

#ifndef FACTOR
#define FACTOR 2
#endif

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * FACTOR, last = textureSize(src, 0) - 1;
  vec3 c = vec3(0.0);
  vec2 nearest = vec2(0.0, 1e30);
  for (int y = 0; y < FACTOR; y++)
    for (int x = 0; x < FACTOR; x++) {
      ivec2 q = min(base + ivec2(x, y), last);
      c += hdr_clamp(texelFetch(src, q, 0).rgb, HALF_MAX);
      vec2 cq = texelFetch(coc, q, 0).rg;
      if (cq.y < nearest.y) nearest = cq;
    }
  dst = vec4(hdr_clamp(c / float(FACTOR * FACTOR), HALF_MAX), 1.0);
  dst_coc = vec4(nearest.x / float(FACTOR), nearest.y, 0.0, 0.0);
}
