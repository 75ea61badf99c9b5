// Temporal reuse of a coarse GI result (seed 004, chapter 3.3; lines
// 560-610): reverse reprojection of each pixel's world position through the
// previous frame's view-projection, a disocclusion test, and accumulation:
// the running mean of the frames a pixel has seen, up to `frames`, after
// which it stops (the seed's "stop when converged"); the seed's confidence
//   conf = 1 - saturate(|V_{t-1} - V_t|) / (1 + bias)
// over values normalized as HDR (v / (1 + v), the seed's "normalize HDR
// values before the confidence") restarts a pixel whose confidence falls
// below `confidence` (its light changed). Disocclusion: the previous frame
// stored its view depth beside its value; the pixel's depth in the previous
// frame (its reprojected clip w) must match it within `epsilon` of itself
// (relative: any unit), else the history is dropped.
// History: value (rgb V, a frames seen) and depth (r: view depth, 0 none).
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;      // this frame's coarse result (rgb, a kept)
uniform sampler2D history, history_depth; // last frame's accumulation
uniform sampler2D dpt, mat; // this frame's coarse depth and coverage
uniform float epsilon = 0.02, bias = 0.1, frames = 36.0, confidence = 0.25;

layout(location = 0) out vec4 result;
layout(location = 1) out vec4 next;
layout(location = 2) out float next_depth;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 cur = texelFetch(src, px, 0);
  float d = texelFetch(dpt, px, 0).r;
  if (texelFetch(mat, px, 0).a < 0.5) {
    result = cur;
    next = vec4(cur.rgb, 0.0);
    next_depth = 0.0;
    return;
  }
  vec3 p = position_from_depth(uv, d);
  vec4 c = frame.prev_view_proj * vec4(p, 1.0);
  vec3 v = cur.rgb;
  float n = 1.0;
  if (c.w > 1e-12) {
    vec2 q = c.xy / c.w * 0.5 + 0.5;
    if (all(greaterThanEqual(q, vec2(0.0))) && all(lessThanEqual(q, vec2(1.0)))) {
      ivec2 t = clamp(ivec2(q * vec2(textureSize(history, 0))), ivec2(0), textureSize(history, 0) - 1);
      vec4 h = texelFetch(history, t, 0);
      float hd = texelFetch(history_depth, t, 0).r;
      vec3 a = h.rgb / (1.0 + h.rgb), b = cur.rgb / (1.0 + cur.rgb), diff = abs(a - b);
      float conf = 1.0 - saturate(max(diff.r, max(diff.g, diff.b))) / (1.0 + bias);
      if (hd > 0.0 && abs(hd - c.w) <= epsilon * hd && conf >= confidence && h.a >= 1.0) {
        float seen = min(h.a, max(frames, 1.0));
        float w = seen >= frames ? 1.0 : seen / (seen + 1.0);
        v = mix(cur.rgb, h.rgb, w);
        n = min(seen + 1.0, max(frames, 1.0));
      }
    }
  }
  v = finite_or_zero(v);
  result = vec4(v, cur.a);
  next = vec4(v, n);
  next_depth = dpt_view_depth(d);
}
