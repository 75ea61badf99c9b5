// The light propagation volumes' light at a point (scripts/lpv.lua), on
// POV-Ray's scale (/work/shared/design/gi-scale.md): lpv_light(p, n) is E / pi
// at p facing n, what k_d albedo multiplies. lpv_lookup.frag reads it at each
// coarse pixel, lpv_inject.vert's BOUNCE at the points it injects again (the
// next bounce). Needs VOLUMES (without, no light) and lpv.glsl's uniforms.
//
// A cell's summed intensity I over the steps is the radiance through it
// times its cross-section h^2, times the steps light spends crossing it: a
// step moves light in w by w / (|w_x| + |w_y| + |w_z|) cells
// (lpv_propagate.frag), so it lingers |w|_1 steps a cell. Hence
//   E / pi = (1 / pi) int I(-w) / h^2 / |w|_1 max(0, n.w) dw
//          ~ D max(0, A - 2/3 B.n) / h^2,  D = mean of 1 / |w|_1 = 0.674213
// (int (A + B.w) max(0, -n.w) dw = pi A - 2 pi / 3 B.n), read trilinearly
// 1.5 cells in front of the surface: the first layer of cells in front of a
// lit surface holds its own VPLs' light going sideways (2 bands cannot
// represent a Lambertian lobe's zero at grazing angles), which read there
// would light a lit plane by itself; measured on the reference set
// (tools/fidelity.sh), 1.5 cells took out the bright ground of the blocks
// views that 0.5 and 1 cell left (56% of dl+esm's indirect error removed,
// every view improved, against 55% and 14 of 15 at 1 cell).
//
// Cascades as distance bands: a step of cascade c carries light as far as
// two of cascade c - 1, so cascade c's steps after the first half
// (`late`: steps floor(S / 2) + 1 .. S) carry light from beyond what cascade
// c - 1's S steps reach, and each path is counted once:
//   E = all steps of the finest cascade c0 that holds p + late steps of each coarser one
// (`all` holds steps 1 .. S; step 0, the injected VPLs in their own cells, is
// in neither, see lpv.lua). A grid holds only the VPLs inside it: a point
// less than S cells from c0's border would miss the light from beyond it, so
// over those S cells the sum blends, by w from 1 inside to 0 at the border,
// into the same sum from c0 + 1 (no seam shows either); past the coarsest
// cascade's border the light fades to nothing. The blend shares the
// cascades past c0 + 1:
//   E = w all(c0) + (1 - w) all(c0 + 1) + w late(c0 + 1) + late of each cascade past c0 + 1
// and each cascade's volumes are read once, those with weight 0 not at all.
#ifndef LIMN_LPV_LIGHT_GLSL
#define LIMN_LPV_LIGHT_GLSL
#include "lpv.glsl"

#ifdef VOLUMES
uniform sampler2D all_r, all_g, all_b;        // sums of steps 1 .. S
uniform sampler2D late_r, late_g, late_b;     // sums of steps floor(S / 2) + 1 .. S
#endif
uniform int lpv_steps = 8;

const float LPV_D = 0.674213;

// D max(0, A - k B.d) per channel: the light arriving from around d, band 1
// weighted by k: 2/3 for the cosine lobe of E / pi (d = n), 1 for the
// radiance arriving along d alone (glossy.frag's fallback).
vec3 lpv_read(vec4 r, vec4 g, vec4 b, vec3 d, float k) {
  vec3 a = vec3(r.x, g.x, b.x), bd = vec3(dot(r.yzw, d), dot(g.yzw, d), dot(b.yzw, d));
  return LPV_D * max(a - k * bd, 0.0);
}

vec4 lpv_sample(sampler2D v, vec2 uv0, vec2 uv1, float f) { return mix(textureLod(v, uv0, 0.0), textureLod(v, uv1, 0.0), f); }

// Each cascade's least corner (lpv_origin, the same for every point), found once a call.
vec3 lpv_origins[4];

// Where p facing n is read in cascade c, in cell centres (1.5 cells in front of it).
vec3 lpv_cell_coords(int c, vec3 p, vec3 n) {
  float h = lpv_cell_size(c);
  return (p + 1.5 * h * n - lpv_origins[c]) / h - 0.5;
}

// How many cells u lies within cascade c's sampled range (negative:
// outside), along the axes that follow the camera: along the others the
// grid holds the whole scene, and no light comes from beyond it.
float lpv_margin(vec3 u, int c) {
  vec3 last = vec3(lpv_dims(c) - 1);
  vec3 m = min(u, last - u);
  bvec3 moves = bvec3((lpv_follow[c] & 1) != 0, (lpv_follow[c] & 2) != 0, (lpv_follow[c] & 4) != 0);
  m = mix(vec3(1e30), m, moves);
  return min(m.x, min(m.y, m.z));
}

// Cascade c's light at p facing n from around d (lpv_read's k): its sum of
// all steps times a plus its late sum times l.
vec3 lpv_cascade_light(int c, vec3 p, vec3 n, vec3 d, float k, float a, float l) {
  vec3 e = vec3(0.0);
#ifdef VOLUMES
  vec3 last = vec3(lpv_dims(c) - 1);
  vec3 u = clamp(lpv_cell_coords(c, p, n), vec3(0.0), last);
  float z0 = floor(u.z), f = u.z - z0, z1 = min(z0 + 1.0, last.z), nx = float(lpv_nx[c]);
  vec2 size = vec2(lpv_size), row = vec2(float(lpv_col[c]) + u.x, u.y);
  vec2 uv0 = (row + vec2(z0 * nx, 0.0) + 0.5) / size, uv1 = (row + vec2(z1 * nx, 0.0) + 0.5) / size;
  if (a > 0.0) e += a * lpv_read(lpv_sample(all_r, uv0, uv1, f), lpv_sample(all_g, uv0, uv1, f), lpv_sample(all_b, uv0, uv1, f), d, k);
  if (l > 0.0)
    e += l * lpv_read(lpv_sample(late_r, uv0, uv1, f), lpv_sample(late_g, uv0, uv1, f), lpv_sample(late_b, uv0, uv1, f), d, k);
#endif
  float h = lpv_cell_size(c);
  return e / max(h * h, 1e-30);
}

// The light at p facing n from around d (lpv_read's k): the finest cascade
// that holds p, blended into the next over its border's steps.
vec3 lpv_light_from(vec3 p, vec3 n, vec3 d, float k) {
  for (int c = 0; c < lpv_cascades; c++) lpv_origins[c] = lpv_origin(c);
  int c0 = lpv_cascades;
  float margin = -1.0;
  for (int c = 0; c < lpv_cascades && c0 == lpv_cascades; c++) {
    margin = lpv_margin(lpv_cell_coords(c, p, n), c);
    if (margin >= 0.0) c0 = c;
  }
  float w = clamp(margin / float(max(lpv_steps, 1)), 0.0, 1.0);
  vec3 e = vec3(0.0);
  for (int c = c0; c < lpv_cascades; c++)
    e += lpv_cascade_light(c, p, n, d, k, c == c0 ? w : c == c0 + 1 ? 1.0 - w : 0.0, c == c0 ? 0.0 : c == c0 + 1 ? w : 1.0);
  return finite_or_zero(e);
}

// E / pi at p facing n.
vec3 lpv_light(vec3 p, vec3 n) { return lpv_light_from(p, n, n, 2.0 / 3.0); }

#ifdef SKY_OCCLUSION
uniform sampler2D geometry;      // blocking lobes (lpv_inject.vert)
uniform int sky_cells = 8;       // cells each direction crosses
uniform float sky_occlusion = 1.0;

// The share of the sky's light along unit direction w that reaches p facing
// n past the geometry volume's surfaces: the light that crosses `sky_cells`
// cells of the finest cascade holding the march's start, each cell letting
// through 1 - sky_occlusion times its blocking for that direction
// (lpv_propagate.frag's gather); past the cascade's border nothing blocks.
// The march starts a cell in front of p: p's own surface blocks in the cell
// half a cell behind it. The volume holds only the surfaces the camera sees
// (lpv_inject.vert). Needs lpv_origins (lpv_light).
float lpv_sky_through(vec3 p, vec3 n, vec3 w) {
  int c = 0;
  vec3 start = vec3(0.0);
  for (; c < lpv_cascades; c++) {
    float h = lpv_cell_size(c);
    start = (p + h * n - lpv_origins[c]) / h;
    if (lpv_inside(ivec3(floor(start)), c)) break;
  }
  if (c >= lpv_cascades) return 1.0;
  float through = 1.0;
  for (int k = 0; k < sky_cells; k++) {
    ivec3 cell = ivec3(floor(start + float(k) * w));
    if (!lpv_inside(cell, c)) break;
    vec4 g = texelFetch(geometry, lpv_texel(cell, c), 0);
    through *= 1.0 - saturate(sky_occlusion) * saturate(g.x + dot(g.yzw, w));
  }
  return through;
}
#endif

#endif
