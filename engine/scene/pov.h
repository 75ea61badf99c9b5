/* pov: one view of a scene as POV-Ray 3.7 scene description (SDL), so that
 * POV-Ray renders the reference the engine's image is judged against (seed
 * 000 chapter 5: radiosity references, parallel light, the engine's camera,
 * mesh2 geometry).
 *
 * What is written, and how it matches the engine (shaders/lighting.glsl):
 * - global_settings: assumed_gamma 1 (linear; render to OpenEXR with +FE),
 *   max_trace_level 5, and with radiosity on a radiosity block from
 *   lm_pov_radiosity. Background black (the engine's default background).
 * - With a sky (lm_pov_desc.sky, scripts/sky.lua's gradient): a sky_sphere of
 *   the same radiance, intensity * (horizon + (zenith - horizon) * max(y, 0)),
 *   which radiosity gathers as the engine gathers its spherical harmonics.
 * - Camera: perspective with explicit vectors taken from the engine's own
 *   frustum (lm_scene_frame_data): direction = the ray to the centre of the
 *   far plane, right/up = its frustum_u/frustum_v. POV-Ray builds a ray as
 *   direction + (x - 1/2) right + (1/2 - y) up, which is the engine's ray for
 *   the same pixel; so vertical fov, aspect (the output's: lm_scene_frame_data)
 *   and looking down the node's -Z carry over exactly. The scene stays in the
 *   engine's right-handed coordinates: POV-Ray's left-handedness only shows
 *   in its look_at/angle shortcuts, which are not used.
 * - Geometry: one mesh2 per mesh node, vertices and normals in world space
 *   (normals by the inverse transpose), zero-area triangles dropped. POV-Ray
 *   shades both sides of a triangle; the engine culls back faces, which only
 *   differs where a view sees a surface from behind.
 * - Materials (the G-buffer clamps colour and k to [0, 1], so the export
 *   does too; it keeps them in 8 bits, the export does not: at most 1/510 off):
 *   pigment rgb color; finish { ambient 0 emission 0 diffuse kd brilliance 1
 *   phong ks phong_size max(shininess, 1) }. POV-Ray's diffuse is
 *   kd * pigment * light * (n.l) and its phong ks * (r.v)^size * light,
 *   the engine's Phong exactly (seed 000 lines 2753-2767). With
 *   pbr_materials, the pbr technique's GGX has no POV-Ray form; the closest
 *   finish is written and a warning says so (never refused): pigment the
 *   base colour, diffuse 1 - metallic, specular (Blinn) with the exponent
 *   s = 2 / roughness^4 - 2 whose lobe matches GGX's and the normalized
 *   amplitude max(F0) (s + 2) / 8, metallic tinting it with the pigment,
 *   emission the emissive colour; Fresnel's rise at grazing angles, Smith
 *   shadowing, the 1 - F diffuse weight and textures are not carried. A
 *   reflective material (reflectivity r > 0) adds "reflection r": POV-Ray
 *   adds r times the colour seen along the mirror direction on top of
 *   diffuse and phong (no conserve_energy, no fresnel), one bounce deep as
 *   the engine's ray-traced reflections (engine/trace). The engine's
 *   ambient term (k_a * ambient) has no counterpart: render the engine with
 *   the option ambient = 0 when comparing.
 *   A blended material (glTF alphaMode BLEND, alpha a, transmission t) is
 *   "rgbft <colour, a t, 1 - a>": filter a t passes tinted by the colour,
 *   transmit 1 - a untinted, as the engine's forward pass (shaders/
 *   transparent.frag), whose Fresnel (1 - F of the ior) POV-Ray's filter
 *   lacks; KHR_materials_volume's absorption becomes interior { fade_power
 *   1001 (exponential) fade_distance, fade_color }, which POV-Ray applies
 *   inside closed meshes only. Rays pass straight (no ior), as the engine's.
 * - Lights, colour = color * power:
 *   directional -> parallel light placed outside the scene's bounds;
 *   point, LM_FALLOFF_NONE -> plain point light;
 *   point, LM_FALLOFF_INVERSE_SQUARE -> fade_power 2 and fade_distance
 *     f = LM_POV_FADE_FRACTION times the radius of the scene's bounding
 *     sphere, with the colour divided by 2 f^2: POV-Ray's 2 / (1 + (d / f)^2)
 *     then gives 1 / (d^2 + f^2), which is 1 / d^2 to a relative 1e-6 at a
 *     thousandth of the scene's size, in any unit;
 *   point, LM_FALLOFF_RANGE (glTF's) -> the same as inverse square when the
 *     range window clamp(1 - (d / range)^4, 0, 1) stays above
 *     1 - LM_POV_RANGE_EXACT over the scene's bounding sphere (no range, or
 *     one at least 4.76 times the farthest distance), else refused: POV-Ray
 *     has no light that fades to zero at a distance (its fade is
 *     2 / (1 + (d / f)^p) with p > 0 only);
 *   spot -> spotlight with radius = inner, falloff = outer half-angle and
 *     tightness 0: POV-Ray's cubic_spline(cos outer, cos inner, cos) is the
 *     engine's smoothstep; it matches when 0 <= inner < outer < 90 degrees;
 *   the seed's window falloff saturate(1 - (d / r)^2) has no POV-Ray form.
 *   A light that casts no shadows is shadowless (refused for spots: POV-Ray
 *   3.7 ignores a shadowless spotlight's cone). With desc.shadows false no
 *   mesh casts shadows (no_shadow), as in the engine's direct light, which
 *   has no shadow maps yet.
 * What cannot match is named (light or material and why): with strict it is
 * refused, otherwise a warning is added and the nearest form is written. */
#ifndef LIMN_POV_H
#define LIMN_POV_H

#include "scene/scene.h"
#include "scene/sky.h"

#define LM_POV_FADE_FRACTION 1e-6
/* Largest departure from 1 of a glTF range window written as plain inverse
 * square: below the G-buffer's 8-bit albedo step. */
#define LM_POV_RANGE_EXACT (1.0 / 512.0)

/* POV-Ray's radiosity settings (seed 000 chapter 5, with brightness 1 since
 * the export is linear and its light matches the engine's). */
typedef struct lm_pov_radiosity {
  int count;            /* 250 */
  double error_bound;   /* 0.25 */
  double pretrace_start; /* 0.08 */
  double pretrace_end;   /* 0.01 */
  int recursion_limit;  /* 2: ambient occlusion and the first bounce */
  double brightness;    /* 1 */
} lm_pov_radiosity;

void lm_pov_radiosity_defaults(lm_pov_radiosity *r);
/* NULL when every setting is in POV-Ray's range, else the first bad one's name. */
const char *lm_pov_radiosity_check(const lm_pov_radiosity *r);

typedef struct lm_pov_desc {
  int camera;         /* index into the scene's cameras (none: the engine's default camera) */
  int width, height;  /* output size: the aspect when the camera has none */
  bool radiosity;
  lm_pov_radiosity rad;
  bool shadows;       /* false: no mesh casts shadows */
  bool strict;        /* refuse what cannot match instead of warning */
  bool pbr_materials; /* the pbr technique's materials (approximated, warned) instead of Phong */
  bool has_sky;       /* write `sky` as a sky_sphere (it lights the scene through radiosity) */
  lm_sky sky;
} lm_pov_desc;

/* Appends the SDL for the view to `out`. Warnings (one per line, naming the
 * light or material) go to `warnings` (may be NULL). False with a message
 * when strict and something cannot match, or the view is unusable (a bad
 * camera index or size, an index past a mesh's vertices, a coordinate or
 * colour that is Inf or NaN). */
bool lm_pov_export(const lm_scene *s, const lm_pov_desc *desc, lm_buf *out, lm_buf *warnings,
                   lm_error *err);

#endif
