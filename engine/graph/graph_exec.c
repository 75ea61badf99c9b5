/* Frame graph execution: textures from the pool, programs and their
 * bindings checked against the recording, each pass run and timed. */
#include "graph/graph_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { POOL_IDLE_FRAMES = 3 }; /* a pooled texture unused this long is freed */

static bool pool_take(lm_graph *g, const lm_texture_desc *want, const char *label, lm_texture *out,
                      lm_error *err) {
  for (int i = 0; i < g->pool_count; i++) {
    pool_texture *p = &g->pool[i];
    if (!p->taken && lm_texture_desc_equal(&p->desc, want)) {
      p->taken = true;
      *out = p->texture;
      return true;
    }
  }
  lm_texture tex;
  if (!lm_texture_create(&tex, want, label, err)) return false;
  pool_texture *p = LM_PUSH(g->pool, g->pool_count, g->pool_cap);
  *p = (pool_texture){*want, tex, 0, true};
  *out = tex;
  return true;
}

static void pool_end_frame(lm_graph *g) {
  for (int i = 0; i < g->pool_count;) {
    pool_texture *p = &g->pool[i];
    p->idle_frames = p->taken ? 0 : p->idle_frames + 1;
    p->taken = false;
    if (p->idle_frames > POOL_IDLE_FRAMES) {
      lm_texture_destroy(&p->texture);
      g->pool[i] = g->pool[--g->pool_count];
    } else {
      i++;
    }
  }
}

void lm_graph_pool_stats(const lm_graph *g, int *textures, double *bytes) {
  double b = 0;
  int n = g->pool_count;
  for (int i = 0; i < g->pool_count; i++)
    b += (double)g->pool[i].desc.width * g->pool[i].desc.height * lm_format_bytes(g->pool[i].desc.format);
  /* A persistent target no pass has used yet holds no texture. */
  for (int i = 0; i < g->persistent_count; i++)
    if (g->targets[i].texture.id) {
      b += (double)g->targets[i].width * g->targets[i].height * lm_format_bytes(g->targets[i].desc.format);
      n++;
    }
  *textures = n;
  *bytes = b;
}

static bool allocate(lm_graph *g, lm_error *err) {
  lm_texture *slot_tex = lm_alloc(sizeof *slot_tex * (size_t)(g->slot_count + 1));
  bool ok = true;
  for (int s = 0; s < g->slot_count && ok; s++) {
    const char *label = "transient target";
    for (int t = g->persistent_count; t < g->target_count; t++)
      if (g->targets[t].slot == s) {
        label = g->targets[t].desc.name; /* the first holder names it in errors */
        break;
      }
    ok = pool_take(g, &g->slots[s].desc, label, &slot_tex[s], err);
  }
  for (int t = 0; t < g->target_count && ok; t++) {
    graph_target *gt = &g->targets[t];
    if (!gt->desc.persistent) {
      gt->texture = gt->slot >= 0 ? slot_tex[gt->slot] : (lm_texture){0};
      continue;
    }
    /* Persistent textures are made once and remade only when the size changes. */
    if (!gt->used || (gt->texture.id && gt->alloc_w == gt->width && gt->alloc_h == gt->height))
      continue;
    lm_texture_destroy(&gt->texture);
    lm_texture_desc want = {gt->desc.format, gt->width, gt->height, gt->desc.mips};
    ok = lm_texture_create(&gt->texture, &want, gt->desc.name, err);
    if (ok) lm_texture_clear(gt->texture);
    gt->alloc_w = gt->width;
    gt->alloc_h = gt->height;
  }
  free(slot_tex);
  return ok;
}

static bool is_sampler(lm_uniform_type t) {
  return t == LM_UNIFORM_SAMPLER || t == LM_UNIFORM_SAMPLER_SHADOW;
}

static bool is_integer(lm_uniform_type t) {
  return t == LM_UNIFORM_INT || t == LM_UNIFORM_IVEC2 || t == LM_UNIFORM_IVEC3 || t == LM_UNIFORM_IVEC4;
}

/* Checks the recorded inputs and parameters against the program's uniforms. */
static bool check_bindings(const lm_graph *g, const lm_pass_desc *d, const lm_program *p,
                           const lm_graph_exec_desc *x, lm_error *err) {
  const char *where = d->where, *name = d->name;
  for (int i = 0; i < d->input_count; i++) {
    const lm_uniform *u = lm_program_uniform(p, d->inputs[i].name);
    const graph_target *t = &g->targets[d->inputs[i].target];
    if (!u || !is_sampler(u->type)) {
      lm_error_set(err, "%s: pass '%s': input '%s': %s declares no sampler of that name", where,
                   name, d->inputs[i].name, p->label);
      return false;
    }
    if (u->type == LM_UNIFORM_SAMPLER_SHADOW && !lm_format_is_depth(t->desc.format)) {
      lm_error_set(err, "%s: pass '%s': input '%s': a shadow sampler cannot take target '%s' (%s)",
                   where, name, d->inputs[i].name, t->desc.name, lm_format_name(t->desc.format));
      return false;
    }
  }
  for (int i = 0; i < p->uniform_count; i++) {
    const lm_uniform *u = &p->uniforms[i];
    if (!is_sampler(u->type) || u->location < 0) continue;
    if (d->kind == LM_PASS_SCENE && x->scene_owns_uniform && x->scene_owns_uniform(u->name)) continue;
    bool bound = false;
    for (int k = 0; k < d->input_count && !bound; k++) bound = !strcmp(d->inputs[k].name, u->name);
    if (!bound) {
      lm_error_set(err, "%s: pass '%s': %s samples '%s' but the pass gives no input of that name",
                   where, name, p->label, u->name);
      return false;
    }
  }
  for (int i = 0; i < d->param_count; i++) {
    const lm_pass_param *pa = &d->params[i];
    const lm_uniform *u = lm_program_uniform(p, pa->name);
    bool engine_owned = !strcmp(pa->name, "pass_view_proj") || !strcmp(pa->name, "pass_depth") ||
                        (d->kind == LM_PASS_SCENE && x->scene_owns_uniform && x->scene_owns_uniform(pa->name));
    if (!u || engine_owned) {
      lm_error_set(err, "%s: pass '%s': parameter '%s': %s %s", where, name, pa->name, p->label,
                   u ? "has this uniform set by the engine" : "declares no uniform of that name");
      return false;
    }
    int want = lm_uniform_type_components(u->type);
    bool type_ok = false;
    if (u->type == LM_UNIFORM_BOOL) {
      type_ok = pa->kind == LM_PARAM_BOOL;
    } else if (want > 0 && pa->kind == LM_PARAM_NUMBER && pa->count == want) {
      type_ok = true;
      for (int c = 0; c < pa->count && is_integer(u->type); c++)
        type_ok &= pa->v[c] == floor(pa->v[c]) && fabs(pa->v[c]) < 2147483648.0;
    }
    if (!type_ok) {
      lm_error_set(err, "%s: pass '%s': parameter '%s': the shader's uniform is a %s; the pass gives %s",
                   where, name, pa->name, lm_uniform_type_name(u->type),
                   pa->kind == LM_PARAM_BOOL ? "a boolean"
                   : pa->count == 1          ? "one number"
                                             : "a list of numbers");
      return false;
    }
  }
  if (d->output_count != p->output_count && d->output_count > 0) {
    lm_error_set(err, "%s: pass '%s': %s writes %d output%s but the pass gives %d target%s", where,
                 name, p->label, p->output_count, p->output_count == 1 ? "" : "s", d->output_count,
                 d->output_count == 1 ? "" : "s");
    return false;
  }
  return true;
}

static void apply_params(const lm_pass_desc *d, const lm_program *p) {
  for (int i = 0; i < d->param_count; i++) {
    const lm_pass_param *pa = &d->params[i];
    const lm_uniform *u = lm_program_uniform(p, pa->name);
    if (u->type == LM_UNIFORM_BOOL || is_integer(u->type)) {
      int v[4] = {0};
      for (int c = 0; c < pa->count && c < 4; c++) v[c] = (int)pa->v[c];
      lm_program_set_int(p, u, v);
    } else {
      float v[16];
      for (int c = 0; c < pa->count; c++) v[c] = (float)pa->v[c];
      lm_program_set(p, u, v);
    }
  }
}

static lm_program *pass_program(const lm_pass_desc *d, const char *extra, lm_error *err) {
  lm_program *p;
  if (d->kind == LM_PASS_SCENE) {
    char vert[256], frag[256], defines[1200];
    snprintf(vert, sizeof vert, "%s.vert", d->shader);
    snprintf(frag, sizeof frag, "%s.frag", d->shader);
    snprintf(defines, sizeof defines, "%s%s%s", d->defines, d->defines[0] && extra[0] ? ";" : "", extra);
    p = lm_program_get(vert, frag, defines, err);
  } else {
    p = lm_program_get(d->kind == LM_PASS_POINTS ? d->vertex : "fullscreen.vert", d->shader, d->defines, err);
  }
  if (!p) lm_error_prefix(err, "%s: pass '%s'", d->where, d->name);
  return p;
}

static bool is_float_format(lm_format f) {
  return f == LM_FORMAT_RGBA16F || f == LM_FORMAT_RGBA32F || f == LM_FORMAT_R16F ||
         f == LM_FORMAT_R32F || f == LM_FORMAT_RG16F || f == LM_FORMAT_RG32F;
}

/* The first non-finite texel of a pass's float outputs, as an error. */
static bool check_outputs_finite(const lm_graph *g, const lm_pass_desc *d, lm_error *err) {
  for (int i = 0; i < d->output_count; i++) {
    const graph_target *t = &g->targets[d->outputs[i]];
    if (!is_float_format(t->desc.format)) continue;
    float *px = lm_alloc(sizeof(float) * 4 * (size_t)t->width * (size_t)t->height);
    lm_texture_read(t->texture, t->width, t->height, true, px);
    for (size_t k = 0; k < (size_t)t->width * t->height * 4; k++) {
      if (isfinite(px[k])) continue;
      size_t texel = k / 4;
      lm_error_set(err, "%s: pass '%s' wrote %s to target '%s' at pixel (%zu, %zu) (channel %zu, rows from the top)",
                   d->where, d->name, isnan(px[k]) ? "NaN" : "Inf", t->desc.name, texel % (size_t)t->width,
                   texel / (size_t)t->width, k % 4);
      free(px);
      return false;
    }
    free(px);
  }
  return true;
}

/* Binds p with the pass's inputs and parameters. */
static void bind_pass(const lm_graph *g, const lm_pass_desc *d, const lm_program *p) {
  lm_program_use(p);
  lm_program_reset(p);
  for (int i = 0; i < d->input_count; i++)
    lm_program_bind_texture(lm_program_uniform(p, d->inputs[i].name), g->targets[d->inputs[i].target].texture);
  apply_params(d, p);
}

/* A shadow tile's view for the "shadow" technique (pass_view_proj, pass_depth). */
static void set_view(const lm_program *p, const lm_pass_view *view) {
  if (!view) return;
  const lm_uniform *u_vp = lm_program_uniform(p, "pass_view_proj"), *u_depth = lm_program_uniform(p, "pass_depth");
  if (u_vp) lm_program_set(p, u_vp, view->view_proj);
  if (u_depth) lm_program_set(p, u_depth, view->depth);
}

/* What lm_scene_pass_variant needs beyond the public fields. */
typedef struct scene_pass_ctx {
  lm_scene_pass pub; /* first: the callback's pointer is this struct's */
  const lm_graph_exec_desc *x;
} scene_pass_ctx;

const lm_program *lm_scene_pass_variant(const lm_scene_pass *sp, const char *defines, lm_error *err) {
  const scene_pass_ctx *c = (const scene_pass_ctx *)sp;
  const lm_pass_desc *d = sp->desc;
  lm_program *p = pass_program(d, defines ? defines : "", err);
  if (!p || !check_bindings(sp->graph, d, p, c->x, err)) return NULL;
  bind_pass(sp->graph, d, p);
  set_view(p, sp->view);
  return p;
}

/* Reads the inputs back, calls the function, uploads what it wrote; timed whole. */
static bool run_cpu_pass(lm_graph *g, const lm_pass_desc *d, lm_timer *timer, const lm_graph_exec_desc *x,
                         lm_error *err) {
  if (!x->run_cpu) {
    lm_error_set(err, "%s: pass '%s': CPU function '%s' is not available here", d->where, d->name, d->shader);
    return false;
  }
  lm_cpu_image in[LM_MAX_PASS_INPUTS], out[LM_MAX_COLOR_OUTPUTS];
  lm_timer_begin(timer, x->clock == LM_CLOCK_PROCESS ? LM_CLOCK_PROCESS : LM_CLOCK_CPU);
  for (int i = 0; i < d->input_count; i++) {
    const graph_target *t = &g->targets[d->inputs[i].target];
    in[i] = (lm_cpu_image){d->inputs[i].name, t->width, t->height,
                           lm_alloc(sizeof(float) * 4 * (size_t)t->width * (size_t)t->height)};
    lm_texture_read(t->texture, t->width, t->height, true, in[i].rgba);
  }
  for (int i = 0; i < d->output_count; i++) {
    const graph_target *t = &g->targets[d->outputs[i]];
    size_t bytes = sizeof(float) * 4 * (size_t)t->width * (size_t)t->height;
    out[i] = (lm_cpu_image){t->desc.name, t->width, t->height, memset(lm_alloc(bytes), 0, bytes)};
  }
  lm_cpu_pass cp = {d, in, d->input_count, out, d->output_count};
  bool ok = x->run_cpu(x->user, &cp, err);
  if (!ok) lm_error_prefix(err, "%s: pass '%s'", d->where, d->name);
  for (int i = 0; i < d->output_count && ok; i++) {
    const graph_target *t = &g->targets[d->outputs[i]];
    lm_texture_upload_floats(t->texture, t->width, t->height, out[i].rgba);
    if (t->desc.mips) lm_texture_generate_mips(t->texture);
  }
  lm_timer_end(timer);
  for (int i = 0; i < d->input_count; i++) free(in[i].rgba);
  for (int i = 0; i < d->output_count; i++) free(out[i].rgba);
  return ok && (!x->check_finite || check_outputs_finite(g, d, err));
}

static bool run_pass(lm_graph *g, graph_pass *gp, lm_timer *timer, const lm_graph_exec_desc *x,
                     lm_error *err) {
  const lm_pass_desc *d = &gp->desc;
  if (d->kind == LM_PASS_CPU) return run_cpu_pass(g, d, timer, x, err);
  const graph_target *fit = d->fits_views ? &g->targets[d->fit_target] : NULL;
  /* The views live in the graph's arena: the callback may rewrite them. */
  if (fit && x->fit_views &&
      !x->fit_views(x->user, d, fit->texture, fit->width, fit->height, (lm_pass_view *)d->views, err)) {
    lm_error_prefix(err, "%s: pass '%s'", d->where, d->name);
    return false;
  }
  lm_program *p = pass_program(d, "", err);
  if (!p || !check_bindings(g, d, p, x, err)) return false;
  lm_attachments att = {.color_count = d->output_count};
  for (int i = 0; i < d->output_count; i++) {
    const graph_target *t = &g->targets[d->outputs[i]];
    att.color[i] = t->texture;
    att.width = t->width, att.height = t->height;
  }
  if (d->depth >= 0) {
    att.depth = g->targets[d->depth].texture;
    att.width = g->targets[d->depth].width, att.height = g->targets[d->depth].height;
  }
  if (!lm_attachments_bind(&att, err)) {
    lm_error_prefix(err, "%s: pass '%s'", d->where, d->name);
    return false;
  }
  bind_pass(g, d, p);
  lm_timer_begin(timer, x->clock);
  bool ok = true;
  if (d->kind == LM_PASS_SCENE) {
    lm_set_scene_state(true, d->view_count > 0); /* tiles are shadow maps */
    lm_set_blend_state(d->blend);
    scene_pass_ctx c = {{d, p, g, NULL}, x};
    bool kept = d->view_count > 0 && x->keeps_views && x->keeps_views(x->user, &c.pub);
    if (d->clear && !kept)
      lm_clear(d->output_count, d->clear_color, d->depth >= 0, lm_scene_clear_depth(d->view_count > 0));
    if (d->view_count == 0 && x->draw_scene) ok = x->draw_scene(x->user, &c.pub, err);
    for (int v = 0; v < d->view_count && ok; v++) {
      c.pub.view = &d->views[v];
      lm_set_viewport(c.pub.view->x, c.pub.view->y, c.pub.view->width, c.pub.view->height);
      if (v > 0) bind_pass(g, d, p); /* the last tile may have left a material's variant bound */
      set_view(p, c.pub.view);
      if (x->draw_scene) ok = x->draw_scene(x->user, &c.pub, err);
    }
    lm_set_blend_state(false);
    lm_set_scene_state(false, false);
    if (!ok) lm_error_prefix(err, "%s: pass '%s'", d->where, d->name);
  } else if (d->kind == LM_PASS_POINTS) {
    static const float zero[4] = {0, 0, 0, 0};
    lm_clear(d->output_count, zero, false, 0);
    lm_draw_points(d->count);
  } else {
    lm_draw_fullscreen();
  }
  lm_timer_end(timer);
  for (int i = 0; i < d->output_count; i++)
    if (g->targets[d->outputs[i]].desc.mips) lm_texture_generate_mips(att.color[i]);
  return ok && (!x->check_finite || check_outputs_finite(g, d, err));
}

bool lm_graph_execute(lm_graph *g, const lm_graph_exec_desc *x, lm_error *err) {
  if (!g->compiled) {
    lm_error_set(err, "the frame graph was not compiled");
    return false;
  }
  bool ok = allocate(g, err);
  g->timers = lm_grow(g->timers, &g->timer_cap, g->pass_count, sizeof *g->timers);
  if (g->timer_count < g->pass_count) g->timer_count = g->pass_count;
  for (int pi = 0; pi < g->pass_count && ok; pi++)
    if (!g->passes[pi].culled) ok = run_pass(g, &g->passes[pi], &g->timers[pi], x, err);
  for (int pi = 0; pi < g->pass_count && ok; pi++)
    if (!g->passes[pi].culled) g->passes[pi].ms = lm_timer_read(&g->timers[pi]);
  pool_end_frame(g);
  return ok;
}
