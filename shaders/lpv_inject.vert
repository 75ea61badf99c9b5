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
//     volumes bring it (lpv_bounce.frag: `bounce_light`, texel k of a
//     `bounce_width`-wide target for point k) times its k_d albedo: the
//     light that has bounced once more. A sender is counted once: with
//     surfels, the VPLs the camera sees are left to them (EXCLUDE_SEEN).
// EXCLUDE_SEEN (the combined technique): a VPL the camera sees is left to the
// screen-space pass, as rsm.frag does.
// Output, flat: the VPL's lobe per colour channel (or the blocking lobe); a
// point that adds nothing is placed off the target. The points:
// lpv_points.glsl.
#include "lpv_points.glsl"

#ifdef BOUNCE
uniform sampler2D bounce_light; // lpv_bounce.frag
uniform int bounce_width = 64;
#endif

flat out vec4 v_r, v_g, v_b; // GEOMETRY: v_r, the blocking lobe

void main() {
  gl_Position = vec4(2.0, 2.0, 0.0, 1.0); // off the target
  v_r = v_g = v_b = vec4(0.0);
  int c;
  vec3 p, n, flux;
  if (!lpv_point(gl_VertexID, c, p, n, flux)) return;
#ifdef GEOMETRY
  float side = -0.5;
#else
  float side = 0.5;
#endif
#ifdef BOUNCE
  int w = max(bounce_width, 1);
  flux *= texelFetch(bounce_light, ivec2(gl_VertexID % w, gl_VertexID / w), 0).rgb;
#endif
  float h = lpv_cell_size(c);
  ivec3 cell = ivec3(floor((p + side * h * n - lpv_origin(c)) / h));
  if (!lpv_inside(cell, c)) return;
  gl_Position = vec4((vec2(lpv_texel(cell, c)) + 0.5) / vec2(lpv_size) * 2.0 - 1.0, 0.0, 1.0);
#ifdef GEOMETRY
  v_r = lpv_finite(lpv_lobe(flux.x / max(h * h, 1e-30), -n)); // h^2 may underflow
#else
  v_r = lpv_finite(lpv_lobe(flux.r, n));
  v_g = lpv_finite(lpv_lobe(flux.g, n));
  v_b = lpv_finite(lpv_lobe(flux.b, n));
#endif
}
