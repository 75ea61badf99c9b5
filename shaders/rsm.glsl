// What a texel of the reflective shadow maps (shadow.frag with RSM: k_d
// albedo, normal, position) stands for, shared by the passes that read them
// (rsm.frag, vpl.frag, lpv_inject.vert). Needs `#define SHADOWS` (the
// shadow views' block, shadow.glsl).
#ifndef LIMN_RSM_GLSL
#define LIMN_RSM_GLSL
#include "gbuffer.glsl"
#include "halton.glsl" // RSM_GATHER's pattern (an include inside an #ifdef would count as made)

// The area of the texel at tile coordinates t (0..1) of view sv (a tile of
// `tile` texels a side) whose sender lies at q, as the light sees it:
// orthographic, a texel's world width times height (a tile not stabilized
// is a rectangle); perspective, its solid angle
// (its size per unit of distance squared times cos^3 of the off-axis angle:
// the image plane lies 1 / cos away and is tilted by the angle) times r^2.
// cos alone counted a cube face's senders 1.5 times on average (the Cornell
// box's first bounce by rsm+esm: 1.5-1.6 times Cycles'). Times the light's
// radiance there (light_incident) and the k_d albedo, it is the sender's
// radiance times area (POV-Ray's diffuse convention, no 1/pi): cos of the
// light's incidence cancels with the projection. perspective: sv.depth.w > 0
// (a spot or point light's view; a constant where the light's kind is).
float rsm_texel_area_as(ShadowView sv, vec2 t, vec3 q, float tile, bool perspective) {
  float area = sv.texel.x * (perspective ? sv.texel.x : sv.texel.z);
  if (perspective) {
    vec2 tn = (t * 2.0 - 1.0) * sv.texel.x * tile * 0.5; // tan of the off-axis angles
    float cos_off = inversesqrt(1.0 + dot(tn, tn));
    area *= dot(q - sv.depth.xyz, q - sv.depth.xyz) * cos_off * cos_off * cos_off;
  }
  return area;
}
float rsm_texel_area(ShadowView sv, vec2 t, vec3 q, float tile) { return rsm_texel_area_as(sv, t, q, tile, sv.depth.w > 0.0); }

// Does the camera see q: on screen and within 2% of the depth buffer's
// depth (`dpt`, the G-buffer's) there? The combined techniques leave such
// senders to the screen-space pass (docs/gi-combined.md). Filtered: on a
// surface seen at a slant the bilinear depth is the plane's at q, where the
// nearest texel's lies up to half a texel's slope off (at 64 x 48 that
// failed the 2% test often enough to count seen senders twice).
bool rsm_seen(sampler2D dpt, vec3 q) {
  vec4 c = frame.view_proj * vec4(q, 1.0);
  if (c.w <= 1e-12) return false;
  vec2 s = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))) return false;
  float z = c.w * frame.clip.z, zb = texture(dpt, s).r; // a perspective's clip w is the view depth
  return abs(z - zb) <= 0.02 * max(zb, 1e-12);
}

#ifdef RSM_GATHER
// The gather of E(p) (rsm.frag's formula) in the passes that compute it:
// rsm.frag and, in the combined technique, ISR's first march
// (isr_march.frag), bound by rsm.bind (scripts/rsm.lua).
// Sampling: the seed's pattern around p's projection into each RSM view,
// offsets xi_1 R at angle 2 pi xi_2 (R = `radius` tiles), denser near the
// centre where senders are nearest; its density per texel falls as
// 1 / (2 pi R^2 xi_1), so each sample weighs 2 pi R^2 xi_1 T^2 / N texels
// (T the tile's side): the seed's "samples weighed by their squared
// distance" (line 917) made exact for this pattern. The disc is drawn inside
// the view's bounds (the part of the tile the scene's box covers: no sender
// lies outside), R at most the distance to their farthest corner, each
// direction's radius cut at their edge for a directional light's view
// (rsm_gather_light says how): no sample is wasted where no texel can hold a
// sender; one on an empty texel adds nothing.
// RSM_INSIDE: every view's samples cut so (the traced hits' gather, rsm.trace).
// Interleaved sampling: the pattern is one sequence, xi_1 = Phi_2(k) (van der
// Corput) and xi_2 = k phi (golden ratio, mod 1), of which pixel j of a 4 x 4
// tile (Bayer order, halton.glsl) takes the block k = j n .. j n + n - 1: each
// pixel's n samples are stratified in xi_1 and spread in angle, and the 16
// blocks together are the sequence's first 16 n points, which the
// geometry-aware blur averages. Each sample still weighs its own density, so
// one pixel alone is exact too, only noisier. The angle steps by a fixed
// rotation (no sin or cos a sample); the pattern turns per frame by `rotate`.
// Each 4 x 4 tile turns the pattern and shifts its radii by its own amounts
// (the R2 sequence over the tiles' coordinates): with one pattern for every
// tile, the points of a surface that project onto nearly the same RSM texels
// (a wall under a high sun) all took the same senders, so a few samples hit
// or missed a thin sunlit strip for the whole wall at once, a bias and not
// noise (the reference street at 64 x 48, rsm+esm's mean indirect light at 24
// samples: 0.044 against 0.078 at 256; with the turns 0.072 and 0.072).
// 1/d^2 is capped at the texel's own area, so a sender next to p stays finite.
// VISIBILITY: the seed's screen-space test (lines 930-958): `steps` points
// on p -> q; one behind the depth buffer rejects q.
// SOLIDS: `solid_steps` points on p -> q; one inside a solid the light's
// views hold rejects q (rsm_inside_solid): off screen too, where VISIBILITY
// sees nothing. Without it, outdoors, the senders behind the buildings lit
// the walls and ceilings facing them (issue 32, docs/gi-combined.md).
// With rsm_solid_senders above 0 the solid tests (SOLIDS, SOLID_GRID) run on
// that many senders a pixel and light, the first that pass the geometry
// term, and the rest take the share of the tested ones' light that no solid
// blocked: a visibility estimated from a few senders, the tests' cost bounded
// (on the yard 2 senders of 16 points blocked as much as every sender's).
// EXCLUDE_SEEN: a sender the camera sees (rsm_seen) is left to the
// screen-space march of the combined technique.
// A light-set variant (LIGHT_SET, lighting.glsl) gathers each light unrolled,
// for its kind alone: a software rasterizer runs every branch of every
// sample (each kind's light and falloff, both texel areas) where the kind is
// read at run time (isr+rsm+esm moving at 256 x 192: isr.transport, march and
// gather, 19% less time over tools/gi_time.sh's four scenes, 29% on the
// Cornell box's point light).
uniform sampler2D rsm_flux, rsm_pos; // shadow.lua's RSM targets (atlas-sized; the normal in rsm_pos.w)
uniform int rsm_samples = 24;        // a coarse pixel and light
uniform float rsm_radius = 1.0;      // the disc's radius, in tiles
uniform float rsm_rotate = 0.0;      // turn of the pattern a frame, in turns (seed 004: 10 degrees)
uniform int rsm_steps = 0;           // VISIBILITY's march
uniform float rsm_thickness = 0.0;   // VISIBILITY: how far behind the depth buffer blocks, a share of its depth (0: any)
#ifdef SOLIDS
uniform sampler2D rsm_back;          // where the first solid on the light's way ends (shadow.frag's RSM_BACK)
uniform int rsm_solid_steps = 0;
#endif
#if defined(SOLIDS) || defined(SOLID_GRID)
uniform int rsm_solid_senders = 0;   // senders a pixel and light the solid tests run on (0: every one)
#endif
#ifdef SOLID_GRID
uniform sampler2D rsm_solid;         // the RSM views' solid grid (rsm_solid.frag): a cell's inside depths
#endif

const int INTERLEAVE = 4;                          // tile side of the interleaved pattern
const float GOLDEN = 0.61803398874989;             // the angle's step, in turns
const vec2 TURN = vec2(-0.73736887807832, -0.67549029426152); // cos, sin of 2 pi GOLDEN
const float PLASTIC = 0.75487766624669;            // 1 / the plastic number

// The pattern's direction one sample on: turned by 2 pi GOLDEN.
vec2 rsm_turn(vec2 dir) { return vec2(dir.x * TURN.x - dir.y * TURN.y, dir.x * TURN.y + dir.y * TURN.x); }

bool rsm_blocked(vec3 p, vec3 q, sampler2D dpt) {
  for (int j = 1; j <= rsm_steps; j++) {
    vec3 x = mix(p, q, float(j) / float(rsm_steps + 1));
    vec4 c = frame.view_proj * vec4(x, 1.0);
    if (c.w <= 1e-12) continue;
    vec2 s = c.xy / c.w * 0.5 + 0.5;
    if (any(lessThan(s, vec2(0.0))) || any(greaterThan(s, vec2(1.0)))) continue;
    float z = c.w * frame.clip.z, zb = texture(dpt, s).r; // a perspective's clip w is the view depth
    bool within = rsm_thickness <= 0.0 || z < zb * (1.0 + rsm_thickness);
    if (zb > 0.0 && z > zb * 1.02 && within) return true; // 0: nothing drawn there
  }
  return false;
}

// Where x falls in RSM view sv (atlas: the RSM atlas' size): false outside
// the view or behind its eye; else its normalized device coordinates, its
// tile coordinates t (0..1) and the texel there (rsm_pos: the sender's
// position, w > 0 where the texel is empty).
bool rsm_view_texel(ShadowView sv, vec3 x, vec2 atlas, out vec3 ndc, out vec2 t, out vec4 qn) {
  vec4 c = sv.view_proj * vec4(x, 1.0);
  ndc = c.xyz / max(c.w, 1e-12);
  t = ndc.xy * 0.5 + 0.5;
  qn = vec4(0.0, 0.0, 0.0, 1.0);
  if (c.w <= 1e-12 || any(lessThan(t, vec2(0.0))) || any(greaterThanEqual(t, vec2(1.0)))) return false;
  qn = texelFetch(rsm_pos, ivec2((sv.rect.xy + t * sv.rect.zw) * atlas), 0);
  return true;
}

// Is x in the shadow of every light whose RSM views hold it, by those views
// (and of one at least): the sender its texel holds lies nearer the light
// than x (by 2% of the light's distance for a spot or point light, 1% of the
// depth range for a directional one)? Over an empty texel x is lit; a light
// whose views do not hold x has no say (a light that lights nothing in view
// changes nothing: test_exposure). The combined technique's march asks it of
// the point above p near the scene box's top (isr_march.frag's UNSEEN): under
// a roof the upward rays the screen lost met a ceiling, in the open the sky.
bool rsm_shadowed(vec3 x) {
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  bool any_view = false;
  for (int i = 0; i < frame.counts.x; i++) {
    ShadowLight sl = shadow_lights[i];
    int first = sl.cube.y, count = sl.cube.z;
    bool shadowed = false, inside = false;
    for (int v = first; v < first + count && !inside; v++) {
      ShadowView sv = shadow_views[v];
      vec3 ndc;
      vec2 t;
      vec4 qn;
      if (!rsm_view_texel(sv, x, atlas, ndc, t, qn)) continue;
      inside = true;
      if (qn.w > 0.0) continue; // empty: nothing between x and the light
      vec4 cq = sv.view_proj * vec4(qn.xyz, 1.0);
      shadowed = sv.depth.w > 0.0 ? distance(x, sv.depth.xyz) > 1.02 * distance(qn.xyz, sv.depth.xyz)
                                  : ndc.z > cq.z / max(cq.w, 1e-12) + 0.02; // ndc z spans 2
    }
    if (inside && !shadowed) return false;
    any_view = any_view || inside;
  }
  return any_view;
}

#ifdef RAY_STEPS
// Does the ray p + t w meet, between t0 and t1, a surface some light's RSM
// views hold? RAY_STEPS points, each tested as the march tests the depth
// buffer: behind the sender its texel holds (farther from the light) and
// within the step's length of it (the ray crossed that surface in this
// step, give or take its texel's side; a point far behind its texel's
// sender lies in the shadow's air, not in a wall). The combined technique's march asks it of the stretch a ray
// the screen lost runs inside the scene's box (isr_march.frag's UNSEEN):
// what the light sees there stands for the surfaces off screen.
bool rsm_meets(vec3 p, vec3 w, float t0, float t1) {
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  float dt = (t1 - t0) / float(RAY_STEPS);
  for (int j = 0; j < RAY_STEPS; j++) {
    vec3 x = p + (t0 + (float(j) + 0.5) * dt) * w;
    for (int i = 0; i < frame.counts.x; i++) {
      ShadowLight sl = shadow_lights[i];
      for (int v = sl.cube.y; v < sl.cube.y + sl.cube.z; v++) {
        ShadowView sv = shadow_views[v];
        vec3 ndc;
        vec2 t;
        vec4 qn;
        if (!rsm_view_texel(sv, x, atlas, ndc, t, qn) || qn.w > 0.0) continue; // outside, or empty
        vec4 cq = sv.view_proj * vec4(qn.xyz, 1.0);
        bool behind = sv.depth.w > 0.0 ? distance(x, sv.depth.xyz) > distance(qn.xyz, sv.depth.xyz)
                                       : ndc.z > cq.z / max(cq.w, 1e-12);
        float side = sqrt(max(rsm_texel_area(sv, t, qn.xyz, sv.rect.z * atlas.x), 0.0)); // the texel's footprint
        if (behind && distance(x, qn.xyz) <= dt + side) return true;
      }
    }
  }
  return false;
}
#endif

#ifdef SOLIDS
// Does a point of p -> q (rsm_solid_steps of them, ends excluded) lie inside a solid that the views
// first .. first + count of one light hold: behind the surface its texel's sender lies on (its plane,
// the normal toward the light) and before the face where that solid ends (rsm_back: its plane, the
// normal away from the light)? Planes, not depths: a point beside a slanted surface reads a sender up to
// half a texel off, whose depth differs by that times the slope (at 0.25 of a texel's side as a depth
// bias, the yard's court view lost 17% of its first bounce). A solid thinner than the points'
// spacing can fall between them; a surface no back face closes (an open mesh) blocks nothing.
bool rsm_inside_solid(int first, int count, vec3 p, vec3 q, vec2 atlas) {
  float margin = 1e-3 * distance(p, q); // keeps p's and q's own surfaces out
  for (int j = 1; j <= rsm_solid_steps; j++) {
    vec3 x = mix(p, q, float(j) / float(rsm_solid_steps + 1));
    for (int v = first; v < first + count; v++) {
      ShadowView sv = shadow_views[v];
      vec3 ndc;
      vec2 t;
      vec4 front;
      if (!rsm_view_texel(sv, x, atlas, ndc, t, front)) continue;
      if (front.w > 0.0) break; // the light sees nothing there: no solid
      vec4 back = texelFetch(rsm_back, ivec2((sv.rect.xy + t * sv.rect.zw) * atlas), 0);
      if (back.w > 0.0) break; // no face closes it
      if (dot(normal_unpack_direction(front.w), x - front.xyz) < -margin &&
          dot(normal_unpack_direction(back.w), x - back.xyz) < -margin)
        return true;
      break;
    }
  }
  return false;
}
#endif

#ifdef SOLID_GRID
// Does p -> q pass inside a solid of the solid grid (rsm_solid.frag) of one of the views first ..
// first + count of a light? A projection maps the segment to a segment in each view's tile coordinates
// and window depth alike (a line stays a line; both ends before the light's eye), so it is marched over
// the cells it crosses (a grid walk: one fetch a cell), the depths it spans over each compared with the
// cell's inside depths. Its ends (a thousandth of it each) are left out: p's and q's own surfaces. The
// walk is exact for the grid; a solid narrower than a cell, or a cell half over its edge, blocks nothing.
bool rsm_solid_between(int first, int count, vec3 p, vec3 q) {
  vec2 cells = vec2(textureSize(rsm_solid, 0));
  for (int v = first; v < first + count; v++) {
    ShadowView sv = shadow_views[v];
    vec4 cp = sv.view_proj * vec4(p, 1.0), cq = sv.view_proj * vec4(q, 1.0);
    if (cp.w <= 1e-12 || cq.w <= 1e-12) continue; // crosses the light's eye plane: another face's
    vec3 a = cp.xyz / cp.w * 0.5 + 0.5, d = cq.xyz / cq.w * 0.5 + 0.5 - a; // tile coordinates, depth
    float s0 = 1e-3, s1 = 1.0 - 1e-3;
    for (int k = 0; k < 2; k++) { // the part inside the tile
      if (abs(d[k]) < 1e-12) {
        if (a[k] < 0.0 || a[k] >= 1.0) s1 = -1.0;
      } else {
        float e0 = -a[k] / d[k], e1 = (1.0 - a[k]) / d[k];
        s0 = max(s0, min(e0, e1));
        s1 = min(s1, max(e0, e1));
      }
    }
    if (s0 >= s1) continue;
    float n = floor(sv.rect.z * cells.x + 0.5); // the tile's cells a side
    vec2 u = a.xy * n, du = d.xy * n, origin = floor(sv.rect.xy * cells + 0.5);
    ivec2 c = ivec2(clamp(floor(u + s0 * du), vec2(0.0), vec2(n - 1.0)));
    ivec2 go = ivec2(sign(du));
    vec2 per = 1.0 / max(abs(du), vec2(1e-12)); // s a cell, each axis
    vec2 next = mix((vec2(c) - u) / min(du, vec2(-1e-12)), (vec2(c + 1) - u) / max(du, vec2(1e-12)),
                    greaterThan(du, vec2(0.0)));
    next = mix(next, vec2(2.0), lessThan(abs(du), vec2(1e-12)));
    float s = s0, margin = 1e-3 * abs(d.z);
    for (int i = 0; i < int(2.0 * n) + 2 && s < s1; i++) {
      float e = min(min(next.x, next.y), s1);
      vec2 inside = texelFetch(rsm_solid, min(ivec2(origin) + c, ivec2(cells) - 1), 0).xy;
      float z0 = a.z + s * d.z, z1 = a.z + e * d.z;
      if (max(z0, z1) > inside.x + margin && min(z0, z1) < inside.y - margin) return true;
      s = e;
      if (next.x < next.y) {
        c.x += go.x;
        next.x += per.x;
      } else {
        c.y += go.y;
        next.y += per.y;
      }
      if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, ivec2(n)))) break;
    }
  }
  return false;
}
#endif

// Light i's share of E(p) at the surface s: its RSM views, j the pixel's
// block of the pattern, turn and shift its frame's turn (rsm_gather); type
// and falloff light i's kind as light_arriving_as takes them. dpt:
// the full G-buffer's depth, for EXCLUDE_SEEN and VISIBILITY.
vec3 rsm_gather_light(int i, int type, int falloff, Surface s, int j, float turn, float shift, sampler2D dpt) {
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  ShadowLight sl = shadow_lights[i];
  Light li = lights[i]; // read once, not in the sample loop (rsm.gather about 8% faster on llvmpipe)
  int first = sl.cube.y, count = sl.cube.z;
  int n = count > 0 ? max(rsm_samples / count, 1) : 0;
  // The block's first angle: j n phi turns (j integer: fract(j fract(n phi)) = fract(j n phi),
  // without the rounding of the large product).
  float a0 = 2.0 * PI * fract(float(j) * fract(float(n) * GOLDEN) + turn);
  uint k0 = uint(j * n);
  float centred = 0.5 / float(max(n * INTERLEAVE * INTERLEAVE, 1)) + shift; // half the union's radial stratum
  // Its direction, once a light and not a view: llvmpipe's cos and sin cost about 70 ns a pair
  // a pixel (a point light's six faces took 2.4 ms of the Cornell box's 8.5 ms gather at 256 x 192).
  vec2 start = vec2(cos(a0), sin(a0));
  vec3 e = vec3(0.0);
#if defined(SOLIDS) || defined(SOLID_GRID)
  int tested = 0;                                 // senders the solid tests ran on (rsm_solid_senders)
  vec3 sent_tested = vec3(0.0), e_tested = vec3(0.0); // their light, and of it what was not blocked
#endif
  for (int v = first; v < first + count; v++) {
    vec2 dir = start;
    ShadowView sv = shadow_views[v];
    vec4 c = sv.view_proj * vec4(s.p, 1.0);
    vec2 projected = c.w > 1e-12 ? c.xy / c.w * 0.5 + 0.5 : vec2(0.5);
    // The samples go where senders can be: the part of the tile the scene's box covers (sv.bounds; a
    // directional light's tile reaches rsm.reach times past what is seen, and where no ground surrounds
    // the scene most of it is empty: the loft's sun, its sunlit senders two small patches).
    vec2 lo = sv.bounds.xy, hi = sv.bounds.zw;
    vec2 centre = clamp(projected, lo, hi); // behind a cube face: its nearest edge
    float tile = sv.rect.z * atlas.x;
    // The disc reaches no farther than the bounds' farthest corner: beyond it every sample would fall
    // outside and add nothing.
    float reach = min(rsm_radius, length(max(centre - lo, hi - centre)));
    // cut: every sample inside the bounds. A direction that leaves them from a centre on their edge
    // (corner: a cube face beside p) folds back across it, the disc being symmetric about the edge (the
    // density inside doubles: each weighs half); and each direction's radius ends at the bounds' edge,
    // L <= reach, xi L from the centre (density 1 / (2 pi L^2 xi) a unit area: each weighs (L / reach)^2
    // of the disc's sample). Else the disc's samples outside the bounds are dropped. A directional
    // light's views cut (its tile reaches past the scene: on the loft the first bounce's error against
    // Cycles' fell by 9-34% a view at the same samples, docs/gi-combined.md "The RSM's samples where the
    // senders are"); a spot or point light's keep the disc (cut, a spot-lit ceiling's clamped history
    // stood 25% off a dimmed floor's light 6 frames on, against 8.4%: test_rsm's
    // a_clamped_history_follows_a_light_step); RSM_INSIDE (the traced hits' gather, where samples are
    // dearest) cuts every view.
#ifdef RSM_INSIDE
    const bool cut = true;
#else
    bool cut = type == 2; // a constant in a light-set variant
#endif
    float texels = 2.0 * PI * tile * tile / float(max(n, 1));
    vec2 fold = cut ? vec2(notEqual(projected, centre)) : vec2(0.0);
    vec2 inward = mix(vec2(-1.0), vec2(1.0), lessThan(centre - lo, hi - centre));
    texels *= exp2(-(fold.x + fold.y));
    for (int k = 0; k < n; k++, dir = rsm_turn(dir)) {
      // The samples up to the next sender that the geometry term lets through, in a loop of their own:
      // llvmpipe runs an if's body for every pixel of its group, so the tests below inside this loop cost
      // as much at every sample, while few pass it (about 1 in 100 on the reference set's framing views).
      // Only the cosines' signs decide there, of vectors not normalized: the normal's length, the distance,
      // the texel's area and the division wait for the few that pass.
      float xi = 0.0, weight = 0.0;
      vec2 t = vec2(0.0);
      ivec2 a = ivec2(0);
      vec3 q = vec3(0.0), nq = vec3(0.0);
      for (; k < n; k++, dir = rsm_turn(dir)) {
        xi = fract(radical_inverse(k0 + uint(k), 2u) + centred);
        vec2 w = mix(dir, abs(dir) * inward, fold);
        vec2 room = mix(centre - lo, hi - centre, step(0.0, w)) / max(abs(w), vec2(1e-6)); // to the edge, each axis
        float along = cut ? min(reach, min(room.x, room.y)) : reach;
        t = centre + xi * along * w;
        weight = along * along * xi; // the sample's weight over texels
        if (any(lessThan(t, lo)) || any(greaterThan(t, hi)) || any(greaterThanEqual(t, vec2(1.0)))) continue;
        a = ivec2((sv.rect.xy + t * sv.rect.zw) * atlas);
        vec4 qn = texelFetch(rsm_pos, a, 0); // position, normal (normal_pack)
        if (qn.w > 0.0) continue; // empty
        q = qn.xyz;
        nq = normal_unpack_direction(qn.w);
        vec3 d = q - s.p;
        if (dot(s.n, d) > 0.0 && dot(nq, d) < 0.0) break; // coplanar and facing-away senders are common
      }
      if (k >= n) break;
      nq = safe_normalize(nq, vec3(0.0, 0.0, 1.0)); // normal_unpack's
      vec3 d = q - s.p;
      float d2 = dot(d, d);
      vec3 towards = d * inversesqrt(max(d2, 1e-30));
      float area = rsm_texel_area_as(sv, t, q, tile, type != 2);
      float g = max(dot(s.n, towards), 0.0) * max(dot(nq, -towards), 0.0) / max(d2, area);
#ifdef EXCLUDE_SEEN
      if (rsm_seen(dpt, q)) continue;
#endif
#ifdef VISIBILITY
      if (rsm_blocked(s.p, q, dpt)) continue;
#endif
#if defined(SOLIDS) || defined(SOLID_GRID)
      bool test = rsm_solid_senders <= 0 || tested < rsm_solid_senders, blocked = false;
      if (test) {
#ifdef SOLIDS
        blocked = rsm_inside_solid(first, count, s.p, q, atlas);
#endif
#ifdef SOLID_GRID
        blocked = blocked || rsm_solid_between(first, count, s.p, q);
#endif
      }
      if (blocked && rsm_solid_senders <= 0) continue; // before the light's evaluation
#endif
      vec3 l;
      vec3 radiance = light_arriving_as(li, type, falloff, q, l);
      vec3 sent = texelFetch(rsm_flux, a, 0).rgb * radiance * area * g * texels * weight;
#if defined(SOLIDS) || defined(SOLID_GRID)
      if (rsm_solid_senders > 0 && test) {
        tested++;
        sent_tested += sent;
        if (!blocked) e_tested += sent;
        continue;
      }
#endif
      e += sent;
    }
  }
#if defined(SOLIDS) || defined(SOLID_GRID)
  // rsm.solid_senders: the untested senders take the share of the tested ones' light that was not blocked
  // (all of it where none was tested).
  vec3 share = mix(vec3(1.0), e_tested / max(sent_tested, vec3(1e-30)), greaterThan(sent_tested, vec3(0.0)));
  e = e_tested + e * share;
#endif
  return e;
}

// E(p) at the surface s of coarse pixel px; dpt: the full G-buffer's depth,
// for EXCLUDE_SEEN and VISIBILITY.
vec3 rsm_gather(Surface s, ivec2 px, sampler2D dpt) {
  int j = interleave_index(px, INTERLEAVE);
  float turn = fract(frame.time.y * rsm_rotate);
  // With temporal reuse the radii move too (by the plastic number's step, unrelated to the angle's), so
  // that the frames a pixel accumulates cover other distances, not only other angles.
  float shift = rsm_rotate > 0.0 ? fract(frame.time.y * PLASTIC) : 0.0;
  vec2 tile = vec2(px / INTERLEAVE), r2 = vec2(PLASTIC, PLASTIC * PLASTIC); // the tile's turn and shift
  turn = fract(turn + dot(tile, r2));
  shift = fract(shift + dot(tile, r2.yx));
  vec3 e = vec3(0.0);
#ifdef LIGHT_SET
  // As reflected_light unrolls the set: four at a time, the compiler drops those past the count.
#define RSM_GATHER_AT(i) \
  if ((i) < LIGHT_SET) e += rsm_gather_light(i, light_set_type(i), light_set_falloff(i), s, j, turn, shift, dpt);
#define RSM_GATHER_FROM(i) RSM_GATHER_AT(i) RSM_GATHER_AT(i + 1) RSM_GATHER_AT(i + 2) RSM_GATHER_AT(i + 3)
#if LIGHT_SET > 0
  RSM_GATHER_FROM(0)
#endif
#if LIGHT_SET > 4
  RSM_GATHER_FROM(4)
#endif
#if LIGHT_SET > 8
  RSM_GATHER_FROM(8)
#endif
#if LIGHT_SET > 12
  RSM_GATHER_FROM(12)
#endif
#else
  for (int i = 0; i < frame.counts.x; i++) {
    Light li = lights[i];
    e += rsm_gather_light(i, light_type(li), light_falloff_mode(li), s, j, turn, shift, dpt);
  }
#endif
  return finite_or_zero(e / PI);
}
#endif

#endif
