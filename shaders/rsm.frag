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
// or on an empty texel add nothing. Halton points rotated per pixel in a 4 x 4
// tile (the blur averages them) and per frame by `rotate`.
// 1/d^2 is capped at the texel's own area, so a sender next to p stays finite.
// VISIBILITY: the seed's screen-space test (lines 930-958): `steps` points
// on p -> q; one behind the depth buffer rejects q.
// EXCLUDE_SEEN: a sender the camera sees (on screen, depth within 2% of the
// buffer's) is left to the screen-space pass the combined technique adds.
// Output: rgb = E, a = 1 (RSM light occludes no ambient term); with BASE,
// the coarse result `base` of the screen-space pass plus E (its a kept).
#include "rsm.glsl"
#include "halton.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat;          // coarse G-buffer
uniform sampler2D rsm_flux, rsm_nrm, rsm_pos;  // shadow.lua's RSM targets (atlas-sized)
uniform int samples = 64;
uniform float radius = 1.0;
uniform float rotate = 0.0; // turn of the pattern a frame, in turns (seed 004: 10 degrees)
uniform int steps = 0;
#ifdef BASE
uniform sampler2D base;
#endif

out vec4 result;

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
#ifdef BASE
  vec4 b = texelFetch(base, px, 0);
#else
  vec4 b = vec4(0.0, 0.0, 0.0, 1.0);
#endif
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, px);
  if (!s.covered) {
    result = b;
    return;
  }
  vec3 offset = halton_offset(px, 4);
  offset.x = fract(offset.x + fract(frame.time.y * rotate));
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  vec3 e = vec3(0.0);
  for (int i = 0; i < frame.counts.x; i++) {
    ShadowLight sl = shadow_lights[i];
    int first = sl.cube.y, count = sl.cube.z;
    int n = count > 0 ? max(samples / count, 1) : 0;
    for (int v = first; v < first + count; v++) {
      ShadowView sv = shadow_views[v];
      vec4 c = sv.view_proj * vec4(s.p, 1.0);
      vec2 centre = c.w > 1e-12 ? c.xy / c.w * 0.5 + 0.5 : vec2(0.5);
      centre = clamp(centre, vec2(0.0), vec2(1.0)); // behind a cube face: its nearest edge
      float tile = sv.rect.z * atlas.x;
      float texels = 2.0 * PI * radius * radius * tile * tile / float(max(n, 1));
      for (int k = 0; k < n; k++) {
        vec3 h = halton_sample(k, offset);
        vec2 t = centre + h.y * radius * vec2(cos(2.0 * PI * h.x), sin(2.0 * PI * h.x));
        if (any(lessThan(t, vec2(0.0))) || any(greaterThanEqual(t, vec2(1.0)))) continue;
        ivec2 a = ivec2((sv.rect.xy + t * sv.rect.zw) * atlas);
        vec3 nq = texelFetch(rsm_nrm, a, 0).xyz;
        if (dot(nq, nq) > 1.5) continue; // empty
        vec3 q = texelFetch(rsm_pos, a, 0).xyz;
        vec3 rho = texelFetch(rsm_flux, a, 0).rgb;
        vec3 l;
        vec3 radiance = light_incident(i, q, l);
        float area = rsm_texel_area(sv, t, q, tile);
        vec3 d = q - s.p;
        float d2 = dot(d, d);
        vec3 dir = d * inversesqrt(max(d2, 1e-30));
        float g = max(dot(s.n, dir), 0.0) * max(dot(nq, -dir), 0.0) / max(d2, area);
        if (g <= 0.0) continue;
#ifdef EXCLUDE_SEEN
        if (rsm_seen(dpt, q)) continue;
#endif
#ifdef VISIBILITY
        if (blocked(s.p, q)) continue;
#endif
        e += rho * radiance * area * g * texels * h.y;
      }
    }
  }
  result = vec4(b.rgb + finite_or_zero(e / PI), b.a);
}
