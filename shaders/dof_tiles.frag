// Depth of field, step 1b: the least and greatest signed circle of
// confusion that can reach any pixel of a TILE x TILE block, so the gather
// (dof_gather.frag) spreads its taps over the largest |coc| only, and reads
// them at a quarter size where every circle it may meet is large and on one
// side of the focus. Without DILATE: the block's (the last row and column of
// tiles also take the pixels a floored tile count leaves over). With DILATE:
// over the tiles within max_radius pixels, which bounds every circle
// reaching the block.
#include "post.glsl"

uniform sampler2D src; // coc (rg: signed coc, depth), or the tiles' (least, greatest) with DILATE
uniform float max_radius = 8.0;

out vec4 dst;

#ifndef TILE
#define TILE 8
#endif

void main() {
  ivec2 t = ivec2(gl_FragCoord.xy);
  vec2 m = vec2(HALF_MAX, -HALF_MAX); // least, greatest
#ifdef DILATE
  ivec2 last = textureSize(src, 0) - 1;
  int k = int(ceil(max(max_radius, 0.0) / float(TILE)));
  for (int y = -k; y <= k; y++)
    for (int x = -k; x <= k; x++) {
      vec2 s = texelFetch(src, clamp(t + ivec2(x, y), ivec2(0), last), 0).rg;
      m = vec2(min(m.x, s.x), max(m.y, s.y));
    }
#else
  ivec2 size = textureSize(src, 0), tiles = max(size / TILE, ivec2(1));
  ivec2 lo = t * TILE, hi = mix(lo + TILE, size, equal(t, tiles - 1)); // the last tiles reach the edge
  for (int y = lo.y; y < min(hi.y, size.y); y++)
    for (int x = lo.x; x < min(hi.x, size.x); x++) {
      float c = texelFetch(src, ivec2(x, y), 0).r;
      m = vec2(min(m.x, c), max(m.y, c));
    }
#endif
  dst = vec4(m, 0.0, 1.0);
}
