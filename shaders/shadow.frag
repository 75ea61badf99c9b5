// Stores depth normalized to the light's range (not exp(c d): filtering in
// log space keeps large c finite, see esm_blur.frag), negated on faces the
// light sees from behind. With RSM (the RSM
// pass over the RSM views, scripts/shadow.lua), instead the reflective
// shadow map of seed 004 (lines 858-904): the sender's
// reflectance k_d albedo (its flux is the light's radiance there times this
// and the texel's area, rsm.glsl), its world normal turned toward the light
// and its world position, with the normal again in w (normal_pack: the
// gather reads both in one fetch). The pass clears every target to 1: a
// normal of length above 1, or a w above 0, marks an empty texel.
// With RSM_BACK (the pass shadow.rsm_back, rsm.solid_steps), the faces the
// light sees from behind alone, the nearest kept: where the first solid on
// the light's way through the texel ends, its position and its face's normal
// pointing away from the light (normal_pack, in w; the gather's
// rsm_inside_solid). The face's own normal (from the position's
// derivatives), not the mesh's: smooth normals lean off the face.
#include "common.glsl"

in vec3 world_pos;
uniform vec4 pass_depth;
#ifdef RSM_BACK
uniform mat4 pass_view_proj;
#endif
#if defined(RSM) || defined(ALPHA_MASK) || defined(ALPHA_BLEND)
in vec2 tex_uv;
#ifdef BASE_COLOR_TEXTURE
uniform sampler2D base_color_tex;
uniform mat3 base_color_xform; // KHR_texture_transform
#endif
#endif
#ifdef RSM
in vec3 world_normal;
uniform vec3 material_color;
uniform vec4 material_k; // k_a, k_d, k_s, shininess
layout(location = 0) out vec4 rsm_flux;
layout(location = 1) out vec4 rsm_nrm;
layout(location = 2) out vec4 rsm_pos;
#elif defined(RSM_BACK)
layout(location = 0) out vec4 rsm_back;
#else
layout(location = 0) out float depth01;
#endif

#ifdef TRANSMIT
// The transmittance output (lm_pass_desc.transmit): what a blended caster
// (ALPHA_BLEND, drawn after the opaque ones into this output alone) lets
// through, rgb, multiplied by blending into the light's other blended
// casters', and its depth in alpha, the least kept; an opaque caster writes
// nothing here. Lighting reads it beyond that depth (shadow.glsl): a lighter,
// tinted shadow, as shaders/transparent.frag lets light through, at normal
// incidence: (1 - a) + a t (1 - F0) base absorbed.
layout(location = TRANSMIT) out vec4 transmit;
#ifdef ALPHA_BLEND
#ifndef RSM
uniform vec3 material_color;
#endif
uniform vec4 material_glass;       // transmission, ior, attenuation distance, thickness
uniform vec3 material_attenuation; // attenuation colour
#ifndef ALPHA_MASK
uniform vec2 material_alpha;
#endif
vec3 glass_transmittance(vec4 texel) {
  vec3 base = saturate(material_color * texel.rgb);
  float a = saturate(material_alpha.x * texel.a), ior = clamp(material_glass.y, 1.0, 10.0);
  float r0 = (ior - 1.0) / (ior + 1.0);
  vec3 absorbed = vec3(1.0);
  if (material_glass.z > 0.0 && material_glass.w > 0.0) {
    float path = min(material_glass.w / material_glass.z, 1e4); // thickness over attenuation distance
    absorbed = exp(log(max(saturate(material_attenuation), vec3(1e-6))) * path);
  }
  return saturate(vec3(1.0 - a) + a * saturate(material_glass.x) * (1.0 - r0 * r0) * base * absorbed);
}
#endif
#endif

void main() {
#if defined(BASE_COLOR_TEXTURE) && (defined(RSM) || defined(ALPHA_MASK) || defined(ALPHA_BLEND))
  vec4 texel = texture(base_color_tex, (base_color_xform * vec3(tex_uv, 1.0)).xy);
#else
  vec4 texel = vec4(1.0);
#endif
#ifdef ALPHA_MASK
  if (alpha_masked(texel.a)) discard;
#endif
#ifdef RSM_BACK
  if (gl_FrontFacing) discard;
  // Away from the light: from its position (perspective), or along the clip depth's gradient in world
  // space (orthographic: the view-projection's third row).
  vec3 away = pass_depth.w > 0.0 ? world_pos - pass_depth.xyz
                                 : vec3(pass_view_proj[0][2], pass_view_proj[1][2], pass_view_proj[2][2]);
  vec3 face = safe_normalize(cross(dFdx(world_pos), dFdy(world_pos)), away);
  rsm_back = vec4(world_pos, normal_pack(dot(face, away) < 0.0 ? -face : face));
#elif !defined(RSM)
  // Perspective: distance from the light / range. Orthographic: window depth,
  // already linear (casters before the near plane are clamped onto it).
  float d = pass_depth.w > 0.0 ? saturate(length(world_pos - pass_depth.xyz) * pass_depth.w) : saturate(gl_FragCoord.z);
  // A face the light sees from behind is stored negated (its least magnitude
  // a normal float, so that a depth of 0 keeps its sign): such a face is dark
  // in its own light, so no lit receiver is that surface and lookups compare
  // against it without the bias meant for a receiver's own surface, which
  // lit the floor and walls beyond the back of a thin wall or ceiling up to
  // two texels from the seam (shadow.glsl: shadow_lit).
  depth01 = gl_FrontFacing ? d : -max(d, 1e-30);
#endif
#ifdef TRANSMIT
#ifdef ALPHA_BLEND
  transmit = vec4(glass_transmittance(texel), d);
#else
  transmit = vec4(1.0); // masked off: opaque casters leave it
#endif
#endif
#ifdef RSM
  vec3 albedo = material_color * texel.rgb;
  vec3 n = safe_normalize(world_normal, vec3(0.0, 1.0, 0.0));
  if (!gl_FrontFacing) n = -n; // two-sided, as the G-buffer
  rsm_flux = vec4(saturate(material_k.y) * saturate(albedo), 1.0);
  rsm_nrm = vec4(n, 0.0);
  rsm_pos = vec4(world_pos, normal_pack(n));
#endif
}
