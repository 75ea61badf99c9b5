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

// k = (k_a, k_d, k_s), shininess >= 0; n and v unit vectors (v toward the eye).
vec3 phong(vec3 albedo, vec3 k, float shininess, vec3 n, vec3 v, vec3 p, vec3 ambient) {
  vec3 sum = k.x * ambient * albedo;
  for (int i = 0; i < frame.counts.x; i++) {
    vec3 l;
    vec3 radiance = light_incident(i, p, l);
    float ndl = dot(n, l);
    if (ndl <= 0.0) continue;
#ifdef SHADOWS
    radiance *= shadow_factor(i, p, n, l);
#endif
    vec3 r = reflect(-l, n);
    // pow(0, 0) is undefined in GLSL: keep the base strictly positive.
    float spec = k.z > 0.0 ? pow(max(dot(r, v), 1e-8), max(shininess, 1.0)) : 0.0;
    sum += radiance * (k.y * albedo * ndl + k.z * spec);
  }
  return sum;
}
#endif
