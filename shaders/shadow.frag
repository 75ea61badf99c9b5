// Stores depth normalized to the light's range (not exp(c d): filtering in
// log space keeps large c finite, see esm_blur.frag). With RSM, the
// reflective shadow map of seed 004 (lines 858-904) as well: the sender's
// reflectance k_d albedo (its flux is the light's radiance there times this
// and the texel's area, rsm.glsl), its world normal turned toward the light
// and its world position, with the normal again in w (normal_pack: the
// gather reads both in one fetch). The pass clears every target to 1: a
// normal of length above 1, or a w above 0, marks an empty texel.
#include "common.glsl"

in vec3 world_pos;
uniform vec4 pass_depth;
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
layout(location = 1) out vec4 rsm_flux;
layout(location = 2) out vec4 rsm_nrm;
layout(location = 3) out vec4 rsm_pos;
#endif

layout(location = 0) out float depth01;

#ifdef ALPHA_BLEND
// A blended material (alphaMode BLEND) casts a lighter shadow: the share of
// light it stops, glass_opacity, of its texels are drawn, in a 4x4 ordered
// dither that the shadow filter (ESM's blur, PCF's taps) averages. Untinted:
// the map holds depth alone.
#ifndef RSM
uniform vec3 material_color;
#endif
uniform vec4 material_glass; // transmission, ior, attenuation distance, thickness
#ifndef ALPHA_MASK
uniform vec2 material_alpha;
#endif
bool glass_dithered_out(vec4 texel) {
  const float bayer[16] = float[](0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0, 3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0);
  ivec2 q = ivec2(gl_FragCoord.xy) & 3;
  vec3 base = saturate(material_color * texel.rgb);
  float passes = saturate(material_glass.x) * (base.r + base.g + base.b) / 3.0;
  float opacity = saturate(material_alpha.x * texel.a) * (1.0 - passes);
  return (bayer[q.y * 4 + q.x] + 0.5) / 16.0 >= opacity;
}
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
#ifdef ALPHA_BLEND
  if (glass_dithered_out(texel)) discard;
#endif
  if (pass_depth.w > 0.0) // perspective: distance from the light / range
    depth01 = saturate(length(world_pos - pass_depth.xyz) * pass_depth.w);
  else                    // orthographic: window depth is already linear
    depth01 = saturate(gl_FragCoord.z); // casters before the near plane are clamped onto it
#ifdef RSM
  vec3 albedo = material_color * texel.rgb;
  vec3 n = safe_normalize(world_normal, vec3(0.0, 1.0, 0.0));
  if (!gl_FrontFacing) n = -n; // two-sided, as the G-buffer
  rsm_flux = vec4(saturate(material_k.y) * saturate(albedo), 1.0);
  rsm_nrm = vec4(n, 0.0);
  rsm_pos = vec4(world_pos, normal_pack(n));
#endif
}
