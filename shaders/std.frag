// G-buffer as seed 000 (lines 1229-1259), plus the Phong factors:
//   clr = albedo, rho     nrm = world normal, shininess (rgba8: gbuffer_normal_encode)
//   dpt = linear depth / far    mat = k_a, k_d, k_s, coverage and reflectivity
//   (mat_alpha_encode: >= 0.5 = geometry)
#include "common.glsl"
#include "velocity.glsl"

in vec3 world_normal;
in float view_depth;
in vec2 tex_uv;

uniform vec3 material_color;
uniform float material_rho;
uniform vec4 material_k; // k_a, k_d, k_s, shininess
uniform float material_reflectivity;
#ifdef BASE_COLOR_TEXTURE
// The material's base-colour image, stored sRGB: texture() returns linear values.
uniform sampler2D base_color_tex;
uniform mat3 base_color_xform; // KHR_texture_transform
#endif

layout(location = 0) out vec4 out_clr;
layout(location = 1) out vec4 out_nrm;
layout(location = 2) out float out_dpt;
layout(location = 3) out vec4 out_mat;

void main() {
  vec3 n = safe_normalize(world_normal, vec3(0.0, 1.0, 0.0));
  if (!gl_FrontFacing) n = -n; // two-sided: a wall seen from behind still lights
  vec4 base = vec4(material_color, 1.0);
#ifdef BASE_COLOR_TEXTURE
  base *= texture(base_color_tex, (base_color_xform * vec3(tex_uv, 1.0)).xy); // glTF: factor * texture
#endif
#ifdef ALPHA_MASK
  if (alpha_masked(base.a)) discard;
#endif
  vec3 albedo = base.rgb;
  out_clr = vec4(saturate(albedo), saturate(material_rho));
  out_nrm = gbuffer_normal_encode(n, material_k.w);
  out_dpt = dpt_encode(view_depth);
  out_mat = vec4(saturate(material_k.xyz), mat_alpha_encode(material_reflectivity, false));
  write_velocity();
}
