// Reading the G-buffer that std.frag writes (seed 000, lines 1229-1259): one
// decoder for every lighting pass, so that they agree on what a channel means.
#ifndef LIMN_GBUFFER_GLSL
#define LIMN_GBUFFER_GLSL
#include "lighting.glsl"
#include "sky.glsl"

const float PBR_MIN_ROUGHNESS = 0.08; // keeps pbr_shininess within rgba16f

// The Blinn-Phong exponent whose lobe matches GGX of alpha = roughness^2
// (2 / alpha^2 - 2, as gltf.h converts for std), and back.
float pbr_shininess(float roughness) {
  float r2 = roughness * roughness;
  return clamp(2.0 / max(r2 * r2, 1e-6) - 2.0, 0.0, 60000.0);
}
float pbr_roughness(float shininess) { return sqrt(sqrt(2.0 / (max(shininess, 0.0) + 2.0))); }

struct Surface {
  vec3 albedo;     // clr.rgb
  float rho;       // clr.a: reflectance, the seed's "radiation mask"
  vec3 n;          // nrm (gbuffer_normal_decode), unit even where the buffer holds zero
  float shininess; // nrm's too
  float depth01;   // dpt: linear depth / far
  vec3 k;          // mat.xyz: k_a, k_d, k_s
  bool covered;    // mat.a >= 0.5: geometry, not background
  float reflectivity; // mat.a (mat_alpha_reflectivity): mirror share, 0 .. 1
  vec3 p;          // world position (eq 23-24)
  bool pbr;        // written by the pbr technique: k = (occlusion, 1 - metallic, max F0)
  float roughness; // pbr: from the shininess
  vec3 f0;         // pbr: mix(0.04, albedo, metallic)
};

Surface gbuffer_decode(vec4 c, vec4 nn, float d, vec4 m, vec2 uv) {
  Surface s;
  s.albedo = c.rgb;
  s.rho = c.a;
  s.n = safe_normalize(nn.xyz, vec3(0.0, 1.0, 0.0));
  s.shininess = nn.w;
  s.depth01 = max(d, 0.0);
  s.k = m.xyz;
  s.covered = m.a >= 0.5;
  s.reflectivity = mat_alpha_reflectivity(m.a);
  s.p = position_from_depth(uv, s.depth01);
#ifdef PHONG_ONLY
  s.pbr = false; // the std technique drew every pixel (gbuffer.defines): no GGX compiled
#else
  s.pbr = mat_alpha_pbr(m.a);
#endif
  s.roughness = pbr_roughness(s.shininess);
  s.f0 = mix(vec3(0.04), s.albedo, 1.0 - s.k.y);
  return s;
}

// Unfiltered read of texel q (blending depths across an edge would invent points).
Surface gbuffer_fetch(sampler2D clr, sampler2D nrm, sampler2D dpt, sampler2D mat, ivec2 q) {
  vec2 uv = (vec2(q) + 0.5) / vec2(textureSize(dpt, 0));
  return gbuffer_decode(texelFetch(clr, q, 0), gbuffer_normal_decode(texelFetch(nrm, q, 0)), texelFetch(dpt, q, 0).r,
                        texelFetch(mat, q, 0), uv);
}

// Direct light leaving a covered surface toward the eye (lighting.glsl: Phong,
// or GGX for the pbr technique's surfaces), with the sky in the ambient term
// where SKY is defined.
// pbr: k = (occlusion, 1 - metallic, max F0), the diffuse colour k_d albedo;
// ambient light reaches it times occlusion, as k_a times the albedo in Phong.
vec3 surface_diffuse(Surface s) { return s.pbr ? s.k.y * s.albedo : s.albedo; }

// The ambient term (the sky's light where SKY is defined) leaving a covered
// surface: what occlusion takes away.
vec3 ambient_light(Surface s, vec3 ambient) { return s.k.x * sky_ambient(ambient, s.n) * surface_diffuse(s); }

vec3 direct_light(Surface s, vec3 ambient) {
  vec3 v = safe_normalize(frame.camera_pos.xyz - s.p, s.n);
  Reflector m = Reflector(s.pbr, surface_diffuse(s), s.k, s.shininess, s.f0, s.roughness);
  return ambient_light(s, ambient) + reflected_light(m, s.n, v, s.p);
}

// Indirect irradiance E / pi (the GI passes' E, gi-scale.md) reflected by a
// covered surface, times the indirect light factor k: k k_d albedo E, the
// term every physical GI composite adds.
vec3 gi_reflected(Surface s, float k, vec3 e) { return max(k, 0.0) * s.k.y * s.albedo * e; }
#endif
