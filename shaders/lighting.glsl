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

// Light li's kind (0 point, 1 spot, 2 directional) and falloff (light_falloff's
// mode) as its record holds them (floats; a constant kind is a light-set
// variant's light_set_type and light_set_falloff).
int light_type(Light li) { return int(li.position.w + 0.5); }
int light_falloff_mode(Light li) { return int(li.params.y + 0.5); }

// Light arriving at p from light li of kind `type` (0 point, 1 spot, 2
// directional) and falloff `falloff` (light_falloff's mode): direction to the
// light in *l, radiance returned. Constant kind and falloff (a light-set
// variant, LIGHT_SET) leave one kind's code, no branch.
vec3 light_arriving_as(Light li, int type, int falloff, vec3 p, out vec3 l) {
  if (type == 2) {
    l = safe_normalize(-li.direction.xyz, vec3(0.0, 1.0, 0.0));
    return li.color.rgb;
  }
  vec3 to_light = li.position.xyz - p;
  float d = length(to_light);
  l = d > 1e-12 ? to_light / d : vec3(0.0, 1.0, 0.0);
  float fall = light_falloff(falloff, d, li.color.w);
  if (type == 1) {
    float cos_angle = dot(-l, li.direction.xyz);
    float inner = li.params.x, outer = li.direction.w;
    fall *= smoothstep(outer, max(inner, outer + 1e-4), cos_angle);
  }
  return li.color.rgb * fall;
}

// Light arriving at p from light li, its kind and falloff read from it. A
// loop over many points of one light reads li once, outside it.
vec3 light_arriving(Light li, vec3 p, out vec3 l) {
  return light_arriving_as(li, light_type(li), light_falloff_mode(li), p, l);
}

// Light arriving at p from light i (light_arriving).
vec3 light_incident(int i, vec3 p, out vec3 l) { return light_arriving(lights[i], p, l); }

// Light i, of kind `type` and falloff `falloff` (light_arriving_as) and
// shadow kind `shadow` (ShadowLight.info.z, 0: none), on a surface at p
// facing n: false when it arrives from behind or gives nothing there (beyond
// its range or cone: no shadow lookup); else its direction l, n.l and its
// radiance (shadowed with SHADOWS; back_faces false where its shadow tiles
// hold no face it sees from behind: shadow_factor_as). Constant kinds (a
// light-set variant, LIGHT_SET) compile one kind's code.
bool light_on_surface_as(int i, int type, int falloff, int shadow, bool back_faces, vec3 p, vec3 n, out vec3 l,
                         out float ndl, out vec3 radiance) {
  radiance = light_arriving_as(lights[i], type, falloff, p, l);
  ndl = dot(n, l);
  if (ndl <= 0.0 || max(radiance.r, max(radiance.g, radiance.b)) <= 0.0) return false;
#ifdef SHADOWS
  if (shadow != 0) radiance *= shadow_light_as(i, shadow, back_faces, p, n, l);
#endif
  return true;
}

// light_on_surface_as with light i's kinds read from its records.
bool light_on_surface(int i, vec3 p, vec3 n, out vec3 l, out float ndl, out vec3 radiance) {
  Light li = lights[i];
#ifdef SHADOWS
  int shadow = shadow_lights[i].info.z;
#else
  int shadow = 0;
#endif
  return light_on_surface_as(i, light_type(li), light_falloff_mode(li), shadow, true, p, n, l, ndl, radiance);
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

// A surface's reflection: Phong (seed 000) or glTF's metallic-roughness BRDF.
struct Reflector {
  bool pbr;
  vec3 albedo;     // Phong: the albedo; pbr: the diffuse colour
  vec3 k;          // Phong: k_d, k_s in y, z (k_a is the caller's)
  float shininess; // Phong, >= 0
  vec3 f0;         // pbr
  float roughness; // pbr
};

// glTF's metallic-roughness BRDF times n.l: Lambert diffuse weighted by 1 - F,
// GGX (Trowbridge-Reitz) specular with Smith's height-correlated visibility
// and Schlick's Fresnel from f0. The engine's lights carry Lambert's 1 / pi
// already (Phong has none; engine/scene/gltf.h), so the specular term is
// pi times the BRDF.
// Smith's height-correlated visibility G / (4 n.l n.v) for GGX of alpha^2 a2.
float ggx_visibility(float ndl, float ndv, float a2) {
  return 0.5 / max(ndl * sqrt(ndv * ndv * (1.0 - a2) + a2) + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2), 1e-8);
}

// Schlick's Fresnel from f0 at v.h.
vec3 ggx_fresnel(vec3 f0, float vdh) { return f0 + (1.0 - f0) * pow(1.0 - vdh, 5.0); }

vec3 pbr_reflect(Reflector m, vec3 n, vec3 v, vec3 l, float ndl) {
  float a = max(m.roughness * m.roughness, 1e-3), a2 = a * a;
  float ndv = max(dot(n, v), 1e-4);
  vec3 h = safe_normalize(l + v, n);
  float ndh = saturate(dot(n, h)), vdh = saturate(dot(v, h));
  float dd = ndh * ndh * (a2 - 1.0) + 1.0;
  float d = a2 / max(PI * dd * dd, 1e-12);
  vec3 f = ggx_fresnel(m.f0, vdh);
  return ndl * ((1.0 - f) * m.albedo + PI * f * d * ggx_visibility(ndl, ndv, a2));
}

// Phong's diffuse and specular terms (k_d n.l + k_s (r.v)^shininess).
vec3 phong_reflect(Reflector m, vec3 n, vec3 v, vec3 l, float ndl) {
  vec3 r = reflect(-l, n);
  // pow(0, 0) is undefined in GLSL: keep the base strictly positive.
  float spec = m.k.z > 0.0 ? pow(max(dot(r, v), 1e-8), max(m.shininess, 1.0)) : 0.0;
  return m.k.y * m.albedo * ndl + m.k.z * spec;
}

// The surface's reflection of light arriving along l with n.l = ndl.
vec3 reflect_light(Reflector m, vec3 n, vec3 v, vec3 l, float ndl) {
  return m.pbr ? pbr_reflect(m, n, v, l, ndl) : phong_reflect(m, n, v, l, ndl);
}

#ifdef LIGHT_SET
// A variant for the scene's light set (light_set() in the pipeline API):
// LIGHT_SET lights, bit i of each mask saying light i's kind, falloff and
// whether it casts shadows. Each light is evaluated for its kind alone, at a
// constant index: a software rasterizer runs every branch of the general
// loop (every kind, every shadow kind) for every light; this runs one.
#ifndef LIGHT_SPOTS
#define LIGHT_SPOTS 0
#endif
#ifndef LIGHT_SUNS
#define LIGHT_SUNS 0
#endif
#ifndef LIGHT_SHADOWED
#define LIGHT_SHADOWED 0
#endif
#ifndef LIGHT_FALLOFF_NONE
#define LIGHT_FALLOFF_NONE 0
#endif
#ifndef LIGHT_FALLOFF_SQUARE
#define LIGHT_FALLOFF_SQUARE 0
#endif
#ifndef LIGHT_FALLOFF_RANGE
#define LIGHT_FALLOFF_RANGE 0
#endif
#ifndef LIGHT_FRONT_LIT
#define LIGHT_FRONT_LIT 0 // shadow tiles that hold no face the light sees from behind (lm_shadow_front_lit)
#endif
bool light_set_has(int mask, int i) { return ((mask >> i) & 1) != 0; }

// Light i's kind and falloff as light_arriving_as takes them, from the masks.
int light_set_type(int i) { return light_set_has(LIGHT_SUNS, i) ? 2 : light_set_has(LIGHT_SPOTS, i) ? 1 : 0; }
int light_set_falloff(int i) {
  return light_set_has(LIGHT_FALLOFF_NONE, i) ? 1 : light_set_has(LIGHT_FALLOFF_SQUARE, i) ? 2
       : light_set_has(LIGHT_FALLOFF_RANGE, i) ? 3 : 0;
}

// Light i of the set reflected toward v: what reflected_light's loop adds
// for it, by the same operations (the same value; only the loop's order of
// summing, light grid first, may differ in the last bits).
vec3 light_set_reflected(int i, Reflector m, vec3 n, vec3 v, vec3 p) {
  int type = light_set_type(i), falloff = light_set_falloff(i);
  // the shadow kind follows the light's (engine/shadow: cascades, spot, cube)
  int shadow = light_set_has(LIGHT_SHADOWED, i) ? (type == 2 ? 1 : type == 1 ? 2 : 3) : 0;
  vec3 l, radiance;
  float ndl;
  if (!light_on_surface_as(i, type, falloff, shadow, !light_set_has(LIGHT_FRONT_LIT, i), p, n, l, ndl, radiance))
    return vec3(0.0);
  return radiance * reflect_light(m, n, v, l, ndl);
}
#endif

// The light of every light that may reach p reflected toward v (unit n and v),
// one loop for both models. The loop tests at its end: a software rasterizer
// would run a head-tested loop's body once more for its last test. With
// LIGHT_SET, each light of the set unrolled instead (up to 16,
// LM_LIGHT_SET_MAX; four at a time, the compiler drops those past the count).
vec3 reflected_light(Reflector m, vec3 n, vec3 v, vec3 p) {
  vec3 sum = vec3(0.0);
#ifdef LIGHT_SET
#define LIGHT_SET_AT(i) if ((i) < LIGHT_SET) sum += light_set_reflected(i, m, n, v, p);
#define LIGHT_SET_FROM(i) LIGHT_SET_AT(i) LIGHT_SET_AT(i + 1) LIGHT_SET_AT(i + 2) LIGHT_SET_AT(i + 3)
#if LIGHT_SET > 0
  LIGHT_SET_FROM(0)
#endif
#if LIGHT_SET > 4
  LIGHT_SET_FROM(4)
#endif
#if LIGHT_SET > 8
  LIGHT_SET_FROM(8)
#endif
#if LIGHT_SET > 12
  LIGHT_SET_FROM(12)
#endif
  return sum;
#else
  LightList near = lights_near(p);
  if (near.count <= 0) return sum;
  int j = 0;
  do {
    vec3 l, radiance;
    float ndl;
    if (light_on_surface(light_index(near, j), p, n, l, ndl, radiance)) sum += radiance * reflect_light(m, n, v, l, ndl);
  } while (++j < near.count);
  return sum;
#endif
}

// k = (k_a, k_d, k_s), shininess >= 0; n and v unit vectors (v toward the eye).
vec3 phong(vec3 albedo, vec3 k, float shininess, vec3 n, vec3 v, vec3 p, vec3 ambient) {
  Reflector m = Reflector(false, albedo, k, shininess, vec3(0.0), 1.0);
  return k.x * ambient * albedo + reflected_light(m, n, v, p);
}

#endif
