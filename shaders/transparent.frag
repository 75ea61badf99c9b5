// The "transparent" material technique: alphaMode BLEND materials drawn by a
// forward pass over the lit image (scene{ blend = true }: back to front,
// dual-source blended, depth tested against the G-buffer's). A surface is
// lit as the deferred passes light one (lighting.glsl: the same lights,
// light set, shadows; the ambient term with the sky's where SKY is defined),
// and what lies behind it is kept times its transmittance:
//   out = a (lit surface) + (a T + 1 - a) behind
// a the base alpha (coverage). KHR_materials_transmission's share t of the
// light passes the surface instead of its diffuse reflection, tinted by the
// base colour and by the volume's absorption (KHR_materials_volume:
// attenuation colour after the attenuation distance, over the thickness
// along the refracted ray) and less the Fresnel reflection of the ior
// (KHR_materials_ior): T = t (1 - F) base absorption. No refraction: the
// background is seen straight through.
// LPV: indirect light as the frame's light propagation volumes give opaque
// surfaces (k k_d albedo E, gbuffer.glsl's gi_reflected), read at the
// surface itself (lpv_light: world space). Screen-space GI (ISR, the RSM's
// gather) holds E only at the opaque surfaces the G-buffer sees; the E of
// the one behind a pane is another surface's (a pane in the Cornell box
// facing its open side took 18 times what it takes opaque), so there the
// pane keeps ambient and sky light alone.
#include "gbuffer.glsl"
#ifdef LPV
#include "lpv_light.glsl"
uniform float k = 1.0; // the LPV's indirect light factor
#endif

in vec3 world_normal;
in vec3 world_pos;
in vec2 tex_uv;

uniform vec3 material_color;       // base colour factor
uniform vec4 material_pbr;         // metallic, roughness, normal scale, occlusion strength
uniform vec4 material_k;           // Phong: k_a, k_d, k_s, shininess
uniform vec3 material_emissive;
uniform vec2 material_alpha;       // alpha, mask cutoff
uniform vec4 material_glass;       // transmission, ior, attenuation distance (0: none), thickness
uniform vec3 material_attenuation; // attenuation colour
#ifdef BASE_COLOR_TEXTURE
uniform sampler2D base_color_tex;  // sRGB: texture() returns linear colour
uniform mat3 base_color_xform;     // KHR_texture_transform
#endif
uniform vec3 ambient = vec3(0.0);

layout(location = 0, index = 0) out vec4 out_color;    // added
layout(location = 0, index = 1) out vec4 out_transmit; // times what the output holds

void main() {
  vec4 base = vec4(material_color, material_alpha.x);
#ifdef BASE_COLOR_TEXTURE
  base *= texture(base_color_tex, (base_color_xform * vec3(tex_uv, 1.0)).xy);
#endif
  vec3 albedo = saturate(base.rgb);
  float a = saturate(base.a), t = saturate(material_glass.x), ior = clamp(material_glass.y, 1.0, 10.0);
  vec3 n = safe_normalize(world_normal, vec3(0.0, 1.0, 0.0));
  if (!gl_FrontFacing) n = -n;
  vec3 v = safe_normalize(frame.camera_pos.xyz - world_pos, n);
  float ndv = saturate(dot(n, v));
  // Fresnel (Schlick) of a dielectric of this ior, seen at n.v.
  float r0 = (ior - 1.0) / (ior + 1.0);
  r0 *= r0;
  float fresnel = r0 + (1.0 - r0) * pow(1.0 - ndv, 5.0);
#ifdef PBR_MATERIALS
  float metallic = saturate(material_pbr.x);
  vec3 diffuse = (1.0 - metallic) * (1.0 - t) * albedo;
  Reflector m = Reflector(true, diffuse, vec3(1.0), 0.0, mix(vec3(r0), albedo, metallic),
                          clamp(material_pbr.y, PBR_MIN_ROUGHNESS, 1.0));
  float ka = 1.0;
#else
  float metallic = 0.0;
  vec3 diffuse = (1.0 - t) * albedo;
  Reflector m = Reflector(false, diffuse, material_k.xyz, max(material_k.w, 0.0), vec3(0.0), 1.0);
  float ka = material_k.x;
#endif
  vec3 surface = ka * sky_ambient(ambient, n) * diffuse + reflected_light(m, n, v, world_pos) + exposed(material_emissive);
#ifdef LPV
#ifdef PBR_MATERIALS
  float kd = 1.0; // diffuse holds 1 - metallic already
#else
  float kd = material_k.y;
#endif
  surface += max(k, 0.0) * kd * diffuse * lpv_light(world_pos, n);
#endif
  // Absorption along the refracted ray through the volume's thickness.
  vec3 absorbed = vec3(1.0);
  if (material_glass.z > 0.0 && material_glass.w > 0.0) {
    float cos_t = sqrt(max(1.0 - (1.0 - ndv * ndv) / (ior * ior), 1e-4));
    float path = material_glass.w / (cos_t * material_glass.z);
    absorbed = exp(log(max(saturate(material_attenuation), vec3(1e-6))) * min(path, 1e4));
  }
  vec3 transmit = t * (1.0 - metallic) * (1.0 - fresnel) * albedo * absorbed;
  out_color = vec4(finite_or_zero(a * surface), 0.0);
  out_transmit = vec4(saturate(a * transmit + (1.0 - a)), 1.0);
}
