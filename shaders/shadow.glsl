// The shadow factor of a light at a world position: the one place lighting
// shaders read shadows (ESM, PCF, Poisson or hard compares, cascades for
// directional lights, cube faces for point lights; PCSS). Needs `#define SHADOWS`
// and a pass input `shadow_atlas` (what scripts/shadow.lua returns).
// SHADOW_FILTER (0 esm, 1 pcf, 2 poisson, 3 hard, 4 pcss: lm_shadow_technique),
// which shadow.bind defines from the plan, compiles in that filter alone:
// without it every filter is compiled and each light's info.w picks one,
// and a software rasterizer runs every branch (all five filters a lookup).
#ifndef LIMN_SHADOW_GLSL
#define LIMN_SHADOW_GLSL
#include "common.glsl"
#ifdef SHADOW_FILTER
#define SHADOW_FILTER_OF(s) SHADOW_FILTER
#else
#define SHADOW_FILTER_OF(s) ((s).info.w)
#endif

struct ShadowLight {
  ivec4 info;  // first view, view count, kind (0 none, 1 cascades, 2 spot, 3 point), technique
  vec4 splits; // cascades: camera depth where each ends
  vec4 params; // c, bias (texels), blend, Poisson radius
  ivec4 cube;  // x: point lights' cube faces drawn (bit f: face f), in order; y, z: the RSM views
  vec4 soft;   // PCSS: light size (radians for cascades, world units else), widest penumbra (texels)
};
struct ShadowView {
  mat4 view_proj;
  vec4 rect;  // tile in atlas uv: offset, size
  vec4 depth; // light position, 1 / range (0: orthographic)
  vec4 texel; // a texel's world width (orthographic) or its size per unit of distance; world depth 0..1 spans;
              // orthographic: a texel's world height; perspective: the projection's x and y scale
  vec4 bounds; // RSM views: the tile coordinates the scene's box covers, min xy, max xy (no sender outside)
};
#ifdef LIGHT_BLOCKS
// Copies in uniform blocks, as common.glsl's lights: at most 6 shadow views a
// light and as many RSM views (engine/scene/scene.h, LM_LIGHT_SET_VIEWS).
layout(std140, binding = 2) uniform LimnLightSetShadows { ShadowLight shadow_lights[LIGHT_BLOCKS]; };
layout(std140, binding = 3) uniform LimnLightSetShadowViews { ShadowView shadow_views[LIGHT_BLOCKS * 12]; };
#else
layout(std430, binding = 2) readonly buffer LimnShadowLights { ShadowLight shadow_lights[]; };
layout(std430, binding = 3) readonly buffer LimnShadowViews { ShadowView shadow_views[]; };
#endif
#ifdef LIGHT_SET
// A light-set variant's copy of each light's shadow views at fixed places
// (engine/shadow/shadow.c, upload_slots): light i's view j at
// SHADOW_SLOTS i + j, j its cube face (+X -X +Y -Y +Z -Z), its cascade, or 0
// for a spot. The light's index is a constant there, so what all its views
// share is read at constant offsets, which llvmpipe reads once for all
// lanes; an offset that varies by pixel (the records' own order: the cube's
// drawn faces counted) it reads lane by lane, value by value.
#define SHADOW_SLOTS 6
layout(std140, binding = 5) uniform LimnLightSetShadowSlots { ShadowView shadow_slots[LIGHT_BLOCKS * SHADOW_SLOTS]; };
#endif

uniform sampler2D shadow_atlas;

const vec2 POISSON[16] = vec2[](
  vec2(-0.942, -0.399), vec2(0.946, -0.769), vec2(-0.094, -0.929), vec2(0.345, 0.294),
  vec2(-0.916, 0.458), vec2(-0.815, -0.879), vec2(-0.383, 0.277), vec2(0.975, 0.756),
  vec2(0.443, -0.975), vec2(0.537, -0.474), vec2(-0.264, -0.419), vec2(0.792, 0.191),
  vec2(-0.242, 0.997), vec2(-0.814, 0.914), vec2(0.200, 0.786), vec2(0.144, -0.141));

float shadow_texel(ivec2 t, ivec2 lo, ivec2 hi) { return texelFetch(shadow_atlas, clamp(t, lo, hi), 0).r; }

// Whether a receiver at depth r is lit against map texel z (shadow.frag:
// the depth, negated where the light saw a face from behind) with a bias:
// `bias` against a face toward the light, which may be the receiver's own
// surface, none against a back face, which a lit receiver never is. That
// bias grows with the tilt (up to 2.5 texels on the room's floor) and
// exceeded the depth between a receiver and the back of a thin wall or
// ceiling within two texels of where they meet: a lit line along the seam
// (docs/shadows.md). A lit face beside lit ground keeps it (the ground's
// texels nearer the light by a texel's tilt).
bool shadow_lit(float r, float bias, float z) { return z >= 0.0 ? r - bias <= z : r <= -z; }
// The same for 4 texels, 1 where lit.
vec4 shadow_lit4(float r, float bias, vec4 z) { return step(vec4(r) - bias * step(0.0, z), abs(z)); }

// The 2 x 2 texels around atlas position `texel` (texel centres at whole
// numbers) within the tile [lo, hi], in the order (0, 0), (1, 0), (0, 1),
// (1, 1), and in *f the bilinear weights between them. A position on the
// tile's outer half texel is moved onto its edge texels' centres, where the
// weights give the value that clamping each texel into the tile gives, by
// one clamp of the position rather than four selects of texels. One gather
// of a block inside the tile (a tile is at least 2 texels a side), at its
// corner, where the reciprocal's rounding cannot pick another block
// (llvmpipe: a gather costs about one fetch; a division, several products).
vec4 shadow_texels(vec2 texel, ivec2 lo, ivec2 hi, out vec2 f) {
  vec2 t = clamp(texel, vec2(lo), vec2(hi));
  vec2 b = min(floor(t), vec2(hi - 1));
  f = t - b;
  return textureGather(shadow_atlas, (b + 1.0) * (1.0 / vec2(textureSize(shadow_atlas, 0))), 0).wzxy;
}

// A texel's world size, where a point at stored depth r is, in stored depth
// (the tile's 0..1): the unit of the bias and of ESM's c, so both mean the
// same in any scene unit, tile size and depth range.
// perspective: sv's projection (sv.depth.w > 0; shadow_perspective).
float shadow_texel_depth_as(ShadowView sv, float r, bool perspective) {
  return max(perspective ? sv.texel.x * r : sv.texel.x / max(sv.texel.y, 1e-30), 1e-30);
}
float shadow_texel_depth(ShadowView sv, float r) { return shadow_texel_depth_as(sv, r, sv.depth.w > 0.0); }

// Whether the views of a light whose shadow is of kind `kind`
// (ShadowLight.info.z) are perspective (spot, point: sv.depth.w = 1 / range
// > 0) or orthographic (cascades: 0), as engine/shadow/shadow.c makes them:
// a constant kind (a light-set variant) compiles one projection's code, not
// both under a mask.
bool shadow_perspective(int kind) { return kind != 1; }

// PCSS penumbra width in texels for a blocker at normalized depth zb over a
// receiver at r (similar triangles, as ratios: no world unit). Orthographic:
// the world depth between them times the light's angular size, over the
// texel's world size. Perspective: the light's size times (d - db) / (d db),
// an angle, over the texel's angle (its size per unit of distance).
float pcss_penumbra(ShadowView sv, bool perspective, float size, float r, float zb) {
  if (perspective) {
    float d = r / sv.depth.w, db = max(zb, 1e-6) / sv.depth.w;
    return size * max(d - db, 0.0) / max(d * db * sv.texel.x, 1e-30);
  }
  return max(r - zb, 0.0) * sv.texel.y * 2.0 * tan(0.5 * min(size, 3.0)) / max(sv.texel.x, 1e-30);
}

// PCSS (seed 003, section 4.4): the mean depth of the blockers within the
// widest penumbra a blocker could cast, the penumbra that depth gives, then
// that many texels of Poisson taps, each a bilinear compare. Taps are at
// fixed offsets from the point's own texel position, so the result follows
// the stabilized map (whole-texel moves only). The bias grows with each
// tap's distance along a tilted receiver.
float pcss_lookup(ShadowLight s, ShadowView sv, bool perspective, vec2 texel, float r, float bias, float tan_tilt,
                  ivec2 lo, ivec2 hi) {
  float size = s.soft.x, widest = s.soft.y;
  float search = clamp(0.5 * pcss_penumbra(sv, perspective, size, r, perspective ? 0.1 * r : 0.0), 1.0, widest);
  float sum = 0.0, n = 0.0;
  for (int i = 0; i < 16; i++) {
    vec2 o = POISSON[i] * search;
    float z = shadow_texel(ivec2(floor(texel + 0.5 + o)), lo, hi);
    if (!shadow_lit(r, bias * (1.0 + length(o) * tan_tilt), z)) { sum += abs(z); n += 1.0; }
  }
  if (n == 0.0) return 1.0;
  float radius = clamp(0.5 * pcss_penumbra(sv, perspective, size, r, sum / n), 1.0, widest);
  float lit = 0.0;
  for (int i = 0; i < 16; i++) {
    vec2 o = POISSON[i] * radius, f;
    vec4 v = shadow_lit4(r, bias * (1.0 + (length(o) + 1.0) * tan_tilt), shadow_texels(texel + o, lo, hi, f));
    lit += mix(mix(v.x, v.y, f.x), mix(v.z, v.w, f.x), f.y);
  }
  return lit / 16.0;
}

// How far filter `technique` of light s reads from the lookup's texel, in
// texels, where a tilted receiver is nearer the light (the hard compare
// reads its own; PCSS at contact its least radius, a texel: more lit the
// thin-wall test's seams under a spot).
float shadow_spread(ShadowLight s, int technique) {
  return technique == 0 ? 1.0 : technique == 1 ? 1.5 : technique == 2 ? s.params.w : technique == 4 ? 1.0 : 0.0;
}

// Whether the 2 x 2 texels z (shadow_texels) hold a face the light sees from
// behind (negated: shadow.frag) within `reach` of depth nearer the light
// than r: one a receiver at r touches.
bool shadow_touches_back_face(vec4 z, float r, float reach) {
  // Back faces' depths are negated: r + z is r less their depth.
  vec4 touching = step(vec4(r) + z, vec4(reach));
  return dot(step(z, vec4(-1e-31)), touching) > 0.0; // stored back faces are -1e-30 or less
}

// Visibility in [0, 1] of p from view sv of light s, p at ls in its clip
// space (shadow_clip), sv perspective or not (shadow_perspective), the
// surface's n.l and the tilt shadow_tilt gives for it.
// With reach > 0, *touching says whether the texels at p hold a face the
// light sees from behind within reach texels of depth nearer the light
// (shadow_touches_back_face); ESM tells it from its own taps, the other
// filters by one gather more.
float shadow_view_lookup(ShadowView sv, bool perspective, vec4 ls, ShadowLight s, vec3 p, float ndl,
                         float tan_tilt, float reach, out bool touching) {
  touching = false;
  if (ls.w <= 1e-12) return 1.0;
  // An orthographic view's w is 1 (its matrix's last row 0 0 0 1): no division.
  vec3 ndc = perspective ? ls.xyz / ls.w : ls.xyz;
  vec2 tuv = ndc.xy * 0.5 + 0.5;
  if (any(lessThan(tuv, vec2(0.0))) || any(greaterThan(tuv, vec2(1.0)))) return 1.0; // outside: lit
  float r = perspective ? length(p - sv.depth.xyz) * sv.depth.w : ndc.z * 0.5 + 0.5;
  if (r >= 1.0) return 1.0;
  vec2 size = vec2(textureSize(shadow_atlas, 0));
  ivec2 lo = ivec2(sv.rect.xy * size + 0.5), hi = ivec2((sv.rect.xy + sv.rect.zw) * size + 0.5) - 1;
  vec2 texel = (sv.rect.xy + tuv * sv.rect.zw) * size - 0.5;
  ivec2 base = ivec2(floor(texel));
  float texel_depth = shadow_texel_depth_as(sv, r, perspective);
  float bias = s.params.y * texel_depth;
  int technique = SHADOW_FILTER_OF(s);
  if (technique != 0 && reach > 0.0) {
    vec2 f;
    touching = shadow_touches_back_face(shadow_texels(texel, lo, hi, f), r, reach * texel_depth);
  }
  if (technique == 4) return pcss_lookup(s, sv, perspective, texel, r, bias, tan_tilt, lo, hi);
  // Filters reach `spread` texels away, where a tilted receiver is deeper:
  // scale the bias by the tilt (tan of the light's angle, capped). Only
  // against faces toward the light (shadow_lit).
  bias *= 1.0 + shadow_spread(s, technique) * tan_tilt;
  if (technique == 0) {
    // ESM with the seed's 4-tap bilinear combination (seed 000, Listing 8):
    // the depth difference is clamped at 0 and scaled by n.l, then exp(-k d)
    // with k = c per texel of depth (a scale-free c; leaks within a texel);
    // no bias against a back face (shadow_lit). Taken as exp2 of the
    // difference times one factor a pixel, -k n.l log2(e) (finite: c <=
    // 10000, texel_depth >= 1e-30), so that each tap costs one product.
    float m = -1.44269504 * s.params.x / texel_depth * saturate(ndl);
    vec2 f;
    vec4 z = shadow_texels(texel, lo, hi, f);
    vec4 vis = exp2(max(vec4(r) - abs(z) - bias * step(0.0, z), 0.0) * m);
    touching = reach > 0.0 && shadow_touches_back_face(z, r, reach * texel_depth);
    return mix(mix(vis.x, vis.y, f.x), mix(vis.z, vis.w, f.x), f.y);
  }
  if (technique == 1) { // PCF 3x3
    float lit = 0.0;
    for (int y = -1; y <= 1; y++)
      for (int x = -1; x <= 1; x++) lit += shadow_lit(r, bias, shadow_texel(base + ivec2(x, y), lo, hi)) ? 1.0 : 0.0;
    return lit / 9.0;
  }
  if (technique == 2) { // Poisson disc
    float lit = 0.0;
    for (int i = 0; i < 16; i++)
      lit += shadow_lit(r, bias, shadow_texel(ivec2(floor(texel + 0.5 + POISSON[i] * s.params.w)), lo, hi)) ? 1.0 : 0.0;
    return lit / 16.0;
  }
  return shadow_lit(r, bias, shadow_texel(ivec2(floor(texel + 0.5)), lo, hi)) ? 1.0 : 0.0;
}

// The tan of the angle between a surface and the light by its n.l, capped.
float shadow_tilt(float ndl) {
  float c = saturate(ndl);
  return min(sqrt(max(1.0 - c * c, 0.0)) / max(c, 0.1), 10.0);
}

// Where point light `light` (record s) is: its cube's centre.
vec3 shadow_cube_centre(int light, ShadowLight s) {
#ifdef LIGHT_SET
  return shadow_slots[light * SHADOW_SLOTS].depth.xyz;
#else
  return shadow_views[s.info.x].depth.xyz;
#endif
}

// Which view of light `light` (record s, shadow of kind `kind`,
// ShadowLight.info.z) p reads, as the light numbers them: the cube face of a
// point light, the cascade, 0 for a spot (shadow_view_of finds it); -1 for
// none, and for cascades the next one's weight *t. One view whatever the kind
// (a software rasterizer runs every kind's branch).
int shadow_view_at(int light, ShadowLight s, int kind, vec3 p, out float t) {
  int count = s.info.y;
  t = 0.0;
  if (count <= 0) return -1;
  if (kind == 3) { // point light: the cube face of the major axis
    vec3 d = p - shadow_cube_centre(light, s);
    vec3 a = abs(d);
    int face = a.x >= a.y && a.x >= a.z ? (d.x >= 0.0 ? 0 : 1) : a.y >= a.z ? (d.y >= 0.0 ? 2 : 3) : (d.z >= 0.0 ? 4 : 5);
    if ((s.cube.x & (1 << face)) == 0) return -1; // no visible pixel was to sample it
    return face;
  }
  if (kind == 1) { // cascades: by camera depth, blended over the last `blend` share of each
    float z = -(frame.view * vec4(p, 1.0)).z;
    // The cascade: how many of the first count - 1 splits z lies beyond
    // (they increase), its ends picked by selects; no loop, which llvmpipe
    // runs until its last lane stops (callgrind: 0.6% of direct's code).
    bvec4 beyond = greaterThan(vec4(z), s.splits);
    int k = int(dot(vec4(beyond), vec4(lessThan(ivec4(0, 1, 2, 3), ivec4(count - 1)))));
    if (z > s.splits[count - 1]) return -1; // beyond the shadowed distance
    float end = k == 0 ? s.splits.x : k == 1 ? s.splits.y : k == 2 ? s.splits.z : s.splits.w;
    float start = k == 0 ? frame.clip.x : k == 1 ? s.splits.x : k == 2 ? s.splits.y : s.splits.z;
    float band = (end - start) * s.params.z;
    if (k < count - 1 && band > 0.0 && z > end - band) t = saturate((z - (end - band)) / band);
    return k;
  }
  return 0;
}

// View j of light `light` (shadow_view_at's numbering). The records hold a
// light's views in order, a cube's drawn faces alone. A light-set variant
// reads the light's fixed places instead: what a cube's faces share (centre,
// range, texel and tile size, the projection's scale) at the first place's
// constant offset, and at the face's place only its tile's corner; the whole
// record read at a pixel's own index made much of the lookup's cost on
// llvmpipe (Cornell box, dl+esm, 128x96, 4 frames, callgrind: the shadow's
// share of the JIT'd code 10.4 -> 6.5 million instructions with this and
// shadow_texels' one gather), which reads a place that varies by pixel lane
// by lane.
ShadowView shadow_view_of(int light, ShadowLight s, int kind, int j) {
#ifdef LIGHT_SET
  int at = light * SHADOW_SLOTS;
  if (kind == 3) {
    ShadowView sv = shadow_slots[at];
    sv.rect.xy = shadow_slots[at + j].rect.xy;
    return sv;
  }
  return shadow_slots[at + j];
#else
  return shadow_views[s.info.x + (kind == 3 ? bitCount(s.cube.x & ((1 << j) - 1)) : j)];
#endif
}

// p in the clip space of view j (sv, shadow_view_of) of a light whose shadow
// is of kind `kind`.
vec4 shadow_clip(ShadowView sv, int kind, int j, vec3 p) {
#ifdef LIGHT_SET
  if (kind == 3) {
    // The face's clip x, y and w from p - centre (its translation moves the
    // centre to 0): each of those rows of its matrix is a signed axis times
    // the scale (perspective_view_proj in engine/shadow/shadow.c: glm_lookat
    // toward the face with up_for's up; x: +z -z -z +z -x +x, y: y or, for
    // the +Y and -Y faces, x), so that no row is read at the face's place
    // (office, isr+esm, 640x480, moving: `direct` 3% faster; docs/benchmarks.md).
    vec3 d = p - sv.depth.xyz;
    float x = j == 0 || j == 3 ? d.z : j == 4 ? -d.x : j == 5 ? d.x : -d.z;
    float y = j == 2 || j == 3 ? d.x : d.y;
    float w = j < 2 ? d.x : j < 4 ? d.y : d.z;
    return vec4(sv.texel.z * x, sv.texel.z * y, 0.0, (j & 1) == 0 ? w : -w);
  }
#endif
  vec4 clip = sv.view_proj * vec4(p, 1.0);
  // An orthographic view's w is 1 (its matrix's last row 0 0 0 1): that row
  // not read, lane by lane where the cascade varies by pixel.
  if (!shadow_perspective(kind)) clip.w = 1.0;
  return clip;
}

// Shadow factor of light `light` at p, whose shadow is of kind `kind`
// (ShadowLight.info.z): a constant kind (a light-set variant, lighting.glsl)
// compiles that kind's lookup alone. back_faces false: the light's tiles
// hold no face it sees from behind (engine/shadow, lm_shadow_front_lit), so
// no lookup touches one and the offset step below is never taken; a
// constant false (a light-set variant's LIGHT_FRONT_LIT) compiles it out,
// which a software rasterizer would run under a mask (Cornell box's lamp).
float shadow_factor_as(int light, int kind, bool back_faces, vec3 p, vec3 n, vec3 l) {
  ShadowLight s = shadow_lights[light];
  float t;
  int v = shadow_view_at(light, s, kind, p, t);
  if (v < 0) return 1.0;
  float ndl = dot(n, l), tan_tilt = shadow_tilt(ndl), vis = 1.0; // the same for both lookups
  // Where the texels at p hold a face the light sees from behind (a thin
  // wall, a ceiling) that p touches, the lookup is at a point `bias` times
  // the filter's spread of texels along the normal (shadow_spread), toward
  // the light where the surface faces it: within a texel of where such a
  // wall meets what it shades (the floor under the window wall, the walls
  // under the ceiling) the taps read texels past the wall's edge, where the
  // light passes beside it, and lit a line along the seam; moved, they fall
  // inside the wall's texels. Elsewhere the lookup stays at p: the offset
  // moves shadow edges toward their casters by as much (at a low sun, a
  // texel times the tilt along the ground), which raised the blocks' and a
  // street view's direct-only error against POV-Ray by 10-28% (offset
  // everywhere, or wherever a back face was near). A spot's or point light's
  // texel grows with the distance from the light; a point light's offset
  // point is looked up in its own cube face (near an edge, another).
  bool perspective = shadow_perspective(kind);
  int technique = SHADOW_FILTER_OF(s);
  float offset = s.params.y * max(shadow_spread(s, technique), 1.0);
  // Every lookup in one loop that tests at its end, not the blend's second
  // view or the offset lookup in an if: a software rasterizer leaves such a
  // loop once no pixel of its group goes on, but runs both sides of every if.
  // The first lookup at p tells from its own taps whether p touches a back
  // face; only then does the next step look again at the offset point.
  float reach = back_faces && offset > 0.0 ? 4.0 * (1.0 + tan_tilt) : 0.0;
  int j = 0;
  bool offset_now = false;
  vec3 q = p;
  do {
    int w = v + j;
    if (kind == 3 && offset_now) {
      float unused;
      int face = shadow_view_at(light, s, kind, q, unused);
      if (face < 0) q = p; // a face no pixel reads: the lookup at p again
      else w = face;
    }
    ShadowView sv = shadow_view_of(light, s, kind, w);
    bool touching;
    float lit = shadow_view_lookup(sv, perspective, shadow_clip(sv, kind, w, q), s, q, ndl, tan_tilt,
                                   offset_now ? 0.0 : reach, touching);
    // The next step's point: the offset by a texel's world size, an
    // orthographic view's texel.x, a perspective one's (the same for a cube's
    // faces) its size per unit of distance times p's.
    q = touching ? p + n * (offset * sv.texel.x * (perspective ? length(p - sv.depth.xyz) : 1.0)) : p;
    offset_now = touching;
    if (!touching) vis = mix(vis, lit, j == 0 ? 1.0 : t), j++;
  } while (j < (t > 0.0 ? 2 : 1));
  return vis;
}

#ifdef SHADOW_TRANSMIT
// What blended casters let through to p from light `light` (pass input
// shadow_transmit, the shadow pass's transmittance output: rgb, the least
// depth in alpha; shadow.frag): each of the 4 texels around p counts where
// p lies beyond its depth, bilinearly weighted. White where none is.
uniform sampler2D shadow_transmit;

vec3 shadow_transmittance_as(int light, int kind, vec3 p) {
  ShadowLight s = shadow_lights[light];
  float t;
  int v = shadow_view_at(light, s, kind, p, t);
  if (v < 0) return vec3(1.0);
  ShadowView sv = shadow_view_of(light, s, kind, v);
  vec4 ls = shadow_clip(sv, kind, v, p);
  if (ls.w <= 1e-12) return vec3(1.0);
  vec3 ndc = ls.xyz / ls.w;
  vec2 tuv = ndc.xy * 0.5 + 0.5;
  if (any(lessThan(tuv, vec2(0.0))) || any(greaterThan(tuv, vec2(1.0)))) return vec3(1.0);
  bool perspective = shadow_perspective(kind);
  float r = perspective ? length(p - sv.depth.xyz) * sv.depth.w : ndc.z * 0.5 + 0.5;
  vec2 size = vec2(textureSize(shadow_transmit, 0));
  ivec2 lo = ivec2(sv.rect.xy * size + 0.5), hi = ivec2((sv.rect.xy + sv.rect.zw) * size + 0.5) - 1;
  vec2 texel = (sv.rect.xy + tuv * sv.rect.zw) * size - 0.5;
  ivec2 base = ivec2(floor(texel));
  vec2 f = texel - vec2(base);
  float bias = s.params.y * shadow_texel_depth_as(sv, r, perspective);
  vec3 c[4];
  for (int k = 0; k < 4; k++) {
    vec4 tr = texelFetch(shadow_transmit, clamp(base + ivec2(k & 1, k >> 1), lo, hi), 0);
    c[k] = r - bias > tr.a ? tr.rgb : vec3(1.0);
  }
  return mix(mix(c[0], c[1], f.x), mix(c[2], c[3], f.x), f.y);
}
#endif

// The light of light `light` that reaches p, as a factor: the shadow factor,
// tinted by the blended casters' transmittance where SHADOW_TRANSMIT is.
vec3 shadow_light_as(int light, int kind, bool back_faces, vec3 p, vec3 n, vec3 l) {
  float vis = shadow_factor_as(light, kind, back_faces, p, n, l);
#ifdef SHADOW_TRANSMIT
  return vis * shadow_transmittance_as(light, kind, p);
#else
  return vec3(vis);
#endif
}
#endif
