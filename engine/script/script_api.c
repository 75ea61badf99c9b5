/* What pipeline scripts call: target{}, scene{}, pass{}, cpu{}, points{},
 * present(), output_size(), shadow_plan{}, sky_sh{}, scene_reflective(),
 * scene_blended(), scene_bounds(). Each validates its table and names the field at fault. */
#include "script/script_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TARGET_META "limn.target"
#define PLAN_META "limn.shadow_plan"

typedef struct target_handle {
  int id;
  unsigned frame; /* 0: persistent (OnCreate) */
  char name[64];
} target_handle;

/* "script.lua:12" of the Lua code that called the running C function. */
static void caller_where(lua_State *L, char *out, size_t cap) {
  luaL_where(L, 1);
  snprintf(out, cap, "%s", lua_tostring(L, -1));
  lua_pop(L, 1);
  size_t n = strlen(out);
  while (n > 0 && (out[n - 1] == ' ' || out[n - 1] == ':')) out[--n] = '\0';
}

/* The name in t[1]: a string that lives as long as the table (a number would
 * be converted into a string nothing keeps alive). NULL when t[1] is nil. */
static const char *first_name(lua_State *L, int t, const char *fn) {
  lua_rawgeti(L, t, 1);
  int type = lua_type(L, -1);
  const char *name = type == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
  lua_pop(L, 1);
  if (type != LUA_TSTRING && type != LUA_TNIL)
    luaL_error(L, "%s: the name (first entry) must be a string, not a %s", fn, lua_typename(L, type));
  return name;
}

static lm_pipeline *recording(lua_State *L, const char *fn) {
  lm_pipeline *p = lm_script_pipeline(L);
  if (!p->graph) luaL_error(L, "%s() is called from OnCreate or OnRender only", fn);
  return p;
}

/* Every key of the table at idx must be in `known` (NULL-terminated). */
static void check_fields(lua_State *L, int idx, const char *what, const char *const *known) {
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    lua_pop(L, 1);
    if (lua_type(L, -1) == LUA_TNUMBER && lua_tointeger(L, -1) == 1) continue; /* the name */
    const char *k = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
    bool ok = false;
    for (const char *const *f = known; k && *f && !ok; f++) ok = !strcmp(k, *f);
    if (!ok) {
      lm_buf list = {0};
      for (const char *const *f = known; *f; f++) lm_buf_printf(&list, "%s%s", f == known ? "" : ", ", *f);
      lua_pushfstring(L, "%s: unknown field '%s' (known: %s)", what,
                      k ? k : luaL_typename(L, -1), list.data);
      lm_buf_free(&list);
      luaL_where(L, 1);
      lua_insert(L, -2);
      lua_concat(L, 2);
      lua_error(L);
    }
  }
}

static const char *opt_string(lua_State *L, int idx, const char *field, const char *what) {
  lua_getfield(L, idx, field);
  const char *s = NULL;
  if (lua_type(L, -1) == LUA_TSTRING)
    s = lua_tostring(L, -1);
  else if (!lua_isnil(L, -1))
    luaL_error(L, "%s: field '%s' must be a string, not a %s", what, field, luaL_typename(L, -1));
  lua_pop(L, 1); /* the string stays alive in the table */
  return s;
}

static target_handle *to_target(lua_State *L, int idx, const char *what) {
  lm_pipeline *p = lm_script_pipeline(L);
  target_handle *t = luaL_testudata(L, idx, TARGET_META);
  if (!t) luaL_error(L, "%s: expected a target (from target{...}), got a %s", what, luaL_typename(L, idx));
  if (t->frame && t->frame != p->frame)
    luaL_error(L, "%s: target '%s' belongs to an earlier frame (declare frame targets in OnRender, "
               "lasting ones in OnCreate)", what, t->name);
  return t;
}

/* ---- target{ name = , format = , scale = | size = {w, h}, mips = } ---- */
static int l_target(lua_State *L) {
  lm_pipeline *p = recording(L, "target");
  luaL_checktype(L, 1, LUA_TTABLE);
  static const char *const fields[] = {"name", "format", "scale", "size", "mips", NULL};
  check_fields(L, 1, "target", fields);
  lm_target_desc d = {.scale = 1.0f, .persistent = p->in_create};
  d.name = first_name(L, 1, "target");
  if (!d.name) d.name = opt_string(L, 1, "name", "target");
  if (!d.name) return luaL_error(L, "target: give it a name: target{ \"lit\", format = \"rgba16f\" }");
  char what[128];
  snprintf(what, sizeof what, "target '%s'", d.name);
  const char *format = opt_string(L, 1, "format", what);
  if (!format) return luaL_error(L, "%s: field 'format' is missing (one of %s)", what, lm_format_list());
  d.format = lm_format_parse(format);
  if (d.format == LM_FORMAT_NONE)
    return luaL_error(L, "%s: unknown format '%s' (one of %s)", what, format, lm_format_list());
  lua_getfield(L, 1, "scale");
  if (!lua_isnil(L, -1)) {
    double s = lua_tonumber(L, -1);
    if (!lua_isnumber(L, -1) || !(s > 0) || s > 16 || !isfinite(s))
      return luaL_error(L, "%s: scale must be a number in (0, 16]", what);
    d.scale = (float)s;
  }
  lua_getfield(L, 1, "size");
  if (!lua_isnil(L, -1)) {
    if (!lua_istable(L, -1)) return luaL_error(L, "%s: size must be {width, height}", what);
    lua_rawgeti(L, -1, 1);
    lua_rawgeti(L, -2, 2);
    lua_Integer w = lua_tointeger(L, -2), h = lua_tointeger(L, -1);
    if (w < 1 || h < 1 || w > 65536 || h > 65536)
      return luaL_error(L, "%s: size must be two whole numbers in 1 .. 65536", what);
    d.width = (int)w, d.height = (int)h;
    lua_pop(L, 2);
  }
  lua_getfield(L, 1, "mips");
  d.mips = lua_toboolean(L, -1);
  lua_pop(L, 2);
  lm_error err;
  int id = lm_graph_add_target(p->graph, &d, &err);
  if (id < 0) return luaL_error(L, "%s", err.msg);
  target_handle *t = lua_newuserdatauv(L, sizeof *t, 0);
  t->id = id;
  t->frame = p->in_create ? 0 : p->frame;
  snprintf(t->name, sizeof t->name, "%s", d.name);
  luaL_setmetatable(L, TARGET_META);
  return 1;
}

static int l_target_tostring(lua_State *L) {
  target_handle *t = luaL_checkudata(L, 1, TARGET_META);
  lua_pushfstring(L, "target '%s'", t->name);
  return 1;
}

static int l_target_index(lua_State *L) {
  target_handle *t = luaL_checkudata(L, 1, TARGET_META);
  const char *k = luaL_checkstring(L, 2);
  if (!strcmp(k, "name")) {
    lua_pushstring(L, t->name);
    return 1;
  }
  return luaL_error(L, "target '%s' has no field '%s' (it has: name)", t->name, k);
}

/* ---- shadow_plan{} ----------------------------------------------------- */
static float opt_number(lua_State *L, int idx, const char *field, float def, float lo, float hi,
                        const char *what) {
  lua_getfield(L, idx, field);
  float v = def;
  if (!lua_isnil(L, -1)) {
    double d = lua_tonumber(L, -1);
    if (!lua_isnumber(L, -1) || !(d >= lo && d <= hi))
      luaL_error(L, "%s: %s must be a number in %g .. %g", what, field, (double)lo, (double)hi);
    v = (float)d;
  }
  lua_pop(L, 1);
  return v;
}

/* shadow_plan{ technique, resolution, c, blur, cascades, lambda, bias, distance,
 * blend, radius, stabilize, size, penumbra, rsm, rsm_resolution, cache, coverage, simplify }: tiles for every light that casts shadows, or nil
 * when none does. scene{ views = plan } draws them; scene{ views = plan, fit =
 * T } first fits them to the camera depths T's first texel holds (min in r,
 * max in g, as depth / far). */
static int l_shadow_plan(lua_State *L) {
  lm_pipeline *p = recording(L, "shadow_plan");
  if (p->in_create) return luaL_error(L, "shadow_plan() is called from OnRender");
  if (!p->scene || !p->shadows) return luaL_error(L, "shadow_plan: this pipeline renders no scene");
  if (p->shadows_frame == p->frame) return luaL_error(L, "shadow_plan: called twice in one frame");
  luaL_checktype(L, 1, LUA_TTABLE);
  static const char *const fields[] = {"technique", "resolution", "c", "blur", "cascades", "lambda",
                                       "bias", "distance", "blend", "radius", "stabilize", "size",
                                       "penumbra", "rsm", "rsm_resolution", "cache", "coverage", "simplify", NULL};
  check_fields(L, 1, "shadow_plan", fields);
  lm_shadow_settings st;
  lm_shadow_settings_default(&st);
  const char *technique = opt_string(L, 1, "technique", "shadow_plan");
  if (technique) {
    int t = lm_shadow_technique_parse(technique);
    if (t < 0) return luaL_error(L, "shadow_plan: unknown technique '%s' (esm, pcf, poisson, hard, pcss)", technique);
    st.technique = (lm_shadow_technique)t;
  }
  const char *what = "shadow_plan";
  st.resolution = (int)opt_number(L, 1, "resolution", (float)st.resolution, 16, 8192, what);
  st.c = opt_number(L, 1, "c", st.c, 1e-3f, 10000, what);
  st.blur = (int)opt_number(L, 1, "blur", (float)st.blur, 0, 32, what);
  st.cascades = (int)opt_number(L, 1, "cascades", (float)st.cascades, 1, 4, what);
  st.lambda = opt_number(L, 1, "lambda", st.lambda, 0, 1, what);
  st.bias = opt_number(L, 1, "bias", st.bias, 0.0f, 64.0f, what);
  st.distance = opt_number(L, 1, "distance", st.distance, 0, 1e9f, what);
  st.blend = opt_number(L, 1, "blend", st.blend, 0, 1, what);
  st.radius = opt_number(L, 1, "radius", st.radius, 0, 32, what);
  st.size = opt_number(L, 1, "size", st.size, -1, 1e30f, what);
  st.penumbra = opt_number(L, 1, "penumbra", st.penumbra, 1, 64, what);
  st.simplify = opt_number(L, 1, "simplify", st.simplify, 0, 64, what);
  lua_getfield(L, 1, "stabilize");
  if (!lua_isnil(L, -1)) st.stabilize = lua_toboolean(L, -1);
  lua_pop(L, 1);
  lua_getfield(L, 1, "cache");
  if (!lua_isnil(L, -1)) st.cache = lua_toboolean(L, -1);
  lua_pop(L, 1);
  lua_getfield(L, 1, "coverage");
  if (!lua_isnil(L, -1)) st.coverage = lua_toboolean(L, -1);
  lua_pop(L, 1);
  st.rsm = opt_number(L, 1, "rsm", 0, 0, 64, what);
  st.rsm_resolution = (int)opt_number(L, 1, "rsm_resolution", (float)st.rsm_resolution, 16, 8192, what);
  st.last_levels = p->shadow_levels, st.last_light_count = p->shadow_level_count;
  memcpy(st.last_range, p->shadows->range, sizeof st.last_range); /* as the last frame's fit left them */
  free(p->shadow_depths); /* the last frame's rows, kept for this plan (lm_shadow_settings.last_depths) */
  p->shadow_depths = p->shadows->depths, p->shadows->depths = NULL;
  st.last_depths = (const float(*)[2])p->shadow_depths;
  lm_shadow_layout layout = p->shadows->layout; /* where the last plan's tiles lay (last_layout) */
  p->shadows->layout = (lm_shadow_layout){0};
  st.last_layout = &layout;
  lm_shadow_plan_free(p->shadows);
  lm_error err;
  bool made = lm_shadow_plan_make(p->shadows, p->scene, p->camera, &st, &err);
  free(layout.places);
  if (!made) return luaL_error(L, "shadow_plan: %s", err.msg);
  int n = p->shadows->light_count; /* the levels, kept for the next plan (lm_shadow_settings.last_levels) */
  p->shadow_levels = lm_realloc(p->shadow_levels, sizeof *p->shadow_levels * (size_t)(n + 1));
  memcpy(p->shadow_levels, p->shadows->levels, sizeof *p->shadow_levels * (size_t)n);
  p->shadow_level_count = n;
  p->shadows_frame = p->frame;
  if (p->shadows->view_count == 0) {
    lm_info("left out: shadows (no light in scene '%s' casts shadows)", p->scene->name);
    lua_pushnil(L);
    return 1;
  }
  unsigned *handle = lua_newuserdatauv(L, sizeof *handle, 0);
  *handle = p->frame;
  luaL_setmetatable(L, PLAN_META);
  return 1;
}

static const lm_shadow_plan *to_plan(lua_State *L, int idx, const char *what) {
  lm_pipeline *p = lm_script_pipeline(L);
  unsigned *handle = luaL_testudata(L, idx, PLAN_META);
  if (!handle) luaL_error(L, "%s: expected a shadow plan (from shadow_plan{...}), got a %s", what, luaL_typename(L, idx));
  if (*handle != p->frame || p->shadows_frame != p->frame)
    luaL_error(L, "%s: the shadow plan belongs to an earlier frame", what);
  return p->shadows;
}

static int l_plan_index(lua_State *L) {
  const lm_shadow_plan *plan = to_plan(L, 1, "shadow plan");
  const char *k = luaL_checkstring(L, 2);
  if (!strcmp(k, "width")) lua_pushinteger(L, plan->atlas_width);
  else if (!strcmp(k, "height")) lua_pushinteger(L, plan->atlas_height);
  else if (!strcmp(k, "tile")) lua_pushinteger(L, plan->tile);
  else if (!strcmp(k, "views")) lua_pushinteger(L, plan->view_count);
  else if (!strcmp(k, "shadow_views")) lua_pushinteger(L, plan->shadow_views);
  else if (!strcmp(k, "rsm_views")) lua_pushinteger(L, plan->rsm_view_count);
  else if (!strcmp(k, "rsm_width")) lua_pushinteger(L, plan->rsm_width);
  else if (!strcmp(k, "rsm_height")) lua_pushinteger(L, plan->rsm_height);
  else if (!strcmp(k, "c")) lua_pushnumber(L, plan->settings.c);
  else if (!strcmp(k, "blur")) lua_pushinteger(L, plan->settings.blur);
  else if (!strcmp(k, "technique")) lua_pushstring(L, (const char *[]){"esm", "pcf", "poisson", "hard", "pcss"}[plan->settings.technique]);
  else return luaL_error(L, "shadow plan has no field '%s' (width, height, tile, views, shadow_views, rsm_views, "
                         "rsm_width, rsm_height, c, blur, technique)", k);
  return 1;
}

/* ---- sky_sh{} ---------------------------------------------------------- */
static void opt_colour(lua_State *L, int idx, const char *field, float out[3]) {
  lua_getfield(L, idx, field);
  if (!lua_istable(L, -1) || lua_rawlen(L, -1) != 3)
    luaL_error(L, "sky_sh: %s must be a list of 3 numbers (r, g, b)", field);
  for (int i = 0; i < 3; i++) {
    lua_rawgeti(L, -1, i + 1);
    double d = lua_tonumber(L, -1);
    if (!lua_isnumber(L, -1) || !(d >= 0 && d <= 1e6))
      luaL_error(L, "sky_sh: %s[%d] must be a number in 0 .. 1e6", field, i + 1);
    out[i] = (float)d;
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

/* sky_sh{ zenith = {r, g, b}, horizon = {r, g, b}, intensity = x, map = path }:
 * the sky's LM_SKY_SH coefficients (scene/sky.h) as three lists of 9, for r,
 * g and b: the gradient's, or with `map` an equirectangular HDR file's (read
 * once and kept while the path stays the same). */
static int l_sky_sh(lua_State *L) {
  lm_pipeline *p = lm_script_pipeline(L);
  luaL_checktype(L, 1, LUA_TTABLE);
  static const char *const fields[] = {"zenith", "horizon", "intensity", "map", NULL};
  check_fields(L, 1, "sky_sh", fields);
  lm_sky sky = {.intensity = opt_number(L, 1, "intensity", 1.0f, 0.0f, 1e6f, "sky_sh")};
  const char *map = opt_string(L, 1, "map", "sky_sh");
  float sh[LM_SKY_SH];
  if (map && *map) {
    if (strcmp(map, p->sky_map) != 0) {
      lm_error err;
      p->sky_map[0] = '\0';
      if (strlen(map) >= sizeof p->sky_map) return luaL_error(L, "sky_sh: map path is too long");
      if (!lm_sky_sh_map(map, 1.0f, p->sky_map_sh, &err)) return luaL_error(L, "sky_sh: %s", err.msg);
      snprintf(p->sky_map, sizeof p->sky_map, "%s", map);
    }
    for (int i = 0; i < LM_SKY_SH; i++) sh[i] = sky.intensity * p->sky_map_sh[i];
  } else {
    opt_colour(L, 1, "zenith", sky.zenith);
    opt_colour(L, 1, "horizon", sky.horizon);
    lm_sky_sh_gradient(&sky, sh);
  }
  for (int k = 0; k < 3; k++) /* the sky's mean radiance (band 0) counts as light the frame adds */
    if (sh[k * 9] * 0.282095f > p->light_peak && isfinite(sh[k * 9])) p->light_peak = sh[k * 9] * 0.282095f;
  lua_createtable(L, 3, 0);
  for (int k = 0; k < 3; k++) {
    lua_createtable(L, 9, 0);
    for (int i = 0; i < 9; i++) {
      lua_pushnumber(L, sh[k * 9 + i]);
      lua_rawseti(L, -2, i + 1);
    }
    lua_rawseti(L, -2, k + 1);
  }
  return 1;
}

/* ---- shared pass fields ----------------------------------------------- */
typedef struct pass_builder {
  lm_pass_desc desc;
  lm_pass_input inputs[LM_MAX_PASS_INPUTS];
  lm_pass_param params[LM_MAX_PASS_PARAMS];
  int outputs[LM_MAX_COLOR_OUTPUTS];
  char where[256], defines[1024];
  char what[160];
  lm_pass_material_param materials[LM_MAX_PASS_PARAMS];
} pass_builder;

static void read_outputs(lua_State *L, int idx, pass_builder *b) {
  lua_getfield(L, idx, "out");
  if (luaL_testudata(L, -1, TARGET_META)) {
    b->outputs[b->desc.output_count++] = to_target(L, -1, b->what)->id;
  } else if (lua_istable(L, -1)) {
    int n = (int)lua_rawlen(L, -1);
    if (n > LM_MAX_COLOR_OUTPUTS) luaL_error(L, "%s: at most %d outputs", b->what, LM_MAX_COLOR_OUTPUTS);
    for (int i = 1; i <= n; i++) {
      lua_rawgeti(L, -1, i);
      b->outputs[b->desc.output_count++] = to_target(L, -1, b->what)->id;
      lua_pop(L, 1);
    }
  } else if (!lua_isnil(L, -1)) {
    luaL_error(L, "%s: field 'out' must be a target or a list of targets", b->what);
  }
  lua_pop(L, 1);
}

static int compare_inputs(const void *a, const void *b) {
  return strcmp(((const lm_pass_input *)a)->name, ((const lm_pass_input *)b)->name);
}

static void read_inputs(lua_State *L, int idx, pass_builder *b) {
  lua_getfield(L, idx, "inputs");
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  if (!lua_istable(L, -1)) luaL_error(L, "%s: field 'inputs' must be a table { sampler = target }", b->what);
  lua_pushnil(L);
  while (lua_next(L, -2)) {
    if (lua_type(L, -2) != LUA_TSTRING) luaL_error(L, "%s: inputs are named: { sampler = target }", b->what);
    if (b->desc.input_count >= LM_MAX_PASS_INPUTS) luaL_error(L, "%s: at most %d inputs", b->what, LM_MAX_PASS_INPUTS);
    char what[256];
    snprintf(what, sizeof what, "%s: input '%s'", b->what, lua_tostring(L, -2));
    lm_pass_input *in = &b->inputs[b->desc.input_count++];
    in->name = lua_tostring(L, -2); /* the key stays alive in the table */
    in->target = to_target(L, -1, what)->id;
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  /* Table order varies from run to run; messages and bindings should not. */
  qsort(b->inputs, (size_t)b->desc.input_count, sizeof *b->inputs, compare_inputs);
}

/* A pass's params, read and sorted as read_inputs reads its inputs: the two
 * read alike (their checks and messages differ). */
static int compare_params(const void *a, const void *b) {
  return strcmp(((const lm_pass_param *)a)->name, ((const lm_pass_param *)b)->name);
}

static void read_params(lua_State *L, int idx, pass_builder *b) {
  lua_getfield(L, idx, "params");
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  if (!lua_istable(L, -1)) luaL_error(L, "%s: field 'params' must be a table { uniform = value }", b->what);
  lua_pushnil(L);
  while (lua_next(L, -2)) {
    if (lua_type(L, -2) != LUA_TSTRING) luaL_error(L, "%s: params are named: { uniform = value }", b->what);
    const char *name = lua_tostring(L, -2);
    if (b->desc.param_count >= LM_MAX_PASS_PARAMS) luaL_error(L, "%s: at most %d params", b->what, LM_MAX_PASS_PARAMS);
    lm_pass_param *pa = &b->params[b->desc.param_count++];
    pa->name = name;
    if (lua_isboolean(L, -1)) {
      pa->kind = LM_PARAM_BOOL;
      pa->count = 1;
      pa->v[0] = lua_toboolean(L, -1);
    } else if (lua_type(L, -1) == LUA_TNUMBER) {
      pa->count = 1;
      pa->v[0] = lua_tonumber(L, -1);
    } else if (lua_istable(L, -1)) {
      int n = (int)lua_rawlen(L, -1);
      if (n < 1 || n > 16) luaL_error(L, "%s: parameter '%s': a list of 1 to 16 numbers", b->what, name);
      for (int i = 1; i <= n; i++) {
        lua_rawgeti(L, -1, i);
        if (lua_type(L, -1) != LUA_TNUMBER)
          luaL_error(L, "%s: parameter '%s': element %d is a %s, not a number", b->what, name, i,
                     luaL_typename(L, -1));
        pa->v[pa->count++] = lua_tonumber(L, -1);
        lua_pop(L, 1);
      }
    } else {
      luaL_error(L, "%s: parameter '%s': a number, boolean or list of numbers, not a %s", b->what,
                 name, luaL_typename(L, -1));
    }
    for (int i = 0; i < pa->count; i++)
      if (!isfinite(pa->v[i])) luaL_error(L, "%s: parameter '%s' is not finite", b->what, name);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  qsort(b->params, (size_t)b->desc.param_count, sizeof *b->params, compare_params);
}

static int compare_strings(const void *a, const void *b) { return strcmp(a, b); }

/* defines = { NAME = value | true }: sorted, so one variant has one cache key. */
static void read_defines(lua_State *L, int idx, pass_builder *b) {
  lua_getfield(L, idx, "defines");
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  if (!lua_istable(L, -1)) luaL_error(L, "%s: field 'defines' must be a table { NAME = value }", b->what);
  char entries[32][96];
  int n = 0;
  lua_pushnil(L);
  while (lua_next(L, -2)) {
    if (lua_type(L, -2) != LUA_TSTRING || n == 32)
      luaL_error(L, "%s: defines are named (at most 32): { NAME = value }", b->what);
    const char *name = lua_tostring(L, -2);
    int type = lua_type(L, -1);
    if (type == LUA_TBOOLEAN) {
      if (lua_toboolean(L, -1)) snprintf(entries[n++], sizeof entries[0], "%s", name);
    } else if (type == LUA_TNUMBER || type == LUA_TSTRING) {
      lua_pushvalue(L, -1); /* tostring on a copy: lua_next needs the key untouched */
      snprintf(entries[n++], sizeof entries[0], "%s=%s", name, lua_tostring(L, -1));
      lua_pop(L, 1);
    } else {
      luaL_error(L, "%s: define '%s' must be a number, string or boolean", b->what, name);
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  qsort(entries, (size_t)n, sizeof entries[0], compare_strings);
  for (int i = 0; i < n; i++) {
    size_t len = strlen(b->defines);
    snprintf(b->defines + len, sizeof b->defines - len, "%s%s", i ? ";" : "", entries[i]);
  }
  b->desc.defines = b->defines;
}

static int compare_material_params(const void *a, const void *b) {
  const lm_pass_material_param *x = a, *y = b;
  int c = strcmp(x->material, y->material);
  return c ? c : strcmp(x->name, y->name);
}

/* materials = { name = { color = {r, g, b}, ks = 0.5, ... } }: overrides of
 * the scene's materials for this pass. The scene checks the names when it
 * draws (it knows its materials); the shape is checked here. */
static void read_materials(lua_State *L, int idx, pass_builder *b) {
  lua_getfield(L, idx, "materials");
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  if (!lua_istable(L, -1))
    luaL_error(L, "%s: field 'materials' must be a table { material = { parameter = value } }", b->what);
  lua_pushnil(L);
  while (lua_next(L, -2)) {
    if (lua_type(L, -2) != LUA_TSTRING || !lua_istable(L, -1))
      luaL_error(L, "%s: materials are named tables: materials = { wall = { color = {1, 0, 0} } }", b->what);
    const char *material = lua_tostring(L, -2);
    lua_pushnil(L);
    while (lua_next(L, -2)) {
      if (lua_type(L, -2) != LUA_TSTRING)
        luaL_error(L, "%s: material '%s': parameters are named: { ks = 0.5 }", b->what, material);
      const char *name = lua_tostring(L, -2);
      if (b->desc.material_param_count >= LM_MAX_PASS_PARAMS)
        luaL_error(L, "%s: at most %d material parameters", b->what, LM_MAX_PASS_PARAMS);
      lm_pass_material_param *mp = &b->materials[b->desc.material_param_count++];
      *mp = (lm_pass_material_param){.material = material, .name = name};
      if (lua_type(L, -1) == LUA_TNUMBER) {
        mp->v[mp->count++] = (float)lua_tonumber(L, -1);
      } else if (lua_istable(L, -1)) {
        int n = (int)lua_rawlen(L, -1);
        if (n < 1 || n > 4) luaL_error(L, "%s: material '%s': parameter '%s': 1 to 4 numbers", b->what, material, name);
        for (int i = 1; i <= n; i++) {
          lua_rawgeti(L, -1, i);
          if (lua_type(L, -1) != LUA_TNUMBER)
            luaL_error(L, "%s: material '%s': parameter '%s': element %d is a %s, not a number", b->what,
                       material, name, i, luaL_typename(L, -1));
          mp->v[mp->count++] = (float)lua_tonumber(L, -1);
          lua_pop(L, 1);
        }
      } else {
        luaL_error(L, "%s: material '%s': parameter '%s': a number or list of numbers, not a %s", b->what,
                   material, name, luaL_typename(L, -1));
      }
      for (int i = 0; i < mp->count; i++)
        if (!isfinite(mp->v[i])) luaL_error(L, "%s: material '%s': parameter '%s' is not finite", b->what, material, name);
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  qsort(b->materials, (size_t)b->desc.material_param_count, sizeof *b->materials, compare_material_params);
  b->desc.material_params = b->materials;
}

static void begin_pass(lua_State *L, pass_builder *b, lm_pass_kind kind, const char *fn) {
  memset(b, 0, sizeof *b);
  luaL_checktype(L, 1, LUA_TTABLE);
  b->desc.kind = kind;
  b->desc.inputs = b->inputs;
  b->desc.params = b->params;
  b->desc.outputs = b->outputs;
  b->desc.depth = -1;
  caller_where(L, b->where, sizeof b->where);
  b->desc.where = b->where;
  b->desc.name = first_name(L, 1, fn);
  if (!b->desc.name) luaL_error(L, "%s: give the pass a name first: %s{ \"name\", ... }", fn, fn);
  snprintf(b->what, sizeof b->what, "pass '%s'", b->desc.name);
}

static void add_pass(lua_State *L, lm_pipeline *p, pass_builder *b) {
  lm_error err;
  if (lm_graph_add_pass(p->graph, &b->desc, &err) < 0) luaL_error(L, "%s", err.msg);
}

/* Adds the pass and returns its first output (pass{} and cpu{} chain). */
static int add_pass_returning_output(lua_State *L, lm_pipeline *p, pass_builder *b, int top) {
  add_pass(L, p, b);
  lua_settop(L, top);
  lua_getfield(L, 1, "out");
  if (lua_istable(L, -1)) lua_rawgeti(L, -1, 1);
  return 1;
}

/* scene{ "name", technique = "std", out = {...}, depth = T, clear = bool | {r,g,b,a}, ...,
 * views = plan, fit = T, inputs = {...}, blend = bool, simplify = pixels } */
static int l_scene(lua_State *L) {
  lm_pipeline *p = recording(L, "scene");
  if (p->in_create) return luaL_error(L, "scene() records a pass: call it from OnRender");
  pass_builder b;
  int top = lua_gettop(L);
  begin_pass(L, &b, LM_PASS_SCENE, "scene");
  static const char *const fields[] = {"technique", "out", "depth", "clear", "params", "defines",
                                       "materials", "views", "rsm", "fit", "fit_margin", "inputs", "blend",
                                       "transmit", "simplify", NULL};
  check_fields(L, 1, b.what, fields);
  b.desc.shader = opt_string(L, 1, "technique", b.what);
  if (!b.desc.shader) b.desc.shader = "std";
  read_outputs(L, 1, &b);
  lua_getfield(L, 1, "depth");
  if (!lua_isnil(L, -1)) b.desc.depth = to_target(L, -1, b.what)->id;
  lua_pop(L, 1);
  lua_getfield(L, 1, "clear");
  b.desc.clear = true;
  if (lua_isboolean(L, -1)) {
    b.desc.clear = lua_toboolean(L, -1);
  } else if (lua_istable(L, -1)) {
    for (int i = 0; i < 4; i++) {
      lua_rawgeti(L, -1, i + 1);
      b.desc.clear_color[i] = (float)luaL_optnumber(L, -1, 0);
      lua_pop(L, 1);
    }
  } else if (!lua_isnil(L, -1)) {
    return luaL_error(L, "%s: clear must be true, false or {r, g, b, a}", b.what);
  }
  lua_pop(L, 1);
  read_params(L, 1, &b);
  read_defines(L, 1, &b);
  read_inputs(L, 1, &b);
  lua_getfield(L, 1, "blend"); /* the blended materials alone, over what out holds (lm_pass_desc) */
  if (!lua_isnil(L, -1) && !lua_isboolean(L, -1)) return luaL_error(L, "%s: blend must be true or false", b.what);
  b.desc.blend = lua_toboolean(L, -1);
  lua_pop(L, 1);
  lua_getfield(L, 1, "simplify"); /* pixels a simplified copy may err by (lm_pass_desc) */
  if (!lua_isnil(L, -1)) {
    lua_Number px = lua_tonumber(L, -1);
    if (!lua_isnumber(L, -1) || !(px >= 0 && px <= 64))
      return luaL_error(L, "%s: simplify must be a number of pixels in 0..64", b.what);
    b.desc.simplify = (float)px;
  }
  lua_pop(L, 1);
  lua_getfield(L, 1, "rsm"); /* the plan's RSM views instead of its shadow tiles (lm_pass_desc.view_set) */
  if (!lua_isnil(L, -1) && !lua_isboolean(L, -1)) return luaL_error(L, "%s: rsm must be true or false", b.what);
  bool rsm = lua_toboolean(L, -1);
  lua_pop(L, 1);
  lua_getfield(L, 1, "views");
  if (!lua_isnil(L, -1)) {
    const lm_shadow_plan *plan = to_plan(L, -1, b.what);
    b.desc.views = rsm ? plan->rsm_views : plan->views;
    b.desc.view_count = rsm ? plan->rsm_view_count : plan->view_count;
    b.desc.view_set = rsm;
    if (rsm && !b.desc.view_count)
      return luaL_error(L, "%s: rsm: the shadow plan has no RSM views (shadow_plan{ rsm = ... })", b.what);
  } else if (rsm) {
    return luaL_error(L, "%s: rsm is for a pass with views (a shadow plan)", b.what);
  }
  lua_pop(L, 1);
  lua_getfield(L, 1, "transmit"); /* the output blended casters multiply (lm_pass_desc) */
  if (!lua_isnil(L, -1)) {
    int t = to_target(L, -1, b.what)->id;
    for (int i = 0; i < b.desc.output_count && !b.desc.transmit; i++)
      if (b.outputs[i] == t) b.desc.transmit = i + 1;
    if (!b.desc.transmit || !b.desc.view_count)
      return luaL_error(L, "%s: transmit must be one of the outputs of a pass with views (a shadow plan)", b.what);
  }
  lua_pop(L, 1);
  lua_getfield(L, 1, "fit");
  if (!lua_isnil(L, -1)) {
    if (!b.desc.view_count) return luaL_error(L, "%s: fit is for a pass with views (a shadow plan)", b.what);
    b.desc.fits_views = true;
    b.desc.fit_target = to_target(L, -1, b.what)->id;
  }
  lua_pop(L, 1);
  lua_getfield(L, 1, "fit_margin"); /* a number: fit to the previous frame's depths (lm_pass_desc) */
  if (!lua_isnil(L, -1)) {
    lua_Number m = lua_tonumber(L, -1);
    if (!lua_isnumber(L, -1) || !(m >= 0 && m <= 10))
      return luaL_error(L, "%s: fit_margin must be a number in 0..10", b.what);
    if (!b.desc.fits_views) return luaL_error(L, "%s: fit_margin needs fit", b.what);
    b.desc.fit_previous = true;
    b.desc.fit_margin = (float)m;
  }
  lua_pop(L, 1);
  read_materials(L, 1, &b);
  add_pass(L, p, &b);
  lua_settop(L, top);
  return 0;
}

/* What pass{} and cpu{} share: the program (field `field`: a shader or a CPU
 * function), outputs, inputs and parameters. */
static lm_pipeline *begin_output_pass(lua_State *L, pass_builder *b, lm_pass_kind kind, const char *fn,
                                      const char *const *fields, const char *field, const char *hint) {
  lm_pipeline *p = recording(L, fn);
  if (p->in_create) luaL_error(L, "%s() records a pass: call it from OnRender", fn);
  begin_pass(L, b, kind, fn);
  check_fields(L, 1, b->what, fields);
  b->desc.shader = opt_string(L, 1, field, b->what);
  if (!b->desc.shader) luaL_error(L, "%s: field '%s' is missing (%s)", b->what, field, hint);
  read_outputs(L, 1, b);
  if (b->desc.output_count == 0) luaL_error(L, "%s: field 'out' is missing", b->what);
  read_inputs(L, 1, b);
  read_params(L, 1, b);
  return p;
}

/* pass{ "name", shader = "x.frag", inputs = {...}, params = {...}, out = T | {...}, defines = {...},
 * fold_output = B } returns its first output, so passes chain. fold_output: the engine's output
 * stage may run in this pass when it presents its image (lm_pass_desc.fold_output). */
static int l_pass(lua_State *L) {
  static const char *const fields[] = {"shader", "inputs", "params", "out", "defines", "fetches", "fold_output",
                                       NULL};
  pass_builder b;
  int top = lua_gettop(L);
  lm_pipeline *p = begin_output_pass(L, &b, LM_PASS_FULLSCREEN, "pass", fields, "shader", "a file in shaders/");
  read_defines(L, 1, &b);
  b.desc.fetches = opt_number(L, 1, "fetches", 0, 0, 1e6f, b.what);
  lua_getfield(L, 1, "fold_output");
  if (!lua_isnil(L, -1) && !lua_isboolean(L, -1)) luaL_error(L, "%s: fold_output must be true or false", b.what);
  b.desc.fold_output = lua_toboolean(L, -1);
  lua_pop(L, 1);
  return add_pass_returning_output(L, p, &b, top);
}

/* cpu{ "name", fn = "trace", inputs = {...}, params = {...}, out = T | {...} }: a
 * CPU pass (the engine's function `fn` between GPU passes); returns its first output. */
static int l_cpu(lua_State *L) {
  static const char *const fields[] = {"fn", "inputs", "params", "out", NULL};
  pass_builder b;
  int top = lua_gettop(L);
  lm_pipeline *p = begin_output_pass(L, &b, LM_PASS_CPU, "cpu", fields, "fn", "an engine function: trace");
  return add_pass_returning_output(L, p, &b, top);
}

/* points{ "name", vertex = "x.vert", shader = "x.frag", count = N, inputs = {...}, params = {...},
 * out = T | {...}, defines = {...}, fetches = F }: N points, each placed on one texel by the vertex
 * shader, added into outputs cleared to zero (a scatter); returns its first output. */
static int l_points(lua_State *L) {
  static const char *const fields[] = {"vertex", "shader", "count", "inputs", "params", "out", "defines",
                                       "fetches", NULL};
  pass_builder b;
  int top = lua_gettop(L);
  lm_pipeline *p = begin_output_pass(L, &b, LM_PASS_POINTS, "points", fields, "shader", "a file in shaders/");
  b.desc.vertex = opt_string(L, 1, "vertex", b.what);
  if (!b.desc.vertex) return luaL_error(L, "%s: field 'vertex' is missing (a vertex shader in shaders/)", b.what);
  lua_getfield(L, 1, "count");
  lua_Number n = lua_tonumber(L, -1);
  if (!lua_isnumber(L, -1) || !(n >= 0 && n <= LM_MAX_POINTS) || n != floor(n))
    return luaL_error(L, "%s: count must be a whole number in 0 .. %d (got %s)", b.what, LM_MAX_POINTS,
                      luaL_tolstring(L, -1, NULL));
  b.desc.count = (int)n;
  lua_pop(L, 1);
  read_defines(L, 1, &b);
  b.desc.fetches = opt_number(L, 1, "fetches", 0, 0, 1e6f, b.what);
  return add_pass_returning_output(L, p, &b, top);
}

/* scene_bounds(): the world box of the scene's meshes as two lists {x, y, z}
 * (least, greatest), or nil for a scene without finite geometry. */
static int l_scene_bounds(lua_State *L) {
  lm_pipeline *p = recording(L, "scene_bounds");
  float lo[3], hi[3];
  if (!p->scene || !lm_scene_bounds(p->scene, lo, hi)) {
    lua_pushnil(L);
    return 1;
  }
  for (int k = 0; k < 2; k++) {
    lua_createtable(L, 3, 0);
    for (int i = 0; i < 3; i++) {
      lua_pushnumber(L, (k ? hi : lo)[i]);
      lua_rawseti(L, -2, i + 1);
    }
  }
  return 2;
}

/* camera_view(): the camera of the frame being recorded, { eye, forward,
 * up, right = world {x, y, z} (unit), near, far, tan_y = tan(fov_y / 2),
 * aspect = width / height }; nil from OnCreate (no camera yet). A script
 * fits what the frame needs to it (lpv.lua's volumes). */
static int l_camera_view(lua_State *L) {
  lm_pipeline *p = recording(L, "camera_view");
  const lm_frame_data *f = p->camera;
  if (p->in_create || !f) {
    lua_pushnil(L);
    return 1;
  }
  /* inv_view's columns: right, up, back (the camera looks down -z). */
  const struct { const char *name; const float *v; float sign; } axes[] = {
      {"eye", f->camera_pos, 1}, {"right", f->inv_view, 1}, {"up", f->inv_view + 4, 1}, {"forward", f->inv_view + 8, -1}};
  lua_createtable(L, 0, 8);
  for (size_t k = 0; k < sizeof axes / sizeof *axes; k++) {
    lua_createtable(L, 3, 0);
    for (int i = 0; i < 3; i++) {
      lua_pushnumber(L, axes[k].sign * axes[k].v[i]);
      lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -2, axes[k].name);
  }
  float h = f->output_size[1];
  const struct { const char *name; float v; } numbers[] = {
      {"near", f->clip[0]}, {"far", f->clip[1]}, {"tan_y", f->clip[3]}, {"aspect", h > 0 ? f->output_size[0] / h : 1}};
  for (size_t k = 0; k < sizeof numbers / sizeof *numbers; k++) {
    lua_pushnumber(L, numbers[k].v);
    lua_setfield(L, -2, numbers[k].name);
  }
  return 1;
}

/* scene_blended(): whether a node of the scene has an alphaMode BLEND material
 * (the pipeline records its forward pass only then). */
static int l_scene_blended(lua_State *L) {
  lm_pipeline *p = recording(L, "scene_blended");
  lua_pushboolean(L, p->scene && lm_scene_has_blend(p->scene));
  return 1;
}

/* scene_reflective(): whether a material the scene draws is reflective. */
static int l_scene_reflective(lua_State *L) {
  lm_pipeline *p = recording(L, "scene_reflective");
  lua_pushboolean(L, p->scene && lm_scene_reflective(p->scene));
  return 1;
}

/* light_set(max[, cull[, front_lit]]): the scene's lights as a lighting pass's defines, which
 * shaders/lighting.glsl reads to evaluate each light unrolled, its kind,
 * falloff and shadow fixed, instead of the general loop: { LIGHT_SET = count,
 * LIGHT_BLOCKS (the records of the uniform blocks it reads: common.glsl),
 * LIGHT_SPOTS, LIGHT_SUNS (directional), LIGHT_SHADOWED (casts shadows),
 * LIGHT_FALLOFF_NONE, LIGHT_FALLOFF_SQUARE, LIGHT_FALLOFF_RANGE, and with
 * front_lit true LIGHT_FRONT_LIT (shadow tiles that hold no back face:
 * lm_shadow_front_lit; no offset lookup) = masks, bit i for light i } (zero
 * masks left out: one variant, one cache key). nil
 * when the scene has more than max lights (0 .. LM_LIGHT_SET_MAX): the
 * general loop, with light culling, reading storage blocks. With cull true,
 * { LIGHT_BLOCKS } alone when the scene has more than one light and the grid
 * can cull one of them (a spot's cone, a finite reach): the general loop,
 * culled, reading the uniform blocks (unrolled, every pixel pays for every
 * light: moving at 640x480, llvmpipe, garage's four spots 0.76x, the big
 * scene's eight ranged lights 0.56x the grid's `direct`). */
static int l_light_set(lua_State *L) {
  lm_pipeline *p = recording(L, "light_set");
  lua_Integer max = luaL_checkinteger(L, 1);
  if (max < 0 || max > LM_LIGHT_SET_MAX)
    return luaL_error(L, "light_set: max must be an integer in 0 .. %d (got %d)", LM_LIGHT_SET_MAX, (int)max);
  bool cull = lua_toboolean(L, 2), front_lit = lua_toboolean(L, 3);
  int n = p->scene ? p->scene->light_count : 0, cullable = 0;
  for (int i = 0; cull && i < n; i++) {
    const lm_light *l = &p->scene->lights[i];
    cullable += l->type == LM_LIGHT_SPOT || isfinite(lm_light_reach(l));
  }
  if (n > max) {
    lua_pushnil(L);
    return 1;
  }
  if (n > 1 && cullable > 0) {
    lua_createtable(L, 0, 1);
    lua_pushinteger(L, LM_LIGHT_SET_MAX);
    lua_setfield(L, -2, "LIGHT_BLOCKS");
    return 1;
  }
  unsigned spots = 0, suns = 0, shadowed = 0, falloff[4] = {0};
  for (int i = 0; i < n; i++) {
    const lm_light *l = &p->scene->lights[i];
    spots |= (unsigned)(l->type == LM_LIGHT_SPOT) << i;
    suns |= (unsigned)(l->type == LM_LIGHT_DIRECTIONAL) << i;
    shadowed |= (unsigned)l->casts_shadows << i;
    if ((unsigned)l->falloff < 4) falloff[l->falloff] |= 1u << i;
  }
  const struct { const char *name; unsigned mask; } masks[] = {
      {"LIGHT_SPOTS", spots}, {"LIGHT_SUNS", suns}, {"LIGHT_SHADOWED", shadowed},
      {"LIGHT_FALLOFF_NONE", falloff[LM_FALLOFF_NONE]}, {"LIGHT_FALLOFF_SQUARE", falloff[LM_FALLOFF_INVERSE_SQUARE]},
      {"LIGHT_FALLOFF_RANGE", falloff[LM_FALLOFF_RANGE]}, {"LIGHT_FRONT_LIT", front_lit ? p->front_lit & shadowed : 0}};
  lua_createtable(L, 0, 9);
  lua_pushinteger(L, n);
  lua_setfield(L, -2, "LIGHT_SET");
  lua_pushinteger(L, LM_LIGHT_SET_MAX); /* the uniform blocks' records (common.glsl) */
  lua_setfield(L, -2, "LIGHT_BLOCKS");
  for (size_t k = 0; k < sizeof masks / sizeof *masks; k++) {
    if (!masks[k].mask) continue;
    lua_pushinteger(L, masks[k].mask);
    lua_setfield(L, -2, masks[k].name);
  }
  return 1;
}

static int l_present(lua_State *L) {
  lm_pipeline *p = recording(L, "present");
  if (p->in_create) return luaL_error(L, "present() is called from OnRender");
  p->presented = to_target(L, 1, "present")->id;
  /* What it holds: pre-exposed radiance, or display values (tone mapped) the exposure leaves alone. */
  static const char *const referred[] = {"scene", "display", NULL};
  p->present_display = luaL_checkoption(L, 2, "scene", referred) == 1;
  caller_where(L, p->present_where, sizeof p->present_where);
  return 0;
}

/* meter(t): the lit image (pre-exposed radiance) whose brightness the
 * renderer reads back for the next frame's pre-exposure, where what the
 * frame presents is display values (tone mapped) or not the whole scene. */
static int l_meter(lua_State *L) {
  lm_pipeline *p = recording(L, "meter");
  if (p->in_create) return luaL_error(L, "meter() is called from OnRender");
  p->metered = to_target(L, 1, "meter")->id;
  return 0;
}

static int l_output_size(lua_State *L) {
  lm_pipeline *p = recording(L, "output_size");
  int w, h;
  lm_graph_output_size(p->graph, &w, &h);
  lua_pushinteger(L, w);
  lua_pushinteger(L, h);
  return 2;
}

/* still_frames(): how many frames in a row before this one drew the same
 * world (pipeline, scene content, lights, camera, output size, shaders);
 * 0 when anything changed since the last frame. still_frames("scene"): the
 * same without the camera and the output size (a light's view, such as an
 * RSM, is the same while it is above 0, whatever the camera does).
 * still_frames("light"): the same light (the lights' records and the
 * materials' emission), whatever moves. */
static int l_still_frames(lua_State *L) {
  lm_pipeline *p = recording(L, "still_frames");
  static const char *const what[] = {"world", "scene", "light", NULL};
  int k = luaL_checkoption(L, 1, "world", what);
  lua_pushinteger(L, p->in_create ? 0 : k == 0 ? p->still.world : k == 1 ? p->still.scene : p->still.light);
  return 1;
}

/* keep_exposure(): this frame shows results kept from an earlier one (a
 * settled GI result), pre-exposed as they were made: the renderer keeps the
 * last frame's pre-exposure, where the meter (a frame late) would change it
 * under them. The world is as it was, so that exposure still holds it. */
static int l_keep_exposure(lua_State *L) {
  lm_pipeline *p = recording(L, "keep_exposure");
  if (p->in_create) return luaL_error(L, "keep_exposure() is called from OnRender");
  p->keep_exposure = true;
  return 0;
}

/* light_peak(x, ...): radiances the frame's script adds besides the scene's
 * lights (ambient, background), so that the renderer's pre-exposure, which
 * brightens a dim scene before half floats store it, keeps them in range. */
static int l_light_peak(lua_State *L) {
  lm_pipeline *p = recording(L, "light_peak");
  for (int i = 1, n = lua_gettop(L); i <= n; i++) {
    double x = luaL_checknumber(L, i);
    if (x > p->light_peak && isfinite(x)) p->light_peak = (float)x;
  }
  return 0;
}

void lm_script_open_api(lua_State *L) {
  luaL_newmetatable(L, PLAN_META);
  lua_pushcfunction(L, l_plan_index);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
  luaL_newmetatable(L, TARGET_META);
  lua_pushcfunction(L, l_target_tostring);
  lua_setfield(L, -2, "__tostring");
  lua_pushcfunction(L, l_target_index);
  lua_setfield(L, -2, "__index");
  lua_pop(L, 1);
  static const luaL_Reg api[] = {{"target", l_target}, {"scene", l_scene}, {"pass", l_pass},
                                 {"present", l_present}, {"output_size", l_output_size}, {"still_frames", l_still_frames},
                                 {"light_peak", l_light_peak}, {"meter", l_meter}, {"keep_exposure", l_keep_exposure},
                                 {"shadow_plan", l_shadow_plan}, {"sky_sh", l_sky_sh}, {"cpu", l_cpu},
                                 {"scene_reflective", l_scene_reflective}, {"points", l_points},
                                 {"scene_blended", l_scene_blended},
                                 {"scene_bounds", l_scene_bounds}, {"light_set", l_light_set},
                                 {"camera_view", l_camera_view},
                                 {NULL, NULL}};
  lua_pushglobaltable(L);
  luaL_setfuncs(L, api, 0);
  lua_pop(L, 1);
}
