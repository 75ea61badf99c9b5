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
// The upsampling: coarse.glsl.
#include "gbuffer.glsl"
#include "coarse.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat, direct;  // full-size G-buffer and direct light
uniform vec3 ambient = vec3(0.0);
uniform vec3 background = vec3(0.0);
#ifdef SEED
uniform float k_isr = 0.5, k_ssao = 0.5;
#else
uniform float k = 1.0;
#endif
uniform int view = 0; // 0: the composite, 1: rho L_ISR alone, 2: accessibility A

out vec4 lit;

void main() {
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, ivec2(gl_FragCoord.xy)); // unfiltered: a pass at the G-buffer's size
  vec4 e = coarse_upsample(uv, s.depth01); // before any branch: QUAD_SHARED's derivatives need every pixel
  if (!s.covered) {
    lit = vec4(background_seen(background, uv), 1.0);
    return;
  }
  // the ambient term as the direct pass's (ambient_light): k_d albedo, which a pbr metal lacks
  vec3 d = texelFetch(direct, ivec2(gl_FragCoord.xy), 0).rgb, sky = ambient_light(s, ambient);
#ifdef SEED
  vec3 indirect = s.rho * e.rgb;
  vec3 l = (d + sky) * saturate(e.a + 1.0 - k_ssao) + k_isr * indirect;
#else
  vec3 indirect = gi_reflected(s, k, e.rgb);
  vec3 l = d + sky * saturate(e.a) + indirect;
#endif
  if (view == 1) l = indirect;
  if (view == 2) l = vec3(e.a);
  lit = vec4(l, 1.0); // unsanitized: tests check the guards, output.frag the rest
}
