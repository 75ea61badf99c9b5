// The light a traced ray brings as its second bounce (rsm.trace; scripts/isr.lua),
// at each texel of the coarse grid: the ray the first march lost
// (isr_march.frag's TRACE) met, by the CPU's "trace" (engine/trace), a
// surface the screen cannot show; that surface sends on its first bounce,
// k_d albedo E1, E1 the RSM's gather at it (rsm.glsl's rsm_gather with every
// sender: the hit is off screen, so neither the camera's senders nor its
// depth buffer say anything there) times rsm_k, as a sender of the
// screen's sends k_d albedo times the first step's E. A miss (the ray left
// the scene) brings nothing: what it sees of the sky is the ambient term's,
// through the march's accessibility, as for a ray the march saw leave.
// Outputs: light (rgb: the radiance sent toward p; a: 1 where a ray was
// traced) and albedo (rgb: the hit's k_d albedo, 0 for a miss, which
// isr_bounce.frag's later bounces (the series' ratio) take; a: 1 for a hit,
// whose lost rays then see a surface, not the sky). BLOCK (rsm.trace
// under 1): a texel per block of pixels, whose ray the engine chose.
#include "gbuffer.glsl"
#include "rsm.glsl"

uniform sampler2D hit_clr, hit_nrm, hit_pos, hit_mat; // the trace's hit record (std.frag's layout)
#ifndef BLOCK
uniform sampler2D rays_o; // the march's rays (w 0: none)
#endif
uniform sampler2D dpt; // the G-buffer's depth (rsm_gather's argument; unused without EXCLUDE_SEEN, VISIBILITY)
uniform float rsm_k = 1.0; // the RSM light's factor (rsm.k)

layout(location = 0) out vec4 light;
layout(location = 1) out vec4 albedo;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  light = vec4(0.0);
  albedo = vec4(0.0);
#ifdef BLOCK
  // A block of pixels' one ray (rsm.trace under 1): the engine marks a traced one, hit or miss, in w
  if (texelFetch(hit_pos, px, 0).w < 0.5) return;
#else
  if (texelFetch(rays_o, px, 0).w < 0.5) return; // nothing lost: nothing traced
#endif
  light.a = 1.0;
  vec4 m = texelFetch(hit_mat, px, 0);
  if (m.a < 0.5) return; // a miss
  vec4 c = texelFetch(hit_clr, px, 0);
  Surface s = gbuffer_decode(c, texelFetch(hit_nrm, px, 0), 0.0, m, vec2(0.5)); // its normal faces the ray
  s.p = texelFetch(hit_pos, px, 0).xyz; // given, not rebuilt from a depth
  vec3 rho = clamp(m.y, 0.0, 1.0) * clamp(c.rgb, 0.0, 1.0);
  light.rgb = finite_or_zero(rho * max(rsm_k, 0.0) * rsm_gather(s, px, dpt));
  albedo = vec4(rho, 1.0); // a: a hit, which isr_bounce.frag takes from the sky's share A
}
