// What a texel of the reflective shadow maps (shadow.frag with RSM: k_d
// albedo, normal, position) stands for, shared by the passes that read them
// (rsm.frag, vpl.frag, lpv_inject.vert). Needs `#define SHADOWS` (the
// shadow views' block, shadow.glsl).
#ifndef LIMN_RSM_GLSL
#define LIMN_RSM_GLSL
#include "gbuffer.glsl"

// The area of the texel at tile coordinates t (0..1) of view sv (a tile of
// `tile` texels a side) whose sender lies at q, as the light sees it:
// orthographic, a texel's world size squared; perspective, its size per unit
// of distance squared times r^2 cos(off-axis angle). Times the light's
// radiance there (light_incident) and the k_d albedo, it is the sender's
// radiance times area (POV-Ray's diffuse convention, no 1/pi): cos of the
// light's incidence cancels with the projection.
float rsm_texel_area(ShadowView sv, vec2 t, vec3 q, float tile) {
  float area = sv.texel.x * sv.texel.x;
  if (sv.depth.w > 0.0) {
    vec2 tn = (t * 2.0 - 1.0) * sv.texel.x * tile * 0.5; // tan of the off-axis angles
    area *= dot(q - sv.depth.xyz, q - sv.depth.xyz) * inversesqrt(1.0 + dot(tn, tn));
  }
  return area;
}

// Does the camera see q: on screen and within 2% of the depth buffer's
// depth (`dpt`, the G-buffer's) there? The combined techniques leave such
// senders to the screen-space pass (docs/gi-combined.md).
bool rsm_seen(sampler2D dpt, vec3 q) {
  vec4 c = frame.view_proj * vec4(q, 1.0);
  if (c.w <= 1e-12) return false;
  vec2 s = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))) return false;
  float z = -(frame.view * vec4(q, 1.0)).z * frame.clip.z, zb = texture(dpt, s).r;
  return abs(z - zb) <= 0.02 * max(zb, 1e-12);
}

#endif
