// A later bounce of the physical ISR transport (isr_march.frag) from the hits
// its first march recorded (HITS targets, four rays each: 1 + the index of
// the G-buffer texel a ray's sender lies on, 0 for none). Every bounce marches the same rays
// through the same depth buffer and meets the same senders, so this sums over
// them what the march with BOUNCE would:
//   E(p) = 1/n sum over sending rays of sender(q) + k_d albedo(q) previous(q)
//        = first(p) + 1/n sum over sending rays of k_d albedo(q) previous(q)
// with first the first march's E (the senders' own light, kept in 32-bit
// floats so that the sum is the march's), previous the last step's E (at the
// coarse texel over q, the G-buffer being STRIDE times finer); A, the share
// of open rays, is first's (TRACE: less the lost rays where the traced one met
// a surface).
// SKY_BOUNCE (isr.sky_bounce): each sender also sends its sky light, its
// ambient term (k_a L_a albedo, the sky's with SKY) times its own A, which
// the direct light the march sent holds none of: the sky's first bounce,
// a step late since A is known once the march is done; at most the sky's
// irradiance times an albedo, so bounded as the senders' light is. UNSEEN
// rays bring none of it: what they meet (a roof's underside, ground off
// screen) the march cannot say the sky lights, and their mean of the seen
// senders' overshot Cycles' sky light on the held-out yard's portico.
// TEMPORAL, TEMPORAL_NEXT: as isr_march.frag (temporal reuse; z, the grid's
// depth the march wrote, places each pixel for the reprojection); a pixel
// the march found converged (hits0 -1) keeps the march's E, its history.
// UNSEEN (rsm.bounces above 1; the hit value the march gives a ray that met
// a surface the screen cannot show, isr_march.frag): those rays are taken to
// fare as the rays whose fate the march knows (each brings the mean of what
// they bring), and with `bounces` above the screen's steps (`steps`,
// isr.bounces) the last step's newest bounce at p goes on as a geometric
// series (later_bounces), in the last step alone (LAST): each step adds one
// bounce, so a series in every step would count the later bounces twice.
// TRACE (rsm.trace): the unseen rays are every ray the march lost, and one
// of them was traced (isr_trace.frag: `traced`, the light its hit sends on,
// k_d albedo E1 there; `traced_albedo`, that k_d albedo). The series' ratio
// r counts the hit's albedo for them, and each brings that light grown as
// the series grows, L (1 + r + ... + r^(step - 2)): the hit's second bounce
// at the second step, and at the later screen steps the bounces the series
// would have carried, so that 64 bounces come to the same light whichever
// of the steps or the series carries bounces 3 and 4 (test_rsm; kept at the
// second bounce, a face whose rays all leave the screen got no bounce past
// the second at isr.bounces 4). Where the screen shows no sender (the
// Cornell box's tall box, its face toward the open side) the second bounce
// is the traced one.
#include "gbuffer.glsl"
#ifdef TEMPORAL
#include "temporal.glsl"
uniform sampler2D z; // the grid's depth / far, 0 where nothing is drawn
#endif

#ifndef STRIDE
#define STRIDE 1
#endif

in vec2 uv;
uniform sampler2D clr, mat;  // the G-buffer the march read
uniform sampler2D first;     // the first march's E (rgb), A (a), the output's size
uniform sampler2D previous;  // the last step's E, the output's size
uniform sampler2D hits0;
#if HITS > 1
uniform sampler2D hits1;
#endif
#if HITS > 2
uniform sampler2D hits2;
#endif
#if HITS > 3
uniform sampler2D hits3;
#endif
#if HITS > 4
uniform sampler2D hits4;
#endif
#if HITS > 5
uniform sampler2D hits5;
#endif
uniform int samples = 4;
#ifdef SKY_BOUNCE
uniform sampler2D nrm;           // the G-buffer's normals
uniform vec3 ambient = vec3(0.0);
#endif
vec3 sky_sent = vec3(0.0); // SKY_BOUNCE: the senders' sky light, summed over the rays
#ifdef TRACE
uniform sampler2D traced, traced_albedo; // isr_trace.frag's outputs, the output's size (or its blocks')
uniform int step = 2;                    // this step (isr.bounces counts them; 1: the march)
#endif
#ifdef TRACE_BLOCK
// One ray traced for a block of TRACE_BLOCK x TRACE_BLOCK pixels (rsm.trace under 1): its light stands
// for every lost ray of the block's pixels.
ivec2 traced_texel(ivec2 px) { return min(px / TRACE_BLOCK, textureSize(traced, 0) - 1); }
#else
ivec2 traced_texel(ivec2 px) { return px; }
#endif

layout(location = 0) out vec4 isr;
#ifdef TEMPORAL_NEXT
layout(location = NEXT) out vec4 next;
layout(location = NEXT + 1) out vec2 next_state; // view depth (0 none), frames seen
#endif

// What a ray whose recorded hit is `hit` sends of the last step's light
// (nothing for 0), into gathered, and its sender's k_d albedo into albedo.
void send(float hit, int width, inout vec3 gathered, inout vec3 albedo) {
  if (hit < 0.5) return;
  int k = int(hit - 0.5);
  ivec2 q = ivec2(k % width, k / width);
  vec4 e = texelFetch(previous, min(q / STRIDE, textureSize(previous, 0) - 1), 0);
  vec4 c = texelFetch(clr, q, 0), m = texelFetch(mat, q, 0);
  vec3 rho = m.y * c.rgb;
  gathered += rho * e.rgb;
  albedo += rho;
#ifdef SKY_BOUNCE
  Surface s = gbuffer_decode(c, gbuffer_normal_decode(texelFetch(nrm, q, 0)), 0.0, m, vec2(0.5)); // its position is not read
  sky_sent += ambient_light(s, ambient) * saturate(e.a);
#endif
}

#ifdef UNSEEN
uniform int bounces = 2; // rsm.bounces: the series runs from bounce steps + 1 to this one
uniform int steps = 2;   // isr.bounces: the bounces the screen's steps carry (the march's and these passes')

// How many of four rays' hits h send (at least 0.5) and how many met an unseen surface.
vec2 count4(vec4 h) {
  return vec2(dot(vec4(greaterThanEqual(h, vec4(0.5))), vec4(1.0)),
              dot(vec4(lessThan(abs(h - vec4(UNSEEN)), vec4(0.01))), vec4(1.0)));
}

// Bounces steps + 1 .. `bounces` after the newest bounce e2 the steps
// carry: each sends on the share r of the last, r the mean k_d albedo of
// the senders p's rays met times the share of its rays that met one (the
// light that arrives at p next has bounced off them, not off p), so they sum
// to e2 (r + r^2 + ... + r^m), m = bounces - steps, the geometric series
// r (1 - r^m) / (1 - r). r is at most BOUNCE_MAX (1 - r >= 0.1), so at any
// count the sum stays below e2 BOUNCE_MAX / (1 - BOUNCE_MAX): energy bounded.
const float BOUNCE_MAX = 0.9;
vec3 later_bounces(vec3 e2, vec3 r) {
  int m = min(bounces, 64) - clamp(steps, 2, 64);
  if (m <= 0) return vec3(0.0);
  r = clamp(r, 0.0, BOUNCE_MAX);
  return e2 * r * (1.0 - pow(r, vec3(float(m)))) / (1.0 - r); // pow: base >= 0, exponent >= 1
}
#endif

// One hit texture's four rays: what they send, into gathered, their
// senders' albedo, into albedo, and (UNSEEN) how many send and how many met
// an unseen surface, into rays: each texture read once for all.
void take4(vec4 h, int width, inout vec3 gathered, inout vec3 albedo, inout vec2 rays) {
  send(h.x, width, gathered, albedo);
  send(h.y, width, gathered, albedo);
  send(h.z, width, gathered, albedo);
  send(h.w, width, gathered, albedo);
#ifdef UNSEEN
  rays += count4(h);
#endif
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 hit0 = texelFetch(hits0, px, 0);
#ifdef TEMPORAL
  float d = texelFetch(z, px, 0).r;
#ifdef TEMPORAL_CLAMP
  temporal_fresh = vec4(0.0, 0.0, 0.0, -1.0);
#endif
#ifdef TEMPORAL_NEXT
  next = vec4(0.0);
  next_state = vec2(dpt_view_depth(d), 0.0);
#endif
  if (hit0.x < 0.0) { // the march found it converged and wrote its history as E: kept as it is
    isr = texelFetch(first, px, 0);
#ifdef TEMPORAL_NEXT
    next = isr;
    next_state.y = max(frames, 1.0);
#endif
    return;
  }
  vec4 h = vec4(0.0);
  float held = 0.0;
  bool found = d > 0.0 && temporal_history(uv, d, h, held);
#endif
  int width = textureSize(clr, 0).x, n = clamp(samples, 1, 4 * HITS);
  vec3 gathered = vec3(0.0), albedo = vec3(0.0);
  vec2 rays = vec2(0.0); // UNSEEN: rays that send, rays that met an unseen surface
  take4(hit0, width, gathered, albedo, rays);
#if HITS > 1
  take4(texelFetch(hits1, px, 0), width, gathered, albedo, rays);
#endif
#if HITS > 2
  take4(texelFetch(hits2, px, 0), width, gathered, albedo, rays);
#endif
#if HITS > 3
  take4(texelFetch(hits3, px, 0), width, gathered, albedo, rays);
#endif
#if HITS > 4
  take4(texelFetch(hits4, px, 0), width, gathered, albedo, rays);
#endif
#if HITS > 5
  take4(texelFetch(hits5, px, 0), width, gathered, albedo, rays);
#endif
  vec4 e = texelFetch(first, px, 0);
#ifdef UNSEEN
  // Each unseen ray brings the mean of what the rays of known fate bring (those that left the scene bring
  // nothing), so nothing is made up where the march knows no ray's fate. The mean over the sending rays
  // alone, or p's own reflected first bounce where none sends, took more from POV-Ray's figure than they
  // gave to Cycles' on the reference set (docs/gi-combined.md).
#ifdef TRACE
  // The hit's light after this step's bounces: its second bounce grown as the series grows, 1 + r + ... +
  // r^(step - 2), r the series' ratio below (1 at the second step; at most 10: bounded)
  ivec2 tp = traced_texel(px);
  vec3 r_hit = clamp((albedo + rays.y * texelFetch(traced_albedo, tp, 0).rgb) / float(n), 0.0, BOUNCE_MAX);
  vec3 grown = (1.0 - pow(r_hit, vec3(float(max(step, 2) - 1)))) / (1.0 - r_hit); // pow: base >= 0, exponent >= 1
  vec3 second = (gathered + rays.y * texelFetch(traced, tp, 0).rgb * grown + sky_sent) / float(n);
  // The march counted the lost rays open (the sky's share A); where the traced one met a surface they met
  // one, whose light they bring: not the sky's too.
  e.a = max(e.a - rays.y / float(max(samples, 1)) * texelFetch(traced_albedo, tp, 0).a, 0.0);
#else
  vec3 second = (gathered + rays.y * gathered / max(float(n) - rays.y, 1.0) + sky_sent) / float(n);
#endif
#ifdef LAST
  // The newest bounce at p: this step's bounces beyond the first less the last step's (its E less the
  // first's), no less than 0 (the rays' noise); at the second step the second bounce itself.
  vec3 newest = max(second - (texelFetch(previous, px, 0).rgb - e.rgb), vec3(0.0));
#ifdef TRACE
  second += later_bounces(newest, r_hit);
#else
  float known = float(n) - rays.y;
  second += later_bounces(newest, known > 0.0 ? albedo / known : vec3(0.0));
#endif
#endif
  isr = vec4(e.rgb + finite_or_zero(second), e.a);
#else
  isr = vec4(e.rgb + (gathered + sky_sent) / float(n), e.a);
#endif
#ifdef TEMPORAL_NEXT
  if (d > 0.0) {
    next = temporal_accumulate(isr, found, h, held, next_state.y);
    isr = next;
  }
#endif
}
