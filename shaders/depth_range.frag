// The camera depths the frame sees, one level of a min/max reduction (as
// sample distribution shadow maps fit cascades to them). Each output texel
// covers a BLOCK x BLOCK square of its source. The first level (FIRST) reads
// the G-buffer's dpt (depth / far, 0 where no geometry is); later levels the
// level below. Output: r = least depth, g = greatest; a block that sees no
// geometry holds r = 2 > g = 0, which min and max then pass over.
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;

#ifndef BLOCK
#define BLOCK 8
#endif

out vec4 range;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * BLOCK, size = textureSize(src, 0);
  vec2 r = vec2(2.0, 0.0);
  for (int y = 0; y < BLOCK; y++) {
    for (int x = 0; x < BLOCK; x++) {
      ivec2 q = base + ivec2(x, y);
      if (any(greaterThanEqual(q, size))) continue;
#ifdef FIRST
      float d = texelFetch(src, q, 0).r;
      if (d > 0.0) r = vec2(min(r.x, d), max(r.y, d));
#else
      vec2 d = texelFetch(src, q, 0).rg;
      r = vec2(min(r.x, d.x), max(r.y, d.y));
#endif
    }
  }
  range = vec4(r, 0.0, 1.0);
}
