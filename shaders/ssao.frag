// Screen-space ambient occlusion as seed 001 (lines 364-420, 1320-1353):
// K cosine-weighted Halton directions in the hemisphere of the view-space
// normal (halton.glsl; built in the normal's frame, so none needs flipping).
// Sample i lies at P + u_i (w.x radius, w.y radius, w.z tolerance) in view
// space and is projected, so its disc on screen shrinks with depth (the
// seed's depth-scaled radius) and, when tolerance = radius, it is a true
// point of the hemisphere. (Offsetting in screen space by the radius and in
// depth by the tolerance, as the seed words it, puts samples of a plane
// seen at a grazing angle below that plane: the floor darkened by 3%.)
// The G-buffer at the sample's pixel occludes it when nearer than the
// sample (by more than `bias` of P's depth) and no more than `tolerance` in
// front of P. A = 1 - strength (occluded / K): with cosine-weighted
// directions the fraction visible is (1/pi) int V (N.w) dw.
// Output: r = A (1 open); background 1.
#include "halton.glsl"

in vec2 uv;
uniform sampler2D nrm, dpt, mat; // full-size G-buffer
uniform int samples = 20;        // multiple of 10
uniform float radius = 0.0;      // world units (0: reach z)
uniform float tolerance = 0.0;   // world units (0: reach z)
uniform float reach = 0.08;      // fraction of the view depth z
uniform float strength = 1.0;    // 0..1
uniform float bias = 0.002;      // fraction of the depth
uniform int interleave = 4;
uniform int factor = 1;          // this pass runs at 1/factor of the G-buffer

out float ao;

void main() {
  ivec2 gsize = textureSize(dpt, 0), px = ivec2(gl_FragCoord.xy);
  int f = max(factor, 1);
  ivec2 g = clamp(px * f + f / 2, ivec2(0), gsize - 1);
  if (texelFetch(mat, g, 0).a < 0.5) {
    ao = 1.0;
    return;
  }
  float far = frame.clip.y, z = max(texelFetch(dpt, g, 0).r, 0.0) * far;
  vec3 nw = gbuffer_normal_decode(texelFetch(nrm, g, 0)).xyz;
  vec3 n = safe_normalize(mat3(frame.view) * nw, vec3(0.0, 0.0, 1.0));
  float rel = max(reach, 0.0) * z; // scale-free default: a fraction of the depth
  float rad = radius > 0.0 ? radius : rel, tol = tolerance > 0.0 ? tolerance : rel;
  vec2 centre = (vec2(g) + 0.5) / vec2(gsize);
  int k = clamp(samples / 10 * 10, 10, HALTON_MAX);
  mat3 frame_n = tangent_frame(n);
  vec3 offset = halton_offset(px, clamp(interleave, 1, 4));
  float occluded = 0.0;
  vec3 pv = (frame.view * vec4(position_from_depth(centre, z / far), 1.0)).xyz;
  for (int i = 0; i < k; i++) {
    vec3 u = halton_sample(i, offset);
    vec3 w = frame_n * hemisphere_cosine(u.xy);
    vec3 sv = pv + u.z * vec3(w.xy * rad, w.z * tol); // view space: x, y by radius, z by tolerance
    vec4 clip = frame.proj * vec4(sv, 1.0);
    if (clip.w < 1e-6) continue; // behind the eye
    vec2 q_uv = clip.xy / clip.w * 0.5 + 0.5;
    if (any(lessThan(q_uv, vec2(0.0))) || any(greaterThanEqual(q_uv, vec2(1.0)))) continue;
    ivec2 q = min(ivec2(q_uv * vec2(gsize)), gsize - 1);
    if (texelFetch(mat, q, 0).a < 0.5) continue;
    // Filtered at the sample's own uv: the texel centre's depth would be
    // off by up to half a texel's depth change, which on a plane seen at a
    // grazing angle is more than a sample near the plane rises above it.
    float zq = texture(dpt, q_uv).r * far;
    if (zq < clip.w - bias * z && z - zq < tol) occluded += 1.0; // clip.w: the sample's depth
  }
  ao = 1.0 - saturate(strength) * occluded / float(k);
}
