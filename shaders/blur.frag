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

// The weight of tap q, whose spatial Gaussian is exp(-spatial): both
// Gaussians in one exp (llvmpipe's exp is a polynomial a lane), the centre's
// 1 / (z tolerance) taken once a pixel (inv_tol), not once a tap.
float weight_at(ivec2 q, float inv_tol, float expected, float spatial) {
  float w = 1.0, x = spatial;
#ifdef MASK
  w *= step(0.5, texelFetch(mask, q, 0).a);
#endif
#ifdef DEPTH
  float d = texelFetch(depth, q, 0).r, dz = (d - expected) * inv_tol;
  x += dz * dz;
#ifndef MASK
  w *= d > 0.0 ? 1.0 : 0.0;
#endif
#endif
  return w * exp(-x);
}

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
  float z = 0.0, slope = 0.0, inv_tol = 0.0;
#ifdef DEPTH
  z = texelFetch(depth, p, 0).r;
  inv_tol = 1.0 / (max(z, 1e-12) * DEPTH_TOLERANCE);
  float ahead = texelFetch(depth, clamp(p + axis, ivec2(0), last), 0).r - z;
  float behind = z - texelFetch(depth, clamp(p - axis, ivec2(0), last), 0).r;
  slope = abs(ahead) < abs(behind) ? ahead : behind;
#endif
  float wsum = weight_at(p, inv_tol, z, 0.0); // the centre's tap, fetched once
  if (wsum == 0.0) {
    dst = centre;
    return;
  }
  float sigma = 0.5 * reach, inv2s2 = 0.5 / (sigma * sigma);
  vec4 sum = wsum * centre;
  for (int i = -taps; i <= taps; i++) {
    if (i == 0) continue;
    ivec2 q = clamp(p + axis * i, ivec2(0), last);
    float w = weight_at(q, inv_tol, z + float(i) * slope, float(i * i) * inv2s2);
    sum += w * texelFetch(src, q, 0);
    wsum += w;
  }
  dst = wsum > 0.0 ? sum / wsum : centre; // the centre tap has weight 1
}
