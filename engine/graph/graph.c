/* Frame graph recording and compiling: everything here is plain data, so
 * validation, culling and the texture plan are testable without GL. */
#include "graph/graph_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lm_target_size(const lm_target_desc *d, int out_w, int out_h, int *w, int *h) {
  if (d->width > 0 && d->height > 0) {
    *w = d->width;
    *h = d->height;
    return;
  }
  double s = d->scale > 0 && isfinite(d->scale) ? d->scale : 1.0;
  double fw = floor(out_w * s), fh = floor(out_h * s);
  *w = fw < 1 ? 1 : fw > 1e6 ? 1000000 : (int)fw;
  *h = fh < 1 ? 1 : fh > 1e6 ? 1000000 : (int)fh;
}

const char *lm_pass_kind_name(lm_pass_kind k) {
  return k == LM_PASS_SCENE ? "scene" : k == LM_PASS_CPU ? "cpu" : k == LM_PASS_POINTS ? "points" : "fullscreen";
}

lm_graph *lm_graph_create(void) { return lm_alloc(sizeof(lm_graph)); }

/* Frees each array the graph owns, one by one: destroy functions read alike. */
void lm_graph_destroy(lm_graph *g) {
  if (!g) return;
  for (int i = 0; i < g->persistent_count; i++) {
    lm_texture_destroy(&g->targets[i].texture);
    free((char *)g->targets[i].desc.name);
  }
  for (int i = 0; i < g->pool_count; i++) lm_texture_destroy(&g->pool[i].texture);
  for (int i = 0; i < g->timer_count; i++) lm_timer_destroy(&g->timers[i]);
  lm_arena_reset(&g->arena);
  free(g->targets);
  free(g->passes);
  free(g->outputs);
  free(g->slots);
  free(g->pool);
  free(g->timers);
  free(g);
}

void lm_graph_begin(lm_graph *g, int width, int height) {
  g->width = width > 0 ? width : 1;
  g->height = height > 0 ? height : 1;
  lm_arena_reset(&g->arena);
  g->target_count = g->persistent_count; /* persistent targets come first */
  g->pass_count = 0;
  g->output_count = 0;
  g->slot_count = 0;
  g->compiled = false;
}

void lm_graph_output_size(const lm_graph *g, int *width, int *height) {
  *width = g->width;
  *height = g->height;
}

bool lm_graph_target_output_sized(const lm_graph *g, int target) {
  if (target < 0 || target >= g->target_count) return false;
  int w, h;
  lm_target_size(&g->targets[target].desc, g->width, g->height, &w, &h);
  return w == g->width && h == g->height;
}

int lm_graph_find_target(const lm_graph *g, const char *name) {
  for (int i = 0; i < g->target_count; i++)
    if (!strcmp(g->targets[i].desc.name, name)) return i;
  return -1;
}

int lm_graph_add_target(lm_graph *g, const lm_target_desc *d, lm_error *err) {
  if (!d->name || !d->name[0]) {
    lm_error_set(err, "a target needs a name");
    return -1;
  }
  if (d->format <= LM_FORMAT_NONE || d->format >= LM_FORMAT_COUNT) {
    lm_error_set(err, "target '%s': no format (one of %s)", d->name, lm_format_list());
    return -1;
  }
  if ((d->width > 0) != (d->height > 0) || d->width < 0 || d->height < 0 || d->scale < 0 ||
      !isfinite(d->scale)) {
    lm_error_set(err, "target '%s': give a positive size {w, h} or a positive scale", d->name);
    return -1;
  }
  if (lm_graph_find_target(g, d->name) >= 0) {
    lm_error_set(err, "target '%s' is declared twice", d->name);
    return -1;
  }
  if (d->persistent && g->target_count != g->persistent_count) {
    lm_error_set(err, "target '%s': persistent targets are declared before any frame target "
                 "(in OnCreate)", d->name);
    return -1;
  }
  graph_target *t = LM_PUSH(g->targets, g->target_count, g->target_cap);
  *t = (graph_target){.desc = *d, .slot = -1};
  t->desc.name = d->persistent ? lm_strdup(d->name) : lm_arena_strdup(&g->arena, d->name);
  if (d->persistent) g->persistent_count++;
  return g->target_count - 1;
}

static const char *arena_str(lm_graph *g, const char *s) {
  return s ? lm_arena_strdup(&g->arena, s) : NULL;
}

int lm_graph_add_pass(lm_graph *g, const lm_pass_desc *d, lm_error *err) {
  const char *name = d->name ? d->name : "?";
  const char *where = d->where ? d->where : "?";
  if (!d->shader || !d->shader[0]) {
    lm_error_set(err, "%s: pass '%s': no %s", where, name,
                 d->kind == LM_PASS_SCENE ? "technique" : d->kind == LM_PASS_CPU ? "function" : "shader");
    return -1;
  }
  if (d->kind == LM_PASS_POINTS && (!d->vertex || !d->vertex[0])) {
    lm_error_set(err, "%s: pass '%s': no vertex shader", where, name);
    return -1;
  }
  if (d->kind == LM_PASS_POINTS && (d->count < 0 || d->count > LM_MAX_POINTS)) {
    lm_error_set(err, "%s: pass '%s': count must be a whole number in 0 .. %d (got %d)", where, name,
                 LM_MAX_POINTS, d->count);
    return -1;
  }
  if (d->output_count > LM_MAX_COLOR_OUTPUTS || d->input_count > LM_MAX_PASS_INPUTS ||
      d->param_count > LM_MAX_PASS_PARAMS) {
    lm_error_set(err, "%s: pass '%s': too many outputs, inputs or parameters (at most %d, %d, %d)",
                 where, name, LM_MAX_COLOR_OUTPUTS, LM_MAX_PASS_INPUTS, LM_MAX_PASS_PARAMS);
    return -1;
  }
  for (int i = 0; i < d->output_count; i++) {
    if (d->outputs[i] < 0 || d->outputs[i] >= g->target_count) {
      lm_error_set(err, "%s: pass '%s': output %d is not a target of this frame", where, name, i + 1);
      return -1;
    }
  }
  for (int i = 0; i < d->input_count; i++) {
    if (d->inputs[i].target < 0 || d->inputs[i].target >= g->target_count) {
      lm_error_set(err, "%s: pass '%s': input '%s' is not a target of this frame", where, name,
                   d->inputs[i].name);
      return -1;
    }
  }
  if (d->view_count < 0 || (d->view_count > 0 && (d->kind != LM_PASS_SCENE || !d->views))) {
    lm_error_set(err, "%s: pass '%s': only scene passes take views", where, name);
    return -1;
  }
  if (d->fits_views && (d->view_count == 0 || d->fit_target < 0 || d->fit_target >= g->target_count)) {
    lm_error_set(err, "%s: pass '%s': fits views to a target it does not have", where, name);
    return -1;
  }
  if (d->depth >= g->target_count) {
    lm_error_set(err, "%s: pass '%s': depth is not a target of this frame", where, name);
    return -1;
  }
  graph_pass *p = LM_PUSH(g->passes, g->pass_count, g->pass_cap);
  *p = (graph_pass){.desc = *d, .ms = -1};
  lm_pass_desc *c = &p->desc;
  c->name = arena_str(g, name);
  c->where = arena_str(g, where);
  c->shader = arena_str(g, d->shader);
  c->vertex = arena_str(g, d->vertex);
  c->defines = arena_str(g, d->defines ? d->defines : "");
  lm_pass_input *in = lm_arena_alloc(&g->arena, sizeof *in * (size_t)(d->input_count + 1));
  for (int i = 0; i < d->input_count; i++)
    in[i] = (lm_pass_input){arena_str(g, d->inputs[i].name), d->inputs[i].target};
  c->inputs = in;
  lm_pass_param *pa = lm_arena_alloc(&g->arena, sizeof *pa * (size_t)(d->param_count + 1));
  for (int i = 0; i < d->param_count; i++) {
    pa[i] = d->params[i];
    pa[i].name = arena_str(g, d->params[i].name);
  }
  c->params = pa;
  if (d->view_count > 0) {
    lm_pass_view *views = lm_arena_alloc(&g->arena, sizeof *views * (size_t)d->view_count);
    memcpy(views, d->views, sizeof *views * (size_t)d->view_count);
    c->views = views;
  }
  lm_pass_material_param *mp = lm_arena_alloc(&g->arena, sizeof *mp * (size_t)(d->material_param_count + 1));
  for (int i = 0; i < d->material_param_count; i++) {
    mp[i] = d->material_params[i];
    mp[i].material = arena_str(g, d->material_params[i].material);
    mp[i].name = arena_str(g, d->material_params[i].name);
  }
  c->material_params = mp;
  int *out = lm_arena_alloc(&g->arena, sizeof *out * (size_t)(d->output_count + 1));
  memcpy(out, d->outputs, sizeof *out * (size_t)d->output_count);
  c->outputs = out;
  return g->pass_count - 1;
}

void lm_graph_mark_output(lm_graph *g, int target) {
  if (target >= 0 && target < g->target_count) *LM_PUSH(g->outputs, g->output_count, g->output_cap) = target;
}

int lm_graph_fold_output(lm_graph *g, int target, const int *outputs, int output_count, const char *defines) {
  if (target < 0 || target >= g->target_count || g->pass_count == 0 || output_count > LM_MAX_COLOR_OUTPUTS)
    return -1;
  const lm_target_desc *t = &g->targets[target].desc;
  bool output_sized = (t->scale == 0 || t->scale == 1) && !(t->width > 0 && t->height > 0);
  if (!output_sized || t->persistent || t->mips) return -1;
  for (int i = 0; i < g->output_count; i++)
    if (g->outputs[i] == target) return -1;
  graph_pass *p = &g->passes[g->pass_count - 1]; /* the last recorded: nothing after it reads its image */
  lm_pass_desc *d = &p->desc;
  if (d->kind != LM_PASS_FULLSCREEN || !d->fold_output || d->output_count != 1 || d->outputs[0] != target ||
      d->depth >= 0)
    return -1;
  for (int i = 0; i < d->input_count; i++)
    if (d->inputs[i].target == target) return -1;
  int *out = lm_arena_alloc(&g->arena, sizeof *out * (size_t)output_count);
  memcpy(out, outputs, sizeof *out * (size_t)output_count);
  d->outputs = out, d->output_count = output_count;
  size_t n = strlen(d->defines) + strlen(defines) + 2;
  char *joined = lm_arena_alloc(&g->arena, n);
  snprintf(joined, n, "%s%s%s", d->defines, d->defines[0] && defines[0] ? ";" : "", defines);
  d->defines = joined;
  return g->pass_count - 1;
}

static bool pass_writes(const lm_pass_desc *d, int t) {
  for (int i = 0; i < d->output_count; i++)
    if (d->outputs[i] == t) return true;
  return d->depth == t && t >= 0;
}

/* The last pass before `before` that writes t, or -1. */
static int last_writer(const lm_graph *g, int t, int before) {
  for (int i = before - 1; i >= 0; i--)
    if (pass_writes(&g->passes[i].desc, t)) return i;
  return -1;
}

static bool validate_pass(lm_graph *g, int pi, lm_error *err) {
  const lm_pass_desc *d = &g->passes[pi].desc;
  const char *where = d->where, *name = d->name;
  if (d->output_count == 0 && d->depth < 0) {
    lm_error_set(err, "%s: pass '%s' writes no target (give it out = target)", where, name);
    return false;
  }
  int w = -1, h = -1;
  for (int i = 0; i < d->output_count + 1; i++) {
    int t = i < d->output_count ? d->outputs[i] : d->depth;
    if (t < 0) continue;
    const graph_target *gt = &g->targets[t];
    bool depth_slot = i == d->output_count;
    if (lm_format_is_depth(gt->desc.format) != depth_slot) {
      lm_error_set(err, "%s: pass '%s': target '%s' (%s) cannot be a %s output", where, name,
                   gt->desc.name, lm_format_name(gt->desc.format), depth_slot ? "depth" : "colour");
      return false;
    }
    if (w >= 0 && (gt->width != w || gt->height != h)) {
      lm_error_set(err, "%s: pass '%s': its outputs differ in size (%dx%d and '%s' %dx%d)", where,
                   name, w, h, gt->desc.name, gt->width, gt->height);
      return false;
    }
    w = gt->width, h = gt->height;
  }
  if (d->blend && (d->kind != LM_PASS_SCENE || d->output_count != 1 || d->clear)) {
    lm_error_set(err, "%s: pass '%s': a blended pass is a scene pass with one output that does not clear", where,
                 name);
    return false;
  }
  if (d->kind != LM_PASS_SCENE && d->depth >= 0) {
    lm_error_set(err, "%s: pass '%s': %s passes take no depth target", where, name,
                 d->kind == LM_PASS_CPU ? "CPU" : d->kind == LM_PASS_POINTS ? "points" : "full-screen");
    return false;
  }
  if (d->fits_views && !g->targets[d->fit_target].desc.persistent && last_writer(g, d->fit_target, pi) < 0) {
    lm_error_set(err, "%s: pass '%s' fits its views to target '%s' that no pass writes before it", where, name,
                 g->targets[d->fit_target].desc.name);
    return false;
  }
  for (int i = 0; i < d->input_count; i++) {
    int t = d->inputs[i].target;
    const graph_target *gt = &g->targets[t];
    if (pass_writes(d, t)) {
      lm_error_set(err, "%s: pass '%s' reads and writes target '%s' (a feedback loop; write to "
                   "another target)", where, name, gt->desc.name);
      return false;
    }
    if (!gt->desc.persistent && last_writer(g, t, pi) < 0) {
      lm_error_set(err, "%s: pass '%s' reads target '%s' that no pass writes before it", where,
                   name, gt->desc.name);
      return false;
    }
  }
  return true;
}

/* Marks pass pi and everything it depends on as needed. */
static void keep(lm_graph *g, int pi, bool *needed) {
  if (pi < 0 || needed[pi]) return;
  needed[pi] = true;
  const lm_pass_desc *d = &g->passes[pi].desc;
  for (int i = 0; i < d->input_count; i++) keep(g, last_writer(g, d->inputs[i].target, pi), needed);
  if (d->fits_views) keep(g, last_writer(g, d->fit_target, pi), needed);
  /* A scene pass that does not clear draws over what an earlier pass left. */
  if (d->kind == LM_PASS_SCENE && !d->clear) {
    for (int i = 0; i < d->output_count; i++) keep(g, last_writer(g, d->outputs[i], pi), needed);
    if (d->depth >= 0) keep(g, last_writer(g, d->depth, pi), needed);
  }
}

static void touch(graph_target *t, int pi) {
  if (!t->used) t->first = pi;
  t->used = true;
  t->last = pi;
}

/* Does a scene pass with views that runs write t? Its tiles are cached in
 * place across frames (render.c's tile cache, lm_graph_target_info.alone). */
static bool holds_tiles(const lm_graph *g, int t) {
  for (int pi = 0; pi < g->pass_count; pi++) {
    const graph_pass *p = &g->passes[pi];
    if (!p->culled && p->desc.view_count > 0 && pass_writes(&p->desc, t)) return true;
  }
  return false;
}

/* Transient targets whose lifetimes do not overlap share a slot (texture),
 * except those that hold tiles: a texture of their own, which no target
 * before or after them in the frame writes, keeps last frame's tiles. */
static void plan_slots(lm_graph *g) {
  g->slot_count = 0;
  for (int pi = 0; pi < g->pass_count; pi++) {
    if (g->passes[pi].culled) continue;
    for (int t = g->persistent_count; t < g->target_count; t++) {
      graph_target *gt = &g->targets[t];
      if (!gt->used || gt->first != pi) continue;
      lm_texture_desc want = {gt->desc.format, gt->width, gt->height, gt->desc.mips};
      bool own = g->no_sharing || holds_tiles(g, t);
      int found = -1;
      for (int s = 0; s < g->slot_count && found < 0 && !own; s++)
        if (lm_texture_desc_equal(&g->slots[s].desc, &want) && g->slots[s].free_after < pi) found = s;
      if (found < 0) {
        graph_slot *s = LM_PUSH(g->slots, g->slot_count, g->slot_cap);
        s->desc = want;
        found = g->slot_count - 1;
      }
      g->slots[found].free_after = own ? g->pass_count : gt->last;
      gt->slot = found;
    }
  }
}

/* lm_graph_target_info.alone: one pass that runs writes the target, and it
 * is persistent or no other target holds its slot. */
static void mark_alone(lm_graph *g) {
  for (int t = 0; t < g->target_count; t++) {
    graph_target *gt = &g->targets[t];
    if (!gt->used) continue;
    int writers = 0;
    for (int pi = 0; pi < g->pass_count; pi++)
      if (!g->passes[pi].culled) writers += pass_writes(&g->passes[pi].desc, t);
    bool shared = false;
    for (int k = g->persistent_count; k < g->target_count && !shared && gt->slot >= 0; k++)
      shared = k != t && g->targets[k].used && g->targets[k].slot == gt->slot;
    gt->alone = writers == 1 && !shared;
  }
}

bool lm_graph_compile(lm_graph *g, lm_error *err) {
  for (int t = 0; t < g->target_count; t++) {
    graph_target *gt = &g->targets[t];
    lm_target_size(&gt->desc, g->width, g->height, &gt->width, &gt->height);
    gt->used = false;
    gt->slot = -1;
    gt->alone = false;
    gt->first = gt->last = -1;
  }
  for (int pi = 0; pi < g->pass_count; pi++)
    if (!validate_pass(g, pi, err)) return false;
  if (g->output_count == 0) {
    lm_error_set(err, "the frame presents nothing (call present(target) in OnRender)");
    return false;
  }
  bool *needed = lm_alloc(sizeof(bool) * (size_t)(g->pass_count + 1));
  for (int i = 0; i < g->output_count; i++) {
    int writer = last_writer(g, g->outputs[i], g->pass_count);
    if (writer < 0 && !g->targets[g->outputs[i]].desc.persistent) {
      lm_error_set(err, "target '%s' is presented but no pass writes it",
                   g->targets[g->outputs[i]].desc.name);
      free(needed);
      return false;
    }
    keep(g, writer, needed);
  }
  for (int pi = 0; pi < g->pass_count; pi++) {
    graph_pass *p = &g->passes[pi];
    p->culled = !needed[pi];
    p->ms = -1;
    if (p->culled) {
      lm_log(LM_LOG_INFO, "left out: pass '%s' (%s): nothing presented reads what it writes",
             p->desc.name, p->desc.where);
      continue;
    }
    for (int i = 0; i < p->desc.input_count; i++) touch(&g->targets[p->desc.inputs[i].target], pi);
    if (p->desc.fits_views) touch(&g->targets[p->desc.fit_target], pi);
    for (int i = 0; i < p->desc.output_count; i++) touch(&g->targets[p->desc.outputs[i]], pi);
    if (p->desc.depth >= 0) touch(&g->targets[p->desc.depth], pi);
  }
  free(needed);
  for (int t = 0; t < g->target_count; t++)
    if (!g->targets[t].used)
      lm_log(LM_LOG_DEBUG, "left out: target '%s' (no pass that runs uses it)", g->targets[t].desc.name);
  plan_slots(g);
  mark_alone(g);
  g->compiled = true;
  return true;
}

int lm_graph_pass_count(const lm_graph *g) { return g->pass_count; }

lm_graph_pass_info lm_graph_pass(const lm_graph *g, int i) {
  const graph_pass *p = &g->passes[i];
  int t = p->desc.output_count > 0 ? p->desc.outputs[0] : p->desc.depth;
  return (lm_graph_pass_info){p->desc.name, p->desc.where, p->desc.shader, p->desc.kind, p->culled,
                              p->ms, p->desc.fetches, t >= 0 ? g->targets[t].width : 0,
                              t >= 0 ? g->targets[t].height : 0, &p->desc};
}

int lm_graph_input_writer(const lm_graph *g, int i, int k) {
  return last_writer(g, g->passes[i].desc.inputs[k].target, i);
}

void lm_graph_pass_depths(const lm_graph *g, int *depth) {
  for (int i = 0; i < g->pass_count; i++) { /* writers come before readers: their depths are known */
    depth[i] = 0;
    for (int k = 0; k < g->passes[i].desc.input_count; k++) {
      int w = lm_graph_input_writer(g, i, k);
      if (w >= 0 && depth[w] + 1 > depth[i]) depth[i] = depth[w] + 1;
    }
  }
}

int lm_graph_target_count(const lm_graph *g) { return g->target_count; }

lm_graph_target_info lm_graph_target(const lm_graph *g, int i) {
  const graph_target *t = &g->targets[i];
  return (lm_graph_target_info){t->desc.name, t->desc.format, t->width, t->height,
                                t->desc.persistent, t->used, t->slot, t->alone, t->texture};
}

int lm_graph_slot_count(const lm_graph *g) { return g->slot_count; }

void lm_graph_set_sharing(lm_graph *g, bool on) { g->no_sharing = !on; }

static bool same_rule(const lm_target_desc *a, const lm_target_desc *b) {
  return !strcmp(a->name, b->name) && a->format == b->format && a->mips == b->mips &&
         a->width == b->width && a->height == b->height && a->scale == b->scale;
}

int lm_graph_take_persistent(lm_graph *to, lm_graph *from) {
  int moved = 0;
  for (int i = 0; i < to->persistent_count; i++) {
    graph_target *t = &to->targets[i];
    for (int k = 0; k < from->persistent_count && !t->texture.id; k++) {
      graph_target *f = &from->targets[k];
      if (!f->texture.id || !same_rule(&t->desc, &f->desc)) continue;
      t->texture = f->texture;
      t->alloc_w = f->alloc_w, t->alloc_h = f->alloc_h;
      f->texture = (lm_texture){0};
      moved++;
    }
  }
  return moved;
}
