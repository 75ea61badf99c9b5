// Separable Gaussian blur, one axis a pass (seed 000, Listing 3 step 4).
// With MASK, texels whose mask.a < 0.5 (background) neither give nor take:
// indirect light does not bleed into the sky and back. With DEPTH, a tap
// whose linear depth is off the centre's plane by more than a few percent
// weighs less, so the blur does not carry light across silhouettes (the
// halos the seed names as a weakness, lines 2592-2688). The plane's slope
// is the smaller one-sided difference, which does not straddle an edge, so
// a floor seen at a grazing angle still blurs along its length. With DEPTH
// and no MASK, a depth of 0 (nothing drawn) is the mask. With AGE (temporal
// reuse's history state, g: the frames a pixel holds), a pixel of n frames takes
// a Gaussian of reach radius / n^narrow (sigma half of it; temporal.narrow):
// a new or disoccluded pixel is blurred in full, at narrow 1/4 a converged
// one (36 frames) with a reach of 1.6 (2 taps) at radius 4, which still
// smooths the 4 x 4 pattern's grain (1 tap left it visible on the room's
// walls). (radius / sqrt(n), the same noise for n frames of samples, left
// converged pixels unblurred: more error against the references,
// docs/gi-combined.md.)
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;
#ifdef MASK
uniform sampler2D mask;
#endif
#ifdef DEPTH
uniform sampler2D depth;
const float DEPTH_TOLERANCE = 0.05; // relative depth difference of weight 1/e
#endif
uniform ivec2 axis = ivec2(1, 0); // (1, 0) horizontal, (0, 1) vertical
uniform int radius = 4;           // taps each side; sigma = radius / 2
#ifdef AGE
uniform sampler2D age;
uniform float narrow = 0.25; // the reach shrinks as n^-narrow (temporal.narrow)
#endif

out vec4 dst;

// The tap at q's weight beside the Gaussian's; d: its depth (DEPTH), which
// the centre's plane expects at `expected`.
float weight_at(ivec2 q, float d, float z, float expected) {
  float w = 1.0;
#ifdef MASK
  w *= step(0.5, texelFetch(mask, q, 0).a);
#endif
#ifdef DEPTH
  float dz = (d - expected) / (max(z, 1e-12) * DEPTH_TOLERANCE);
  w *= exp(-dz * dz);
#ifndef MASK
  w *= d > 0.0 ? 1.0 : 0.0;
#endif
#endif
  return w;
}

// Tap i of the Gaussian (i != 0, depth d), added to sum and its weight to wsum.
void add_tap(ivec2 p, int i, float d, ivec2 last, float z, float slope, float inv2s2, inout vec4 sum,
             inout float wsum) {
  ivec2 q = clamp(p + axis * i, ivec2(0), last);
  float w = exp(-float(i * i) * inv2s2) * weight_at(q, d, z, z + float(i) * slope);
  sum += w * texelFetch(src, q, 0);
  wsum += w;
}

#ifdef DEPTH
// The depths of taps i and i + 1 in one gather at the corner they share
// (clamped at the border, as the taps are): a gather costs about a fetch.
vec2 depth_pair(ivec2 p, int i) {
  vec2 corner = vec2(p + axis * (i + 1) + (ivec2(1) - axis)) / vec2(textureSize(depth, 0));
  vec4 g = textureGather(depth, corner, 0); // w: (i0, j0), z: (i1, j0), x: (i0, j1)
  return vec2(g.w, axis.x == 1 ? g.z : g.x);
}
#endif

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  vec4 centre = texelFetch(src, p, 0);
#ifdef AGE
  // Its Gaussian narrows smoothly as the history grows: whole taps (sigma half of them, as without AGE)
  // made the image jump where the rounding stepped (on the door sequence, a flicker spike a few frames
  // after the door stopped; rsm+esm's flicker 0.00270 against 0.00265 with this).
  float reach = aged_reach(radius, texelFetch(age, p, 0).g, narrow);
  int taps = int(ceil(reach - 0.01));
#else
  float reach = float(radius);
  int taps = radius;
#endif
  if (taps < 1) {
    dst = centre;
    return;
  }
  float z = 0.0, slope = 0.0;
#ifdef DEPTH
  vec2 below = depth_pair(p, -1), above = depth_pair(p, 1); // taps -1, 0 and 1, 2
  z = below.y;
  float ahead = above.x - z, behind = z - below.x;
  slope = abs(ahead) < abs(behind) ? ahead : behind;
#endif
  float wsum = weight_at(p, z, z, z); // the centre's tap, fetched once
  if (wsum == 0.0) {
    dst = centre;
    return;
  }
  float sigma = 0.5 * reach, inv2s2 = 0.5 / (sigma * sigma);
  vec4 sum = wsum * centre;
  // Two loops around the centre: a `continue` at i = 0 would still cost a
  // tap's reads, which a software rasterizer makes under a mask. With DEPTH
  // the taps go in pairs, one gather of depths each.
#ifdef DEPTH
  for (int i = -taps; i < 0; i += 2) {
    vec2 d = depth_pair(p, i);
    add_tap(p, i, d.x, last, z, slope, inv2s2, sum, wsum);
    if (i + 1 < 0) add_tap(p, i + 1, d.y, last, z, slope, inv2s2, sum, wsum);
  }
  add_tap(p, 1, above.x, last, z, slope, inv2s2, sum, wsum);
  if (taps >= 2) add_tap(p, 2, above.y, last, z, slope, inv2s2, sum, wsum);
  for (int i = 3; i <= taps; i += 2) {
    vec2 d = depth_pair(p, i);
    add_tap(p, i, d.x, last, z, slope, inv2s2, sum, wsum);
    if (i + 1 <= taps) add_tap(p, i + 1, d.y, last, z, slope, inv2s2, sum, wsum);
  }
#else
  for (int i = -taps; i < 0; i++) add_tap(p, i, 0.0, last, z, slope, inv2s2, sum, wsum);
  for (int i = 1; i <= taps; i++) add_tap(p, i, 0.0, last, z, slope, inv2s2, sum, wsum);
#endif
  dst = wsum > 0.0 ? sum / wsum : centre; // the centre tap has weight 1
}
