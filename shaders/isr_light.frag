// The ISR lighting pass (seed 000, eq 27-29, Listing 7, lines 1564-1702):
// the coarse ISR buffer (rgb E, a A) brought to full size by depth-aware
// bilateral upsampling, and the composite with the frame's direct light D
// (the `direct` pass: lights and shadows, no ambient term) and the ambient
// term k_a L_a albedo:
//   physical  L = D + k_a L_a albedo A + k k_d albedo E
//             (isr_march.frag: E = (1/pi) int L cos dw over the seen senders,
//             A the cosine-weighted share of rays that see no surface, the
//             ambient light being the sky's: only it is occluded)
//   SEED      L = (D + k_a L_a albedo) saturate(A + 1 - k_SSAO) + k_ISR rho E
//             (isr.frag; C0 k_dl of eq 29 is the direct light with its
//             ambient term, A the accessibility: 1 open, 0 occluded)
// The coarse texels' coverage is coarse_mat's (a coarse copy of the
// G-buffer) or with Z_MASK their depth's, 0 where nothing was drawn (a
// coarse view's depth, isr.coarse_view).
#include "gbuffer.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat, direct;  // full-size G-buffer and direct light
uniform sampler2D isr, coarse_dpt;             // coarse ISR (rgb E, a A) and its depth
#ifndef Z_MASK
uniform sampler2D coarse_mat;                  // its coverage (a)
#endif
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);
#ifdef SEED
uniform float k_isr = 0.5, k_ssao = 0.5;
#else
uniform float k = 1.0;
#endif
uniform int view = 0; // 0: the composite, 1: rho L_ISR alone, 2: accessibility A

out vec4 lit;

// Eq 27's depth weight 1 / |z_p - z_i|, with |dz| relative to z_p (the same
// at any distance) and offset so that equal depths weigh 1 / EPS_Z, not Inf.
const float EPS_Z = 0.01;

// Eq 27-28 over the 2x2 coarse texels around uv. When the weights are all
// about zero (no covered texel) the texel nearest in depth is taken.
vec4 upsample(float z) {
  ivec2 last = textureSize(isr, 0) - 1;
  vec2 t = uv * vec2(textureSize(isr, 0)) - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 f = t - floor(t);
  vec4 sum = vec4(0.0), nearest = vec4(0.0, 0.0, 0.0, 1.0);
  float wsum = 0.0, nearest_dz = 1e30;
  // The four texels' depths (and coverage) in one gather each, at their
  // shared corner (clamped at the border, as q is): x (0, 1), y (1, 1),
  // z (1, 0), w (0, 0) from base.
  vec2 corner = (vec2(base) + 1.0) / vec2(textureSize(isr, 0));
  vec4 zs = textureGather(coarse_dpt, corner, 0).wzxy;
#ifdef Z_MASK
  vec4 cover = vec4(greaterThan(zs, vec4(0.0)));
#else
  vec4 cover = step(0.5, textureGather(coarse_mat, corner, 3).wzxy);
#endif
  for (int i = 0; i < 4; i++) {
    ivec2 o = ivec2(i & 1, i >> 1), q = clamp(base + o, ivec2(0), last);
    vec2 wb2 = mix(1.0 - f, f, vec2(o));
    vec4 v = texelFetch(isr, q, 0);
    float covered = cover[i], dz = abs(z - zs[i]) / max(z, 1e-12);
    float w = wb2.x * wb2.y * covered / (EPS_Z + dz);
    sum += w * v;
    wsum += w;
    if (dz < nearest_dz) {
      nearest_dz = dz;
      nearest = v;
    }
  }
  return wsum > 1e-6 ? sum / wsum : nearest;
}

void main() {
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, ivec2(gl_FragCoord.xy)); // unfiltered: a pass at the G-buffer's size
  if (!s.covered) {
    lit = vec4(background + sky_seen(uv), 1.0);
    return;
  }
  vec4 e = upsample(s.depth01);
  vec3 d = texelFetch(direct, ivec2(gl_FragCoord.xy), 0).rgb, sky = s.k.x * sky_ambient(ambient, s.n) * s.albedo;
#ifdef SEED
  vec3 indirect = s.rho * e.rgb;
  vec3 l = (d + sky) * saturate(e.a + 1.0 - k_ssao) + k_isr * indirect;
#else
  vec3 indirect = max(k, 0.0) * s.k.y * s.albedo * e.rgb;
  vec3 l = d + sky * saturate(e.a) + indirect;
#endif
  if (view == 1) l = indirect;
  if (view == 2) l = vec3(e.a);
  lit = vec4(l, 1.0); // unsanitized: tests check the guards, output.frag the rest
}
