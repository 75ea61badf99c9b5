// Light propagation volumes (seed 003, section 5.2; scripts/lpv.lua): the
// cascades' grids, their unwrapped layout and the 2-band spherical harmonics
// the cells hold, shared by lpv_inject.vert, lpv_propagate.frag and
// lpv_lookup.frag.
//
// Grids: `lpv_cascades` cubes of `lpv_cells` cells a side; cascade c's cell
// is 2^c times cascade 0's `lpv_cell` (world units). All follow the camera,
// centred `lpv_shift` times the seen distance ahead of it (the geometric mean
// of the least and greatest depth the G-buffer sees, `lpv_seen`: from
// outside a room the finest cascade holds what the view centres on, from
// inside the room around it), each snapped to whole cells of its own: a
// camera that moves less than a cell moves no cell, one that moves more
// shifts them by whole cells, so nothing swims.
//
// Layout (the seed's fig 5.4, its 32^3 as 1024 x 32): cell (x, y, z) of
// cascade c is texel (z N + x, c N + y) of an N^2 x (N cascades) texture, one
// per colour channel (and one for the geometry volume).
//
// A cell holds the radiant intensity I(w) of the light in it (radiance times
// area, the engine's and POV-Ray's diffuse convention), travelling in
// direction w, in 2 bands: I(w) = A + B.w, stored (A, B.x, B.y, B.z). Its
// power is 4 pi A; a Lambertian sender of radiance L and area a is the lobe
// L a max(0, n.w): A = L a / 4, B = L a n / 2.
#ifndef LIMN_LPV_GLSL
#define LIMN_LPV_GLSL
#include "common.glsl"

uniform int lpv_cells = 32;
uniform int lpv_cascades = 3;
uniform float lpv_cell = 1.0;
uniform float lpv_shift = 1.0;
uniform sampler2D lpv_seen; // 1 x 1: least and greatest depth / far seen (shadow.depth_range)

// Never 0: positions are divided by it.
float lpv_cell_size(int c) { return max(lpv_cell * exp2(float(c)), 1e-30); }

// World position of the least corner of cascade c's grid.
vec3 lpv_origin(int c) {
  float h = lpv_cell_size(c);
  vec3 forward = -frame.inv_view[2].xyz;
  vec2 seen = texelFetch(lpv_seen, ivec2(0), 0).rg;
  float ahead = sqrt(max(seen.x, 0.0) * max(seen.y, 0.0)) * frame.clip.y;
  vec3 centre = frame.camera_pos.xyz + forward * (lpv_shift * ahead);
  return (floor(centre / h) - float(lpv_cells / 2)) * h;
}

ivec2 lpv_texel(ivec3 cell, int c) { return ivec2(cell.z * lpv_cells + cell.x, c * lpv_cells + cell.y); }

// A Lambertian lobe K max(0, n.w) in 2 bands.
vec4 lpv_lobe(float k, vec3 n) { return vec4(0.25 * k, 0.5 * k * n); }

// NaN and Inf to zero, signs kept (B may point anywhere).
vec4 lpv_finite(vec4 v) {
  bvec4 bad = bvec4(isnan(v.x) || isinf(v.x), isnan(v.y) || isinf(v.y), isnan(v.z) || isinf(v.z),
                    isnan(v.w) || isinf(v.w));
  return mix(v, vec4(0.0), bad);
}

#endif
