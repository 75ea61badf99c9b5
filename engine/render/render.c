#include "render/render.h"

#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trace/trace.h"

enum { MAX_LIGHTS = 256, VIEW_PASSES = 4 /* scene passes with views: shadow.depth, shadow.rsm, shadow.rsm_back */ };

/* Shadow tiles kept from frame to frame, one cache for each scene pass with
 * views (tile_cache_of: the shadow pass, the RSM passes): a copy of
 * every output of the pass, and per tile drawn the key of what drew it.
 * While casters move, a second copy keeps each drawn tile's static layer
 * (its casters that did not move this frame, and their key): a tile a moving
 * caster touches copies that layer back and draws the moving casters over it
 * (the depth test merges them as one draw would).
 * A view whose key matches the tile in its place copies the texels back
 * instead of drawing (lm_shadow_settings.cache). When the pass's outputs
 * are the very textures it left last frame, which nothing else wrote since
 * (lm_graph_target_info.alone), the texels of the tiles it drew or kept
 * then are still there: the pass clears nothing, such a tile kept in its
 * place costs nothing, and a drawn one is cleared alone (keeps_views). */
typedef struct tile_cache {
  lm_texture tex[LM_MAX_COLOR_OUTPUTS + 1];
  lm_format format[LM_MAX_COLOR_OUTPUTS + 1];
  int count, width, height;
  struct cached_tile {
    int x, y, width, height;
    bool drawn, layered; /* its texels, its static layer kept */
    bool copied;         /* its texels in the cache's textures too, not only in the pass's */
    uint64_t key, static_key;
    uint64_t pass;               /* pass_key when its texels were last made or kept */
    long at;                     /* lm_renderer.executions then */
    float view_proj[16], cull[16]; /* its view then (scroll_tile) */
  } *tiles;
  lm_texture layer[LM_MAX_COLOR_OUTPUTS + 1]; /* the static layers (made when a caster first moves) */
  int tile_count, tile_cap;
  uint32_t left[LM_MAX_COLOR_OUTPUTS + 1]; /* the textures the pass left, 0 where another may write */
  long execution;  /* lm_renderer.executions when it left them */
  uint64_t owner;  /* lm_hash of its pass's name (0: free) */
  bool in_place;   /* this frame's pass: they hold the tiles it processed last frame still */
} tile_cache;

struct lm_renderer {
  lm_renderer_desc desc;
  lm_graph *graph;
  lm_clock clock;
  int output_srgb, output_linear;
  int frame;
  /* 1 when the view's first frame was drawn again (lm_renderer_frame): the
   * frame's number (frame.time.y, which turns the GI passes' sampling
   * patterns) counts the frames shown, so that a view's frames take the same
   * samples whether or not its first was drawn again (a guess of the
   * exposure from its lights that the meter found far off). */
  int redrawn;
  float prev_view_proj[16];
  lm_frame_data camera;
  lm_shadow_plan shadows;
  lm_light_grid light_grid;
  double record_ms, compile_ms, fit_ms;
  lm_readback fit_read; /* the shadow fit's depth range, read for the next frame (fit_views) */
  float fit_far;        /* the far plane it was read under */
  lm_scene_draw_stats stats;  /* this frame's camera draws */
  lm_scene_draw_stats shadow_stats; /* and its shadow tiles' */
  bool sharing;
  lm_trace *trace; /* the scene's BVH, built by the first CPU "trace" pass */
  uint64_t trace_hash; /* geometry_hash when it was built or refitted */
  tile_cache tiles[VIEW_PASSES];
  uint64_t casters_hash; /* this frame's material_hash (record) */
  float *prev_world; /* each node's world transform in the previous frame (velocities) */
  int prev_world_count, prev_world_cap; /* nodes it holds (another count than the scene's: a first frame) */
  uint64_t pose;   /* frames in which deformed meshes changed (geometry_hash) */
  uint64_t *deforms; /* per mesh: the frames in which it deformed (tile_casters) */
  int deform_count, deform_cap;
  bool *dynamic;   /* per node: a mesh node that moved or deformed since the last frame */
  int dynamic_cap;
  bool any_dynamic;
  uint64_t world;  /* the last frame's world_hash */
  int still;       /* frames in a row before this one whose world_hash was this one's */
  uint64_t scene;  /* the last frame's scene_hash (the world without the camera) */
  int scene_still; /* the same count for scene_hash */
  uint64_t light;  /* the last frame's light_hash */
  int light_still; /* the same count for light_hash */
  /* lm_shadow_front_lit's mask (light_set()'s LIGHT_FRONT_LIT), found again when a caster or light
   * changed (front_key: caster_hash with light_hash), from the meshes it read once (front_casters). */
  unsigned front_lit;
  uint64_t front_key;
  bool front_known;
  lm_shadow_casters *front_casters;
  long executions; /* frames executed, never reset (tile_cache.execution) */
  float exposure;  /* the last frame's pre-exposure (frame_exposure) */
  lm_readback meter_read; /* the last frame's exposure meter, read for this one's pre-exposure */
  float meter_exposure;   /* the pre-exposure it was metered under (0: none started) */
  struct meter { bool valid; float key, brightest; } meter; /* what it read (read_meter) */
  float key;              /* the last key metered (radiance; 0: none yet), the histories' scale of light */
  float peak;             /* this frame's light_peak */
  float script_peak; /* the radiance the script's own light reaches (lm_pipeline_light_peak) */
  bool keep_exposure; /* the frame shows results kept under the last one's pre-exposure (keep_exposure()) */
};

lm_renderer *lm_renderer_create(const lm_renderer_desc *desc, lm_error *err) {
  if (!lm_scene_upload(desc->scene, err)) return NULL;
  lm_renderer *r = lm_alloc(sizeof *r);
  r->desc = *desc;
  r->graph = lm_graph_create();
  r->sharing = true;
  r->output_srgb = r->output_linear = -1;
  for (int i = 0; i < VIEW_PASSES; i++) r->tiles[i].execution = -1;
  lm_renderer_resize(r, desc->width, desc->height);
  r->clock = lm_clock_choose(desc->clock);
  return r;
}

static void tile_cache_free(tile_cache *c) {
  for (int i = 0; i < c->count; i++) lm_texture_destroy(&c->tex[i]), lm_texture_destroy(&c->layer[i]);
  free(c->tiles);
  uint64_t owner = c->owner; /* still its pass's */
  *c = (tile_cache){.execution = -1, .owner = owner};
}

void lm_renderer_destroy(lm_renderer *r) {
  if (!r) return;
  for (int i = 0; i < VIEW_PASSES; i++) tile_cache_free(&r->tiles[i]);
  lm_graph_destroy(r->graph);
  lm_shadow_plan_free(&r->shadows);
  lm_shadow_casters_free(r->front_casters);
  lm_readback_free(&r->fit_read);
  lm_readback_free(&r->meter_read);
  lm_light_grid_free(&r->light_grid);
  lm_trace_destroy(r->trace);
  free(r->prev_world);
  free(r->deforms);
  free(r->dynamic);
  free(r);
}

lm_graph *lm_renderer_graph(lm_renderer *r) { return r->graph; }
lm_clock lm_renderer_clock(const lm_renderer *r) { return r->clock; }
float lm_renderer_exposure(const lm_renderer *r) { return r->exposure; }
const lm_light_grid *lm_renderer_light_grid(const lm_renderer *r) { return &r->light_grid; }

void lm_renderer_overhead(const lm_renderer *r, double *record_ms, double *compile_ms) {
  *record_ms = r->record_ms;
  *compile_ms = r->compile_ms;
}

double lm_renderer_fit_ms(const lm_renderer *r) { return r->fit_ms; }
const lm_shadow_plan *lm_renderer_shadows(const lm_renderer *r) { return &r->shadows; }

/* The shadow pass fits its views to the camera depths the G-buffer holds
 * (the script's reduction: min in r, max in g, as depth / far). Reading this
 * frame's waits for the passes before it (timed: lm_renderer_fit_ms); with
 * fit_previous the frame fits to the last frame's, read without a stall
 * (lm_readback; a view's first frame reads its own), widened by fit_margin
 * for what came into view since: on still frames too, so that cascades do
 * not jump when the camera starts or stops. */
static bool fit_views(void *user, const lm_pass_desc *d, lm_texture fit, int w, int h, lm_pass_view *views,
                      lm_error *err) {
  (void)err;
  lm_renderer *r = user;
  lm_shadow_plan *plan = &r->shadows;
  if (d->view_set == 1) { /* the RSM views: the shadow pass before it fitted the plan */
    if (d->view_count == plan->rsm_view_count) memcpy(views, plan->rsm_views, sizeof *views * (size_t)d->view_count);
    return true;
  }
  if (d->view_count != plan->view_count || w < 1 || h < 1) return true;
  double t0 = lm_now_ms();
  float far = r->camera.clip[1], seen_far = far;
  float *px = lm_alloc(sizeof(float) * 4 * (size_t)w * (size_t)h);
  if (d->fit_previous && r->frame > 1 && r->fit_read.width == w && r->fit_read.height == h &&
      lm_readback_collect(&r->fit_read, px))
    seen_far = r->fit_far;
  else
    lm_texture_read(fit, w, h, true, px);
  float widen = d->fit_previous ? 1 + d->fit_margin : 1;
  float zmin = px[0] * seen_far / widen, zmax = px[1] * seen_far * widen;
  free(px);
  if (d->fit_previous) {
    lm_readback_start(&r->fit_read, fit, w, h);
    r->fit_far = far;
  }
  lm_shadow_plan_fit(plan, r->desc.scene, &r->camera, zmin, zmax);
  for (int v = 0; v < plan->view_count; v++) views[v] = plan->views[v];
  lm_shadow_plan_upload(plan, plan->light_count);
  r->fit_ms += lm_now_ms() - t0;
  return true;
}

static int pass_textures(const lm_scene_pass *sp, lm_graph_target_info out[LM_MAX_COLOR_OUTPUTS + 1]);

static const lm_program *scene_variant(void *ctx, const char *defines, lm_error *err) {
  return lm_scene_pass_variant(ctx, defines, err);
}

/* Whether scene pass sp draws a shadow tile (not an RSM view) of a light whose tiles hold no face it
 * sees from behind (lm_shadow_front_lit): the nearest face along each of its rays faces it, so the
 * tile draws front faces alone. Drawn, a closed caster's back face met its front face at the caster's
 * outline with the same depth and took a texel or two by the tie (the office's desks' corners, 198
 * texels in office's and garage's lamps' tiles), stored negated there: a lookup touched it, and the
 * variant without the offset step (LIGHT_FRONT_LIT) differed from the one with it. */
static bool tile_front_faces_alone(const lm_renderer *r, const lm_scene_pass *sp) {
  if (!sp->view || sp->desc->view_set != 0) return false;
  ptrdiff_t v = sp->view - sp->desc->views;
  if (v < 0 || v >= r->shadows.layout.count) return false;
  int light = r->shadows.layout.places[v].light;
  return light >= 0 && light < 32 && (r->front_lit >> light & 1);
}

/* Draws the scene for a scene pass: the camera's, or one shadow tile's
 * (layer: lm_scene_draw_desc's, 0 all its casters; cull: the clip volume
 * outside which nodes are left out, NULL: the view's). */
static bool draw_pass(lm_renderer *r, const lm_scene_pass *sp, int layer, const float *cull, lm_error *err) {
  enum { MAX_PARAMS = 256 };
  lm_material_param params[MAX_PARAMS];
  int n = sp->desc->material_param_count < MAX_PARAMS ? sp->desc->material_param_count : MAX_PARAMS;
  for (int i = 0; i < n; i++) {
    const lm_pass_material_param *q = &sp->desc->material_params[i];
    params[i] = (lm_material_param){q->material, q->name, q->count, {q->v[0], q->v[1], q->v[2], q->v[3]}};
  }
  if (!lm_scene_check_params(r->desc.scene, params, n, err)) return false;
  /* Cull against the camera or the tile's cull volume (a cascade's: the
   * slice it serves); a cascade tile keeps casters before its near plane,
   * which its depth clamp flattens onto it (pancaking). */
  const float *view_proj = cull ? cull : sp->view ? sp->view->cull : r->camera.view_proj;
  lm_scene_draw_desc d = {.program = sp->program, .variant = scene_variant, .ctx = (void *)sp,
                          .view_proj = r->desc.no_culling ? NULL : view_proj,
                          .pancake = sp->view && sp->view->depth[3] == 0,
                          .params = params, .param_count = n, .prev_world = r->prev_world,
                          .dynamic = r->dynamic, .layer = layer,
                          /* blended casters: no RSM senders (the shadow pass's transmittance alone) */
                          .blend = sp->view ? (sp->desc->view_set ? LM_BLEND_SKIP : LM_BLEND_CAST)
                                            : sp->desc->blend ? LM_BLEND_ONLY : LM_BLEND_SKIP,
                          .eye_view_proj = sp->view ? NULL : r->camera.view_proj,
                          .transmit = sp->view ? sp->desc->transmit : 0, .outputs = sp->desc->output_count};
  /* Simplified casters where a tile's texels hide them. The RSM views
   * (view_set 1) store each sender's normal and albedo, which the caster
   * copies (over positions alone: each corner takes one of its faces'
   * normal and uv) do not keep, so they draw the camera's copies, whose
   * seams stay (a box room's floor read as facing a wall made its bounce
   * light three times too bright). */
  if (sp->view && r->shadows.settings.simplify > 0)
    d.lod_view_proj = sp->view->view_proj, d.lod_size[0] = sp->view->width, d.lod_size[1] = sp->view->height,
    d.lod_texels = r->shadows.settings.simplify, d.lod_camera = sp->desc->view_set == 1;
  lm_graph_target_info t[LM_MAX_COLOR_OUTPUTS + 1];
  if (!sp->view && sp->desc->simplify > 0 && pass_textures(sp, t) > 0) /* and where pixels hide them */
    d.lod_view_proj = r->camera.view_proj, d.lod_size[0] = t[0].width, d.lod_size[1] = t[0].height,
    d.lod_texels = sp->desc->simplify, d.lod_camera = true;
  bool front_alone = tile_front_faces_alone(r, sp);
  if (front_alone) lm_set_cull_back_faces(true);
  bool ok = lm_scene_draw(r->desc.scene, &d, sp->view ? &r->shadow_stats : &r->stats, err);
  if (front_alone) lm_set_cull_back_faces(false);
  return ok;
}

/* The textures a scene pass draws: its colour outputs, then its depth target
 * if it has one. Returns how many. */
static int pass_textures(const lm_scene_pass *sp, lm_graph_target_info out[LM_MAX_COLOR_OUTPUTS + 1]) {
  int n = 0;
  for (int i = 0; i < sp->desc->output_count && n < LM_MAX_COLOR_OUTPUTS; i++)
    out[n++] = lm_graph_target(sp->graph, sp->desc->outputs[i]);
  if (sp->desc->depth >= 0) out[n++] = lm_graph_target(sp->graph, sp->desc->depth);
  return n;
}

/* The casters a tile draws: each mesh node its cull volume keeps (as
 * draw_pass culls: a cascade keeps those before its near plane), with its
 * mesh, material, world transform and deformation count. A caster that moves
 * changes the key of the tiles it touches now and of those it touched last
 * frame (it left their set); the others stay cached. */
static uint64_t tile_casters(const lm_renderer *r, const lm_pass_view *v, bool static_only, uint64_t h) {
  const lm_scene *s = r->desc.scene;
  bool pancake = v->depth[3] == 0;
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0 || n->mesh >= s->mesh_count || (static_only && r->dynamic[i])) continue;
    if (!r->desc.no_culling && lm_scene_node_culled(s, i, v->cull, pancake)) continue;
    int k[3] = {i, n->mesh, n->material};
    h = lm_hash(k, sizeof k, h);
    h = lm_hash(n->world, sizeof n->world, h);
    if (n->mesh < r->deform_count) h = lm_hash(&r->deforms[n->mesh], sizeof r->deforms[n->mesh], h);
  }
  return h;
}

/* What a shadow tile's texels follow from besides its view's matrices and
 * casters (tile_key): its place and depth mapping, the pass (technique's
 * program, defines, clear colour, material overrides), the scene's
 * materials (casters_hash) and whether it draws front faces alone. */
static uint64_t pass_key(const lm_renderer *r, const lm_scene_pass *sp) {
  const lm_pass_view *v = sp->view;
  const lm_pass_desc *d = sp->desc;
  int place[4] = {v->x, v->y, v->width, v->height};
  uint64_t h = lm_hash(place, sizeof place, r->casters_hash);
  h = lm_hash(v->depth, sizeof v->depth, h);
  h = lm_hash(&sp->program->id, sizeof sp->program->id, h);
  h = lm_hash(d->shader, strlen(d->shader), h);
  h = lm_hash(d->defines, strlen(d->defines), h);
  h = lm_hash(d->clear_color, sizeof d->clear_color, h);
  h = lm_hash(&r->shadows.settings.simplify, sizeof r->shadows.settings.simplify, h);
  bool front_alone = tile_front_faces_alone(r, sp);
  h = lm_hash(&front_alone, sizeof front_alone, h);
  for (int i = 0; i < d->material_param_count; i++) {
    const lm_pass_material_param *q = &d->material_params[i];
    h = lm_hash(q->material, strlen(q->material), h);
    h = lm_hash(q->name, strlen(q->name), h);
    h = lm_hash(q->v, sizeof(float) * (size_t)q->count, h);
  }
  return h;
}

/* What a shadow tile's texels follow from: the pass (pass_key), the view's
 * matrices and cull volume and the casters in the tile (tile_casters;
 * static_only: those that did not move, its static layer's). */
static uint64_t tile_key(const lm_renderer *r, const lm_scene_pass *sp, bool static_only, uint64_t pass) {
  const lm_pass_view *v = sp->view;
  uint64_t h = tile_casters(r, v, static_only, pass);
  h = lm_hash(v->view_proj, sizeof v->view_proj, h);
  return lm_hash(v->cull, sizeof v->cull, h);
}

/* Scene pass sp's cache, by its name: two passes over the same views (the
 * RSM's and its back faces') each keep their own tiles, where one cache for
 * both made each forget the other's every frame. Past VIEW_PASSES passes
 * the last cache is shared: tiles drawn again, never wrong ones (the key
 * holds the pass). */
static tile_cache *tile_cache_of(lm_renderer *r, const lm_scene_pass *sp) {
  const char *name = sp->desc->name ? sp->desc->name : "";
  uint64_t h = lm_hash(name, strlen(name), 1) | 1; /* never 0, the free mark */
  for (int i = 0; i < VIEW_PASSES; i++) {
    tile_cache *c = &r->tiles[i];
    if (c->owner == h) return c;
    if (c->owner == 0) {
      c->owner = h;
      return c;
    }
  }
  return &r->tiles[VIEW_PASSES - 1];
}

/* Makes the cache hold textures like the pass's (forgetting every tile when
 * they change); false when a texture cannot be made. */
static bool tile_cache_fit(tile_cache *c, const lm_graph_target_info *t, int n, lm_error *err) {
  bool same = c->count == n && n > 0 && c->width == t[0].width && c->height == t[0].height;
  for (int i = 0; same && i < n; i++)
    same = c->format[i] == t[i].format && t[i].width == c->width && t[i].height == c->height;
  if (same) return true;
  tile_cache_free(c);
  for (int i = 0; i < n; i++) {
    c->format[i] = t[i].format;
    c->count = i + 1;
    /* No depth: a tile copied back is done with depth testing, and a
     * scrolled one's strips clear their own before they draw (the static
     * layers keep theirs: moving casters are drawn over them). */
    if (lm_format_is_depth(t[i].format)) continue;
    if (!lm_texture_create(&c->tex[i], &(lm_texture_desc){t[i].format, t[i].width, t[i].height, false},
                           "shadow tile cache", err)) {
      tile_cache_free(c);
      return false;
    }
  }
  c->width = t[0].width, c->height = t[0].height;
  return true;
}

/* The cached tile at view v's place (a new, empty one when none is). */
static struct cached_tile *tile_at(tile_cache *c, const lm_pass_view *v) {
  for (int i = 0; i < c->tile_count; i++) {
    struct cached_tile *t = &c->tiles[i];
    if (t->x == v->x && t->y == v->y && t->width == v->width && t->height == v->height) return t;
  }
  struct cached_tile *t = LM_PUSH(c->tiles, c->tile_count, c->tile_cap);
  *t = (struct cached_tile){.x = v->x, .y = v->y, .width = v->width, .height = v->height};
  return t;
}

/* lm_graph_exec_desc.keeps_views: the shadow pass's outputs still hold last
 * frame's tiles (its textures, which only it writes, in the last frame
 * executed, of the same size). Views may lie elsewhere (lm_shadow_layout: a
 * cube face that appears takes a free square): a tile processed last frame
 * is still where it lay (draw_scene), and one drawn is cleared alone. */
static bool keeps_views(void *user, const lm_scene_pass *sp) {
  lm_renderer *r = user;
  tile_cache *c = tile_cache_of(r, sp);
  lm_graph_target_info t[LM_MAX_COLOR_OUTPUTS + 1];
  int nt = r->shadows.settings.cache ? pass_textures(sp, t) : 0;
  bool same = nt > 0 && nt == c->count && c->execution == r->executions - 1 && t[0].width == c->width &&
              t[0].height == c->height;
  for (int i = 0; i < nt && same; i++) same = t[i].alone && t[i].texture.id == c->left[i];
  c->in_place = same;
  return same;
}

/* Copies the rectangle of tile t between the pass's textures and a copy of them. */
static void copy_tile(const lm_graph_target_info *t, const lm_texture *copy, int n, const struct cached_tile *at,
                      bool to_copy) {
  for (int i = 0; i < n; i++) {
    if (!copy[i].id) continue; /* the cache's depth (tile_cache_fit) */
    lm_texture dst = to_copy ? copy[i] : t[i].texture, src = to_copy ? t[i].texture : copy[i];
    lm_texture_copy_rect(dst, src, at->x, at->y, at->width, at->height);
  }
}

/* Tile t was drawn again (for view v in execution `at`) into the pass's
 * textures tex: a cached tile of another size that overlaps it (tiles resize
 * with a light's coverage or the RSM's resolution) lost texels, so it is
 * drawn again when its view comes back, even with the same key. Its texels
 * are copied into the cache only when the pass was not in place: in place,
 * the next frame most likely finds them where they are (a copy of a 512x512
 * tile of an RSM's five targets costs 2.6 ms on llvmpipe), and a frame that
 * does not draws the tile again. */
static void tile_cache_drawn(tile_cache *c, const lm_graph_target_info *tex, int n, struct cached_tile *t,
                             uint64_t key, uint64_t pass, const lm_pass_view *v, long at) {
  for (int i = 0; i < c->tile_count; i++) {
    struct cached_tile *o = &c->tiles[i];
    if (o != t && o->x < t->x + t->width && t->x < o->x + o->width && o->y < t->y + t->height &&
        t->y < o->y + o->height)
      o->drawn = o->layered = false;
  }
  t->copied = !c->in_place;
  if (t->copied) copy_tile(tex, c->tex, n, t, true);
  t->drawn = true, t->key = key, t->pass = pass, t->at = at;
  memcpy(t->view_proj, v->view_proj, sizeof t->view_proj);
  memcpy(t->cull, v->cull, sizeof t->cull);
}

/* Sets the rectangle x, y, width, height of the pass's textures t to its
 * clear values (far depth), as its own clear would the whole. */
static void clear_texels(const lm_scene_pass *sp, const lm_graph_target_info *t, int n, int x, int y, int width,
                         int height) {
  float depth[4] = {lm_scene_clear_depth(true), 0, 0, 0};
  for (int i = 0; i < n; i++)
    lm_texture_clear_rect(t[i].texture, t[i].format, x, y, width, height,
                          lm_format_is_depth(t[i].format) ? depth : sp->desc->clear_color);
}

/* Makes the static layers' textures, like the cache's; false when one cannot be made. */
static bool tile_cache_layers(tile_cache *c, lm_error *err) {
  for (int i = 0; i < c->count; i++)
    if (!c->layer[i].id &&
        !lm_texture_create(&c->layer[i], &(lm_texture_desc){c->format[i], c->width, c->height, false},
                           "shadow tile static layers", err))
      return false;
  return true;
}

/* May a caster move: does an animation move a node no camera sits on (a
 * mesh's, a joint's, one above them; a light's too, whose layers then go
 * unused)? Then the static layers are made with the cache, on the first
 * frame, not on the frame a caster first moves: their first allocation and
 * touch made that frame 1.28x the same frame drawn with no cache (door,
 * 256x192, llvmpipe: CPU time). */
static bool casters_animated(const lm_scene *s) {
  for (int a = 0; a < s->animation_count; a++)
    for (int k = 0; k < s->animations[a].channel_count; k++) {
      bool camera = false;
      for (int i = 0; i < s->camera_count && !camera; i++) camera = s->cameras[i].node == s->animations[a].channels[k].node;
      if (!camera) return true;
    }
  return false;
}

/* Draws a tile that changed while casters move (or whose static layer is
 * kept): its static layer, drawn again only when its own casters changed,
 * then the moving casters over it. */
static bool draw_layered(lm_renderer *r, const lm_scene_pass *sp, const lm_graph_target_info *t, int nt,
                         struct cached_tile *cached, uint64_t pass, bool in_place, lm_error *err) {
  tile_cache *c = tile_cache_of(r, sp);
  if (!tile_cache_layers(c, err)) return false;
  uint64_t key = tile_key(r, sp, true, pass);
  if (cached->layered && cached->static_key == key) {
    copy_tile(t, c->layer, nt, cached, false);
    r->shadow_stats.layered++;
  } else {
    if (in_place) clear_texels(sp, t, nt, cached->x, cached->y, cached->width, cached->height);
    if (!draw_pass(r, sp, 1, NULL, err)) return false;
    copy_tile(t, c->layer, nt, cached, true);
    cached->layered = true, cached->static_key = key;
  }
  return !r->any_dynamic || draw_pass(r, sp, 2, NULL, err);
}

/* The texels of a w x h orthographic tile of view_proj within the box of
 * clip volume `cull` (orthographic, over the same light view): rect x0, y0,
 * x1, y1 (ends excluded), the texels it touches (outward) or those wholly
 * inside it; *far: the box's far end in view_proj's clip depth. */
static void cull_texels(const float *view_proj, const float *cull, int w, int h, bool outward, int rect[4],
                        float *far) {
  mat4 vp, inv, m; /* aligned copies: cglm's SIMD wants them */
  memcpy(inv, cull, sizeof inv);
  memcpy(vp, view_proj, sizeof vp);
  glm_mat4_inv(inv, inv);
  glm_mat4_mul(vp, inv, m); /* cull's clip space to view_proj's */
  float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
  for (int c = 0; c < 8; c++) {
    vec4 p = {c & 1 ? 1.0f : -1.0f, c & 2 ? 1.0f : -1.0f, c & 4 ? 1.0f : -1.0f, 1}, q;
    glm_mat4_mulv(m, p, q);
    glm_vec3_minv(lo, q, lo);
    glm_vec3_maxv(hi, q, hi);
  }
  float x0 = (lo[0] + 1) * 0.5f * (float)w, x1 = (hi[0] + 1) * 0.5f * (float)w;
  float y0 = (lo[1] + 1) * 0.5f * (float)h, y1 = (hi[1] + 1) * 0.5f * (float)h;
  float in = outward ? -1.0f : 1.0f; /* a texel to spare: the box's edges cut texels */
  rect[0] = (int)fmaxf(floorf(x0 + in), 0), rect[1] = (int)fmaxf(floorf(y0 + in), 0);
  rect[2] = (int)fminf(ceilf(x1 - in), (float)w), rect[3] = (int)fminf(ceilf(y1 - in), (float)h);
  *far = hi[2];
}

/* Scrolls a cascade's tile: when its view only moved across the light by
 * whole texels since last frame (a moving camera: texel snapping keeps the
 * texel grid, the snapped eye plane and depth range the depth mapping) and
 * nothing in the scene moved, the texels both frames' lookups read (their
 * cull volumes' boxes, xy; no deeper than last frame's) are last frame's,
 * moved with the view, and only the strips of this frame's box that they do
 * not cover are drawn, each a scissored draw of the casters over it.
 * 1: scrolled, 0: the tile must be drawn whole, -1: a draw failed (err). */
static int scroll_tile(lm_renderer *r, const lm_scene_pass *sp, const lm_graph_target_info *t, int nt,
                       struct cached_tile *cached, uint64_t pass, bool in_place, lm_error *err) {
  const lm_pass_view *v = sp->view;
  int w = v->width, h = v->height;
  if (!cached->drawn || !(in_place || cached->copied) || cached->at != r->executions - 1 || cached->pass != pass ||
      v->depth[3] != 0 || !lm_shadow_view_moved_across(cached->view_proj, v->view_proj))
    return 0;
  float sx = (v->view_proj[12] - cached->view_proj[12]) * 0.5f * (float)w;
  float sy = (v->view_proj[13] - cached->view_proj[13]) * 0.5f * (float)h;
  int kx = (int)lroundf(sx), ky = (int)lroundf(sy); /* a world point's texel moved by (kx, ky) */
  if (!(fabsf(sx - (float)kx) <= 0.01f && fabsf(sy - (float)ky) <= 0.01f) || abs(kx) >= w || abs(ky) >= h)
    return 0;
  int need[4], had[4];
  float far, had_far;
  cull_texels(v->view_proj, v->cull, w, h, true, need, &far);
  cull_texels(cached->view_proj, cached->cull, w, h, false, had, &had_far);
  int keep[4] = {had[0] + kx > need[0] ? had[0] + kx : need[0], had[1] + ky > need[1] ? had[1] + ky : need[1],
                 had[2] + kx < need[2] ? had[2] + kx : need[2], had[3] + ky < need[3] ? had[3] + ky : need[3]};
  if (!(far <= had_far + 1e-5f && far > -1.0f + 1e-6f) || keep[0] >= keep[2] || keep[1] >= keep[3]) return 0;
  const lm_texture *copy = tile_cache_of(r, sp)->tex;
  if (!cached->copied) copy_tile(t, copy, nt, cached, true); /* last frame's, where they move from */
  /* The whole tile moved (outside the box too: what lookups never read stays as it was) */
  int x0 = kx > 0 ? kx : 0, y0 = ky > 0 ? ky : 0, x1 = kx < 0 ? w + kx : w, y1 = ky < 0 ? h + ky : h;
  for (int i = 0; i < nt; i++)
    if (copy[i].id)
      lm_texture_copy_moved(t[i].texture, v->x + x0, v->y + y0, copy[i], v->x + x0 - kx, v->y + y0 - ky,
                            x1 - x0, y1 - y0);
  if (in_place) { /* the bands the move left hold last frame's texels: cleared, as a pass not in place is */
    clear_texels(sp, t, nt, v->x, v->y, w, y0);
    clear_texels(sp, t, nt, v->x, v->y + y1, w, h - y1);
    clear_texels(sp, t, nt, v->x, v->y + y0, x0, y1 - y0);
    clear_texels(sp, t, nt, v->x + x1, v->y + y0, w - x1, y1 - y0);
  }
  /* need less keep: below and above keep across need, then left and right of it */
  int strips[4][4] = {{need[0], need[1], need[2], keep[1]}, {need[0], keep[3], need[2], need[3]},
                      {need[0], keep[1], keep[0], keep[3]}, {keep[2], keep[1], need[2], keep[3]}};
  for (int k = 0; k < 4; k++) {
    const int *s = strips[k];
    if (s[0] >= s[2] || s[1] >= s[3]) continue;
    /* The strip's box in view_proj's clip space, a texel wider each way, to its far end. */
    float x0 = 2.0f * (float)(s[0] - 1) / (float)w - 1, x1 = 2.0f * (float)(s[2] + 1) / (float)w - 1;
    float y0 = 2.0f * (float)(s[1] - 1) / (float)h - 1, y1 = 2.0f * (float)(s[3] + 1) / (float)h - 1;
    mat4 box, vp, cull;
    glm_ortho(x0, x1, y0, y1, 1.0f, -far, box); /* clip z -1 .. far to -1 .. 1 */
    memcpy(vp, v->view_proj, sizeof vp);
    glm_mat4_mul(box, vp, cull);
    clear_texels(sp, t, nt, v->x + s[0], v->y + s[1], s[2] - s[0], s[3] - s[1]);
    lm_set_scissor(true, v->x + s[0], v->y + s[1], s[2] - s[0], s[3] - s[1]);
    bool ok = draw_pass(r, sp, 0, (const float *)cull, err);
    lm_set_scissor(false, 0, 0, 0, 0);
    if (!ok) return -1;
  }
  r->shadow_stats.scrolled++;
  return 1;
}

static bool draw_scene(void *user, const lm_scene_pass *sp, lm_error *err) {
  lm_renderer *r = user;
  /* A shadow tile drawn last frame from the same view and casters: copy it back. */
  struct cached_tile *cached = NULL;
  lm_graph_target_info t[LM_MAX_COLOR_OUTPUTS + 1];
  int nt = sp->view && r->shadows.settings.cache ? pass_textures(sp, t) : 0;
  uint64_t key = 0, pass = 0;
  tile_cache *c = tile_cache_of(r, sp);
  if (nt > 0) {
    bool in_place = c->in_place;
    if (!tile_cache_fit(c, t, nt, err)) return false;
    if (!c->layer[0].id && casters_animated(r->desc.scene) && !tile_cache_layers(c, err)) return false;
    pass = pass_key(r, sp);
    key = tile_key(r, sp, false, pass);
    cached = tile_at(c, sp->view);
    /* What the pass leaves for the next frame (whether or not it was in place). */
    for (int i = 0; i < nt; i++) c->left[i] = t[i].alone ? t[i].texture.id : 0;
    c->execution = r->executions;
    /* Its texels are in the outputs when it was processed last frame (another tile drawn over
     * them since would have marked it not drawn: tile_cache_drawn). */
    bool held = in_place && cached->at == r->executions - 1;
    if (cached->drawn && cached->key == key && (held || cached->copied)) {
      if (!held) copy_tile(t, c->tex, nt, cached, false);
      r->shadow_stats.kept++;
      r->shadow_stats.in_place += held;
      cached->at = r->executions;
      return true;
    }
    if (r->any_dynamic || cached->layered) {
      if (!draw_layered(r, sp, t, nt, cached, pass, in_place, err)) return false;
      tile_cache_drawn(c, t, nt, cached, key, pass, sp->view, r->executions);
      return true;
    }
    int scrolled = scroll_tile(r, sp, t, nt, cached, pass, in_place, err);
    if (scrolled != 0) {
      if (scrolled < 0) return false;
      tile_cache_drawn(c, t, nt, cached, key, pass, sp->view, r->executions);
      return true;
    }
    if (in_place) /* the pass cleared nothing: this tile alone */
      clear_texels(sp, t, nt, cached->x, cached->y, cached->width, cached->height);
  }
  if (!draw_pass(r, sp, 0, NULL, err)) return false;
  if (cached) {
    tile_cache_drawn(c, t, nt, cached, key, pass, sp->view, r->executions);
  }
  return true;
}

bool lm_renderer_set_scene(lm_renderer *r, lm_scene *scene, lm_error *err) {
  if (!lm_scene_upload(scene, err)) return false;
  r->desc.scene = scene;
  for (int i = 0; i < VIEW_PASSES; i++) /* another scene's textures are not hashed: draw every tile again */
    r->tiles[i].tile_count = 0;
  r->frame = r->redrawn = 0;
  lm_trace_destroy(r->trace);
  r->trace = NULL;
  return true;
}

/* A hash of what the BVH is built from: mesh nodes, their meshes and world
 * transforms, and the pose of deformed meshes (a count of the frames in
 * which any deformed: cheaper than hashing their vertices). */
static uint64_t geometry_hash(const lm_renderer *r) {
  const lm_scene *s = r->desc.scene;
  uint64_t h = lm_hash(&s->node_count, sizeof s->node_count, lm_hash(&r->pose, sizeof r->pose, 0));
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh < 0) continue;
    h = lm_hash(&n->mesh, sizeof n->mesh, h);
    h = lm_hash(n->world, sizeof n->world, h);
  }
  return h;
}

/* A hash of the scene and what the shadow and RSM shaders read of its
 * materials (colour, factors, base-colour texture, alpha mask and texture
 * transforms). */
static uint64_t material_hash(const lm_scene *s) {
  uint64_t h = lm_hash(&s, sizeof s, 0);
  for (int i = 0; i < s->material_count; i++) {
    const lm_material *m = &s->materials[i];
    const lm_material_pbr *p = &s->material_pbr[i];
    float f[9] = {m->color[0], m->color[1], m->color[2], m->rho, m->ka, m->kd, m->ks, m->shininess, m->reflectivity};
    float a[3] = {p->alpha, p->alpha_cutoff, p->transmission};
    int k[3] = {m->base_color_texture, (int)p->alpha_mode, p->set};
    h = lm_hash(f, sizeof f, h);
    h = lm_hash(a, sizeof a, h);
    h = lm_hash(k, sizeof k, h);
    h = lm_hash(p->textures, sizeof p->textures, h);
    h = lm_hash(p->uv_transform, sizeof p->uv_transform, h);
  }
  return h;
}

/* A hash of what shadow tiles are drawn from beside their views: the
 * materials, and the mesh nodes (mesh, material, world transform, pose). */
static uint64_t caster_hash(const lm_renderer *r) {
  const lm_scene *s = r->desc.scene;
  uint64_t h = lm_hash(&s, sizeof s, geometry_hash(r));
  for (int i = 0; i < s->node_count; i++)
    if (s->nodes[i].mesh >= 0) h = lm_hash(&s->nodes[i].material, sizeof s->nodes[i].material, h);
  return lm_hash(&h, sizeof h, r->casters_hash);
}

static float srgb_to_linear(unsigned char c) {
  float v = c / 255.0f;
  return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

/* The hit's albedo: the material's colour times its base-colour texel
 * (nearest, repeating, decoded from sRGB as the GPU's sampler does). */
static void hit_albedo(const lm_scene *s, const lm_material *m, const float uv[2], float out[3]) {
  memcpy(out, m->color, sizeof m->color);
  int t = m->base_color_texture - 1;
  if (t < 0 || t >= s->texture_count || !s->textures[t].rgba) return;
  const lm_scene_texture *tx = &s->textures[t];
  float u = uv[0] - floorf(uv[0]), v = uv[1] - floorf(uv[1]);
  if (!isfinite(u) || !isfinite(v)) return;
  int x = (int)(u * tx->width), y = (int)(v * tx->height);
  x = x < tx->width ? x : tx->width - 1, y = y < tx->height ? y : tx->height - 1;
  const unsigned char *px = tx->rgba + ((size_t)y * tx->width + x) * 4;
  for (int k = 0; k < 3; k++) out[k] *= srgb_to_linear(px[k]);
}

static const lm_cpu_image *cpu_input(const lm_cpu_pass *cp, const char *name) {
  for (int i = 0; i < cp->input_count; i++)
    if (!strcmp(cp->inputs[i].name, name)) return &cp->inputs[i];
  return NULL;
}

/* A whole number param of a CPU pass, or `fallback` where it has none. */
static int cpu_param_int(const lm_cpu_pass *cp, const char *name, int fallback) {
  for (int i = 0; i < cp->desc->param_count; i++) {
    const lm_pass_param *p = &cp->desc->params[i];
    if (!strcmp(p->name, name) && p->kind == LM_PARAM_NUMBER && p->count == 1 && isfinite(p->v[0]))
      return (int)p->v[0];
  }
  return fallback;
}

/* With params.block = b > 1, one ray for each b x b block of rays_o's pixels
 * (rsm.trace under 1): chosen among the block's rays with chance in
 * proportion to rays_o's w (the lost rays each stands for: every lost ray
 * alike), by a hash of the pixel and `frame` (params.turn 1, with temporal
 * reuse: the choice turns each frame; 0: a still camera keeps its image).
 * Writes into pixel[] the index of each block's ray, -1 for none. */
static void choose_in_blocks(const lm_cpu_image *ro, int b, int ow, int oh, unsigned frame, int *pixel) {
  float *total = lm_alloc(sizeof *total * (size_t)ow * oh);
  for (int i = 0; i < ow * oh; i++) pixel[i] = -1;
  for (int y = 0; y < ro->height; y++)
    for (int x = 0; x < ro->width; x++) {
      float w = ro->rgba[((size_t)y * ro->width + x) * 4 + 3];
      int bx = x / b, by = y / b, k = by * ow + bx;
      if (!(w > 0.5f) || bx >= ow || by >= oh) continue;
      total[k] += w;
      unsigned key[3] = {(unsigned)x, (unsigned)y, frame};
      double u = (double)(lm_hash(key, sizeof key, 0x7ace) >> 11) / 9007199254740992.0; /* [0, 1) */
      if (u * total[k] < w) pixel[k] = y * ro->width + x; /* kept with chance w / total so far */
    }
  free(total);
}

/* The CPU step of ray-traced reflections (seed 003 section 6.2): rays from
 * rays_o (origin, w > 0.5: a ray) and rays_d (direction, w: the longest
 * distance, 0 for none), traced on every core; out: a G-buffer of the hits
 * as std.frag lays it out (albedo and rho; normal and shininess; position
 * and 1; k_a, k_d, k_s and coverage), zero for a miss. The materials are the
 * scene's own: a pass's material overrides do not reach the hits. With
 * params.block (choose_in_blocks) the outputs hold a texel a block, and a
 * traced miss has position w 1 too. */
static bool run_trace(lm_renderer *r, const lm_cpu_pass *cp, lm_error *err) {
  const lm_cpu_image *ro = cpu_input(cp, "rays_o"), *rd = cpu_input(cp, "rays_d");
  int b = cpu_param_int(cp, "block", 1);
  bool sized = ro && cp->output_count == 4 && b >= 1 && b <= 16 &&
               cp->outputs[0].width == (ro->width + b - 1) / b && cp->outputs[0].height == (ro->height + b - 1) / b;
  if (!ro || !rd || !sized || rd->width != ro->width || rd->height != ro->height) {
    lm_error_set(err, "function 'trace' takes inputs rays_o and rays_d and 4 outputs of their size, or of their "
                      "size / params.block (1..16) rounded up (hit colour, normal, position, material)");
    return false;
  }
  const lm_scene *s = r->desc.scene;
  uint64_t h = geometry_hash(r);
  if (!r->trace) {
    lm_scene_restore_geometry(r->desc.scene); /* a gpu_only scene's */
    r->trace = lm_trace_create(s, NULL);
  }
  else if (h != r->trace_hash) lm_trace_update(r->trace, s, NULL); /* nodes moved: refit (or rebuild) */
  r->trace_hash = h;
  int ow = cp->outputs[0].width, n = ow * cp->outputs[0].height, count = 0;
  lm_trace_ray *rays = lm_alloc(sizeof *rays * (size_t)n);
  int *pixel = lm_alloc(sizeof *pixel * (size_t)n); /* the output texel of each ray */
  int *chosen = b > 1 ? lm_alloc(sizeof *chosen * (size_t)n) : NULL;
  if (chosen) {
    unsigned frame = cpu_param_int(cp, "turn", 0) ? (unsigned)r->frame : 0u;
    choose_in_blocks(ro, b, ow, cp->outputs[0].height, frame, chosen);
  }
  for (int i = 0; i < n; i++) {
    int from = chosen ? chosen[i] : i;
    if (from < 0) continue;
    const float *o = ro->rgba + (size_t)from * 4, *d = rd->rgba + (size_t)from * 4;
    if (!(o[3] > 0.5f)) continue;
    rays[count] = (lm_trace_ray){{o[0], o[1], o[2]}, 0, {d[0], d[1], d[2]}, d[3] > 0 ? d[3] : INFINITY};
    pixel[count++] = i;
    if (chosen) cp->outputs[2].rgba[(size_t)i * 4 + 3] = 1; /* traced, hit or miss */
  }
  lm_trace_hit *hits = lm_alloc(sizeof *hits * (size_t)(count ? count : 1));
  lm_trace_rays(r->trace, rays, hits, count, 0);
  for (int k = 0; k < count; k++) {
    if (hits[k].tri < 0) continue;
    lm_trace_surface sf;
    lm_trace_surface_at(r->trace, &rays[k], &hits[k], &sf);
    const lm_material *m = lm_scene_node_material(s, &s->nodes[sf.node]);
    float *clr = cp->outputs[0].rgba + (size_t)pixel[k] * 4, *nrm = cp->outputs[1].rgba + (size_t)pixel[k] * 4;
    float *pos = cp->outputs[2].rgba + (size_t)pixel[k] * 4, *mat = cp->outputs[3].rgba + (size_t)pixel[k] * 4;
    hit_albedo(s, m, sf.uv, clr);
    clr[3] = m->rho;
    memcpy(nrm, sf.normal, sizeof sf.normal);
    nrm[3] = m->shininess > 0 ? m->shininess : 0;
    memcpy(pos, sf.position, sizeof sf.position);
    pos[3] = 1;
    mat[0] = m->ka, mat[1] = m->kd, mat[2] = m->ks, mat[3] = 1;
  }
  free(rays), free(pixel), free(hits), free(chosen);
  return true;
}

static bool run_cpu(void *user, const lm_cpu_pass *cp, lm_error *err) {
  if (!strcmp(cp->desc->shader, "trace")) return run_trace(user, cp, err);
  lm_error_set(err, "no CPU function '%s' (the engine has: trace)", cp->desc->shader);
  return false;
}

void lm_renderer_set_view(lm_renderer *r, int camera, int width, int height) {
  lm_renderer_set_camera(r, camera);
  lm_renderer_resize(r, width, height);
  r->frame = r->redrawn = 0; /* a new view has no previous frame to reproject from */
}

lm_scene_draw_stats lm_renderer_draw_stats(const lm_renderer *r) { return r->stats; }
lm_scene_draw_stats lm_renderer_shadow_draw_stats(const lm_renderer *r) { return r->shadow_stats; }

enum { METER_SIDE = 16, METER_SAMPLES = 8 }; /* exposure_meter.frag's SIDE and SAMPLES */

/* lm_renderer_desc.exposure fixes the pre-exposure: no meter. */
static bool fixed_exposure(const lm_renderer *r) { return r->desc.exposure > 0 && isfinite(r->desc.exposure); }

/* The target the exposure meter reads: the one the script metered
 * (meter(t)), or else what it presented when that is radiance; -1: none
 * (display values alone, or a fixed exposure). */
static int meter_source(const lm_renderer *r, const lm_pipeline *p, int presented) {
  if (fixed_exposure(r)) return -1;
  return lm_pipeline_metered(p) >= 0 ? lm_pipeline_metered(p) : lm_pipeline_present_display(p) ? -1 : presented;
}

/* The engine's last stage: sanitize and encode what the script presented, in
 * the pass that wrote it where that pass allows it (fold_output), else a pass.
 * out[0], out[1] get the sRGB and linear outputs (-1: none). */
static bool add_output_stage(lm_renderer *r, lm_graph *g, lm_pipeline *p, int presented, int out[2],
                             lm_error *err) {
  out[0] = lm_graph_add_target(g, &(lm_target_desc){.name = "output.srgb", .format = LM_FORMAT_RGBA8}, err);
  out[1] = -1;
  if (r->desc.linear_output)
    out[1] = lm_graph_add_target(g, &(lm_target_desc){.name = "output.linear",
                                                      .format = LM_FORMAT_RGBA32F}, err);
  if (out[0] < 0 || (r->desc.linear_output && out[1] < 0)) return false;
  lm_pass_input input = {"src", presented};
  static const char *const defines[2][2] = {{"", "DISPLAY"}, {"LINEAR_OUTPUT", "LINEAR_OUTPUT;DISPLAY"}};
  const char *mode = defines[r->desc.linear_output][lm_pipeline_present_display(p)];
  int count = r->desc.linear_output ? 2 : 1;
  /* In the pass that wrote the image where it allows it (hdr.tonemap): a full-size image fewer written
   * and read. Not where the meter reads that image, nor where the viewer inspects every target. */
  char folded[64];
  snprintf(folded, sizeof folded, "OUTPUT_STAGE%s%s", mode[0] ? ";" : "", mode);
  if (meter_source(r, p, presented) != presented && r->sharing &&
      lm_graph_fold_output(g, presented, out, count, folded) >= 0)
  {
    lm_graph_mark_output(g, out[0]);
    lm_graph_mark_output(g, out[1]);
    return true;
  }
  /* A pass of its own reads an output-sized image by its texels (OUTPUT_SIZED): the same values, and a
   * filtered read costs llvmpipe four fetches (office at 640x480: 8.0 -> 6.5 ms). */
  char alone[64];
  bool sized = lm_graph_target_output_sized(g, presented);
  snprintf(alone, sizeof alone, "%s%s%s", mode, mode[0] && sized ? ";" : "", sized ? "OUTPUT_SIZED" : "");
  lm_pass_desc d = {.kind = LM_PASS_FULLSCREEN, .name = "output", .where = lm_pipeline_present_where(p),
                    .shader = "output.frag", .defines = alone, .inputs = &input, .input_count = 1, .outputs = out,
                    .output_count = count, .depth = -1};
  if (lm_graph_add_pass(g, &d, err) < 0) return false;
  lm_graph_mark_output(g, out[0]);
  if (out[1] >= 0) lm_graph_mark_output(g, out[1]);
  return true;
}

/* The exposure meter (shaders/exposure_meter.frag) over the image the script
 * metered (meter(t)), or else what it presented when that is radiance;
 * *meter gets its target (-1: none, display values alone). */
static bool add_meter_stage(const lm_renderer *r, lm_graph *g, lm_pipeline *p, int presented, int *meter,
                            lm_error *err) {
  int src = meter_source(r, p, presented);
  *meter = -1;
  if (src < 0) return true;
  *meter = lm_graph_add_target(g, &(lm_target_desc){.name = "exposure.meter", .format = LM_FORMAT_RGBA32F,
                                                    .width = METER_SIDE, .height = METER_SIDE}, err);
  if (*meter < 0) return false;
  char defines[64];
  snprintf(defines, sizeof defines, "SIDE=%d;SAMPLES=%d", METER_SIDE, METER_SAMPLES);
  lm_pass_input input = {"src", src};
  lm_pass_desc d = {.kind = LM_PASS_FULLSCREEN, .name = "exposure.meter", .where = lm_pipeline_present_where(p),
                    .shader = "exposure_meter.frag", .defines = defines, .inputs = &input, .input_count = 1,
                    .outputs = meter, .output_count = 1, .depth = -1};
  if (lm_graph_add_pass(g, &d, err) < 0) return false;
  lm_graph_mark_output(g, *meter);
  return true;
}

/* A hash of the scene's light: its lights' records (colour, power,
 * position, direction, cones, falloff) and its materials' emission. A
 * change restarts the GI histories (still_frames("light"), temporal.lua),
 * where a running mean would keep the old light. */
static uint64_t light_hash(const lm_scene *s) {
  lm_light_data lights[MAX_LIGHTS];
  int n = lm_scene_light_data(s, lights, MAX_LIGHTS);
  uint64_t h = lm_hash(lights, sizeof *lights * (size_t)n, lm_hash(&n, sizeof n, 0));
  for (int i = 0; i < s->material_count; i++)
    h = lm_hash(s->material_pbr[i].emissive, sizeof s->material_pbr[i].emissive, h);
  return h;
}

/* A hash of what a frame draws besides its script's settings and the
 * camera: the pipeline, the scene's casters and materials (caster_hash, the
 * nodes' transforms and pose with them), its light (light_hash) and the
 * shaders' generation. What a light's view (shadow tiles, RSM) sees depends
 * on nothing else. */
static uint64_t scene_hash(const lm_pipeline *p, uint64_t casters, uint64_t light) {
  unsigned shaders = lm_programs_generation();
  uint64_t h = lm_hash(&p, sizeof p, casters);
  h = lm_hash(&light, sizeof light, h);
  return lm_hash(&shaders, sizeof shaders, h);
}

/* The scene's hash with the camera and the output size: all a frame draws
 * besides its script's settings (not the time: a GI pass's pattern turns
 * each frame, but a still world's converged result stays). */
static uint64_t world_hash(uint64_t scene, const lm_frame_data *frame) {
  uint64_t h = lm_hash(frame->view_proj, sizeof frame->view_proj, scene);
  h = lm_hash(frame->camera_pos, sizeof frame->camera_pos, h);
  h = lm_hash(frame->clip, sizeof frame->clip, h);
  return lm_hash(frame->output_size, sizeof frame->output_size, h);
}

/* Records (OnRender) and compiles one frame of pipeline p into g; out gets
 * the sRGB and linear outputs and the exposure meter (-1: none). */
static bool record(lm_renderer *r, lm_graph *g, lm_pipeline *p, int out[3], lm_error *err) {
  if (!lm_scene_camera_check(r->desc.scene, r->desc.camera, err)) return false;
  lm_graph_begin(g, r->desc.width, r->desc.height);
  lm_frame_data *frame = &r->camera;
  lm_scene_frame_data(r->desc.scene, r->desc.camera, r->desc.width, r->desc.height, frame);
  /* For the next plan: lm_shadow_settings.last_range and last_depths, none for a new view (frame 0),
   * and last_layout, kept across views as the tile cache is. */
  float range[2] = {r->shadows.range[0], r->shadows.range[1]}, (*depths)[2] = r->shadows.depths;
  lm_shadow_layout layout = r->shadows.layout;
  r->shadows.depths = NULL, r->shadows.layout = (lm_shadow_layout){0};
  lm_shadow_plan_free(&r->shadows);
  r->shadows.layout = layout;
  if (r->frame > 0) {
    memcpy(r->shadows.range, range, sizeof range);
    r->shadows.depths = depths;
  } else
    free(depths);
  /* Deformed meshes' new poses, before anything hashes or draws them (the
   * renderer alone calls lm_scene_upload_deformed: it clears their marks). */
  const lm_scene *s = r->desc.scene;
  r->deforms = lm_grow(r->deforms, &r->deform_cap, s->mesh_count, sizeof *r->deforms);
  r->deform_count = s->mesh_count;
  for (int i = 0; i < s->mesh_count; i++) r->deforms[i] += s->meshes[i].dirty;
  /* The mesh nodes that moved or deformed since the last frame (none on a first one). */
  r->dynamic = lm_grow(r->dynamic, &r->dynamic_cap, s->node_count, sizeof *r->dynamic);
  r->any_dynamic = false;
  bool known = r->frame > 0 && r->prev_world_count == s->node_count;
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    bool mesh = n->mesh >= 0 && n->mesh < s->mesh_count;
    r->dynamic[i] = mesh && known &&
                    (s->meshes[n->mesh].dirty || memcmp(n->world, r->prev_world + (size_t)i * 16, sizeof n->world));
    r->any_dynamic |= r->dynamic[i];
  }
  r->pose += lm_scene_upload_deformed(r->desc.scene) > 0;
  r->casters_hash = material_hash(s); /* once a frame: the world hash and the tile keys read it */
  uint64_t casters = caster_hash(r), light = light_hash(s);
  uint64_t scene = scene_hash(p, casters, light), world = world_hash(scene, frame);
  r->still = r->frame > 0 && world == r->world ? r->still + 1 : 0;
  r->scene_still = r->frame > 0 && scene == r->scene ? r->scene_still + 1 : 0;
  r->light_still = r->frame > 0 && light == r->light ? r->light_still + 1 : 0;
  r->world = world;
  r->scene = scene;
  r->light = light;
  lm_pipeline_set_scene(p, r->desc.scene, frame, &r->shadows,
                        (lm_still_frames){.world = r->still, .scene = r->scene_still, .light = r->light_still});
  uint64_t front = lm_hash(&light, sizeof light, casters);
  if (!r->front_known || front != r->front_key) {
    double t = lm_now_ms();
    r->front_lit = lm_shadow_front_lit(s, &r->front_casters);
    lm_debug("lights whose shadow tiles hold no back face: 0x%x of %d (%.1f ms)", r->front_lit, s->light_count,
             lm_now_ms() - t);
  }
  r->front_key = front, r->front_known = true;
  lm_pipeline_set_front_lit(p, r->front_lit);
  double t0 = lm_cpu_ms();
  int presented = -1;
  if (!lm_pipeline_record(p, g, &presented, err)) return false;
  r->script_peak = lm_pipeline_light_peak(p);
  r->keep_exposure = lm_pipeline_keeps_exposure(p);
  double t1 = lm_cpu_ms();
  if (!add_output_stage(r, g, p, presented, out, err) || !add_meter_stage(r, g, p, presented, &out[2], err) ||
      !lm_graph_compile(g, err))
    return false;
  r->record_ms = t1 - t0;
  r->compile_ms = lm_cpu_ms() - t1;
  return true;
}

/* Keeps each node's world transform for the next frame's velocities (lm_scene_draw_desc.prev_world). */
static void remember_world(lm_renderer *r) {
  const lm_scene *s = r->desc.scene;
  r->prev_world = lm_grow(r->prev_world, &r->prev_world_cap, s->node_count, 16 * sizeof(float));
  r->prev_world_count = s->node_count;
  for (int i = 0; i < s->node_count; i++) memcpy(r->prev_world + (size_t)i * 16, s->nodes[i].world, 16 * sizeof(float));
}

/* The brightest light the frame may show: a light's peak radiance on a
 * white surface facing it (a light of inverse-square falloff at the
 * camera's distance, no nearer than the near plane), emission of the scene
 * or light the script adds (ambient, background, sky: lm_pipeline_light_peak). */
static float light_peak(const lm_scene *s, const lm_frame_data *f, const lm_light_data *lights, int n,
                        float script_peak) {
  float peak = isfinite(script_peak) ? fmaxf(script_peak, 0) : 0;
  for (int i = 0; i < n; i++) {
    const lm_light_data *l = &lights[i];
    float c = fmaxf(l->color[0], fmaxf(l->color[1], l->color[2]));
    int falloff = (int)(l->params[1] + 0.5f);
    if ((int)(l->position[3] + 0.5f) != LM_LIGHT_DIRECTIONAL && (falloff == 2 || falloff == 3)) {
      float d2 = 0;
      for (int k = 0; k < 3; k++) d2 += (l->position[k] - f->camera_pos[k]) * (l->position[k] - f->camera_pos[k]);
      c /= fmaxf(d2, f->clip[0] * f->clip[0]);
    }
    if (isfinite(c)) peak = fmaxf(peak, c);
  }
  for (int i = 0; i < s->material_count; i++)
    for (int k = 0; k < 3; k++)
      if (isfinite(s->material_pbr[i].emissive[k])) peak = fmaxf(peak, s->material_pbr[i].emissive[k]);
  return peak;
}

/* The power of two that brings radiance x to about 1; 1 while x lies within
 * 1/16 .. 16 (most scenes, whose images it then leaves bit for bit) or is
 * no light at all. A power of two scales exactly. */
static float exposure_for(float x) {
  if (!(x > 0) || (x >= 1.0f / 16 && x <= 16)) return 1;
  return ldexpf(1, (int)lroundf(fminf(fmaxf(-log2f(x), -64), 64)));
}

/* The largest power of two E at most `ceiling` (itself a bound on E). */
static float power_at_most(float ceiling) {
  return ldexpf(1, (int)floorf(fminf(fmaxf(log2f(ceiling), -64), 64)));
}

static int compare_floats(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* Collects the exposure meter started last (r->meter.valid: it saw light
 * or an overflow), as radiance: its key, the median of its
 * blocks' brightest pixels among the blocks that are lit, and the brightest
 * (at least what overflowed, where a pixel did). */
static void read_meter(lm_renderer *r) {
  float texels[METER_SIDE * METER_SIDE * 4], lit[METER_SIDE * METER_SIDE];
  float metered = r->meter_exposure;
  r->meter_exposure = 0;
  r->meter.valid = false;
  if (!lm_readback_collect(&r->meter_read, texels)) return;
  int count = 0;
  float brightest = 0, over = 0;
  for (int i = 0; i < METER_SIDE * METER_SIDE; i++) {
    float m = texels[4 * i] / metered;
    over += texels[4 * i + 1];
    if (!(m > 0) || !isfinite(m)) continue;
    lit[count++] = m;
    brightest = fmaxf(brightest, m);
  }
  if (over > 0) brightest = fmaxf(brightest, 65504 / metered);
  if (count == 0 && !(over > 0)) return; /* nothing lit in view */
  qsort(lit, (size_t)count, sizeof *lit, compare_floats);
  r->meter = (struct meter){true, count ? lit[count / 2] : brightest, brightest};
}

/* The frame's pre-exposure E (common.glsl's exposed()), a power of two, so
 * that half floats (11 bits from 6e-5 to 65504) hold the frame's light at
 * any level. Production engines pre-expose with the last frame's adapted
 * exposure; so does this one, from the last frame's exposure meter
 * (exposure_meter.frag, read back without a stall; read_meter): its key is
 * kept within 2^-8 .. 2^8 after exposure, and when it leaves that band E
 * brings it back to about 1 (exposure_for: hysteresis, no pumping while it
 * drifts). Two ceilings keep half floats from overflowing before the next
 * meter sees it: the brightest pixel metered stays under 2^13 (2^12 when E
 * is chosen anew) and the brightest light the frame may show (r->peak,
 * light_peak) under 2^15 (2^14), below 65504; a metered overflow brings
 * the metered image down 16-fold. A frame with no meter behind it (a view's
 * first, or one presenting display values alone) takes E from the lights
 * (light_peak to about 1, as bright as any pixel they light at the camera's
 * distance), which a bright light that lights nothing in view makes far too
 * dark: lm_renderer_frame then draws a view's first frame again. */
static float frame_exposure(const lm_renderer *r) {
  float guess = exposure_for(r->peak), e = r->exposure > 0 ? r->exposure : guess;
  const struct meter *m = &r->meter;
  if (!m->valid) return guess;
  if (m->key * e >= 0x1p-8f && m->key * e <= 0x1p8f && m->brightest * e <= 0x1p13f && r->peak * e <= 0x1p15f)
    return e;
  e = exposure_for(m->key);
  if (m->brightest > 0) e = fminf(e, power_at_most(0x1p12f / m->brightest));
  if (r->peak > 0) e = fminf(e, power_at_most(0x1p14f / r->peak));
  return e;
}

/* Runs what record() compiled into g (the camera and shadow plan it made). */
static bool execute(lm_renderer *r, lm_graph *g, int meter, lm_error *err) {
  lm_frame_data *frame = &r->camera;
  r->stats = r->shadow_stats = (lm_scene_draw_stats){0};
  r->executions++;
  for (int i = 0; i < VIEW_PASSES; i++) r->tiles[i].in_place = false;
  memcpy(frame->prev_view_proj, r->frame ? r->prev_view_proj : frame->view_proj, sizeof frame->prev_view_proj);
  memcpy(r->prev_view_proj, frame->view_proj, sizeof r->prev_view_proj);
  /* A first frame (after a cut, or another scene) has no previous transforms: nothing moved. */
  if (r->frame == 0 || r->prev_world_count != r->desc.scene->node_count) remember_world(r);
  frame->time[1] = (float)(r->frame++ - r->redrawn);
  lm_light_data lights[MAX_LIGHTS];
  int n = lm_scene_light_data(r->desc.scene, lights, MAX_LIGHTS);
  frame->counts[0] = n;
  r->peak = light_peak(r->desc.scene, frame, lights, n, r->script_peak);
  if (r->meter_exposure > 0) read_meter(r); /* else a view's first frame read it at once */
  if (r->frame < 2) r->meter.valid = false; /* a view's first frame: the meter saw another */
  float e = fixed_exposure(r)                     ? r->desc.exposure
            : r->keep_exposure && r->exposure > 0 ? r->exposure /* results kept under it (a settled frame) */
                                                  : frame_exposure(r);
  if (r->meter.valid) r->key = r->meter.key;
  r->meter.valid = false;
  frame->exposure[0] = e, frame->exposure[1] = 1 / e;
  frame->exposure[2] = r->frame > 1 && r->exposure > 0 ? e / r->exposure : 1;
  /* The key pre-exposed: a history's confidence judges light relative to it (temporal.glsl), the same
   * at any light level, where E alone (a power of two, held within a band) leaves the key anywhere in
   * 2^-8 .. 2^8. None metered (a fixed exposure, a view's first frames): E stands for it. */
  frame->exposure[3] = r->key > 0 && isfinite(r->key * e) ? fmaxf(r->key * e, 0x1p-24f) : 1;
  r->exposure = e;
  for (int i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) lights[i].color[c] *= e;
  lm_frame_upload(frame, lights, n);
  lm_uniform_upload(1, lights, sizeof *lights * (size_t)n, sizeof *lights * LM_LIGHT_SET_MAX);
  lm_light_grid_build(&r->light_grid, frame, lights, n, !r->desc.no_light_culling);
  lm_storage_upload(4, r->light_grid.data, r->light_grid.count * sizeof *r->light_grid.data);
  lm_shadow_plan_upload(r->shadows.view_count > 0 ? &r->shadows : NULL, n);
  r->fit_ms = 0;
  lm_graph_exec_desc x = {.clock = r->clock, .draw_scene = draw_scene, .fit_views = fit_views,
                          .keeps_views = keeps_views, .run_cpu = run_cpu,
                          .scene_owns_uniform = lm_scene_owns_uniform, .user = r,
                          .check_finite = r->desc.check_finite};
  bool ok = lm_graph_execute(g, &x, err);
  if (ok && meter >= 0) { /* read while the next frame records */
    lm_graph_target_info t = lm_graph_target(g, meter);
    if (t.texture.id && t.width == METER_SIDE && t.height == METER_SIDE) {
      lm_readback_start(&r->meter_read, t.texture, METER_SIDE, METER_SIDE);
      r->meter_exposure = e;
      if (r->frame == 1) read_meter(r); /* at once: lm_renderer_frame may draw it again */
    }
  }
  remember_world(r);
  return ok;
}

bool lm_renderer_frame(lm_renderer *r, lm_error *err) {
  for (int again = 0;; again++) {
    int out[3];
    if (!record(r, r->graph, r->desc.pipeline, out, err)) return false;
    r->output_srgb = out[0], r->output_linear = out[1];
    if (!execute(r, r->graph, out[2], err)) return false;
    /* A view's first frame, exposed by its lights alone, where its meter
     * finds the exposure far off (a bright light that lights nothing in
     * view: frame_exposure), is drawn again as the second frame would be,
     * so a capture of one frame loses no more to precision than a longer one;
     * it keeps its number (redrawn). */
    if (again || r->frame != 1 || !r->meter.valid || frame_exposure(r) == r->exposure) return true;
    r->redrawn = 1;
  }
}

bool lm_renderer_swap_pipeline(lm_renderer *r, lm_pipeline *p, lm_error *err) {
  lm_graph *g = lm_graph_create();
  lm_graph_set_sharing(g, r->sharing);
  int out[3];
  bool ok = record(r, g, p, out, err);
  if (ok) {
    int kept = lm_graph_take_persistent(g, r->graph);
    lm_debug("new pipeline: %d persistent target(s) kept their textures", kept);
    ok = execute(r, g, out[2], err);
    if (!ok) lm_graph_take_persistent(r->graph, g); /* give the history back */
  }
  if (!ok) {
    lm_graph_destroy(g);
    return false;
  }
  lm_graph_destroy(r->graph);
  r->graph = g;
  r->desc.pipeline = p;
  r->output_srgb = out[0], r->output_linear = out[1];
  return true;
}

void lm_renderer_resize(lm_renderer *r, int width, int height) {
  r->desc.width = width > 0 ? width : 1;
  r->desc.height = height > 0 ? height : 1;
}

void lm_renderer_set_camera(lm_renderer *r, int camera) { r->desc.camera = camera; }

void lm_renderer_set_sharing(lm_renderer *r, bool on) {
  r->sharing = on;
  lm_graph_set_sharing(r->graph, on);
}

void lm_renderer_set_linear_output(lm_renderer *r, bool on) { r->desc.linear_output = on; }

bool lm_renderer_output(lm_renderer *r, lm_texture *tex, int *width, int *height) {
  if (r->output_srgb < 0 || r->output_srgb >= lm_graph_target_count(r->graph)) return false;
  lm_graph_target_info t = lm_graph_target(r->graph, r->output_srgb);
  if (!t.texture.id) return false;
  *tex = t.texture;
  *width = t.width, *height = t.height;
  return true;
}

bool lm_renderer_read(lm_renderer *r, bool linear, void *rgb, lm_error *err) {
  int id = linear ? r->output_linear : r->output_srgb;
  if (id < 0) {
    lm_error_set(err, "no %s output was kept for this frame", linear ? "linear" : "sRGB");
    return false;
  }
  lm_graph_target_info t = lm_graph_target(r->graph, id);
  size_t texel = linear ? 16 : 4, px = (size_t)t.width * t.height;
  unsigned char *rgba = lm_alloc(px * texel);
  lm_texture_read(t.texture, t.width, t.height, linear, rgba);
  size_t comp = linear ? 4 : 1;
  for (size_t i = 0; i < px; i++) /* drop alpha */
    memcpy((unsigned char *)rgb + i * 3 * comp, rgba + i * 4 * comp, 3 * comp);
  free(rgba);
  return true;
}
