// Temporal reuse of a coarse GI result (seed 004, chapter 3.3; lines
// 560-610), inside the GI pass that computes it (TEMPORAL in rsm.frag,
// isr_march.frag, isr_bounce.frag and ssdo.frag; scripts/temporal.lua binds
// the history): reverse reprojection of each pixel's world position
// through the previous frame's view-projection, a disocclusion test, and
// accumulation: the running mean of the frames a
// pixel has seen, up to `frames`, after which it stops (the seed's "stop
// when converged"): a converged pixel keeps its history, and the pass takes
// no samples for it except in the frames that refresh its tile. The seed's
// confidence
//   conf = 1 - saturate(|V_{t-1} - V_t|) / (1 + bias)
// over values normalized as HDR (v / (1 + v), the seed's "normalize HDR
// values before the confidence"; v is light over the frame's metered key, so
// the same at any light level) restarts a pixel whose confidence falls
// below `confidence` (its light changed), on the frames it has fresh samples.
// The history is last frame's accumulation: value (rgba, every channel
// accumulated; the confidence reads rgb) and state (r: view depth, 0 none;
// g: frames seen), at the coarse size of the pass; the pass writes this
// frame's into two more outputs. Its rgb is light (pre-exposed: the last
// frame's exposure, rescaled to this frame's as it is read); a is not.
#ifndef LIMN_TEMPORAL_GLSL
#define LIMN_TEMPORAL_GLSL
#include "common.glsl"
#include "halton.glsl"

uniform sampler2D history, history_state;
uniform float epsilon = 0.02, frames = 36.0, bias = 0.1, confidence = 0.25;
uniform int refresh = 32;
uniform int restart = 0; // 1: the settings or the light changed (temporal.begin), no history is kept
uniform float moving = 0.0; // > 0: a view-dependent result's most frames while the view changes
uniform int world_moved = 0; // 1: the world changed since the last frame (a view-dependent result: the camera
                             // too; another: the scene alone, still_frames("scene"))
uniform int view_dependent = 0; // 1: the result depends on the view (ISR, SSDO), so a moving view caps it too
uniform int turn = 1; // 1: the pass's pattern turns every frame; 0: only while the view moves (temporal.turn)
uniform int gather_turns = 0; // 1: another gather in the pass turns every frame (isr+rsm+esm's RSM): the
                              // history averages anyway, so the pass's own pattern turns too (kept, a
                              // fixed pattern would lose the blur it needs as the history grows)
#ifdef VELOCITY
// The G-buffer's velocity target (velocity.glsl): a pixel whose surface moved
// on its own (a = 2) reprojects along its motion, to the view depth it had.
uniform sampler2D velocity;
#endif
#ifdef TEMPORAL_CLAMP
// Neighbourhood clamping (temporal.clamp, temporal_clamp.frag): the pass also
// writes this frame's fresh estimate (rgb) and the weight its history took
// (a: raw = mix(fresh, h, w); -1 where no fresh samples were taken), after
// its other outputs (NEXT + 2). A pass sets it to (0, 0, 0, -1) first.
layout(location = NEXT + 2) out vec4 temporal_fresh;
#endif
// Set by temporal_history: the pixel's surface moved on its own since the
// last frame (a node or a deformation), so its light may have changed.
bool temporal_self_moved = false;

// Does the view change this frame, for a result that depends on it
// (`view_dependent`: ISR's and SSDO's light at a point depends on what the
// screen shows, where RSM's does not), or the world that lights it (a door
// opening onto the sun changes the light on walls that stood still; a
// light or caster that moves changes the RSM)? Its history then counts at
// most `moving` frames, so that it follows the change with about that lag,
// and no pixel counts as converged (a converged one would keep the old
// light until its tile's refresh). `moving` 0: never. For a result that
// does not depend on the view, world_moved is the scene's change alone
// (temporal.bind), so a camera moving while a light moves caps it too.
bool temporal_moving() {
  bool view = frame.view_proj != frame.prev_view_proj;
  return moving > 0.0 && ((view_dependent != 0 && view) || temporal_self_moved || world_moved != 0);
}

// The frame by which the pass turns its sampling pattern: the frame's
// number, or with `turn` 0 on a still view 0, the pattern reuse off takes.
// A still view then keeps one pattern: each frame takes the samples the
// last took, so the history holds nothing new (temporal_accumulate keeps
// the fresh value, which follows a change of the world at once) and serves
// only to skip converged pixels and settled frames, and the image is reuse
// off's, without the flicker of a running mean that moves by its noise each
// frame until it converges. A moving view turns it: the reprojected history
// then holds other samples of the same surface.
bool temporal_turning() { return turn != 0 || gather_turns != 0 || frame.view_proj != frame.prev_view_proj; }
int temporal_turn() { return temporal_turning() ? int(uint(frame.time.y) & 65535u) : 0; }

// The history of the pixel at uv whose coarse depth is d (dpt): the
// pixel's world position through the previous frame's view-projection; kept
// where the previous frame stored a depth that matches the reprojected
// clip w (the view depth there) within `epsilon` of it (relative: any
// unit), else dropped (off the last frame, disoccluded). With VELOCITY, a
// surface that moved on its own is looked up where its motion says it lay,
// against the view depth it had then; a still one as above, so that a still
// world reprojects exactly as without. False: none; else h its value and n
// the frames it holds.
bool temporal_history(vec2 uv, float d, out vec4 h, out float n) {
  h = vec4(0.0);
  n = 0.0;
  if (restart != 0) return false;
  vec4 c = frame.prev_view_proj * vec4(position_from_depth(uv, d), 1.0);
  if (c.w <= 1e-12) return false;
  vec2 q = c.xy / c.w * 0.5 + 0.5;
  float then = c.w;
#ifdef VELOCITY
  ivec2 vsize = textureSize(velocity, 0);
  vec4 v = texelFetch(velocity, clamp(ivec2(uv * vec2(vsize)), ivec2(0), vsize - 1), 0);
  temporal_self_moved = v.a > 1.5;
  if (temporal_self_moved) {
    if (!(v.b > 0.0)) return false; // behind the last camera: no history
    q = uv - v.xy * frame.output_size.zw;
    then = v.b;
  }
#endif
  if (any(lessThan(q, vec2(0.0))) || any(greaterThan(q, vec2(1.0)))) return false;
  ivec2 size = textureSize(history, 0), t = clamp(ivec2(q * vec2(size)), ivec2(0), size - 1);
  h = texelFetch(history, t, 0);
  h.rgb *= frame.exposure.z; // light under the last frame's pre-exposure, in this one's (exposed())
  vec2 state = texelFetch(history_state, t, 0).rg;
  n = state.g;
  return state.r > 0.0 && abs(state.r - then) <= epsilon * state.r && n >= 1.0;
}

// Does pixel px take fresh samples this frame although it has converged?
// Tiles of 4 x 4 pixels (the interleaved pattern's) take turns, one frame
// in `refresh` each (the seed's refreshed tiles), so that a converged pixel
// whose light changed finds out (its confidence drops) within `refresh`
// frames. A tile's turn is its Bayer index among 4 x 4 tiles and of its
// block among 4 x 4 blocks (256 turns): each frame refreshes the same share
// of the image, scattered over it. 0: never.
bool temporal_refresh(ivec2 px) {
  if (refresh <= 0) return false;
  ivec2 tile = px >> 2;
  int turn = interleave_index(tile, 4) + 16 * interleave_index(tile >> 2, 4);
  return (turn + int(frame.time.y)) % refresh == 0;
}

// Has the pixel whose history holds n frames converged, so that this
// frame's samples would not change it? It holds `frames` frames and is not
// being refreshed. The accumulation then keeps the history as it is.
bool temporal_converged(float n, ivec2 px) {
  return n >= max(frames, 1.0) && !temporal_refresh(px) && !temporal_moving() && !temporal_self_moved;
}

// The value to store for a pixel that took fresh samples `cur`: the running
// mean with its history h of n frames (found: temporal_history) while the
// confidence holds, else cur alone; `seen` the frames it then holds.
vec4 temporal_accumulate(vec4 cur, bool found, vec4 h, float n, out float seen) {
  bool moved = temporal_moving();  // (a surface that moved alone, as a moving view)
  float most = moved ? clamp(moving, 1.0, max(frames, 1.0)) : max(frames, 1.0);
  // The same samples as the history's (a still view's kept pattern): nothing to average, and one
  // frame's samples held (so the blur's age stays that of a fresh frame, the one reuse off blurs).
  if (found && (temporal_turning() || gather_turns != 0)) {
    // Judged on light relative to the frame's key (frame.exposure.w, pre-exposed as h and cur), so
    // that a change restarts a pixel alike under starlight and sunlight: on radiance v / (1 + v)
    // saturates above about 1 (a bright scene never restarted) and is linear below (a dim one
    // neither), and E alone leaves the key anywhere within its band, where the noise of a few
    // samples restarts pixels at one level and not at another.
    vec3 ha = h.rgb / frame.exposure.w, hb = cur.rgb / frame.exposure.w; // w > 0
    vec3 a = ha / (1.0 + ha), b = hb / (1.0 + hb), diff = abs(a - b);
    float conf = 1.0 - saturate(max(diff.r, max(diff.g, diff.b))) / (1.0 + bias);
    if (conf >= confidence) {
      float held = min(n, most);
      float w = held >= frames && !moved ? 1.0 : held / (held + 1.0);
      seen = min(held + 1.0, most);
#ifdef TEMPORAL_CLAMP
      temporal_fresh = vec4(finite_or_zero(cur.rgb), w);
#endif
      return finite_or_zero(mix(cur, h, w));
    }
  }
  seen = 1.0;
#ifdef TEMPORAL_CLAMP
  temporal_fresh = vec4(finite_or_zero(cur.rgb), 0.0);
#endif
  return finite_or_zero(cur);
}
#endif
