// Physically scaled image-space radiosity (/work/shared/design/gi-scale.md),
// the transport step of isr.lua's default mode, at each texel of a coarse
// grid over the G-buffer:
//   E(p) = (1/pi) int over the hemisphere of L(x(w)) cos(theta) dw
// where x(w) is the first surface seen from p in direction w and L(x) its
// lit radiance (`sender`: the frame's direct light, shadows included; with
// BOUNCE also k_d albedo E of the last step, the next bounce). The composite
// (isr_light.frag) multiplies by k_d albedo, POV-Ray's radiosity convention.
// The G-buffer is read at STRIDE texels a side per coarse texel: p is the
// surface at its block's centre (block_centre) and the rays march through
// the full buffer's depth (STRIDE 1: a coarse copy, isr_downsample.frag).
//
// Estimator: `samples` cosine-weighted directions a texel (pdf cos / pi, so
// each ray weighs 1 / samples and the cosines cancel), interleaved: the 16
// texels of a 4 x 4 tile take consecutive runs of one low-discrepancy
// sequence (R3, halton.glsl), texel k of the tile (in Bayer order) points
// k n .. k n + n - 1, so that the tile holds 16 n directions that fill the
// hemisphere evenly and the blur, at least 4 wide, averages them. Every
// tile takes the same directions: turning them per tile made the error
// vary from tile to tile, blotches the blur spreads (4 rays a texel then
// came as close to 64 as 12 a texel, each turned per texel, did before).
// A ray counts a
// sender only when the depth buffer says it is seen: the ray is marched in
// `steps` samples at distances t_j = t_0 (t_end / t_0)^((j + u) / (steps - 1 + u)),
// j = 0 .. steps - 1, u in (0, 1) a per-ray jitter, from about t_0 = one
// coarse texel's footprint at p's depth to t_end, where the ray leaves the
// view frustum or the scene's box. The spacing is geometric,
// so the march reaches across the whole visible scene with a few samples and
// has no length in world units (a scene in millimetres or kilometres gives
// the same image). A sample behind the depth buffer ends the coarse march;
// the secant through the depths off the buffer at it and at the last sample
// in front finds where the ray passed the surface (one fetch where four
// bisections took five, as close to the POV-Ray references in
// tools/fidelity.sh), a hit when that point lies on the plane
// of the surface seen there (within half the step, or `thickness` of its
// depth; measured off the plane, not along the view ray, so that a surface
// seen at a grazing angle is not missed); otherwise the ray passed behind a
// nearer object and goes on. A hit on a
// surface facing away, or not above p's tangent plane, sends nothing: the
// first blocks (it is seen, only its back), the second is p's own plane met
// through the depth buffer's steps and is passed.
// What the screen does not show (off screen, behind the first depth layer)
// is missing, never made up by a factor. Rays that leave the view see the
// sky: the ambient term, occluded by the returned accessibility.
//
// Output: rgb = E, a = A, the share of rays (cosine-weighted) that meet no
// surface: the sky's (a ray UNSEEN counts below met one off screen, whose
// light it brings; the yard's portico took the sky through its roof as well:
// docs/gi-combined.md). Background texels: (0, 0, 0, 1). With Z, also z: p's depth / far,
// 0 where nothing is drawn (the view's depth that the blur and composite
// read, isr.coarse_view).
// With HITS (1..6, the first bounce of several), also the sending hit of each
// ray, four rays a target in hits0.. (HITS targets): 1 + the index y * width
// + x of the depth buffer's texel the ray met (exact in a float below 2^24
// texels; isr.lua keeps within), or 0 when the ray sends nothing;
// isr_bounce.frag takes the later bounces from them instead of marching the
// same rays again.
// UNSEEN (with HITS; rsm.bounces above 1, scripts/isr.lua): a ray that met
// no surface the screen shows, points down or level (world y, glTF's up)
// and stayed in the scene's box (box_exit) met one the screen cannot show
// (off screen, behind the first depth layer): its hit is UNSEEN (the value,
// under 0.5), which isr_bounce.frag counts. A ray that left the box stays 0
// (open), and so does one that points up, unless p lies under a roof (with
// RSM_GATHER: rsm_shadowed above it): outdoors such rays meet the sky (on
// the reference set's blocks, counted as unseen, they took the ground's
// light: 71.9% / 68.4% of dl+esm's indirect error removed against POV-Ray /
// Cycles at rsm.bounces 2 with them open, 67.8% / 69.6% counted, 72.9% /
// 67.2% at 1), and indoors they meet the ceiling.
// RAY_STEPS (rsm.ray_steps): an upward ray is also tested at that many points
// between where it leaves the view and where it leaves the box against the
// lights' RSM views (rsm.glsl's rsm_meets); one that crosses a surface they
// hold met it off screen (the street's facades; docs/gi-combined.md).
// TRACE (rsm.trace; with UNSEEN): every ray the screen lost (not seen, and
// inside the scene's box where it leaves the view, or passed behind a surface
// on its way: what it met there the screen cannot say; the Cornell box's rays
// behind its boxes, counted as leaving the scene, left its views at 0.77 of
// Cycles' indirect light) is UNSEEN, whatever its
// direction (the tracer, not a guess, says what it meets), and one of them,
// chosen uniformly (a reservoir over a hash of the pixel and ray), goes to
// outputs TRACE (origin a little off p along its normal, w the count of lost rays) and TRACE + 1
// (direction, w 0: unlimited) for the CPU's "trace" (engine/trace); both 0
// where none was lost, which the tracer skips. isr_trace.frag lights the
// hit, isr_bounce.frag sends its light on for the pixel's unseen rays and,
// where it met a surface, takes them from A (here they count open).
// TEMPORAL (isr.temporal, temporal.glsl): each frame the rays are the next
// 16 n points of the sequence, and a pixel whose history has converged is
// not marched: its E is that history (every bounce's sum), which a later
// bounce then reads as the sender's light of this step (a bounce more than
// the march's own: it matters only where a pixel starts again beside
// converged ones). With TEMPORAL_NEXT (the last step) the result is the
// accumulation, and the history for the next frame goes to outputs NEXT
// (value) and NEXT + 1 (state); with HITS a converged pixel's hits0 is -1,
// which tells the recorded-senders bounce (isr_bounce.frag) to keep it.
// RSM_GATHER (the combined technique, isr+rsm+esm; docs/gi-combined.md):
// the first march adds the RSM's light of the senders the camera does not
// see (rsm.glsl's rsm_gather, EXCLUDE_SEEN, times rsm_k) to E, so one pass,
// one blur and one composite carry both, and the next step sends it on
// from the senders it lights. FIRST (the later marches then): a ray's
// sender sends only k_d albedo times the last step's E, and E adds the
// first step's E at p, which holds the rays' direct light (the same rays
// meet the same senders) and the RSM's light at p, as isr_bounce.frag sums.
#include "gbuffer.glsl"
#include "halton.glsl"
#ifdef TEMPORAL
#include "temporal.glsl"
#endif
#ifdef RSM_GATHER
#include "rsm.glsl"
uniform float rsm_k = 1.0; // the RSM light's factor (rsm.k)
#endif

#ifndef STRIDE
#define STRIDE 1
#endif

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat; // the G-buffer, STRIDE times finer than the output
uniform sampler2D sender;             // direct light, the G-buffer's size
#ifdef BOUNCE
uniform sampler2D previous;           // the last step's E, the output's size
#endif
#ifdef FIRST
uniform sampler2D first_step;         // the first step's E, the output's size
#endif
uniform int samples = 4;
uniform int steps = 10;
uniform float thickness = 0.02; // fraction of a surface's depth
uniform vec3 scene_lo = vec3(-1e30), scene_hi = vec3(1e30); // the scene's box, a little wider (isr.lua)

layout(location = 0) out vec4 isr;
#ifdef Z
layout(location = 1) out float z;
#endif
#ifdef TEMPORAL_NEXT
layout(location = NEXT) out vec4 next;
layout(location = NEXT + 1) out vec2 next_state; // view depth (0 none), frames seen
#endif
#ifdef TRACE
layout(location = TRACE) out vec4 ray_o;
layout(location = TRACE + 1) out vec4 ray_d;

// A hash of a pixel and a ray index to [0, 1): the choice among the lost rays.
float trace_hash(ivec2 px, int i) {
  uint h = uint(px.x) * 1973u + uint(px.y) * 9277u + uint(i) * 26699u;
  h = (h ^ (h >> 16u)) * 0x7feb352du;
  h = (h ^ (h >> 15u)) * 0x846ca68bu;
  h ^= h >> 16u;
  return float(h >> 8u) / 16777216.0;
}
#endif
#ifdef HITS
layout(location = 2) out vec4 hits0;
#if HITS > 1
layout(location = 3) out vec4 hits1;
#endif
#if HITS > 2
layout(location = 4) out vec4 hits2;
#endif
#if HITS > 3
layout(location = 5) out vec4 hits3;
#endif
#if HITS > 4
layout(location = 6) out vec4 hits4;
#endif
#if HITS > 5
layout(location = 7) out vec4 hits5;
#endif

// Records ray i's hit h into component i % 4 of target i / 4. The outputs
// themselves hold the hits (cleared first): an array indexed by i, which
// varies at run time, went through memory and cost the march 4-7%.
void record_hit(int i, float h) {
  vec4 add = h * vec4(equal(ivec4(i & 3), ivec4(0, 1, 2, 3)));
  int k = i >> 2;
  hits0 += k == 0 ? add : vec4(0.0);
#if HITS > 1
  hits1 += k == 1 ? add : vec4(0.0);
#endif
#if HITS > 2
  hits2 += k == 2 ? add : vec4(0.0);
#endif
#if HITS > 3
  hits3 += k == 3 ? add : vec4(0.0);
#endif
#if HITS > 4
  hits4 += k == 4 ? add : vec4(0.0);
#endif
#if HITS > 5
  hits5 += k == 5 ? add : vec4(0.0);
#endif
}
#endif

// Tightens t so that the constraint g0 + g1 t >= 0 holds on [0, t].
float limit(float g0, float g1, float t) { return g1 < 0.0 ? min(t, max(g0, 0.0) / -g1) : t; }

// How far the ray p + t w stays in the scene's box, t >= 0. Past the box
// nothing is met, and a ray that only the far plane stops would spread its
// steps that far: the image would depend on where the far plane lies
// (test_scale). UNSEEN: where it bounds exit_distance, the ray left the
// scene and meets nothing anywhere.
float box_exit(vec3 p, vec3 w) {
  float t = 4.0 * frame.clip.y; // a bound for rays the planes do not stop
  for (int k = 0; k < 3; k++) {
    t = limit(p[k] - scene_lo[k], w[k], t);
    t = limit(scene_hi[k] - p[k], -w[k], t);
  }
  return t;
}

// How far the ray a + t b (clip space) stays in the view frustum, within
// t_box (box_exit: the ray's own, computed once for both).
float exit_distance(vec4 a, vec4 b, float t_box) {
  float t = t_box;
  t = limit(a.w - a.x, b.w - b.x, t);
  t = limit(a.w + a.x, b.w + b.x, t);
  t = limit(a.w - a.y, b.w - b.y, t);
  t = limit(a.w + a.y, b.w + b.y, t);
  t = limit(a.w - frame.clip.x, b.w, t);
  return limit(frame.clip.y - a.w, -b.w, t);
}

// The texel a clip-space point falls on, and that texel's view depth (0: background).
float buffer_depth(vec4 c, ivec2 size, out ivec2 q) {
  vec2 quv = clamp(c.xy / max(c.w, 1e-12) * 0.5 + 0.5, 0.0, 1.0);
  q = min(ivec2(quv * vec2(size)), size - 1);
  return texelFetch(dpt, q, 0).r * frame.clip.y;
}

void main() {
  ivec2 size = textureSize(dpt, 0), px = ivec2(gl_FragCoord.xy);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, block_centre(px, STRIDE, size));
#ifdef Z
  z = s.covered ? s.depth01 : 0.0;
#endif
#ifdef HITS
  hits0 = vec4(0.0); // 0: no hit
#if HITS > 1
  hits1 = vec4(0.0);
#endif
#if HITS > 2
  hits2 = vec4(0.0);
#endif
#if HITS > 3
  hits3 = vec4(0.0);
#endif
#if HITS > 4
  hits4 = vec4(0.0);
#endif
#if HITS > 5
  hits5 = vec4(0.0);
#endif
#endif
#ifdef TRACE
  ray_o = vec4(0.0); // no ray: the tracer skips it
  ray_d = vec4(0.0);
  float lost = 0.0; // the rays the screen lost so far (the reservoir's count)
#endif
#ifdef TEMPORAL_CLAMP
  temporal_fresh = vec4(0.0, 0.0, 0.0, -1.0);
#endif
#ifdef TEMPORAL_NEXT
  next = vec4(0.0);
  next_state = vec2(s.covered ? dpt_view_depth(s.depth01) : 0.0, 0.0);
#endif
  if (!s.covered) {
    isr = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
#ifdef TEMPORAL
  vec4 h;
  float held;
  bool found = temporal_history(uv, s.depth01, h, held);
  if (found && temporal_converged(held, px)) { // kept as it is
    isr = h;
#ifdef TEMPORAL_NEXT
    next = h;
    next_state.y = max(frames, 1.0);
#endif
#ifdef HITS
    hits0 = vec4(-1.0); // converged: isr_bounce.frag keeps `isr` without reprojecting again
#endif
    return;
  }
#endif
  int n = clamp(samples, 1, 256), m = clamp(steps, 1, 64);
  float far = frame.clip.y, thick = max(thickness, 0.0);
  // World size of one coarse texel at p: 2 z tan(fov / 2) / height.
  float foot = max(2.0 * s.depth01 * far * frame.clip.w * float(STRIDE) / float(size.y), 1e-12 * far); // never 0
  mat3 basis = tangent_frame(s.n);
  int first = interleave_index(px, 4) * n;
#ifdef TEMPORAL
  first += temporal_turn() * 16 * n; // this frame's points (below 2^28: no overflow)
#endif
  vec4 a = frame.view_proj * vec4(s.p, 1.0);
#if defined(UNSEEN) && !defined(TRACE)
#ifdef RSM_GATHER
  // Under a roof: the point straight above p, near the scene box's top, lies in the lights' shadow
  // (halfway up put the blocks' shaded ground under the blocks' shadow; docs/gi-combined.md).
  const vec3 UP = vec3(0.0, 1.0, 0.0);
  bool roofed = rsm_shadowed(s.p + 0.9 * box_exit(s.p, UP) * UP);
#else
  const bool roofed = false;
#endif
#endif
  vec3 gathered = vec3(0.0);
  float open = 0.0;
  for (int i = 0; i < n; i++) {
    vec3 u = r3_sample(first + i, vec3(0.0)); // no turn: every tile the same
    vec3 w = basis * hemisphere_cosine(u.xy);
    vec4 b = frame.view_proj * vec4(w, 0.0);
    float t_box = box_exit(s.p, w), t_end = exit_distance(a, b, t_box);
    bool seen = false;
#ifdef TRACE
    bool hidden = false; // the ray passed behind a surface it did not meet: what it met there is unknown
#endif
    float t_prev = 0.0, t = 0.0, ahead = -1.0;
    ivec2 q = px;
    // The march goes on to the next sample behind the depth buffer in a loop
    // of its own, and only there tests for a hit: a software rasterizer runs
    // an if's body for every pixel of its group, so the test inside the
    // march's loop would cost as much at every step.
    // Sample j lies at foot (t_end / foot)^((j + u.z) e): each the last times
    // a ratio. The last lies on t_end: a surface where the ray leaves the view is met too.
    float e = 1.0 / max(float(m) - 1.0 + u.z, 1e-6), span = max(t_end / foot, 1.0); // > 1 where it marches
    float ratio = pow(span, e), t_next = foot * pow(span, u.z * e);
    int j = 0;
    while (j < m && t_end > foot) {
      float zq = 0.0, behind = 0.0;
      for (; j < m; j++) {
        t = t_next;
        t_next *= ratio;
        vec4 c = a + t * b;
        zq = buffer_depth(c, size, q);
        behind = c.w - zq;
        if (zq > 0.0 && behind > 0.0) break; // behind the surface there
        t_prev = t;
        ahead = zq > 0.0 ? -behind : -1.0;
      }
      if (j >= m) break;
      // Behind a surface: where the ray passed it, by the secant through the
      // depths off the buffer at t_prev (in front, `ahead`) and t (behind),
      // or halfway where t_prev's is unknown (p itself, or nothing drawn).
      float t_hit = ahead >= 0.0 ? mix(t_prev, t, ahead / max(ahead + behind, 1e-30 * far)) : 0.5 * (t_prev + t);
      zq = buffer_depth(a + t_hit * b, size, q);
      Surface x = gbuffer_fetch(clr, nrm, dpt, mat, q);
      vec3 to_x = x.p - s.p;
      // A hit when that point lies on the plane of the surface seen there,
      // within `thickness` of its depth or half the step (the secant's
      // uncertainty: it assumes the buffer's depth linear over the step).
      if (zq > 0.0 && abs(dot(x.n, s.p + t_hit * w - x.p)) <= max(thick * zq, 0.5 * (t - t_prev)) &&
          dot(s.n, to_x) > 0.25 * foot) { // above p's tangent plane: not p's own surface
        seen = true;
        float cos_x = dot(x.n, -safe_normalize(to_x, w));
        if (cos_x > 0.0) {
#ifdef FIRST
          vec3 radiance = vec3(0.0); // the direct light is in `first_step`
#else
          vec3 radiance = texelFetch(sender, q, 0).rgb;
#endif
#ifdef BOUNCE
          radiance += x.k.y * x.albedo * texelFetch(previous, min(q / STRIDE, textureSize(previous, 0) - 1), 0).rgb;
#endif
          gathered += radiance;
#ifdef HITS
          if (i < 4 * HITS) record_hit(i, float(q.y * size.x + q.x + 1));
#endif
        }
        break;
      }
#ifdef TRACE
      hidden = true;
#endif
      t_prev = t;
      ahead = -1.0;
      j++;
    }
    bool sky = !seen; // a ray that meets no surface sees the sky: the ambient term's, through A
#ifdef UNSEEN
#if defined(TRACE)
    const bool closed = true; // the tracer says what it meets
#elif defined(RAY_STEPS)
    // An upward ray in the open meets a surface off screen where the lights' RSM views hold one on its
    // way out of the scene's box (rsm.ray_steps; a street's facades, docs/gi-combined.md).
    bool closed = w.y <= 0.0 || roofed || (!seen && t_box > t_end && rsm_meets(s.p, w, t_end, t_box));
#else
    bool closed = w.y <= 0.0 || roofed;
#endif
#ifdef TRACE
    bool lost_ray = t_box > t_end || hidden;
#else
    bool lost_ray = t_box > t_end;
#endif
    if (!seen && i < 4 * HITS && closed && lost_ray) {
      record_hit(i, float(UNSEEN));
#ifndef TRACE
      sky = false; // it brings the light of the surface it met, not the sky's (with TRACE the tracer says)
#endif
#ifdef TRACE
      lost += 1.0;
      if (trace_hash(px, i) * lost < 1.0) { // kept with chance 1 / lost: each lost ray alike
        // Off p by a share of its distance to the eye, as the reflection rays (reflect_rays.frag).
        ray_o = vec4(s.p + s.n * (1e-4 * distance(s.p, frame.camera_pos.xyz)), 1.0);
        ray_d = vec4(w, 0.0);
      }
#endif
    }
#endif
    if (sky) open += 1.0;
  }
#ifdef TRACE
  if (lost > 0.0) ray_o.w = lost; // the reservoir's weight where one ray stands for a block's (rsm.trace under 1)
#endif
  isr = vec4(gathered / float(n), open / float(n));
#ifdef RSM_GATHER
  isr.rgb += max(rsm_k, 0.0) * rsm_gather(s, px, dpt);
#endif
#ifdef FIRST
  isr.rgb += texelFetch(first_step, px, 0).rgb;
#endif
#ifdef TEMPORAL_NEXT
  next = temporal_accumulate(isr, found, h, held, next_state.y);
  isr = next;
#endif
}
