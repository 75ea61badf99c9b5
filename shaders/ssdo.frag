// Screen-space directional occlusion (seed 001, lines 422-568, 864-948,
// 1222-1318). For each of K directions w_i (halton.glsl) and step
// r_i = u_i r_max the sample S = P + r_i w_i is projected; the G-buffer
// texel it lands on holds a surface point P_i with normal N_i. S counts as
// occluded (V = 0) when it lies behind that surface: farther from the eye
// than P_i, below P_i's tangent plane (which keeps a plane from occluding
// itself when S snaps to a texel centre), and by less than r_max (the range
// check every SSAO makes: a surface far in front is no occluder of S).
// Samples off the screen or on background are visible.
//
// Incoming light L_in(w) [INF]: the seed evaluates it per direction, which a
// point or directional light (a delta) does not allow. Each light here
// spreads over a lobe E_l max(w.l, 0)^n around its direction l (E_l the
// light's radiance at P from lighting.glsl, n = `lobe`). Both variants use
// it only in a ratio, the modulation factor of eq 4.4
//   M = sum L_in(w_i) V(w_i) (N.w_i) / p(w_i) / sum L_in(w_i) (N.w_i) / p(w_i)
// per RGB channel, and multiply Phong's light (gbuffer.glsl, lighting.glsl)
// by it: where nothing occludes M = 1 and the result is the scene's direct
// light exactly, at any lobe and sample count. Where the sum of L_in is 0
// (an unlit pixel, or no direction in the lobe) M is the accessibility,
// the cosine-weighted fraction of visible samples.
//
// Variants (defines):
//  PHYSICAL      the default (/work/shared/design/gi-scale.md): cosine-
//                weighted directions; the lit image is not darkened (its
//                shadows come from the shadow maps), only the ambient (sky)
//                term, by the accessibility; the bounce is the share of the
//                irradiance integral the occluded samples see,
//                E = (1/K) sum over occluded samples of L_i, each sample
//                standing for its direction (pdf cos / pi: the cosines
//                cancel), so that k_d albedo E is on POV-Ray's scale with
//                bounce = 1. out0 = (A, A, A, A), out1 = (bounce k_d albedo E, 0).
//  MERGED        the author's (eq 4.1-4.4): cosine-weighted directions
//                (p = cos / pi: the cosines cancel), one loop gives M and
//                the bounce from `sender`, the scene without SSDO darkening.
//                out0 = (M, accessibility), out1 = (bounce, 0).
//  DIRECT        the original first step (eq 3.3): uniform directions
//                (p = 1 / 2 pi, dw = 2 pi / K). L_dir = the diffuse light
//                times M, the ambient term times the accessibility, the
//                specular unoccluded (a lobe far narrower than the samples
//                resolve); Phong's terms, or for a pbr surface GGX's
//                (lighting.glsl's reflected_light, as the direct pass).
//  BOUNCE        the original second step (eq 3.4) from `sender` = L_dir.
// Bounce (eq 3.4), in both variants the same sum
//   L_ind = (rho / pi) sum_i L_i (1 - V_i) (N.w_i) (N_i.(-w_i)) A_s / d_i^2
// over the occluded samples, as Ritschel et al. (the seed's ref. [19])
// write it: A_s / d^2 is already the sender's solid angle, so the seed's
// extra dw = 2 pi / K (which would shrink the bounce by another 1/K) is
// left out [INF]. A sender is rejected when it faces away
// (N_i.(-w_i) <= 0) or P faces away from it (N.w_i <= 0). A_s = bounce
// pi r_max^2 / K (bounce = 1: the seed's default). Against fireflies
// 1/d^2 becomes 1/(d^2 + r_max^2 / 2): at bounce = 1 a sender's solid
// angle then never exceeds 2 pi / K, its share of the hemisphere, however
// close it lies.
// TEMPORAL (PHYSICAL only; temporal.glsl, scripts/temporal.lua): each frame
// turns the pixel's samples by another point of the R3 sequence, out0 and
// out1 are the accumulation of (bounce, A), whose history goes to `next`
// and `next_state`; a converged pixel takes no samples and keeps it.
#include "gbuffer.glsl"
#include "halton.glsl"
#ifdef TEMPORAL
#include "temporal.glsl"
#endif

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat; // full-size G-buffer
#if defined(MERGED) || defined(BOUNCE) || defined(PHYSICAL)
uniform sampler2D sender;             // full-size: undarkened lit colour or L_dir
#endif
#ifdef ADAPTIVE
uniform sampler2D edges;              // 1/16 size: 10, 20 or 30 samples (ssdo_edges.frag)
#endif
uniform int samples = 20;     // K, a multiple of 10
uniform float r_max = 0.0;    // world units; 0: `radius` of P's view depth
uniform float radius = 0.5;   // fraction of P's view depth
uniform float bounce = 1.0;   // A_s over the seed's pi r_max^2 / K
uniform float lobe = 4.0;     // light lobe exponent n
uniform int interleave = 4;   // rotation tile side (halton.glsl)
uniform int factor = 1;       // this pass runs at 1/factor of the G-buffer
#ifdef DIRECT
uniform vec3 ambient = vec3(0.0);
#endif

layout(location = 0) out vec4 out0;
#if defined(MERGED) || defined(PHYSICAL)
layout(location = 1) out vec4 out1;
#endif
#ifdef TEMPORAL
layout(location = 2) out vec4 next;       // the history's value: (bounce, A)
layout(location = 3) out vec2 next_state; // and state: view depth (0 none), frames seen
#endif

// The shadow manager's factor for light i at p goes here (1: unshadowed).
float light_visibility(int i, vec3 p) { return 1.0; }

// L_in(w) at p: every light's radiance spread over its lobe (see above).
vec3 incoming(vec3 p, vec3 w) {
  vec3 sum = vec3(0.0);
  float n = clamp(lobe, 1.0, 64.0);
  for (int i = 0; i < frame.counts.x; i++) {
    vec3 l;
    vec3 e = light_incident(i, p, l) * light_visibility(i, p);
    sum += e * pow(max(dot(w, l), 0.0), n); // base >= 0, exponent >= 1
  }
  return sum;
}

void main() {
  ivec2 gsize = textureSize(dpt, 0), px = ivec2(gl_FragCoord.xy);
  int f = max(factor, 1);
  ivec2 g = clamp(px * f + f / 2, ivec2(0), gsize - 1);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, g);
#ifdef TEMPORAL
  next = vec4(0.0);
  next_state = vec2(s.covered ? dpt_view_depth(s.depth01) : 0.0, 0.0);
  vec4 h;
  float held;
  bool found = s.covered && temporal_history((vec2(g) + 0.5) / vec2(gsize), s.depth01, h, held);
  if (found && temporal_converged(held, px)) { // kept as it is
    next = h;
    next_state.y = max(frames, 1.0);
    out0 = vec4(h.a);
    out1 = vec4(h.rgb, 0.0);
    return;
  }
#endif
  if (!s.covered) { // background: nothing to darken or light
#if defined(MERGED) || defined(PHYSICAL)
    out0 = vec4(1.0);
    out1 = vec4(0.0);
#else
    out0 = vec4(0.0);
#endif
    return;
  }
#ifdef ADAPTIVE
  int k = int(texelFetch(edges, clamp(g / 16, ivec2(0), textureSize(edges, 0) - 1), 0).r + 0.5);
#else
  int k = samples;
#endif
  k = clamp(k / 10 * 10, 10, HALTON_MAX);
  float rmax = r_max > 0.0 ? r_max : max(radius, 0.0) * s.depth01 * frame.clip.y;
  float area = max(bounce, 0.0) * PI * rmax * rmax / float(k);  // A_s
  float far = frame.clip.y;
  mat3 frame_n = tangent_frame(s.n);
  vec3 offset = halton_offset(px, clamp(interleave, 1, 4));
#ifdef TEMPORAL
  if (temporal_turning()) offset = r3_sample(temporal_turn(), offset); // this frame's turn of the pattern
#endif
  vec3 visible = vec3(0.0), total = vec3(0.0), gathered = vec3(0.0);
  float open = 0.0;
  for (int i = 0; i < k; i++) {
    vec3 u = halton_sample(i, offset);
#if defined(MERGED) || defined(PHYSICAL)
    vec3 wl = hemisphere_cosine(u.xy);
#else
    vec3 wl = hemisphere_uniform(u.xy);
#endif
    vec3 w = frame_n * wl;
    vec3 sp = s.p + (u.z * rmax) * w;
    // Project S; behind the eye or off the screen it is visible.
    vec4 clip = frame.view_proj * vec4(sp, 1.0);
    bool occluded = false;
    ivec2 q = ivec2(0);
    if (clip.w > 1e-6) {
      vec2 quv = clip.xy / clip.w * 0.5 + 0.5;
      if (all(greaterThanEqual(quv, vec2(0.0))) && all(lessThan(quv, vec2(1.0)))) {
        q = min(ivec2(quv * vec2(gsize)), gsize - 1);
        float zq = texelFetch(dpt, q, 0).r * far, zs = clip.w; // view depth of S: w of a perspective projection
        if (texelFetch(mat, q, 0).a >= 0.5 && zs > zq * (1.0 + 1e-4) && zs - zq < rmax) {
          vec3 nq = gbuffer_normal_decode(texelFetch(nrm, q, 0)).xyz;
          vec3 pq = position_from_depth((vec2(q) + 0.5) / vec2(gsize), zq / far);
          occluded = dot(nq, sp - pq) < 0.0;
        }
      }
    }
#if defined(MERGED) || defined(DIRECT)
    vec3 lin = incoming(s.p, w);
#endif
#ifdef MERGED
    float weight = 1.0;  // (N.w) / p(w) = pi, a common factor
#else
    float weight = wl.z; // (N.w) / p(w) = 2 pi (N.w)
#endif
#if defined(MERGED) || defined(DIRECT)
    total += lin * weight;
    if (!occluded) visible += lin * weight, open += weight;
#endif
#ifdef PHYSICAL
    if (!occluded) open += 1.0;
    else {
      Surface x = gbuffer_fetch(clr, nrm, dpt, mat, q);
      if (dot(x.n, -safe_normalize(x.p - s.p, w)) > 0.0) gathered += texelFetch(sender, q, 0).rgb;
    }
#endif
#if defined(MERGED) || defined(BOUNCE)
    if (occluded && area > 0.0) {
      Surface x = gbuffer_fetch(clr, nrm, dpt, mat, q);
      vec3 d = x.p - s.p;
      float cos_s = dot(x.n, -w), cos_r = wl.z;
      if (cos_s > 0.0 && cos_r > 0.0) {
        vec3 li = texelFetch(sender, q, 0).rgb;
        float solid = area / (dot(d, d) + 0.5 * rmax * rmax); // A_s / d^2, at most bounce 2 pi / K
        gathered += li * (cos_r * cos_s * solid);
      }
    }
#endif
  }
  vec3 rho = s.k.y * s.albedo; // the diffuse reflectance Phong uses
#if defined(MERGED) || defined(DIRECT)
  #ifdef MERGED
  float access = open / float(k);
  #else
  float access = saturate(2.0 * open / float(k)); // (1/pi) sum V (N.w) 2 pi / K
  #endif
  vec3 m = vec3(total.r > 1e-8 ? visible.r / total.r : access, total.g > 1e-8 ? visible.g / total.g : access,
                total.b > 1e-8 ? visible.b / total.b : access);
  m = saturate(m);
#endif
#ifdef PHYSICAL
  vec4 v = vec4(max(bounce, 0.0) * rho * gathered / float(k), open / float(k));
  #ifdef TEMPORAL
  v = next = temporal_accumulate(v, found, h, held, next_state.y);
  #endif
  out0 = vec4(v.a);
  out1 = vec4(v.rgb, 0.0);
#elif defined(MERGED)
  out0 = vec4(m, access);
  out1 = vec4(rho / PI * gathered, 0.0);
#elif defined(DIRECT)
  vec3 v = safe_normalize(frame.camera_pos.xyz - s.p, s.n);
  // The direct pass's reflector; without its diffuse colour, the specular term alone (Phong's k_d
  // albedo and GGX's Lambert part both scale with it), and without k_s, Phong's diffuse term alone.
  Reflector r = Reflector(s.pbr, surface_diffuse(s), s.k, s.shininess, s.f0, s.roughness), glossy = r, matte = r;
  glossy.albedo = vec3(0.0);
  matte.k.z = 0.0;
  vec3 specular = reflected_light(glossy, s.n, v, s.p);
  vec3 diffuse = s.pbr ? max(reflected_light(r, s.n, v, s.p) - specular, 0.0) : reflected_light(matte, s.n, v, s.p);
  out0 = vec4(ambient_light(s, ambient) * access + specular + diffuse * m, 1.0);
#else
  out0 = vec4(rho / PI * gathered, 0.0);
#endif
}
