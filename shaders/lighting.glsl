// Direct light: Phong (seed 000, lines 2753-2767) with the seed's point light
// fall-off saturate(1 - (d / r)^2) (eq 16) or none or 1/d^2 (the falloffs
// POV-Ray can match) or KHR_lights_punctual's 1/d^2 with its range window,
// spot cones and directional lights.
#ifndef LIMN_LIGHTING_GLSL
#define LIMN_LIGHTING_GLSL
#include "common.glsl"
#ifdef SHADOWS
#include "shadow.glsl"
#endif

// How a point or spot light fades at distance d (lm_falloff; the C twin is
// lm_light_falloff in engine/scene/scene.c, lm_light_reach says where it ends).
float light_falloff(int mode, float d, float radius) {
  if (mode == 1) return 1.0; // none: POV-Ray's default point light
  float inv_d2 = 1.0 / max(d * d, 1e-8); // inverse square, finite at the light itself
  if (mode == 2) return inv_d2;
  if (mode == 3) { // KHR_lights_punctual: clamp(1 - (d / range)^4, 0, 1) / d^2; range 0: none
    if (radius <= 0.0) return inv_d2;
    float q = d / radius;
    q *= q;
    return saturate(1.0 - q * q) * inv_d2;
  }
  float radius_safe = max(radius, 1e-12); // the seed's window (eq 16), zero beyond the radius
  return saturate(1.0 - (d / radius_safe) * (d / radius_safe));
}

// Light arriving at p from light i: direction to the light in *l, radiance returned.
vec3 light_incident(int i, vec3 p, out vec3 l) {
  Light li = lights[i];
  int type = int(li.position.w + 0.5);
  if (type == 2) {
    l = safe_normalize(-li.direction.xyz, vec3(0.0, 1.0, 0.0));
    return li.color.rgb;
  }
  vec3 to_light = li.position.xyz - p;
  float d = length(to_light);
  l = d > 1e-12 ? to_light / d : vec3(0.0, 1.0, 0.0);
  float fall = light_falloff(int(li.params.y + 0.5), d, li.color.w);
  if (type == 1) {
    float cos_angle = dot(-l, li.direction.xyz);
    float inner = li.params.x, outer = li.direction.w;
    fall *= smoothstep(outer, max(inner, outer + 1e-4), cos_angle);
  }
  return li.color.rgb * fall;
}

// Light i on a surface at p facing n: false when it arrives from behind or
// gives nothing there (beyond its range or cone: no shadow lookup); else its
// direction l, n.l and its radiance (shadowed with SHADOWS).
bool light_on_surface(int i, vec3 p, vec3 n, out vec3 l, out float ndl, out vec3 radiance) {
  radiance = light_incident(i, p, l);
  ndl = dot(n, l);
  if (ndl <= 0.0 || max(radiance.r, max(radiance.g, radiance.b)) <= 0.0) return false;
#ifdef SHADOWS
  radiance *= shadow_factor(i, p, n, l);
#endif
  return true;
}

// The lights that may reach p: light_index(r, j) for j < r.count. Every light
// when culling is off or p lies outside the grid (a point off screen).
struct LightList { int count, global; uint offset; bool all; };

LightList lights_near(vec3 p) {
  LightList all = LightList(frame.counts.x, 0, 0u, true);
  if (grid.w <= 0) return all;
  vec4 c = frame.view_proj * vec4(p, 1.0);
  float z = c.w; // a perspective's clip w is the view depth
  if (!(z >= slicing.y)) return all;
  vec2 px = (c.xy / c.w * 0.5 + 0.5) * frame.output_size.xy;
  ivec3 q = ivec3(floor(vec3(px / float(grid.w), log(z / slicing.y) * slicing.x)));
  if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, grid.xyz))) return all;
  int cell = (q.z * grid.y + q.y) * grid.x + q.x;
  int global = int(grid_global.x);
  return LightList(global + int(cells[2 * cell + 1]), global, cells[2 * cell], false);
}

int light_index(LightList r, int j) {
  if (r.all) return j;
  return int(cells[j < r.global ? grid_global.y + uint(j) : r.offset + uint(j - r.global)]);
}

// k = (k_a, k_d, k_s), shininess >= 0; n and v unit vectors (v toward the eye).
vec3 phong(vec3 albedo, vec3 k, float shininess, vec3 n, vec3 v, vec3 p, vec3 ambient) {
  vec3 sum = k.x * ambient * albedo;
  LightList near = lights_near(p);
  for (int j = 0; j < near.count; j++) {
    int i = light_index(near, j);
    vec3 l, radiance;
    float ndl;
    if (!light_on_surface(i, p, n, l, ndl, radiance)) continue;
    vec3 r = reflect(-l, n);
    // pow(0, 0) is undefined in GLSL: keep the base strictly positive.
    float spec = k.z > 0.0 ? pow(max(dot(r, v), 1e-8), max(shininess, 1.0)) : 0.0;
    sum += radiance * (k.y * albedo * ndl + k.z * spec);
  }
  return sum;
}

// glTF's metallic-roughness BRDF: Lambert diffuse weighted by 1 - F, GGX
// (Trowbridge-Reitz) specular with Smith's height-correlated visibility and
// Schlick's Fresnel from f0. The engine's lights carry Lambert's 1 / pi
// already (Phong has none; engine/scene/gltf.h), so the specular term is
// pi times the BRDF. Ambient light reaches the diffuse part times occlusion.
vec3 pbr_light(vec3 diffuse, vec3 f0, float roughness, float occlusion, vec3 n, vec3 v, vec3 p, vec3 ambient) {
  float a = max(roughness * roughness, 1e-3), a2 = a * a;
  float ndv = max(dot(n, v), 1e-4);
  vec3 sum = occlusion * ambient * diffuse;
  LightList near = lights_near(p);
  for (int j = 0; j < near.count; j++) {
    int i = light_index(near, j);
    vec3 l, radiance;
    float ndl;
    if (!light_on_surface(i, p, n, l, ndl, radiance)) continue;
    vec3 h = safe_normalize(l + v, n);
    float ndh = saturate(dot(n, h)), vdh = saturate(dot(v, h));
    float dd = ndh * ndh * (a2 - 1.0) + 1.0;
    float d = a2 / max(PI * dd * dd, 1e-12);
    float vis = 0.5 / max(ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2), 1e-8);
    vec3 f = f0 + (1.0 - f0) * pow(1.0 - vdh, 5.0);
    sum += radiance * ndl * ((1.0 - f) * diffuse + PI * f * d * vis);
  }
  return sum;
}
#endif
