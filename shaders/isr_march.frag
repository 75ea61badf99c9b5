// Physically scaled image-space radiosity (/work/shared/design/gi-scale.md),
// the transport step of isr.lua's default mode, over the coarse G-buffer:
//   E(p) = (1/pi) int over the hemisphere of L(x(w)) cos(theta) dw
// where x(w) is the first surface seen from p in direction w and L(x) its
// lit radiance (`sender`: the frame's direct light, shadows included; with
// BOUNCE also k_d albedo E of the last step, the next bounce). The composite
// (isr_light.frag) multiplies by k_d albedo, POV-Ray's radiosity convention.
//
// Estimator: `samples` cosine-weighted directions (pdf cos / pi, so each ray
// weighs 1 / samples and the cosines cancel), Halton points (halton.glsl)
// turned per pixel in a 4 x 4 tile that the blur averages. A ray counts a
// sender only when the depth buffer says it is seen: the ray is marched in
// `steps` samples at distances t_j = t_0 (t_end / t_0)^((j + u) / (steps - 1 + u)),
// j = 0 .. steps - 1, u in (0, 1) a per-ray jitter, from about t_0 = one
// coarse texel's footprint at p's depth to t_end, where the ray leaves the
// view frustum. The spacing is geometric,
// so the march reaches across the whole visible scene with a few samples and
// has no length in world units (a scene in millimetres or kilometres gives
// the same image). A sample behind the depth buffer ends the coarse march;
// four bisections between it and the last sample in front find the surface
// it passed, which is a hit when the refined step reaches that surface's
// plane (or comes within `thickness` of its depth of it; measured off the
// plane, not along the view ray, so that a surface seen at a grazing angle
// is not missed); otherwise the ray passed behind a nearer object and goes
// on. A hit on a
// surface facing away, or not above p's tangent plane, sends nothing: the
// first blocks (it is seen, only its back), the second is p's own plane met
// through the depth buffer's steps and is passed.
// What the screen does not show (off screen, behind the first depth layer)
// is missing, never made up by a factor. Rays that leave the view see the
// sky: the ambient term, occluded by the returned accessibility.
//
// Output: rgb = E, a = A, the share of rays (cosine-weighted) that meet no
// surface. Background texels: (0, 0, 0, 1).
// With HITS (1..7, the first bounce of several), also the sending hit of each
// ray, four rays a target in hits0.. (HITS targets): 1 + the coarse texel's
// index y * width + x (exact in a float below 2^24 texels; isr.lua keeps
// within), or 0 when the ray sends nothing; isr_bounce.frag takes the later
// bounces from them instead of marching the same rays again.
#include "gbuffer.glsl"
#include "halton.glsl"

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat; // coarse G-buffer
uniform sampler2D sender;             // coarse direct light
#ifdef BOUNCE
uniform sampler2D previous;           // the last step's E
#endif
uniform int samples = 12;
uniform int steps = 10;
uniform float thickness = 0.02; // fraction of a surface's depth

layout(location = 0) out vec4 isr;
#ifdef HITS
layout(location = 1) out vec4 hits0;
#if HITS > 1
layout(location = 2) out vec4 hits1;
#endif
#if HITS > 2
layout(location = 3) out vec4 hits2;
#endif
#if HITS > 3
layout(location = 4) out vec4 hits3;
#endif
#if HITS > 4
layout(location = 5) out vec4 hits4;
#endif
#if HITS > 5
layout(location = 6) out vec4 hits5;
#endif
#if HITS > 6
layout(location = 7) out vec4 hits6;
#endif

// Writes the recorded hits (0 for none) to the HITS targets, four a target.
void write_hits(float hit[4 * HITS]) {
  hits0 = vec4(hit[0], hit[1], hit[2], hit[3]);
#if HITS > 1
  hits1 = vec4(hit[4], hit[5], hit[6], hit[7]);
#endif
#if HITS > 2
  hits2 = vec4(hit[8], hit[9], hit[10], hit[11]);
#endif
#if HITS > 3
  hits3 = vec4(hit[12], hit[13], hit[14], hit[15]);
#endif
#if HITS > 4
  hits4 = vec4(hit[16], hit[17], hit[18], hit[19]);
#endif
#if HITS > 5
  hits5 = vec4(hit[20], hit[21], hit[22], hit[23]);
#endif
#if HITS > 6
  hits6 = vec4(hit[24], hit[25], hit[26], hit[27]);
#endif
}
#endif

// Tightens t so that the constraint g0 + g1 t >= 0 holds on [0, t].
float limit(float g0, float g1, float t) { return g1 < 0.0 ? min(t, max(g0, 0.0) / -g1) : t; }

// How far the ray a + t b (clip space) stays in the view frustum, t >= 0.
float exit_distance(vec4 a, vec4 b) {
  float t = 4.0 * frame.clip.y; // a bound for rays the planes do not stop
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
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, px);
#ifdef HITS
  float hit[4 * HITS];
  for (int k = 0; k < 4 * HITS; k++) hit[k] = 0.0;
#endif
  if (!s.covered) {
    isr = vec4(0.0, 0.0, 0.0, 1.0);
#ifdef HITS
    write_hits(hit);
#endif
    return;
  }
  int n = clamp(samples, 1, 256), m = clamp(steps, 1, 64);
  float far = frame.clip.y, thick = max(thickness, 0.0);
  // World size of one coarse texel at p: 2 z tan(fov / 2) / height.
  float foot = max(2.0 * s.depth01 * far * frame.clip.w / float(size.y), 1e-7 * far);
  mat3 basis = tangent_frame(s.n);
  vec3 offset = halton_offset(px, 4);
  vec4 a = frame.view_proj * vec4(s.p, 1.0);
  vec3 gathered = vec3(0.0);
  float open = 0.0;
  for (int i = 0; i < n; i++) {
    vec3 u = halton_sample(i, offset);
    vec3 w = basis * hemisphere_cosine(u.xy);
    vec4 b = frame.view_proj * vec4(w, 0.0);
    float t_end = exit_distance(a, b);
    bool seen = false;
    float t_prev = 0.0, t = 0.0;
    ivec2 q = px;
    // The march goes on to the next sample behind the depth buffer in a loop
    // of its own, and only there refines and tests for a hit: a software
    // rasterizer runs an if's body for every pixel of its group, so the
    // refinement inside the march's loop would cost as much at every step.
    // Sample j lies at foot (t_end / foot)^((j + u.z) e): each the last times
    // a ratio. The last lies on t_end: a surface where the ray leaves the view is met too.
    float e = 1.0 / max(float(m) - 1.0 + u.z, 1e-6), span = max(t_end / foot, 1.0); // > 1 where it marches
    float ratio = pow(span, e), t_next = foot * pow(span, u.z * e);
    int j = 0;
    while (j < m && t_end > foot) {
      float zq = 0.0;
      vec4 c;
      for (; j < m; j++) {
        t = t_next;
        t_next *= ratio;
        c = a + t * b;
        zq = buffer_depth(c, size, q);
        if (zq > 0.0 && c.w > zq) break; // behind the surface there
        t_prev = t;
      }
      if (j >= m) break;
      // Behind a surface: bisect [t_prev, t] for where the ray passed it.
      float lo = t_prev, hi = t;
      for (int k = 0; k < 4; k++) {
        float mid = 0.5 * (lo + hi);
        vec4 cm = a + mid * b;
        ivec2 qm;
        float zm = buffer_depth(cm, size, qm);
        if (zm > 0.0 && cm.w > zm) hi = mid;
        else lo = mid;
      }
      zq = buffer_depth(a + hi * b, size, q);
      Surface x = gbuffer_fetch(clr, nrm, dpt, mat, q);
      vec3 to_x = x.p - s.p;
      // A hit when the refined step reaches the seen surface's plane.
      if (zq > 0.0 && abs(dot(x.n, s.p + hi * w - x.p)) <= max(thick * zq, hi - lo) &&
          dot(s.n, to_x) > 0.25 * foot) { // above p's tangent plane: not p's own surface
        seen = true;
        float cos_x = dot(x.n, -safe_normalize(to_x, w));
        if (cos_x > 0.0) {
          vec3 radiance = texelFetch(sender, q, 0).rgb;
#ifdef BOUNCE
          radiance += x.k.y * x.albedo * texelFetch(previous, q, 0).rgb;
#endif
          gathered += radiance;
#ifdef HITS
          if (i < 4 * HITS) hit[i] = float(q.y * size.x + q.x + 1);
#endif
        }
        break;
      }
      t_prev = t;
      j++;
    }
    if (!seen) open += 1.0;
  }
  isr = vec4(gathered / float(n), open / float(n));
#ifdef HITS
  write_hits(hit);
#endif
}
