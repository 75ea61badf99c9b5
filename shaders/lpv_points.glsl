// The injection's points (scripts/lpv.lua; lpv_inject.vert draws them,
// lpv_bounce.frag finds the light each receives for the next bounce): point
// k's cascade, position, normal and what it sends (lpv_point). See
// lpv_inject.vert for the points and their order.
#ifndef LIMN_LPV_POINTS_GLSL
#define LIMN_LPV_POINTS_GLSL
#include "rsm.glsl"
#include "lpv.glsl"

uniform sampler2D rsm_flux, rsm_nrm, rsm_pos; // shadow.lua's RSM targets
uniform sampler2D clr, nrm, dpt, mat;         // the G-buffer
uniform ivec4 vpl_sides = ivec4(64); // per cascade
uniform int rsm_views = 0;
uniform ivec4 surfel_cols = ivec4(0), surfel_rows = ivec4(0); // per cascade

const float MIN_COS = 0.2; // caps a surfel's area at 5 times its projection (grazing views)

// The part of view sv's tile (lo, hi in 0..1) that cascade c's grid covers:
// for an orthographic view (a directional light's), the box's projection, its
// centre's plus the sum of its half axes' (the projection is affine); for a
// perspective one, the whole tile (a box may lie around its light).
bool cascade_rect(ShadowView sv, int c, out vec2 lo, out vec2 hi) {
  lo = vec2(0.0);
  hi = vec2(1.0);
  if (sv.depth.w > 0.0) return true;
  vec3 half_side = 0.5 * vec3(lpv_dims(c)) * lpv_cell_size(c);
  vec2 centre = (sv.view_proj * vec4(lpv_origin(c) + half_side, 1.0)).xy * 0.5 + 0.5;
  vec2 reach = 0.5 * (abs(sv.view_proj[0].xy) * half_side.x + abs(sv.view_proj[1].xy) * half_side.y +
                      abs(sv.view_proj[2].xy) * half_side.z);
  lo = clamp(centre - reach, 0.0, 1.0);
  hi = clamp(centre + reach, 0.0, 1.0);
  return all(greaterThan(hi, lo));
}

// VPL k of cascade c: position, normal and radiance times area; false when it stands for nothing.
bool vpl(int k, int c, out vec3 q, out vec3 n, out vec3 flux) {
  int side = max(vpl_sides[c], 1), per_view = side * side, v = k / per_view, b = k % per_view;
  int light = -1;
  for (int i = 0; i < frame.counts.x && light < 0; i++) { // the v-th RSM view, light by light
    ivec4 cube = shadow_lights[i].cube;
    if (v < cube.z) light = i;
    else v -= cube.z;
  }
  if (light < 0) return false;
  v += shadow_lights[light].cube.y;
  ShadowView sv = shadow_views[v];
  vec2 lo, hi;
  if (!cascade_rect(sv, c, lo, hi)) return false;
  vec2 atlas = vec2(textureSize(rsm_pos, 0));
  float tile = sv.rect.z * atlas.x;
  vec2 t = lo + (vec2(b % side, b / side) + 0.5) / float(side) * (hi - lo);
  ivec2 a = ivec2((sv.rect.xy + t * sv.rect.zw) * atlas);
  n = texelFetch(rsm_nrm, a, 0).xyz;
  if (dot(n, n) > 1.5) return false; // empty
  q = texelFetch(rsm_pos, a, 0).xyz;
#ifdef EXCLUDE_SEEN
  if (rsm_seen(dpt, q)) return false;
#endif
#ifdef BOUNCE
  vec3 radiance = vec3(1.0); // times the light it receives (lpv_bounce.frag), sent on by its albedo
#else
  vec3 l, radiance = light_incident(light, q, l);
#endif
  float texels = tile * tile * (hi.x - lo.x) * (hi.y - lo.y) / float(per_view); // the RSM texels a point stands for
  flux = texelFetch(rsm_flux, a, 0).rgb * radiance * rsm_texel_area(sv, t, q, tile) * texels;
  return true;
}

// Surfel k of cascade c: the G-buffer pixel px, its position, normal and area
// (its footprint over the cosine to the camera, capped); false on background.
bool surfel(int k, int c, out ivec2 px, out vec3 p, out vec3 n, out float area) {
  ivec2 size = textureSize(dpt, 0), grid = max(ivec2(surfel_cols[c], surfel_rows[c]), ivec2(1));
  int columns = grid.x;
  vec2 step = vec2(size) / vec2(grid);
  vec2 uv = (vec2(k % columns, k / columns) + 0.5) * step / vec2(size);
  px = ivec2(uv * vec2(size));
  if (texelFetch(mat, px, 0).a < 0.5) return false; // background
  float z = texelFetch(dpt, px, 0).r;
  p = position_from_depth(uv, z);
  n = gbuffer_normal_decode(texelFetch(nrm, px, 0)).xyz;
  float foot = 2.0 * dpt_view_depth(z) * frame.clip.w / float(size.y); // a pixel's world size
  vec3 v = safe_normalize(frame.camera_pos.xyz - p, n);
  area = foot * foot * step.x * step.y / max(abs(dot(n, v)), MIN_COS);
  return true;
}

// Point k of the injection (the cascades' points one after the other): its
// cascade c, position p, normal n, and flux: the VPL's radiance times area,
// or GEOMETRY's surfel area (in flux.x), or BOUNCE's k_d albedo times area
// (VPLs, then surfels), which the light it receives multiplies. False when
// it stands for nothing.
bool lpv_point(int k, out int c, out vec3 p, out vec3 n, out vec3 flux) {
  flux = vec3(0.0);
  for (c = 0; c < lpv_cascades; c++) { // the cascade's points, and the point's index among them
    int vpls = rsm_views * vpl_sides[c] * vpl_sides[c], surfels = surfel_cols[c] * surfel_rows[c];
#ifdef GEOMETRY
    int points = surfels;
#elif defined(BOUNCE)
    int points = vpls + surfels;
#else
    int points = vpls;
#endif
    if (k < points) break;
    k -= points;
  }
  if (c >= lpv_cascades) return false;
  float area;
  ivec2 px;
#ifdef GEOMETRY
  if (!surfel(k, c, px, p, n, area)) return false;
  flux.x = area;
  return true;
#else
#ifdef BOUNCE
  int vpls = rsm_views * vpl_sides[c] * vpl_sides[c];
  if (k >= vpls) { // a surfel
    if (!surfel(k - vpls, c, px, p, n, area)) return false;
    flux = texelFetch(mat, px, 0).y * texelFetch(clr, px, 0).rgb * area;
    return true;
  }
#endif
  return vpl(k, c, p, n, flux);
#endif
}

#endif
