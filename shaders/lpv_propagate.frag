// One propagation step of the light propagation volumes (seed 003, section
// 5.2.6; scripts/lpv.lua): every cell of every cascade gathers what its six
// neighbours send it, in one pass over the unwrapped volume (a neighbour
// across a layer's or cascade's edge is no neighbour: nothing wraps; a texel
// no cell uses holds nothing).
//
// The transfer. The seed takes the second LPV version's cell-to-cell step
// (the source's intensity towards each face of the destination times the
// face's solid angle, re-sent from the destination as a lobe facing out of
// that face). That step turns light that crosses a cell obliquely into light
// facing a side face, so a wave loses its direction within a few steps and
// spreads as a diffusion: after 8 steps the light three cells above a lit
// infinite plane is a tenth of the exact irradiance (a CPU model of both
// steps; this one keeps 40% there, 90% in the first cell). Here each
// direction's light moves to a neighbour as a cube's faces see it: light
// travelling in w leaves through face k in the share
//   w_k(w) = max(0, w.e_k) / (|w_x| + |w_y| + |w_z|)
// (its projected area; the six shares sum to 1, so nothing is made or lost),
// keeping its direction. The destination gets the 2-band projection of
// I(w) w_k(w), linear in the source's (A, B):
//   A' = S_k / 4 pi,  S_k = W0 A + ALPHA B.e_k
//   B' = 3 / 4 pi (ALPHA A e_k + BETA (B.e_k) e_k + GAMMA (B - (B.e_k) e_k))
// with W0 = int w_k = 2 pi / 3, ALPHA = int w_k w.e_k, BETA = int w_k (w.e_k)^2,
// GAMMA = int w_k (w.e_x)^2 for e_x across e_k (numerical integrals; BETA +
// 2 GAMMA = W0 exactly). S_k is the power sent to neighbour k.
// Energy never grows: 2 bands go negative behind a directional lobe, so
// S_k < 0 for some k while the sum over k is the cell's power 4 pi A. Negative
// transfers are dropped and the positive ones scaled so that they sum to at
// most 4 pi A (send_scale: the injected wave's in the FIRST step, later
// waves are stored scaled, which saves each destination computing its six
// sources' scales); the geometry volume's blocking only takes away. Each
// step's wave then holds at most the last one's power (test_lpv).
// Blocking: light entering the destination in direction e_k is stopped by
// the share of it the destination's surfaces cover, B_d(e_k) clamped to
// [0, 1] (the geometry volume's lobe at the destination cell), times
// `occlusion`.
// Output: the new wave (rgb channels in three targets, scaled by send_scale),
// and with SUM each channel's running sum over the steps (the lookup's
// light), the input sum plus the new wave; without SUM the new wave starts a
// sum. With ALL (the last step, whose wave nobody reads) the first three
// targets get the sum over all steps instead, the running sum plus the
// `early` sums of the first half (lpv.lua), so that the lookup reads one sum
// where it would add two.
#include "lpv.glsl"

uniform sampler2D wave_r, wave_g, wave_b; // the last step's wave
uniform sampler2D geometry;               // blocking lobes (lpv_inject.vert)
uniform float occlusion = 1.0;
#ifdef SUM
uniform sampler2D sum_r, sum_g, sum_b;
#endif
#ifdef ALL
uniform sampler2D early_r, early_g, early_b;
#endif

layout(location = 0) out vec4 out_r;
layout(location = 1) out vec4 out_g;
layout(location = 2) out vec4 out_b;
layout(location = 3) out vec4 out_sum_r;
layout(location = 4) out vec4 out_sum_g;
layout(location = 5) out vec4 out_sum_b;

const float W0 = 2.0943951, ALPHA = 1.4120679, BETA = 1.0749945, GAMMA = 0.5097003;
const float INV_4PI = 0.0795774715;

// The share of its transfers a cell holding sh sends (1 unless 2 bands' negative lobes make the
// positive transfers add up to more than its power 4 pi A).
float send_scale(vec4 sh) {
  float a = max(sh.x, 0.0);
  vec3 plus = max(W0 * a + ALPHA * sh.yzw, 0.0), minus = max(W0 * a - ALPHA * sh.yzw, 0.0);
  float sent = plus.x + plus.y + plus.z + minus.x + minus.y + minus.z;
  return sent > 0.0 ? min(4.0 * PI * a / sent, 1.0) : 0.0;
}

// What a source cell holding sh sends to its neighbour along axis `axis` in direction `sign`.
// Waves after the first step are stored scaled by their send_scale.
vec4 transfer(vec4 sh, int axis, float sign) {
  float a = max(sh.x, 0.0), be = sign * sh[axis + 1], s = W0 * a + ALPHA * be;
  if (s <= 0.0) return vec4(0.0);
  vec4 out_sh = vec4(s * INV_4PI, 3.0 * INV_4PI * GAMMA * sh.yzw);
  out_sh[axis + 1] = sign * 3.0 * INV_4PI * (ALPHA * a + BETA * be);
#ifdef FIRST
  out_sh *= send_scale(sh);
#endif
  return out_sh;
}

vec4 r = vec4(0.0), gr = vec4(0.0), b = vec4(0.0);

// Adds what the neighbour on the `sign` side along `axis` sends this cell (at `cell` of cascade
// c, texel t; n: the cascade's cells a side), less what the cell's geometry g blocks. The
// neighbour's texel is t less one column along x, one row along y and a slice's nx columns along z
// (lpv.glsl's layout), which spares each neighbour lpv_texel's per-cascade uniforms.
void gather(ivec3 cell, ivec2 t, ivec3 n, vec4 g, int axis, float sign) {
  int s = cell[axis] - int(sign);
  if (s < 0 || s >= n[axis]) return;
  ivec2 ts = t - int(sign) * (axis == 0 ? ivec2(1, 0) : axis == 1 ? ivec2(0, 1) : ivec2(n.x, 0));
  float open = 1.0 - occlusion * clamp(g.x + sign * g[axis + 1], 0.0, 1.0);
  r += open * transfer(texelFetch(wave_r, ts, 0), axis, sign);
  gr += open * transfer(texelFetch(wave_g, ts, 0), axis, sign);
  b += open * transfer(texelFetch(wave_b, ts, 0), axis, sign);
}

void main() {
  ivec2 t = ivec2(gl_FragCoord.xy);
  int c;
  ivec3 cell;
  if (!lpv_cell_at(t, c, cell)) {
    out_r = out_g = out_b = out_sum_r = out_sum_g = out_sum_b = vec4(0.0);
    return;
  }
  vec4 g = texelFetch(geometry, t, 0);
  ivec3 n = lpv_dims(c);
  gather(cell, t, n, g, 0, 1.0);
  gather(cell, t, n, g, 0, -1.0);
  gather(cell, t, n, g, 1, 1.0);
  gather(cell, t, n, g, 1, -1.0);
  gather(cell, t, n, g, 2, 1.0);
  gather(cell, t, n, g, 2, -1.0);
  r = lpv_finite(r);
  gr = lpv_finite(gr);
  b = lpv_finite(b);
#ifdef SUM
  out_sum_r = lpv_finite(r + texelFetch(sum_r, t, 0));
  out_sum_g = lpv_finite(gr + texelFetch(sum_g, t, 0));
  out_sum_b = lpv_finite(b + texelFetch(sum_b, t, 0));
#else
  out_sum_r = r;
  out_sum_g = gr;
  out_sum_b = b;
#endif
#ifdef ALL
  out_r = lpv_finite(out_sum_r + texelFetch(early_r, t, 0));
  out_g = lpv_finite(out_sum_g + texelFetch(early_g, t, 0));
  out_b = lpv_finite(out_sum_b + texelFetch(early_b, t, 0));
#else
  out_r = r * send_scale(r);
  out_g = gr * send_scale(gr);
  out_b = b * send_scale(b);
#endif
}
