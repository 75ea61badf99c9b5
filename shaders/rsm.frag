// Indirect light from reflective shadow maps (seed 004, lines 858-958; the
// maps: shadow.frag), on POV-Ray's scale (/work/shared/design/gi-scale.md):
//   E(p) = (1/pi) sum_q Phi_q max(0, n_p.D) max(0, n_q.-D) / |q - p|^2 w_q
// (seed eq 9-10 with D = (q - p) / |q - p|), where q runs over RSM texels,
// Phi_q = L_q A_q is the radiance leaving the sender (k_d albedo times the
// light's radiance there, light_incident: what the direct pass gives it,
// with cos cancelled by the area) times the texel's area seen from the light
// A_q (orthographic: a texel's world size squared; perspective: its size per
// unit distance squared times r^2 cos^3(off-axis angle)), and w_q the texels a
// sample stands for. The composite (isr_light.frag) multiplies by k_d albedo.
//
// The sampling and its options: rsm_gather (rsm.glsl's RSM_GATHER).
// TEMPORAL: temporal reuse (temporal.glsl): the result is the accumulation,
// and the history for the next frame goes to `next` and `next_state`; a
// pixel whose accumulation has converged takes no samples and keeps it.
// Output: rgb = E, a = 1 (RSM light occludes no ambient term), or with
// ACCESS the share of open sky the direct pass leaves the ambient term and
// the sky: 1 - sky_occlusion (1 - A), A from `access` (ssao.frag at this
// grid; scripts/rsm.lua), which the history does not keep (it is taken afresh).
// With STRIDE, each texel reads the G-buffer, STRIDE times finer, at its
// block's centre (isr.coarse_view); with Z it also writes that depth / far,
// 0 where nothing is drawn, into z (the view's depth).
#define RSM_GATHER
#include "rsm.glsl"
#ifdef TEMPORAL
#define NEXT 2 // where the history's outputs start (temporal.glsl's TEMPORAL_CLAMP)
#include "temporal.glsl"
#endif

#ifndef STRIDE
#define STRIDE 1
#endif

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat; // G-buffer, STRIDE times finer than the output
#ifdef ACCESS
uniform sampler2D access;             // r = A at this grid (ssao.frag)
uniform float sky_occlusion = 1.0;
#endif

layout(location = 0) out vec4 result;
#ifdef Z
layout(location = 1) out float z;
#endif
#ifdef TEMPORAL
layout(location = 2) out vec4 next;       // the history's value
layout(location = 3) out vec2 next_state; // and state: view depth (0 none), frames seen
#endif

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  const vec4 none = vec4(0.0, 0.0, 0.0, 1.0);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, block_centre(px, STRIDE, textureSize(dpt, 0)));
#ifdef Z
  z = s.covered ? s.depth01 : 0.0;
#endif
#ifdef TEMPORAL
  next = vec4(0.0);
  next_state = vec2(s.covered ? dpt_view_depth(s.depth01) : 0.0, 0.0);
#endif
#ifdef TEMPORAL_CLAMP
  temporal_fresh = vec4(0.0, 0.0, 0.0, -1.0);
#endif
  if (!s.covered) {
    result = none;
    return;
  }
#ifdef ACCESS
  float open = 1.0 - saturate(sky_occlusion) * (1.0 - saturate(texelFetch(access, px, 0).r));
#else
  float open = 1.0;
#endif
#ifdef TEMPORAL
  vec4 h;
  float held;
  bool found = temporal_history(uv, s.depth01, h, held);
  if (found && temporal_converged(held, px)) { // kept as it is
    next = vec4(h.rgb, 1.0);
    next_state.y = max(frames, 1.0);
    result = vec4(next.rgb, open);
    return;
  }
#endif

  vec3 v = rsm_gather(s, px, dpt);
#ifdef TEMPORAL
  next = temporal_accumulate(vec4(v, 1.0), found, h, held, next_state.y);
  v = next.rgb;
#endif
  result = vec4(v, open);
}
