// Light propagation volumes (seed 003, section 5.2; scripts/lpv.lua): the
// cascades' grids, their unwrapped layout and the 2-band spherical harmonics
// the cells hold, shared by lpv_inject.vert, lpv_propagate.frag and
// lpv_lookup.frag.
//
// Grids: `lpv_cascades` grids; cascade c's cell is 2^c times cascade 0's
// `lpv_cell` (world units), and it has lpv_nx[c] x lpv_ny[c] x lpv_nz[c]
// cells (component c of each). Along an axis where the scene's box (and a
// cell either side) fits in lpv.cells cells, the grid covers just the box:
// it stays put, its least corner at lpv_ax/ay/az[c] (scripts/lpv.lua), and
// nothing lies beyond it. Along the others (bit k of lpv_follow[c] set for
// axis k) it has lpv.cells cells and follows the camera, centred
// `lpv_shift` times the seen distance ahead of it (the geometric mean of the
// least and greatest depth the G-buffer sees, `lpv_seen`: from outside a
// room the finest cascade holds what the view centres on, from inside the
// room around it), snapped to whole cells of its own: a camera that moves
// less than a cell moves no cell, one that moves more shifts them by whole
// cells, so nothing swims. A scene that fits leaves most of a cube of
// lpv.cells^3 cells out: the three cascades of the reference scenes hold
// 3.8 (the Cornell box) to 18 (the street) times fewer cells than 3 x 32^3.
//
// Layout (the seed's fig 5.4 unwrapped its 32^3 as 1024 x 32): cascade c is
// a block of lpv_nz[c] slices side by side, from column lpv_col[c]; cell
// (x, y, z) is texel (lpv_col[c] + z nx + x, y) of a texture `lpv_size`
// (the blocks' widths summed, the most rows), one per colour channel (and
// one for the geometry volume). Texels past a block's rows hold nothing.
//
// A cell holds the radiant intensity I(w) of the light in it (radiance times
// area, the engine's and POV-Ray's diffuse convention), travelling in
// direction w, in 2 bands: I(w) = A + B.w, stored (A, B.x, B.y, B.z). Its
// power is 4 pi A; a Lambertian sender of radiance L and area a is the lobe
// L a max(0, n.w): A = L a / 4, B = L a n / 2.
#ifndef LIMN_LPV_GLSL
#define LIMN_LPV_GLSL
#include "common.glsl"

uniform int lpv_cascades = 3;
uniform float lpv_cell = 1.0;
uniform float lpv_shift = 1.0;
uniform sampler2D lpv_seen; // 1 x 1: least and greatest depth / far seen (shadow.depth_range)
uniform ivec4 lpv_nx = ivec4(32), lpv_ny = ivec4(32), lpv_nz = ivec4(32); // cells a side, per cascade
uniform ivec4 lpv_col = ivec4(0, 1024, 2048, 3072);                        // each block's first column
uniform ivec4 lpv_follow = ivec4(7);                                       // axes that follow the camera
uniform vec4 lpv_ax = vec4(0.0), lpv_ay = vec4(0.0), lpv_az = vec4(0.0);   // least corners, kept axes
uniform ivec2 lpv_size = ivec2(4096, 32);                                  // the volumes' texture

// Never 0: positions are divided by it.
float lpv_cell_size(int c) { return max(lpv_cell * exp2(float(c)), 1e-30); }

ivec3 lpv_dims(int c) { return ivec3(lpv_nx[c], lpv_ny[c], lpv_nz[c]); }

// World position of the least corner of cascade c's grid.
vec3 lpv_origin(int c) {
  float h = lpv_cell_size(c);
  vec3 forward = -frame.inv_view[2].xyz;
  vec2 seen = texelFetch(lpv_seen, ivec2(0), 0).rg;
  float ahead = sqrt(max(seen.x, 0.0) * max(seen.y, 0.0)) * frame.clip.y;
  vec3 centre = frame.camera_pos.xyz + forward * (lpv_shift * ahead);
  vec3 follow = (floor(centre / h) - vec3(lpv_dims(c) / 2)) * h;
  bvec3 moves = bvec3((lpv_follow[c] & 1) != 0, (lpv_follow[c] & 2) != 0, (lpv_follow[c] & 4) != 0);
  return mix(vec3(lpv_ax[c], lpv_ay[c], lpv_az[c]), follow, moves);
}

bool lpv_inside(ivec3 cell, int c) { return all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, lpv_dims(c))); }

ivec2 lpv_texel(ivec3 cell, int c) { return ivec2(lpv_col[c] + cell.z * lpv_nx[c] + cell.x, cell.y); }

// The cascade and cell of texel t; false for a texel no cell uses.
bool lpv_cell_at(ivec2 t, out int c, out ivec3 cell) {
  c = 0;
  for (int k = 1; k < lpv_cascades; k++)
    if (t.x >= lpv_col[k]) c = k;
  int nx = max(lpv_nx[c], 1), i = t.x - lpv_col[c];
  cell = ivec3(i % nx, t.y, i / nx);
  return lpv_inside(cell, c);
}

// A Lambertian lobe K max(0, n.w) in 2 bands.
vec4 lpv_lobe(float k, vec3 n) { return vec4(0.25 * k, 0.5 * k * n); }

// NaN and Inf to zero, signs kept (B may point anywhere).
vec4 lpv_finite(vec4 v) {
  bvec4 bad = bvec4(isnan(v.x) || isinf(v.x), isnan(v.y) || isinf(v.y), isnan(v.z) || isinf(v.z),
                    isnan(v.w) || isinf(v.w));
  return mix(v, vec4(0.0), bad);
}

#endif
