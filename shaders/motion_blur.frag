// Motion blur along each pixel's screen motion (scripts/motion_blur.lua), in
// three passes of this file:
//   TILES:      each texel of a grid of 4-pixel tiles takes the longest
//               streak of its tile (the last row and column of tiles reach
//               the image's edge), then (BLOCKS) of `tile`-pixel ones from it;
//   NEIGHBOURS: each tile the longest of its own and its 8 neighbours';
//   (neither):  each pixel gathers along its tile's longest streak near.
// A pixel's motion comes from the G-buffer's velocity target (VELOCITY;
// camera, node and deformation motion: velocity.glsl), or, where no surface
// was drawn (and without the target), from the camera alone: the pixel's
// world position (rebuilt from linear depth, seed 000 eq 23-24; the far
// plane for the background) through the previous frame's view-projection.
//
// The shutter is open for `strength` of the frame, centred on it: a pixel
// gathers `samples` reads along the longest streak near it (a moving object
// smears over the still background it passes). Each read Y counts for the
// centre X when Y's own streak reaches X and Y lies in front (an object over
// the background), or X's streak reaches Y and Y lies behind (X smeared over
// what is behind it), or both streaks reach the other (a surface blurred
// along itself). Streaks are capped at `max_length` pixels; NaN motion is
// none. Where no streak near reaches half a pixel (a still frame), the pixel
// is left exactly as it is.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, dpt, near;
#ifdef VELOCITY
uniform sampler2D vel;
#endif
uniform float strength = 0.5;    // 0..4
uniform float max_length = 32.0; // pixels, >= 0
uniform int samples = 12;        // 1..64
uniform int tile = 16;           // pixels a side of the tiles (TILES: pixels or, BLOCKS, texels of near)

out vec4 dst;

// Does the camera move this frame? (Set by main: one test, not one a read.)
bool camera_moves = false;

// The camera's motion (output pixels, now minus then) of the point at uv
// (its depth 0: the background, taken at the far plane).
vec2 camera_motion(vec2 at) {
  float d = texture(dpt, at).r;
  vec3 p = position_from_depth(at, d > 0.0 ? clamp(d, 0.0, 1.0) : 1.0);
  vec4 prev = frame.prev_view_proj * vec4(p, 1.0);
  if (!(prev.w > EPS)) return vec2(0.0); // behind the last camera: no trustworthy motion
  return (at - (prev.xy / prev.w * 0.5 + 0.5)) * frame.output_size.xy;
}

// The streak (pixels, scaled by the shutter and capped) of the pixel at uv.
// A still camera moves nothing (the far plane's reprojection alone is off by
// a fraction of a pixel).
vec2 streak(vec2 at) {
  vec2 m = vec2(0.0);
#ifdef VELOCITY
  vec4 v = texture(vel, at);
  if (v.a > 0.5) m = v.xy;
  else if (camera_moves) m = camera_motion(at);
#else
  if (camera_moves) m = camera_motion(at);
#endif
  m *= clamp(strength, 0.0, 4.0);
  float len = length(m), cap = max(max_length, 0.0);
  if (!(len > 1e-3) || isinf(len)) return vec2(0.0); // none, NaN, or Inf
  return m * (min(len, cap) / len);
}

#if defined(TILES)
// With BLOCKS the texels of `near` (a finer grid of tiles) stand for pixels:
// the grid is reduced in two steps, each texel reading a few (a single step
// of 16 x 16 reads a texel left llvmpipe's cores idle: 3.1 ms at 256x192).
void main() {
  camera_moves = frame.view_proj != frame.prev_view_proj;
#ifdef BLOCKS
  ivec2 size = textureSize(near, 0);
#else
  ivec2 size = ivec2(frame.output_size.xy);
#endif
  ivec2 q = ivec2(gl_FragCoord.xy), tiles = max(size / max(tile, 1), ivec2(1));
  ivec2 lo = q * tile, hi = min(mix(lo + tile, size, equal(q, tiles - 1)), size);
  vec2 best = vec2(0.0);
  for (int y = lo.y; y < hi.y; y++)
    for (int x = lo.x; x < hi.x; x++) {
#ifdef BLOCKS
      vec2 m = texelFetch(near, ivec2(x, y), 0).xy;
#else
      vec2 m = streak((vec2(x, y) + 0.5) * frame.output_size.zw);
#endif
      if (dot(m, m) > dot(best, best)) best = m;
    }
  dst = vec4(best, 0.0, 1.0);
}
#elif defined(NEIGHBOURS)
void main() {
  ivec2 q = ivec2(gl_FragCoord.xy), size = textureSize(near, 0);
  vec2 best = vec2(0.0);
  for (int y = -1; y <= 1; y++)
    for (int x = -1; x <= 1; x++) {
      vec2 m = texelFetch(near, clamp(q + ivec2(x, y), ivec2(0), size - 1), 0).xy;
      if (dot(m, m) > dot(best, best)) best = m;
    }
  dst = vec4(best, 0.0, 1.0);
}
#else
// 1 when depth a lies in front of depth b (eye depths), fading over 1%.
float in_front(float a, float b) { return saturate(1.0 - (a - b) / max(0.01 * b, EPS)); }
// Does a streak of length len reach a point d pixels away?
float reaches(float d, float len) { return saturate(1.0 - d / max(len, 0.5)); }

// The centre's colour blurred along `far` (pixels, of length len_far).
vec3 gather(vec3 centre, vec2 far, float len_far) {
  vec2 px = frame.output_size.zw, own = streak(uv);
  float zx = eye_depth(texture(dpt, uv).r), len_x = length(own);
  int n = clamp(samples, 1, 64);
  float total = 1.0 / max(len_x, 0.5); // the centre, as a streak of its own length
  vec3 sum = centre * total;
  for (int i = 0; i < n; i++) {
    float t = (float(i) + 0.5) / float(n) - 0.5; // -0.5 .. 0.5 of the shutter
    vec2 at = uv + far * t * px;
    float d = abs(t) * len_far; // pixels from the centre
    float zy = eye_depth(texture(dpt, at).r), len_y = length(streak(at));
    float w = in_front(zy, zx) * reaches(d, len_y) + in_front(zx, zy) * reaches(d, len_x) +
              2.0 * step(d, len_y) * step(d, len_x) / max(max(len_x, len_y), 0.5);
    sum += w * hdr_clamp(texture(src, at).rgb, HALF_MAX);
    total += w;
  }
  return hdr_clamp(sum / max(total, EPS), HALF_MAX);
}

void main() {
  camera_moves = frame.view_proj != frame.prev_view_proj;
  vec3 centre = hdr_clamp(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb, HALF_MAX);
  ivec2 size = textureSize(near, 0);
  vec2 far = texelFetch(near, clamp(ivec2(gl_FragCoord.xy) / max(tile, 1), ivec2(0), size - 1), 0).xy;
  float len_far = length(far);
  dst = vec4(centre, 1.0);
  if (len_far >= 0.5) dst = vec4(gather(centre, far, len_far), 1.0); // else (or NaN) nothing to blur
}
#endif
