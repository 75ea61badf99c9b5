// Direct light: Phong (seed 000, lines 2753-2767) with the seed's point light
// fall-off saturate(1 - (d / r)^2) (eq 16) or none or 1/d^2 (the falloffs
// POV-Ray can match), spot cones and directional lights.
#ifndef LIMN_LIGHTING_GLSL
#define LIMN_LIGHTING_GLSL
#include "common.glsl"
#ifdef SHADOWS
#include "shadow.glsl"
#endif

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
  float fall;
  int mode = int(li.params.y + 0.5);
  if (mode == 1) { // none: POV-Ray's default point light
    fall = 1.0;
  } else if (mode == 2) { // inverse square, finite at the light itself
    fall = 1.0 / max(d * d, 1e-8);
  } else { // the seed's window (eq 16), zero beyond the radius
    float radius = max(li.color.w, 1e-12);
    fall = saturate(1.0 - (d / radius) * (d / radius));
  }
  if (type == 1) {
    float cos_angle = dot(-l, li.direction.xyz);
    float inner = li.params.x, outer = li.direction.w;
    fall *= smoothstep(outer, max(inner, outer + 1e-4), cos_angle);
  }
  return li.color.rgb * fall;
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
    vec3 l;
    vec3 radiance = light_incident(i, p, l);
    float ndl = dot(n, l);
    // Facing away, or beyond the light's range or cone: no shadow lookup.
    if (ndl <= 0.0 || max(radiance.r, max(radiance.g, radiance.b)) <= 0.0) continue;
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
