// Indirect point lights with negative lights (seed 002, sections 3.1-3.4),
// on POV-Ray's scale (/work/shared/design/gi-scale.md), over the reflective
// shadow maps of shadow.frag. Five passes (scripts/vpl.lua), by define:
//   LIGHTS    the indirect lights, one texel each: texel (k, r) is light k
//             of the r-th RSM view (light by light, as shadow.render's
//             `views` counts them): position and normal (normal_pack; w > 0:
//             it stands for nothing), radiance times area and the area
//   GATHER    coarse: E+ from the N indirect lights, and the seed's S_neg:
//             the light that would arrive from behind p's tangent plane
//             (n_p.t negated) and its intensity-weighted mean direction
//   NEGATIVES the M negative lights, one texel each, from S_neg at Halton
//             pixels: position and the direction they block (normal_pack;
//             w > 0: none), S_neg and the area
//   NEGATIVE  coarse: E = E+ minus the M negative lights
//   REFINE    full size, the frame's direct pass too: the coarse E where the
//             2 x 2 coarse texels around a pixel agree with it in normal and
//             depth (the seed's discontinuity threshold), else E recomputed
//             at full size; with RECOMPUTE_ANY where any of them disagrees
//             (the seed), without only where all do: elsewhere the bilinear
//             weights of those that agree, renormalized (llvmpipe runs the
//             recomputation for a whole block of pixels where one of them
//             needs it); then the pixel's direct light and ambient term
//             (direct.frag) plus k k_d albedo E: one full-size pass, not a
//             refinement and a direct pass that reads it
// Every pixel meets the same lights, so what each light is (its RSM texel,
// the light there, its area) is worked out once in LIGHTS and NEGATIVES, not
// per pixel: the per-pixel loops read one small texture at one place for
// all pixels, and compute the geometry alone.
// The coarse grid is a view of the G-buffer (isr.coarse_view): GATHER and
// NEGATIVE read it, STRIDE times finer, at each coarse texel's block centre,
// GATHER writes that depth / far (0 where nothing is drawn) as the grid's
// depth (`z`), and REFINE compares a pixel with the normals at those block
// centres and that depth.
// Indirect lights: the i-th of N lies where the Halton point
// (Phi_2(i), Phi_3(i)) falls in the light's RSM view (fixed: nothing
// flickers); the seed's points are directions in a spotlight's cone, which
// a directional light has none of: points uniform over the tile stand for
// the same thing, each weighing its share of the tile's area (seen from the
// light: orthographic T^2 texel areas / N; perspective its texel's area
// r^2 cos^3(a) tan-step^2 times T^2 / N). A light at q sends
//   E(p) += (1/pi) Phi max(0, n_p.t) max(0, n_q.-t) / max(|q - p|^2, A)
// (seed 002's gather, t = (q - p)/|q - p|), A the area the light stands
// for: its own size caps 1/d^2. Output of GATHER: E+ (rgb), S_neg (rgb) and
// its mean direction (xyz); NEGATIVE: rgb = E, a = 1; REFINE: the lit pixel.
#include "rsm.glsl"
#include "halton.glsl"

#ifndef STRIDE
#define STRIDE 1
#endif

in vec2 uv;
uniform int indirect_count = 100;              // N indirect lights a light
uniform int negative = 50;                     // M negative lights
#ifdef LIGHTS
uniform sampler2D rsm_flux, rsm_nrm, rsm_pos;  // shadow.lua's RSM targets
uniform float focus = 1.0;                     // orthographic tiles: the central share of a side they fill
layout(location = 0) out vec4 out_pos;         // position, normal (normal_pack; w > 0: none)
layout(location = 1) out vec4 out_flux;        // radiance times area, area
#else
uniform sampler2D clr, nrm, dpt, mat;          // G-buffer, STRIDE times finer than the coarse grid
uniform sampler2D vpl_pos, vpl_flux;           // LIGHTS
#endif
#ifdef NEGATIVES
uniform sampler2D neg, neg_dir;                // GATHER's S_neg, coarse
uniform sampler2D cdpt;                        // the coarse grid's depth (GATHER's z)
layout(location = 0) out vec4 out_pos;         // position, the indirect lights' mean direction there
                                               // (normal_pack; w > 0: none)
layout(location = 1) out vec4 out_neg;         // S_neg, area
#endif
#if defined(NEGATIVE) || defined(REFINE)
uniform sampler2D neg_pos, neg_s;              // NEGATIVES
#endif
#ifdef NEGATIVE
uniform sampler2D positive;                    // GATHER's E+
#endif
#ifdef REFINE
uniform sampler2D coarse;                      // NEGATIVE's E
uniform sampler2D cdpt;                        // the coarse grid's depth (GATHER's z)
uniform float threshold = 0.1;                 // relative depth and 1 - cos of the normals
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);
uniform float k = 1.0;                         // indirect light factor
#endif

#ifdef GATHER
layout(location = 0) out vec4 result;
layout(location = 1) out vec4 out_neg;
layout(location = 2) out vec4 out_neg_dir;
layout(location = 3) out float z;
#elif defined(NEGATIVE) || defined(REFINE)
out vec4 result;
#endif

// Indirect lights a view of light i holds (its share of N).
int lights_per_view(int i) {
  int count = shadow_lights[i].cube.z;
  return count > 0 && indirect_count > 0 ? max(indirect_count / count, 1) : 0;
}

#ifdef LIGHTS
// Indirect light k of the r-th RSM view: false when it stands for nothing.
bool indirect_light(int k, int r, out vec3 q, out vec3 nq, out vec3 flux, out float area) {
  int light = -1;
  for (int i = 0; i < frame.counts.x && light < 0; i++) { // the r-th RSM view, light by light
    if (r < shadow_lights[i].cube.z) light = i;
    else r -= shadow_lights[i].cube.z;
  }
  if (light < 0) return false;
  int per_view = lights_per_view(light);
  if (k >= per_view) return false;
  ShadowView sv = shadow_views[shadow_lights[light].cube.y + r];
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  float tile = sv.rect.z * atlas.x;
  vec2 t = vec2(radical_inverse(uint(k + 1), 2u), radical_inverse(uint(k + 1), 3u));
  float side = sv.depth.w > 0.0 ? 1.0 : clamp(focus, 1e-3, 1.0);
  t = 0.5 + (t - 0.5) * side;
  ivec2 a = ivec2((sv.rect.xy + t * sv.rect.zw) * atlas);
  nq = texelFetch(rsm_nrm, a, 0).xyz;
  if (dot(nq, nq) > 1.5) return false; // empty
  q = texelFetch(rsm_pos, a, 0).xyz;
  vec3 l;
  vec3 radiance = light_incident(light, q, l);
  area = rsm_texel_area(sv, t, q, tile) * tile * tile * side * side / float(per_view);
  flux = texelFetch(rsm_flux, a, 0).rgb * radiance * area;
  return area > 0.0;
}
#endif

#ifndef LIGHTS
// E+ at (p, n) from every indirect light; S_neg and its direction when asked.
vec3 indirect(vec3 p, vec3 n, out vec3 s_neg, out vec3 neg_d) {
  vec3 e = vec3(0.0);
  s_neg = vec3(0.0);
  neg_d = vec3(0.0);
  int r = 0; // row of the lights' texture: RSM views light by light
  for (int i = 0; i < frame.counts.x; i++) {
    int per_view = lights_per_view(i);
    for (int v = 0; v < shadow_lights[i].cube.z; v++, r++) {
      for (int k = 0; k < per_view; k++) {
        vec4 qn = texelFetch(vpl_pos, ivec2(k, r), 0);
        if (qn.w > 0.0) continue; // the same light for every pixel: a branch all take alike
        vec4 fa = texelFetch(vpl_flux, ivec2(k, r), 0);
        vec3 q = qn.xyz, nq = normal_unpack(qn.w), flux = fa.rgb;
        vec3 d = q - p;
        float d2 = dot(d, d);
        vec3 dir = d * inversesqrt(max(d2, 1e-30));
        float g = max(dot(nq, -dir), 0.0) / max(d2, fa.a);
        float ndt = dot(n, dir);
        e += flux * max(ndt, 0.0) * g;
        vec3 behind = flux * max(-ndt, 0.0) * g;
        s_neg += behind;
        neg_d += luminance(behind) * dir;
      }
    }
  }
  return e / PI;
}
#endif

#ifdef NEGATIVES
// The m-th negative light: the Halton pixel of S_neg, a point light at the
// pixel's surface, standing for its share of the coarse image's surface
// (the pixel's world footprint squared times the pixels it stands for);
// false when it blocks nothing.
bool negative_light_at(int m, out vec3 q, out vec3 dir_l, out vec3 s, out float area) {
  ivec2 size = textureSize(neg, 0);
  float share = float(size.x * size.y) / float(max(negative, 1));
  vec2 h = vec2(radical_inverse(uint(m + 1), 2u), radical_inverse(uint(m + 1), 3u));
  ivec2 x = ivec2(h * vec2(size));
  s = texelFetch(neg, x, 0).rgb;
  if (luminance(s) <= 0.0) return false;
  vec2 xuv = (vec2(x) + 0.5) / vec2(size);
  float z = texelFetch(cdpt, x, 0).r;
  q = position_from_depth(xuv, z);
  dir_l = safe_normalize(texelFetch(neg_dir, x, 0).xyz, vec3(0.0));
  float foot = 2.0 * dpt_view_depth(z) * frame.clip.w / float(size.y); // a pixel's world size
  area = foot * foot * share;
  return area > 0.0 && dot(dir_l, dir_l) > 0.5; // without a direction it blocks nothing

}
#endif

#if defined(NEGATIVE) || defined(REFINE)
// The light the M negative lights take from p: each blocks the light that
// arrives at its back from the indirect lights (pi S_neg times its area) and
// sends it on as a Lambertian emitter facing away from them (toward -dir_l),
// onto what lies in its shadow facing back toward it.
vec3 negative_light(vec3 p, vec3 n) {
  vec3 e = vec3(0.0);
  for (int m = 0; m < negative; m++) {
    vec4 qd = texelFetch(neg_pos, ivec2(m, 0), 0);
    if (qd.w > 0.0) continue; // the same for every pixel
    vec4 sa = texelFetch(neg_s, ivec2(m, 0), 0);
    vec3 dir_l = normal_unpack(qd.w);
    vec3 d = p - qd.xyz;
    float d2 = dot(d, d);
    vec3 t = d * inversesqrt(max(d2, 1e-30));
    e += sa.rgb * sa.a * max(dot(-dir_l, t), 0.0) * max(dot(n, -t), 0.0) / max(d2, sa.a);
  }
  return e / PI;
}
#endif

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef LIGHTS
  vec3 q, nq, flux;
  float area;
  if (indirect_light(px.x, px.y, q, nq, flux, area)) {
    out_pos = vec4(q, normal_pack(nq));
    out_flux = vec4(finite_or_zero(flux), area);
  } else {
    out_pos = vec4(0.0, 0.0, 0.0, 1.0);
    out_flux = vec4(0.0);
  }
#elif defined(NEGATIVES)
  vec3 q, dir_l, s;
  float area;
  if (px.x < negative && negative_light_at(px.x, q, dir_l, s, area)) {
    out_pos = vec4(q, normal_pack(dir_l));
    out_neg = vec4(s, area);
  } else {
    out_pos = vec4(0.0, 0.0, 0.0, 1.0);
    out_neg = vec4(0.0);
  }
#else
#ifdef REFINE
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, px);
#else
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, block_centre(px, STRIDE, textureSize(dpt, 0)));
#endif
  vec3 s_neg, neg_d;
#endif
#ifdef GATHER
  z = s.covered ? s.depth01 : 0.0;
  if (!s.covered) {
    result = vec4(0.0, 0.0, 0.0, 1.0);
    out_neg = out_neg_dir = vec4(0.0);
    return;
  }
  vec3 e = indirect(s.p, s.n, s_neg, neg_d);
  result = vec4(finite_or_zero(e), 1.0);
  out_neg = vec4(finite_or_zero(s_neg / PI), 1.0);
  out_neg_dir = vec4(finite_or_zero(neg_d), 0.0);
#elif defined(NEGATIVE)
  vec3 e = texelFetch(positive, px, 0).rgb;
  if (s.covered) e = max(e - negative_light(s.p, s.n), vec3(0.0));
  result = vec4(finite_or_zero(e), 1.0);
#elif defined(REFINE)
  if (!s.covered) {
    result = vec4(background_seen(background, uv), 1.0);
    return;
  }
  ivec2 csize = textureSize(coarse, 0);
  vec2 tc = uv * vec2(csize) - 0.5;
  ivec2 base = ivec2(floor(tc));
  vec2 f = tc - floor(tc);
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  bool all_agree = true;
  for (int i = 0; i < 4; i++) {
    ivec2 o = ivec2(i & 1, i >> 1), q = clamp(base + o, ivec2(0), csize - 1);
    float zc = texelFetch(cdpt, q, 0).r;
    vec3 nc = gbuffer_normal_decode(texelFetch(nrm, block_centre(q, STRIDE, textureSize(nrm, 0)), 0)).xyz;
    bool agree = abs(zc - s.depth01) <= threshold * max(s.depth01, 1e-12) && dot(nc, s.n) >= 1.0 - threshold;
    all_agree = all_agree && agree;
    vec2 w = mix(1.0 - f, f, vec2(o));
    float wq = agree ? w.x * w.y : 0.0;
    sum += wq * texelFetch(coarse, q, 0).rgb;
    wsum += wq;
  }
#ifdef RECOMPUTE_ANY
  bool interpolate = all_agree;
#else
  bool interpolate = wsum > 0.0;
#endif
  vec3 e = interpolate ? sum / max(wsum, 1e-30)
                       : max(indirect(s.p, s.n, s_neg, neg_d) - negative_light(s.p, s.n), vec3(0.0));
  result = vec4(direct_light(s, ambient) + gi_reflected(s, k, finite_or_zero(e)), 1.0);
#endif
}
