// Helpers shared by the post-processing effects (scripts/post.lua).
#ifndef LIMN_POST_GLSL
#define LIMN_POST_GLSL
#include "common.glsl"

// Under rgba16f's largest finite value (65504): what an effect may write to a
// half-float target without it turning into Inf.
const float HALF_MAX = 65000.0;

// NaN and negatives become 0, +Inf and anything above hi becomes hi. Effects
// call it on what they read (a lighting pass may have overflowed) and on what
// they write to a half-float target (hi = HALF_MAX).
vec3 hdr_clamp(vec3 c, float hi) {
  c = mix(c, vec3(0.0), isnan(c));
  return clamp(c, vec3(0.0), vec3(hi));
}
vec4 hdr_clamp(vec4 c, float hi) { return vec4(hdr_clamp(c.rgb, hi), c.a); }

// The mean of the 2 x 2 texels of s whose lowest corner is `corner`: one
// filtered read at their shared corner, where the bilinear weights are a
// quarter each (clamped at the border as texel clamps are): a quarter of the
// reads of four fetches (the reductions of dof and bloom).
vec4 block_mean(sampler2D s, ivec2 corner) { return texture(s, vec2(corner + 1) / vec2(textureSize(s, 0))); }

// Bloom's sum (bloom_add.frag, and hdr's passes that add it as they read the
// image): the image and `strength` of the blurred bright pass, each clamped
// as read and the sum under the half-float limit, so a very bright source
// cannot overflow to Inf.
vec3 bloom_sum(vec3 image, vec3 bloom, float strength) {
  return hdr_clamp(hdr_clamp(image, HALF_MAX) + max(strength, 0.0) * hdr_clamp(bloom, HALF_MAX), HALF_MAX);
}

// Linear eye depth at a G-buffer texel: dpt holds depth / far, 0 where no
// geometry was drawn (the background counts as the far plane).
float eye_depth(float depth01) {
  return dpt_view_depth(depth01 > 0.0 ? min(depth01, 1.0) : 1.0);
}

// A golden-angle (Vogel) spiral of n points filling the unit disc: point i
// at radius sqrt((i + 0.5) / n) in direction i times the golden angle. A loop
// over the points turns the direction by that angle each step (vogel_next)
// rather than take a sine and a cosine a point: on llvmpipe each costs a
// polynomial a lane. In float the turned direction drifts under 1e-5 over
// 256 steps (6.9e-6), 0.0002 pixels at dof's largest radius (32).
const vec2 GOLDEN_TURN = vec2(-0.73736887808, 0.67549029426); // cos, sin of 2.39996323, the golden angle
vec2 vogel_next(vec2 d) {
  return vec2(d.x * GOLDEN_TURN.x - d.y * GOLDEN_TURN.y, d.x * GOLDEN_TURN.y + d.y * GOLDEN_TURN.x);
}
vec2 vogel_point(int i, int n, vec2 d) { return sqrt((float(i) + 0.5) / float(max(n, 1))) * d; }
#endif
