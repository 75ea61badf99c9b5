// Temporal reuse of a coarse GI result (seed 004, chapter 3.3; lines
// 560-610): reverse reprojection of each pixel's world position through the
// previous frame's view-projection, a disocclusion test (temporal.glsl), and
// accumulation: the running mean of the frames a pixel has seen, up to
// `frames`, after which it stops (the seed's "stop when converged"): a
// converged pixel keeps its history, and the GI pass skips it
// (TEMPORAL_SKIP) except in the frames that refresh its tile. The seed's
// confidence
//   conf = 1 - saturate(|V_{t-1} - V_t|) / (1 + bias)
// over values normalized as HDR (v / (1 + v), the seed's "normalize HDR
// values before the confidence") restarts a pixel whose confidence falls
// below `confidence` (its light changed), on the frames it has fresh samples.
// History: value (rgb V, a frames seen) and depth (r: view depth, 0 none).
#include "temporal.glsl"

in vec2 uv;
uniform sampler2D src;      // this frame's coarse result (rgb, a kept); where converged, not computed
uniform sampler2D dpt;      // this frame's coarse depth
#ifndef Z_MASK
uniform sampler2D mat;      // its coverage (a); with Z_MASK, the depth's: 0 where nothing was drawn
#endif
uniform float bias = 0.1, confidence = 0.25;

layout(location = 0) out vec4 result;
layout(location = 1) out vec4 next;
layout(location = 2) out float next_depth;

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 cur = texelFetch(src, px, 0);
  float d = texelFetch(dpt, px, 0).r;
#ifdef Z_MASK
  if (d <= 0.0) {
#else
  if (texelFetch(mat, px, 0).a < 0.5) {
#endif
    result = cur;
    next = vec4(cur.rgb, 0.0);
    next_depth = 0.0;
    return;
  }
  vec3 v = cur.rgb;
  float n = 1.0;
  vec4 h;
  float most = max(frames, 1.0);
  if (temporal_converged(uv, d, px, h)) {
    v = h.rgb;
    n = most;
  } else if (temporal_history(uv, d, h)) {
    vec3 a = h.rgb / (1.0 + h.rgb), b = cur.rgb / (1.0 + cur.rgb), diff = abs(a - b);
    float conf = 1.0 - saturate(max(diff.r, max(diff.g, diff.b))) / (1.0 + bias);
    if (conf >= confidence) {
      float seen = min(h.a, most);
      float w = seen >= frames ? 1.0 : seen / (seen + 1.0);
      v = mix(cur.rgb, h.rgb, w);
      n = min(seen + 1.0, most);
    }
  }
  v = finite_or_zero(v);
  result = vec4(v, cur.a);
  next = vec4(v, n);
  next_depth = dpt_view_depth(d);
}
