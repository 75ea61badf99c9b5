// Indirect light from reflective shadow maps (seed 004, lines 858-958; the
// maps: shadow.frag), on POV-Ray's scale (/work/shared/design/gi-scale.md):
//   E(p) = (1/pi) sum_q Phi_q max(0, n_p.D) max(0, n_q.-D) / |q - p|^2 w_q
// (seed eq 9-10 with D = (q - p) / |q - p|), where q runs over RSM texels,
// Phi_q = L_q A_q is the radiance leaving the sender (k_d albedo times the
// light's radiance there, light_incident: what the direct pass gives it,
// with cos cancelled by the area) times the texel's area seen from the light
// A_q (orthographic: a texel's world size squared; perspective: its size per
// unit distance squared times r^2 cos(off-axis angle)), and w_q the texels a
// sample stands for. The composite (isr_light.frag) multiplies by k_d albedo.
//
// Sampling: the seed's pattern around p's projection into each RSM view,
// offsets xi_1 R at angle 2 pi xi_2 (R = `radius` tiles), denser near the
// centre where senders are nearest; its density per texel falls as
// 1 / (2 pi R^2 xi_1), so each sample weighs 2 pi R^2 xi_1 T^2 / N texels
// (T the tile's side): the seed's "samples weighed by their squared
// distance" (line 917) made exact for this pattern. Samples outside the tile
// or on an empty texel add nothing; so R is at most the distance to the
// tile's farthest corner, where the disc covers the whole tile already.
// Interleaved sampling: the pattern is one sequence, xi_1 = Phi_2(k) (van der
// Corput) and xi_2 = k phi (golden ratio, mod 1), of which pixel j of a 4 x 4
// tile (Bayer order, halton.glsl) takes the block k = j n .. j n + n - 1: each
// pixel's n samples are stratified in xi_1 and spread in angle, and the 16
// blocks together are the sequence's first 16 n points, which the
// geometry-aware blur averages. Each sample still weighs its own density, so
// one pixel alone is exact too, only noisier. The angle steps by a fixed
// rotation (no sin or cos a sample); the pattern turns per frame by `rotate`.
// 1/d^2 is capped at the texel's own area, so a sender next to p stays finite.
// VISIBILITY: the seed's screen-space test (lines 930-958): `steps` points
// on p -> q; one behind the depth buffer rejects q.
// EXCLUDE_SEEN: a sender the camera sees (on screen, depth within 2% of the
// buffer's) is left to the screen-space pass of the combined technique.
// TEMPORAL: temporal reuse (temporal.glsl): the result is the accumulation,
// and the history for the next frame goes to `next` and `next_state`; a
// pixel whose accumulation has converged takes no samples and keeps it.
// Output: rgb = E, a = 1 (RSM light occludes no ambient term).
// With STRIDE, each texel reads the G-buffer, STRIDE times finer, at its
// block's centre (isr.coarse_view); with Z it also writes that depth / far,
// 0 where nothing is drawn, into z (the view's depth).
#include "rsm.glsl"
#include "halton.glsl"
#ifdef TEMPORAL
#include "temporal.glsl"
#endif

#ifndef STRIDE
#define STRIDE 1
#endif

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat;          // G-buffer, STRIDE times finer than the output
uniform sampler2D rsm_flux, rsm_pos;  // shadow.lua's RSM targets (atlas-sized; the normal in rsm_pos.w)
uniform int samples = 64;
uniform float radius = 1.0;
uniform float rotate = 0.0; // turn of the pattern a frame, in turns (seed 004: 10 degrees)
uniform int steps = 0;

layout(location = 0) out vec4 result;
#ifdef Z
layout(location = 1) out float z;
#endif
#ifdef TEMPORAL
layout(location = 2) out vec4 next;       // the history's value
layout(location = 3) out vec2 next_state; // and state: view depth (0 none), frames seen
#endif

const int INTERLEAVE = 4;                          // tile side of the interleaved pattern
const float GOLDEN = 0.61803398874989;             // the angle's step, in turns
const vec2 TURN = vec2(-0.73736887807832, -0.67549029426152); // cos, sin of 2 pi GOLDEN
const float PLASTIC = 0.75487766624669;            // 1 / the plastic number

bool blocked(vec3 p, vec3 q) {
  for (int j = 1; j <= steps; j++) {
    vec3 x = mix(p, q, float(j) / float(steps + 1));
    vec4 c = frame.view_proj * vec4(x, 1.0);
    if (c.w <= 1e-12) continue;
    vec2 s = c.xy / c.w * 0.5 + 0.5;
    if (any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))) continue;
    float z = -(frame.view * vec4(x, 1.0)).z * frame.clip.z, zb = texture(dpt, s).r;
    if (texture(mat, s).a >= 0.5 && z > zb * 1.02) return true;
  }
  return false;
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  const vec4 none = vec4(0.0, 0.0, 0.0, 1.0);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, block_centre(px, STRIDE, textureSize(dpt, 0)));
#ifdef Z
  z = s.covered ? s.depth01 : 0.0;
#endif
#ifdef TEMPORAL
  next = vec4(0.0);
  next_state = vec2(s.covered ? dpt_view_depth(s.depth01) : 0.0, 0.0);
#endif
  if (!s.covered) {
    result = none;
    return;
  }
#ifdef TEMPORAL
  vec4 h;
  float held;
  bool found = temporal_history(uv, s.depth01, h, held);
  if (found && temporal_converged(held, px)) { // kept as it is
    next = vec4(h.rgb, 1.0);
    next_state.y = max(frames, 1.0);
    result = next;
    return;
  }
#endif

  int j = interleave_index(px, INTERLEAVE);
  float turn = fract(frame.time.y * rotate);
  // With temporal reuse the radii move too (by the plastic number's step, unrelated to the angle's), so
  // that the frames a pixel accumulates cover other distances, not only other angles.
  float shift = rotate > 0.0 ? fract(frame.time.y * PLASTIC) : 0.0;
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  vec3 e = vec3(0.0);
  for (int i = 0; i < frame.counts.x; i++) {
    ShadowLight sl = shadow_lights[i];
    Light li = lights[i]; // read once, not in the sample loop (rsm.gather about 8% faster on llvmpipe)
    int first = sl.cube.y, count = sl.cube.z;
    int n = count > 0 ? max(samples / count, 1) : 0;
    // The block's first angle: j n phi turns (j integer: fract(j fract(n phi)) = fract(j n phi),
    // without the rounding of the large product).
    float a0 = 2.0 * PI * fract(float(j) * fract(float(n) * GOLDEN) + turn);
    uint k0 = uint(j * n);
    float centred = 0.5 / float(max(n * INTERLEAVE * INTERLEAVE, 1)) + shift; // half the union's radial stratum
    for (int v = first; v < first + count; v++) {
      ShadowView sv = shadow_views[v];
      vec4 c = sv.view_proj * vec4(s.p, 1.0);
      vec2 centre = c.w > 1e-12 ? c.xy / c.w * 0.5 + 0.5 : vec2(0.5);
      centre = clamp(centre, vec2(0.0), vec2(1.0)); // behind a cube face: its nearest edge
      float tile = sv.rect.z * atlas.x;
      // The disc reaches no farther than the tile's farthest corner: beyond it every sample would fall
      // outside and add nothing, so the pattern keeps its samples where texels are.
      float reach = min(radius, length(max(centre, 1.0 - centre)));
      float texels = 2.0 * PI * reach * reach * tile * tile / float(max(n, 1));
      vec2 dir = vec2(cos(a0), sin(a0));
      for (int k = 0; k < n; k++, dir = vec2(dir.x * TURN.x - dir.y * TURN.y, dir.x * TURN.y + dir.y * TURN.x)) {
        float xi = fract(radical_inverse(k0 + uint(k), 2u) + centred);
        vec2 t = centre + xi * reach * dir;
        if (any(lessThan(t, vec2(0.0))) || any(greaterThanEqual(t, vec2(1.0)))) continue;
        ivec2 a = ivec2((sv.rect.xy + t * sv.rect.zw) * atlas);
        vec4 qn = texelFetch(rsm_pos, a, 0); // position, normal (normal_pack)
        if (qn.w > 0.0) continue; // empty
        vec3 q = qn.xyz, nq = normal_unpack(qn.w);
        float area = rsm_texel_area(sv, t, q, tile);
        vec3 d = q - s.p;
        float d2 = dot(d, d);
        vec3 towards = d * inversesqrt(max(d2, 1e-30));
        float g = max(dot(s.n, towards), 0.0) * max(dot(nq, -towards), 0.0) / max(d2, area);
        if (g <= 0.0) continue; // before the flux and the light: coplanar and facing-away senders are common
#ifdef EXCLUDE_SEEN
        if (rsm_seen(dpt, q)) continue;
#endif
#ifdef VISIBILITY
        if (blocked(s.p, q)) continue;
#endif
        vec3 l;
        vec3 radiance = light_arriving(li, q, l);
        e += texelFetch(rsm_flux, a, 0).rgb * radiance * area * g * texels * xi;
      }
    }
  }
  vec3 v = finite_or_zero(e / PI);
#ifdef TEMPORAL
  next = temporal_accumulate(vec4(v, 1.0), found, h, held, next_state.y);
  v = next.rgb;
#endif
  result = vec4(v, 1.0);
}
