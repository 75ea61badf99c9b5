// The "pbr" material technique: glTF metallic-roughness into the G-buffer,
// in std's channels so that every pass reads it (gbuffer.glsl):
//   clr = base colour, rho            nrm = shading normal, shininess whose
//   dpt = linear depth / far                Blinn-Phong lobe matches GGX's
//   mat = k_a = occlusion, k_d = 1 - metallic, k_s = max(F0), mat_alpha_encode(reflectivity, true)
// so k_d * clr is the diffuse albedo GI passes use, and lighting.glsl's
// pbr_reflect gets roughness and F0 = mix(0.04, clr, metallic) back.
// Location 4 (when the pass gives it) takes the emitted radiance.
#include "gbuffer.glsl"
#include "velocity.glsl"

in vec3 world_normal;
in vec3 world_pos;
in vec4 world_tangent; // the mesh's (glTF TANGENT); w: handedness, 0 when it has none
in float view_depth;
in vec2 tex_uv;

uniform vec3 material_color;   // base colour factor
uniform vec4 material_pbr;     // metallic, roughness, normal scale, occlusion strength
uniform vec3 material_emissive;
uniform vec2 material_alpha;   // alpha, mask cutoff (< 0: opaque)
uniform float material_reflectivity;
#ifdef BASE_COLOR_TEXTURE
uniform sampler2D base_color_tex; // sRGB: texture() returns linear colour
uniform mat3 base_color_xform;    // KHR_texture_transform
#endif
#ifdef MR_TEXTURE
uniform sampler2D mr_tex; // g: roughness, b: metallic
uniform mat3 mr_xform;
#endif
#ifdef NORMAL_TEXTURE
uniform sampler2D normal_tex;
uniform mat3 normal_xform;
#endif
#ifdef OCCLUSION_TEXTURE
uniform sampler2D occlusion_tex; // r
uniform mat3 occlusion_xform;
#endif
#ifdef EMISSIVE_TEXTURE
uniform sampler2D emissive_tex; // sRGB
uniform mat3 emissive_xform;
#endif

layout(location = 0) out vec4 out_clr;
layout(location = 1) out vec4 out_nrm;
layout(location = 2) out float out_dpt;
layout(location = 3) out vec4 out_mat;
layout(location = 4) out vec4 out_emi;

vec2 uv_of(mat3 xform) { return (xform * vec3(tex_uv, 1.0)).xy; }

#ifdef NORMAL_TEXTURE
// The tangent frame: the mesh's tangents where it has them (glTF: B = N x T
// times the handedness w), else one from screen derivatives with T along +u
// and B = N x T. A degenerate frame keeps n.
vec3 perturb(vec3 n, vec3 tn) {
  vec3 t = world_tangent.xyz;
  float w = world_tangent.w < 0.0 ? -1.0 : 1.0;
  if (abs(world_tangent.w) < 0.5) {
    vec3 dp1 = dFdx(world_pos), dp2 = dFdy(world_pos);
    vec2 duv1 = dFdx(tex_uv), duv2 = dFdy(tex_uv);
    float det = duv1.x * duv2.y - duv2.x * duv1.y;
    t = dp1 * duv2.y - dp2 * duv1.y;
    t = det < 0.0 ? -t : t;
    w = 1.0;
  }
  t = safe_normalize(t - n * dot(n, t), vec3(0.0));
  if (dot(t, t) < 0.5) return n;
  vec3 b = cross(n, t) * w;
  return safe_normalize(mat3(t, b, n) * tn, n);
}
#endif

void main() {
  vec4 base = vec4(material_color, material_alpha.x);
#ifdef BASE_COLOR_TEXTURE
  base *= texture(base_color_tex, uv_of(base_color_xform));
#endif
  if (material_alpha.y >= 0.0 && base.a < material_alpha.y) discard; // alpha mask
  float metallic = material_pbr.x, roughness = material_pbr.y;
#ifdef MR_TEXTURE
  vec4 mr = texture(mr_tex, uv_of(mr_xform));
  roughness *= mr.g;
  metallic *= mr.b;
#endif
  metallic = saturate(metallic);
  roughness = clamp(roughness, PBR_MIN_ROUGHNESS, 1.0);
  vec3 n = safe_normalize(world_normal, vec3(0.0, 1.0, 0.0));
  if (!gl_FrontFacing) n = -n; // two-sided, as std
#ifdef NORMAL_TEXTURE
  vec3 tn = texture(normal_tex, uv_of(normal_xform)).xyz * 2.0 - 1.0;
  n = perturb(n, tn * vec3(material_pbr.z, material_pbr.z, 1.0));
#endif
  float occlusion = 1.0;
#ifdef OCCLUSION_TEXTURE
  occlusion = 1.0 + material_pbr.w * (texture(occlusion_tex, uv_of(occlusion_xform)).r - 1.0);
#endif
  vec3 emissive = material_emissive;
#ifdef EMISSIVE_TEXTURE
  emissive *= texture(emissive_tex, uv_of(emissive_xform)).rgb;
#endif
  vec3 albedo = saturate(base.rgb);
  vec3 f0 = mix(vec3(0.04), albedo, metallic);
  out_clr = vec4(albedo, max(max(albedo.r, albedo.g), albedo.b) * (1.0 - metallic));
  out_nrm = gbuffer_normal_encode(n, pbr_shininess(roughness));
  out_dpt = max(view_depth, 0.0) * frame.clip.z;
  out_mat = vec4(saturate(occlusion), 1.0 - metallic, max(max(f0.r, f0.g), f0.b),
                 mat_alpha_encode(material_reflectivity, true));
  out_emi = vec4(min(finite_or_zero(exposed(emissive)), vec3(65000.0)), 1.0); // under half's largest
  write_velocity();
}
