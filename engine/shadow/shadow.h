/* shadow: the shadow manager. Plans one atlas of shadow-map tiles for every
 * light that casts shadows: cascades for directional lights (practical split
 * scheme, stabilized as seed 003), one perspective tile for a spot light, six
 * cube faces for a point light. The plan becomes one scene pass drawn once
 * per tile, and two storage blocks the lighting shaders read through
 * shaders/shadow.glsl. A frame that plans nothing renders no shadow map.
 * With settings.rsm it also plans the lights' RSM views, drawn by a second
 * scene pass into their own atlas of reflective shadow maps (scripts/shadow.lua,
 * shaders/rsm.glsl). */
#ifndef LIMN_SHADOW_H
#define LIMN_SHADOW_H

#include "graph/graph.h"
#include "scene/scene.h"

typedef enum lm_shadow_technique {
  LM_SHADOW_ESM,     /* exponential shadow maps, seed 000 eq 30 and Listing 8 */
  LM_SHADOW_PCF,     /* 3x3 percentage-closer filtering with a bias */
  LM_SHADOW_POISSON, /* 16 Poisson-disc taps over a wider radius */
  LM_SHADOW_HARD,    /* one compare with a bias */
  LM_SHADOW_PCSS,    /* percentage-closer soft shadows: blocker search, penumbra from the light's size */
} lm_shadow_technique;
/* "esm", "pcf", "poisson", "hard", "pcss"; -1 when unknown. */
int lm_shadow_technique_parse(const char *name);

/* A shadow tile's place in the atlas, kept for the next frame's plan (lm_shadow_layout). */
typedef struct lm_shadow_place {
  int light, view; /* the scene light, and its cascade, cube face (+X -X +Y -Y +Z -Z) or 0 for a spot */
  int size, x, y;  /* texels a side, and its corner in the atlas */
} lm_shadow_place;
/* Where a plan's tiles lie: one place a shadow view, in the views' order, in a grid of columns x
 * rows cells of tile texels. */
typedef struct lm_shadow_layout {
  lm_shadow_place *places;
  int count, columns, rows, tile;
} lm_shadow_layout;

typedef struct lm_shadow_settings {
  lm_shadow_technique technique;
  int resolution;  /* tile size in texels (16 .. 8192) */
  float c;         /* ESM exponent per texel of depth (shadow.glsl: shadow_texel_depth) */
  int blur;        /* ESM Gaussian radius in texels (0: none) */
  int cascades;    /* directional lights: 1 .. 4 */
  float lambda;    /* split scheme: 0 uniform, 1 logarithmic */
  float bias;      /* depth bias in texels of the tile (world size of a texel at the receiver) */
  float distance;  /* how far from the camera cascades reach, world units (0: all that is seen) */
  float blend;     /* share of a cascade blended into the next one */
  float radius;    /* Poisson disc radius in texels */
  bool stabilize;  /* bounding spheres and texel snapping (seed 003) */
  float size;      /* PCSS: every light's size (see lm_light.size); <= 0: each light's own */
  float penumbra;  /* PCSS: the widest penumbra radius and blocker search, texels */
  bool cache;      /* a tile whose view and casters are those of the last frame's tile in its
                    * place keeps that tile's texels (engine/render: copied, not drawn) */
  bool coverage;   /* spot and point tiles as fine as the screen needs (lm_shadow_plan.levels);
                    * false: every tile at resolution */
  float simplify;  /* a caster whose simplified copy (lm_scene_mesh.casters) errs by at most this
                    * many texels of a tile draws that copy there (far cascades, small tiles); 0: none */
  float rsm;       /* > 0: a frame reads reflective shadow maps (seed 004's senders): every light
                    * gets RSM views, a directional light one tile over the sphere around all
                    * that is seen with its radius times rsm (senders off screen), 0..64 */
  int rsm_resolution; /* texels a side of every RSM view (16 .. 8192): the cell's tile halved whole
                       * times, the least at or above this (the gathers' cost grows with the texels
                       * they scatter over, not their count) */
  /* The last frame's plan's levels (lm_shadow_plan.levels), last_light_count
   * of them, or NULL: with coverage, a local light keeps its last level
   * while that level's tile is within LM_SHADOW_LEVEL_SLACK of the size the
   * screen asks for, so that a camera moving near a boundary neither resizes
   * (redraws) its tiles nor moves every other tile in the atlas. */
  const int *last_levels;
  int last_light_count;
  /* The last frame's plan's cascade depths (lm_shadow_plan.range), 0 0: none: kept while they
   * hold the depths seen now and reach no more than LM_SHADOW_RANGE_SLACK times past them, so
   * that a moving camera's cascades keep their size and scroll (engine/render) instead of
   * being drawn whole each time the depths seen cross a step of their grid. */
  float last_range[2];
  /* The last frame's plan's cascade depth rows (lm_shadow_plan.depths), last_light_count *
   * LM_SHADOW_MAX_CASCADES of them, or NULL: a cascade keeps its row while it holds the depths its
   * tile needs and spans at most LM_SHADOW_RANGE_SLACK times them, so that a camera moving along
   * the light, whose tiles' eye plane steps, scrolls them instead of drawing them whole. */
  const float (*last_depths)[2];
  /* The last frame's plan's layout (lm_shadow_plan.layout), or NULL: its grid stays while the
   * tiles fit in it and a fresh packing would fill more than half its cells, so that the atlas'
   * sides (and the shaders that sample it, which llvmpipe compiles again when they change) stay
   * as a camera walks to and fro; in it, a tile of the same light, view and size keeps its place
   * and the others take free squares, so that the tile cache (engine/render), keyed by place,
   * keeps them when a cube face appears or a light's tiles resize. */
  const lm_shadow_layout *last_layout;
} lm_shadow_settings;
#define LM_SHADOW_LEVEL_SLACK 1.25f
#define LM_SHADOW_RANGE_SLACK 1.25f
#define LM_SHADOW_MAX_CASCADES 4
void lm_shadow_settings_default(lm_shadow_settings *s);

/* std430 layouts mirrored by shaders/shadow.glsl. */
typedef struct lm_shadow_light_data {
  int32_t info[4]; /* first view, view count, kind (0 none, 1 cascades, 2 spot, 3 point), technique */
  float splits[4]; /* cascades: camera depth where each ends */
  float params[4]; /* c, bias (texels), blend, Poisson radius */
  int32_t cube[4]; /* x: point lights' cube faces drawn (bit f: face f, +X -X +Y -Y +Z -Z), in order;
                    * y, z: the light's RSM views (first record in block 3, count; count 0 without
                    * RSM): the wide tile of a directional light, else its shadow views' matrices,
                    * in the RSM atlas (lm_shadow_plan.rsm_views) */
  float soft[4];   /* PCSS: light size (radians for cascades, world units else), widest penumbra (texels) */
} lm_shadow_light_data;
typedef struct lm_shadow_view_data {
  float view_proj[16];
  float rect[4];  /* the tile in atlas uv: offset xy, size zw */
  float depth[4]; /* light position xyz, 1 / range (0: orthographic) */
  float texel[4]; /* a texel's world width (orthographic) or its size per unit of distance; the world depth 0..1 spans;
                   * orthographic: a texel's world height; perspective: the projection's x and y scale */
  float bounds[4]; /* RSM views: the tile coordinates (0..1) the scene's box projects to, min xy, max xy
                    * (0 0 1 1 where it reaches behind the eye); no texel outside holds a sender, so the
                    * RSM's gather draws its samples within (shaders/rsm.glsl) */
} lm_shadow_view_data;

typedef struct lm_shadow_plan {
  lm_shadow_settings settings;
  /* The atlas is a grid of columns x rows cells of tile texels a side (the
   * resolution, halved while the atlas would pass the GL limit; the last
   * frame's grid while it suits: lm_shadow_settings.last_layout). A cascade
   * fills a cell; a spot or point light's tiles are the cell
   * halved levels[light] times, packed into quadrants of shared cells. */
  int tile, columns, rows, atlas_width, atlas_height;
  lm_shadow_layout layout; /* the shadow views' places (the views hold them too) */
  int *levels;         /* per scene light */
  int rsm_level;       /* the halvings of the cell that give an RSM view (settings.rsm_resolution) */
  lm_pass_view *views; /* for the shadow pass, one per tile */
  int view_count;
  int shadow_views; /* the views shadow lookups read: all of them (the ESM blur's) */
  /* The RSM views (settings.rsm > 0), for the RSM pass: every light's, each
   * rsm_tile texels a side (the cell halved rsm_level times, halved again
   * while the RSM atlas would pass the GL limit), in rows of rsm_columns in
   * their own atlas of rsm_width x rsm_height texels, in the lights' order. */
  lm_pass_view *rsm_views;
  int rsm_view_count, rsm_tile, rsm_columns, rsm_width, rsm_height;
  /* Block 3: the shadow views' records, then the RSM views' (their rect in the RSM atlas). */
  lm_shadow_view_data *view_data;
  lm_shadow_light_data *lights; /* one per scene light */
  int light_count;
  float seen[2]; /* camera depths cascades cover: where receivers are seen */
  float range[2]; /* the camera depths the cascades span: seen, snapped (or the last frame's) */
  /* Per light and cascade (light * LM_SHADOW_MAX_CASCADES + cascade): the depths along the light
   * (world units, dot(p, direction)) that its tile's 0..1 spans; 0 0 where none. last_depths:
   * settings.last_depths as the plan was made (a fit reads them again). */
  float (*depths)[2], (*last_depths)[2];
} lm_shadow_plan;

/* Plans the tiles for `camera` (a frame block from lm_scene_frame_data).
 * view_count is 0 when no light casts shadows. Cascades cover the camera
 * depths of the mesh nodes in view until lm_shadow_plan_fit says more. */
bool lm_shadow_plan_make(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *camera,
                         const lm_shadow_settings *settings, lm_error *err);
/* Fits the views again to the camera depths zmin .. zmax actually seen (the
 * G-buffer's, from the depth-range reduction); the tiles and their count
 * stay. Ignored unless 0 < zmin < zmax. */
void lm_shadow_plan_fit(lm_shadow_plan *plan, const lm_scene *s, const lm_frame_data *camera, float zmin,
                        float zmax);
void lm_shadow_plan_free(lm_shadow_plan *plan);
/* True when view matrix b is a within float noise (rotation rows and depth
 * row, made again from a moved eye) but for its xy translation (m[12],
 * m[13]): a cascade that only moved across the light, which its tile can
 * scroll to. */
bool lm_shadow_view_moved_across(const float a[16], const float b[16]);
/* The lights whose shadow tiles can hold no face they see from behind
 * nearest (bit i: light i, of the first LM_LIGHT_SET_MAX, that casts):
 * those need no second lookup at a normal offset (shaders/shadow.glsl,
 * shadow_factor_as), which a light-set variant then compiles out
 * (light_set(), LIGHT_FRONT_LIT). Each caster, as its draws give it (its
 * own triangles and its simplified copies'), either faces the light with
 * every triangle, or is opaque and closed (every edge shared by two
 * triangles of opposite windings) with the light outside each of its
 * shells (inside one whose faces point inward, as a room's): then the
 * nearest face along any ray from the light enters a solid, a face toward
 * the light. Shells are taken not to pass through themselves. Reads a
 * GPU-only scene's meshes back (lm_mesh_read) into *casters (NULL the
 * first time), which keeps them for the next call (a deformed mesh's pose
 * is read each time). */
typedef struct lm_shadow_casters lm_shadow_casters;
unsigned lm_shadow_front_lit(const lm_scene *s, lm_shadow_casters **casters);
void lm_shadow_casters_free(lm_shadow_casters *c);
/* Storage blocks 2 (per light) and 3 (per tile), and uniform block 5 (each light's views at fixed
 * places, for light-set variants); a NULL plan marks every light unshadowed. */
void lm_shadow_plan_upload(const lm_shadow_plan *plan, int light_count);

#endif
