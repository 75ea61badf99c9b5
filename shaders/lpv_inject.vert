// Injection into the light propagation volumes (seed 003, sections 5.2.3 and
// 5.2.5; scripts/lpv.lua): points passes, one point a cell write, added up.
// The cascades take their points one after the other, cascade c
// `vpl_sides`[c]^2 VPLs a view, a grid of `surfel_cols`[c] x
// `surfel_rows`[c] surfels (as many a cell in each; lpv.lua):
//   - VPLs: `vpl_sides`[c]^2 points in each of the lights' `rsm_views` RSM
//     views (light by light; lpv.lua shares lpv.vpls^2 among them), the
//     centre texels of a grid over the part of the view's RSM that the
//     cascade's grid covers (empty texels are dropped), each standing for
//     its share of that part's texels. A VPL is the sender's Lambertian lobe, its
//     radiance (k_d albedo times light_incident) times the area it stands for
//     (rsm_texel_area), put in the cell half a cell in front of the sender
//     (the seed's VPLs "placed above their surfaces");
//   - GEOMETRY: surfels, a grid of G-buffer pixels (the surfaces the
//     camera sees), into the geometry volume: the share of a cell's
//     cross-section a surfel covers for light travelling in w, its area over
//     h^2 times max(0, -n.w) (2 bands), in the cell half a cell behind the
//     surface (light reaching the surface fills the cell in front of it,
//     where the lookup reads, and stops at the next). Surfaces the camera
//     does not see block nothing: the RSM's surfels (as the second LPV
//     version takes) measured no better on the reference set and doubled
//     the points, which cost llvmpipe most of the injection's time.
//   - BOUNCE (a bounce past the first, lpv.bounces): the same VPL points and
//     then the same surfels, each now sending the light the last bounce's
//     volumes bring it (lpv_light.glsl) times its k_d albedo: the light
//     that has bounced once more. A sender is counted once: with surfels,
//     the VPLs the camera sees are left to them (EXCLUDE_SEEN).
// EXCLUDE_SEEN (the combined technique): a VPL the camera sees is left to the
// screen-space pass, as rsm.frag does.
// Output, flat: the VPL's lobe per colour channel (or the blocking lobe); a
// point that adds nothing is placed off the target.
#include "rsm.glsl"
#include "lpv_light.glsl"

uniform sampler2D rsm_flux, rsm_nrm, rsm_pos; // shadow.lua's RSM targets
uniform sampler2D clr, nrm, dpt, mat;         // the G-buffer
uniform ivec4 vpl_sides = ivec4(64); // per cascade
uniform int rsm_views = 0;
uniform ivec4 surfel_cols = ivec4(0), surfel_rows = ivec4(0); // per cascade

flat out vec4 v_r, v_g, v_b; // GEOMETRY: v_r, the blocking lobe

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
  vec3 radiance = lpv_light(q, n); // the light it receives, which the albedo below sends on
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
  n = safe_normalize(texelFetch(nrm, px, 0).xyz, vec3(0.0, 1.0, 0.0));
  float foot = 2.0 * dpt_view_depth(z) * frame.clip.w / float(size.y); // a pixel's world size
  vec3 v = safe_normalize(frame.camera_pos.xyz - p, n);
  area = foot * foot * step.x * step.y / max(abs(dot(n, v)), MIN_COS);
  return true;
}

void main() {
  gl_Position = vec4(2.0, 2.0, 0.0, 1.0); // off the target
  v_r = v_g = v_b = vec4(0.0);
  int c = 0, k = gl_VertexID;
  for (; c < lpv_cascades; c++) { // the cascade's points, and the point's index among them
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
  if (c >= lpv_cascades) return;
  vec3 p, n, flux;
  float area;
  ivec2 px;
#ifdef GEOMETRY
  if (!surfel(k, c, px, p, n, area)) return;
  float side = -0.5;
#else
#ifdef BOUNCE
  int vpls = rsm_views * vpl_sides[c] * vpl_sides[c];
  if (k >= vpls) { // a surfel: its k_d albedo times the light it receives, times its area
    if (!surfel(k - vpls, c, px, p, n, area)) return;
    flux = texelFetch(mat, px, 0).y * texelFetch(clr, px, 0).rgb * lpv_light(p, n) * area;
  } else if (!vpl(k, c, p, n, flux)) return;
#else
  if (!vpl(k, c, p, n, flux)) return;
#endif
  float side = 0.5;
#endif
  float h = lpv_cell_size(c);
  ivec3 cell = ivec3(floor((p + side * h * n - lpv_origin(c)) / h));
  if (!lpv_inside(cell, c)) return;
  gl_Position = vec4((vec2(lpv_texel(cell, c)) + 0.5) / vec2(lpv_size) * 2.0 - 1.0, 0.0, 1.0);
#ifdef GEOMETRY
  v_r = lpv_finite(lpv_lobe(area / max(h * h, 1e-30), -n)); // h^2 may underflow
#else
  v_r = lpv_finite(lpv_lobe(flux.r, n));
  v_g = lpv_finite(lpv_lobe(flux.g, n));
  v_b = lpv_finite(lpv_lobe(flux.b, n));
#endif
}
