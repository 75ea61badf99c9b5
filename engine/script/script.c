/* The Lua state of a pipeline: sandbox, require, budget, options, calls. */
#include "script/script_internal.h"

#include <ctype.h>
#include <errno.h>
#include <lualib.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LOADED_KEY "limn.loaded"

/* ---- sandbox ----------------------------------------------------------- */
static void budget_hook(lua_State *L, lua_Debug *ar) {
  (void)ar;
  lm_pipeline *p = lm_script_pipeline(L);
  p->executed += 1000;
  if (p->executed > p->budget) {
    luaL_where(L, 0); /* inside a hook, level 0 is the Lua function that runs */
    lua_pushfstring(L, "instruction budget of %I exceeded (an endless loop?)", (lua_Integer)p->budget);
    lua_concat(L, 2);
    lua_error(L);
  }
}

static int l_print(lua_State *L) {
  lm_buf b = {0};
  int n = lua_gettop(L);
  for (int i = 1; i <= n; i++) {
    if (i > 1) lm_buf_append(&b, "\t", 1);
    lm_buf_append(&b, luaL_tolstring(L, i, NULL), -1);
    lua_pop(L, 1);
  }
  luaL_where(L, 1);
  lm_info("%s%s", lua_tostring(L, -1), b.data ? b.data : "");
  lm_buf_free(&b);
  return 0;
}

static bool module_name_ok(const char *name) {
  if (!*name || *name == '.') return false;
  for (const char *c = name; *c; c++)
    if (!(isalnum((unsigned char)*c) || *c == '_' || (*c == '.' && c[1] != '.'))) return false;
  return true;
}

/* require(name): a Lua file from the script's folder or <root>/scripts,
 * never a C module. Dots in the name are folders. */
static int l_require(lua_State *L) {
  const char *name = luaL_checkstring(L, 1);
  lm_pipeline *p = lm_script_pipeline(L);
  lua_getfield(L, LUA_REGISTRYINDEX, LOADED_KEY);
  lua_getfield(L, -1, name);
  if (!lua_isnil(L, -1)) return 1;
  lua_pop(L, 1);
  if (!module_name_ok(name))
    return luaL_error(L, "require '%s': module names are letters, digits, '_' and '.'", name);
  char rel[512], path[2048];
  snprintf(rel, sizeof rel, "%s", name);
  for (char *c = rel; *c; c++)
    if (*c == '.') *c = '/';
  snprintf(path, sizeof path, "%s/%s.lua", p->dir, rel);
  if (!lm_file_exists(path)) snprintf(path, sizeof path, "%s/scripts/%s.lua", lm_root_dir(), rel);
  if (!lm_file_exists(path))
    return luaL_error(L, "require '%s': no %s.lua in %s or %s/scripts", name, rel, p->dir, lm_root_dir());
  char chunk[2100];
  const char *root = lm_root_dir();
  size_t n = strlen(root);
  snprintf(chunk, sizeof chunk, "@%s", !strncmp(path, root, n) && path[n] == '/' ? path + n + 1 : path);
  lm_error err;
  char *text = lm_read_file(path, NULL, &err);
  if (!text) return luaL_error(L, "require '%s': %s", name, err.msg);
  int status = luaL_loadbufferx(L, text, strlen(text), chunk, "t");
  free(text);
  if (status != LUA_OK) return lua_error(L);
  lua_pushstring(L, name);
  lua_call(L, 1, 1);
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    lua_pushboolean(L, 1);
  }
  lua_pushvalue(L, -1);
  lua_setfield(L, -3, name);
  return 1;
}

static void open_sandbox(lua_State *L) {
  static const luaL_Reg libs[] = {{LUA_GNAME, luaopen_base},        {LUA_TABLIBNAME, luaopen_table},
                                  {LUA_STRLIBNAME, luaopen_string}, {LUA_MATHLIBNAME, luaopen_math},
                                  {LUA_UTF8LIBNAME, luaopen_utf8},  {LUA_COLIBNAME, luaopen_coroutine},
                                  {LUA_OSLIBNAME, luaopen_os},      {NULL, NULL}};
  for (const luaL_Reg *lib = libs; lib->func; lib++) {
    luaL_requiref(L, lib->name, lib->func, 1);
    lua_pop(L, 1);
  }
  /* Nothing that reads files or loads code from outside the engine's API. */
  static const char *drop[] = {"dofile", "loadfile", "load", NULL};
  for (const char **d = drop; *d; d++) {
    lua_pushnil(L);
    lua_setglobal(L, *d);
  }
  /* os keeps its clocks only: no execute, remove, rename, exit, getenv, tmpname. */
  lua_newtable(L);
  static const char *keep_os[] = {"clock", "time", "date", "difftime", NULL};
  lua_getglobal(L, "os");
  for (const char **k = keep_os; *k; k++) {
    lua_getfield(L, -1, *k);
    lua_setfield(L, -3, *k);
  }
  lua_pop(L, 1);
  lua_setglobal(L, "os");
  lua_getglobal(L, "string");
  lua_pushnil(L);
  lua_setfield(L, -2, "dump");
  lua_pop(L, 1);
  lua_register(L, "print", l_print);
  lua_register(L, "require", l_require);
  lua_newtable(L);
  lua_setfield(L, LUA_REGISTRYINDEX, LOADED_KEY);
}

/* ---- protected calls --------------------------------------------------- */
static int traceback(lua_State *L) {
  const char *msg = lua_tostring(L, 1);
  if (!msg) msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  luaL_traceback(L, L, msg, 1);
  return 1;
}

/* Calls the function below nargs arguments on the stack; on failure the
 * message is "script:line: cause" and the traceback follows on later lines. */
static bool pcall(lm_pipeline *p, int nargs, lm_error *err) {
  lua_State *L = p->L;
  int base = lua_gettop(L) - nargs;
  lua_pushcfunction(L, traceback);
  lua_insert(L, base);
  p->executed = 0;
  lua_sethook(L, budget_hook, LUA_MASKCOUNT, 1000);
  int status = lua_pcall(L, nargs, 0, base);
  lua_sethook(L, NULL, 0, 0);
  if (status != LUA_OK) {
    lm_error_set(err, "%s", lua_tostring(L, -1) ? lua_tostring(L, -1) : "unknown Lua error");
    lua_pop(L, 1);
  }
  lua_remove(L, base);
  return status == LUA_OK;
}

/* ---- options ----------------------------------------------------------- */
static void deep_copy(lua_State *L, int idx) {
  idx = lua_absindex(L, idx);
  lua_newtable(L);
  int copy = lua_gettop(L);
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    lua_pushvalue(L, -2);
    if (lua_istable(L, -2))
      deep_copy(L, -2);
    else
      lua_pushvalue(L, -2);
    lua_settable(L, copy);
    lua_pop(L, 1);
  }
}

/* Calls leaf(L, name, user) with each option's value on the stack top, in
 * name order; a table with string keys holds options, any other table is
 * one option's value. Sorted, so messages and lists read the same every time. */
static void walk_options(lua_State *L, int idx, const char *prefix,
                         void (*leaf)(lua_State *L, const char *name, void *user), void *user) {
  idx = lua_absindex(L, idx);
  lua_newtable(L);
  int keys = lua_absindex(L, -1), n = 0;
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    lua_pop(L, 1);
    if (lua_type(L, -1) == LUA_TSTRING) {
      lua_pushvalue(L, -1);
      lua_rawseti(L, keys, ++n);
    }
  }
  lua_getglobal(L, "table");
  lua_getfield(L, -1, "sort");
  lua_pushvalue(L, keys);
  lua_call(L, 1, 0);
  lua_pop(L, 1);
  for (int i = 1; i <= n; i++) {
    lua_rawgeti(L, keys, i);
    const char *k = lua_tostring(L, -1);
    char full[256];
    snprintf(full, sizeof full, "%s%s%s", prefix, *prefix ? "." : "", k);
    lua_gettable(L, idx);
    bool options = false;
    if (lua_istable(L, -1)) {
      lua_pushnil(L);
      while (!options && lua_next(L, -2)) {
        options = lua_type(L, -2) == LUA_TSTRING;
        lua_pop(L, lua_type(L, -2) == LUA_TSTRING ? 2 : 1);
      }
    }
    if (options)
      walk_options(L, -1, full, leaf, user);
    else
      leaf(L, full, user);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

static void list_leaf(lua_State *L, const char *name, void *user) {
  lm_buf *out = user;
  if (lua_istable(L, -1)) return; /* a list: --set cannot set it */
  lm_buf_printf(out, "%s%s=%s", out->len ? ", " : "", name, luaL_tolstring(L, -1, NULL));
  lua_pop(L, 1);
}

void lm_pipeline_list_options(const lm_pipeline *p, lm_buf *out) {
  lua_rawgeti(p->L, LUA_REGISTRYINDEX, p->options_ref);
  walk_options(p->L, -1, "", list_leaf, out);
  lua_pop(p->L, 1);
}

typedef struct option_list {
  lm_option_info *items;
  int count, cap;
} option_list;

static void info_leaf(lua_State *L, const char *name, void *user) {
  option_list *list = user;
  if (list->count == list->cap) {
    list->cap = list->cap ? list->cap * 2 : 64;
    list->items = lm_realloc(list->items, (size_t)list->cap * sizeof *list->items);
  }
  lm_option_info *o = &list->items[list->count++];
  *o = (lm_option_info){.rule = LM_RULE_NONE};
  snprintf(o->name, sizeof o->name, "%s", name);
  switch (lua_type(L, -1)) {
  case LUA_TBOOLEAN: o->type = LM_OPTION_BOOLEAN; break;
  case LUA_TNUMBER: o->type = LM_OPTION_NUMBER; break;
  case LUA_TSTRING: o->type = LM_OPTION_STRING; break;
  default: o->type = LM_OPTION_OTHER;
  }
  if (o->type == LM_OPTION_OTHER)
    snprintf(o->value, sizeof o->value, "%s", luaL_typename(L, -1));
  else {
    snprintf(o->value, sizeof o->value, "%s", luaL_tolstring(L, -1, NULL));
    lua_pop(L, 1);
  }
}

/* describe(info, name): the script's options.describe(name) into info (run by pcall). */
static int describe_rule(lua_State *L) {
  lm_option_info *o = lua_touserdata(L, 1);
  lua_getfield(L, LUA_REGISTRYINDEX, LOADED_KEY);
  lua_getfield(L, -1, "options");
  if (!lua_istable(L, -1)) return 0; /* the script never required options.lua */
  lua_getfield(L, -1, "describe");
  if (!lua_isfunction(L, -1)) return 0;
  lua_pushvalue(L, 2);
  lua_call(L, 1, 1);
  if (!lua_istable(L, -1)) return 0;
  static const char *kinds[] = {"number", "whole", "boolean", "one_of", "colour"};
  static const lm_option_rule rules[] = {LM_RULE_NUMBER, LM_RULE_WHOLE, LM_RULE_BOOLEAN, LM_RULE_ONE_OF,
                                         LM_RULE_COLOUR};
  lua_getfield(L, -1, "kind");
  const char *kind = lua_tostring(L, -1);
  for (int i = 0; kind && i < 5; i++)
    if (!strcmp(kind, kinds[i])) o->rule = rules[i];
  lua_pop(L, 1);
  double *bounds[] = {&o->lo, &o->hi, &o->step};
  const char *fields[] = {"lo", "hi", "step"};
  for (int i = 0; i < 3; i++) {
    lua_getfield(L, -1, fields[i]);
    *bounds[i] = lua_isnumber(L, -1) ? lua_tonumber(L, -1) : 0;
    lua_pop(L, 1);
  }
  lua_getfield(L, -1, "values");
  for (int i = 1; lua_istable(L, -1) && o->choice_count < LM_OPTION_CHOICES; i++) {
    lua_rawgeti(L, -1, i);
    if (lua_isnil(L, -1)) break;
    snprintf(o->choices[o->choice_count++], sizeof o->choices[0], "%s", luaL_tolstring(L, -1, NULL));
    lua_pop(L, 2);
  }
  return 0;
}

int lm_pipeline_options(lm_pipeline *p, lm_option_info **out) {
  option_list list = {0};
  lua_rawgeti(p->L, LUA_REGISTRYINDEX, p->options_ref);
  walk_options(p->L, -1, "", info_leaf, &list);
  lua_pop(p->L, 1);
  for (int i = 0; i < list.count; i++) {
    lm_error err;
    lua_pushcfunction(p->L, describe_rule);
    lua_pushlightuserdata(p->L, &list.items[i]);
    lua_pushstring(p->L, list.items[i].name);
    if (!pcall(p, 2, &err)) lm_warn("%s: describing option %s: %s", p->path, list.items[i].name, err.msg);
  }
  *out = list.items;
  return list.count;
}

bool lm_pipeline_get_option(const lm_pipeline *p, const char *name, char *value, size_t cap) {
  lua_State *L = p->L;
  int top = lua_gettop(L);
  lua_rawgeti(L, LUA_REGISTRYINDEX, p->options_ref);
  char key[256];
  for (const char *rest = name;;) {
    const char *dot = strchr(rest, '.');
    snprintf(key, sizeof key, "%.*s", dot ? (int)(dot - rest) : (int)strlen(rest), rest);
    if (!lua_istable(L, -1)) break;
    lua_getfield(L, -1, key);
    if (dot) {
      rest = dot + 1;
      continue;
    }
    bool found = !lua_isnil(L, -1);
    if (found) snprintf(value, cap, "%s", lua_istable(L, -1) ? "table" : luaL_tolstring(L, -1, NULL));
    lua_settop(L, top);
    return found;
  }
  lua_settop(L, top);
  return false;
}

bool lm_option_bool(const char *v, bool *out) {
  static const char *yes[] = {"true", "1", "on", "yes"}, *no[] = {"false", "0", "off", "no"};
  for (int i = 0; i < 4; i++) {
    if (!strcmp(v, yes[i])) return *out = true, true;
    if (!strcmp(v, no[i])) return *out = false, true;
  }
  return false;
}

bool lm_pipeline_set_option(lm_pipeline *p, const char *name, const char *value, lm_error *err) {
  lua_State *L = p->L;
  int top = lua_gettop(L);
  lua_rawgeti(L, LUA_REGISTRYINDEX, p->options_ref);
  char key[256];
  const char *rest = name;
  bool ok = false;
  for (;;) {
    const char *dot = strchr(rest, '.');
    snprintf(key, sizeof key, "%.*s", dot ? (int)(dot - rest) : (int)strlen(rest), rest);
    lua_getfield(L, -1, key);
    if (dot && lua_istable(L, -1)) {
      rest = dot + 1;
      continue;
    }
    /* "bloom=true" on a table with a boolean `enabled` sets bloom.enabled. */
    if (!dot && lua_istable(L, -1)) {
      lua_getfield(L, -1, "enabled");
      bool has_switch = lua_isboolean(L, -1);
      lua_pop(L, 1);
      if (has_switch) {
        rest = "enabled";
        continue;
      }
    }
    if (dot || lua_isnil(L, -1) || lua_istable(L, -1)) break;
    int type = lua_type(L, -1);
    lua_pop(L, 1);
    if (type == LUA_TBOOLEAN) {
      bool b;
      if (!lm_option_bool(value, &b)) {
        lm_error_set(err, "option %s: '%s' is not a boolean (true/false)", name, value);
        lua_settop(L, top);
        return false;
      }
      lua_pushboolean(L, b);
    } else if (type == LUA_TNUMBER) {
      char *end;
      errno = 0;
      double d = strtod(value, &end);
      if (end == value || *end || !isfinite(d) || errno) {
        lm_error_set(err, "option %s: '%s' is not a finite number", name, value);
        lua_settop(L, top);
        return false;
      }
      if (d == floor(d) && fabs(d) < 9e15)
        lua_pushinteger(L, (lua_Integer)d);
      else
        lua_pushnumber(L, d);
    } else {
      lua_pushstring(L, value);
    }
    lua_setfield(L, -2, key);
    ok = true;
    break;
  }
  lua_settop(L, top);
  if (!ok) {
    lm_buf known = {0};
    lm_pipeline_list_options(p, &known);
    lm_error_set(err, "unknown option '%s' for %s (known: %s)", name, p->path,
                 known.data ? known.data : "none");
    lm_buf_free(&known);
  }
  return ok;
}

/* ---- techniques -------------------------------------------------------- */
/* Techniques lists names, or rows { name, field = value, ... } (pp.lua's:
 * the script reads the rest of a row; the engine its name and viewer key). */
static int techniques(const lm_pipeline *p) {
  lua_getglobal(p->L, "Techniques");
  int n = lua_istable(p->L, -1) ? (int)lua_rawlen(p->L, -1) : 0;
  return n;
}

/* The field of technique i (NULL: its name) when it is a string, else
 * NULL; the string stays valid while Techniques holds it. */
static const char *technique_field(const lm_pipeline *p, int i, const char *field) {
  lua_State *L = p->L;
  techniques(p);
  lua_rawgeti(L, -1, i + 1);
  if (lua_istable(L, -1)) {
    if (field) lua_getfield(L, -1, field);
    else lua_rawgeti(L, -1, 1);
  } else if (field) {
    lua_pushnil(L); /* a name alone has no fields */
  } else {
    lua_pushvalue(L, -1);
  }
  const char *s = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
  lua_pop(L, 3);
  return s;
}

int lm_pipeline_technique_count(const lm_pipeline *p) {
  int n = techniques(p);
  lua_pop(p->L, 1);
  return n;
}

const char *lm_pipeline_technique_name(const lm_pipeline *p, int i) {
  const char *s = technique_field(p, i, NULL);
  return s ? s : "?";
}

const char *lm_pipeline_technique_key(const lm_pipeline *p, int i) { return technique_field(p, i, "key"); }

const char *lm_pipeline_technique(const lm_pipeline *p) { return p->technique; }
const char *lm_pipeline_path(const lm_pipeline *p) { return p->path; }

bool lm_pipeline_set_technique(lm_pipeline *p, const char *name, lm_error *err) {
  int n = lm_pipeline_technique_count(p);
  for (int i = 0; i < n; i++) {
    if (!strcmp(lm_pipeline_technique_name(p, i), name)) {
      snprintf(p->technique, sizeof p->technique, "%s", name);
      return true;
    }
  }
  lm_buf known = {0};
  for (int i = 0; i < n; i++) lm_buf_printf(&known, "%s%s", i ? ", " : "", lm_pipeline_technique_name(p, i));
  lm_error_set(err, "unknown technique '%s' for %s (known: %s)", name, p->path, known.data ? known.data : "none");
  lm_buf_free(&known);
  return false;
}

/* ---- loading and recording --------------------------------------------- */
lm_pipeline *lm_pipeline_load(const lm_pipeline_desc *desc, lm_error *err) {
  lm_pipeline *p = lm_alloc(sizeof *p);
  snprintf(p->path, sizeof p->path, "%s", desc->path);
  lm_dirname(desc->path, p->dir, sizeof p->dir);
  p->budget = desc->instruction_budget > 0 ? desc->instruction_budget : 100000000L;
  p->presented = p->metered = -1;
  p->L = luaL_newstate();
  lua_State *L = p->L;
  lua_pushlightuserdata(L, p);
  lua_setfield(L, LUA_REGISTRYINDEX, LM_SCRIPT_PIPELINE_KEY);
  open_sandbox(L);
  lm_script_open_api(L);
  char *text = lm_read_file(desc->path, NULL, err);
  if (!text) {
    lm_pipeline_destroy(p);
    return NULL;
  }
  char chunk[1100];
  snprintf(chunk, sizeof chunk, "@%s", desc->path);
  int status = luaL_loadbufferx(L, text, strlen(text), chunk, "t");
  free(text);
  if (status != LUA_OK) {
    lm_error_set(err, "%s", lua_tostring(L, -1));
    lm_pipeline_destroy(p);
    return NULL;
  }
  if (!pcall(p, 0, err)) {
    lm_pipeline_destroy(p);
    return NULL;
  }
  lua_getglobal(L, "OnRender");
  bool has_render = lua_isfunction(L, -1);
  lua_pop(L, 1);
  if (!has_render) {
    lm_error_set(err, "%s: defines no function OnRender(tech)", desc->path);
    lm_pipeline_destroy(p);
    return NULL;
  }
  lua_getglobal(L, "Options");
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    lua_newtable(L);
  } else if (!lua_istable(L, -1)) {
    lm_error_set(err, "%s: Options must be a table of option = default", desc->path);
    lm_pipeline_destroy(p);
    return NULL;
  }
  deep_copy(L, -1);
  p->options_ref = luaL_ref(L, LUA_REGISTRYINDEX);
  lua_pop(L, 1);
  if (lm_pipeline_technique_count(p) < 1) {
    lm_error_set(err, "%s: Techniques must list the script's techniques, e.g. Techniques = { \"dl\" }",
                 desc->path);
    lm_pipeline_destroy(p);
    return NULL;
  }
  for (int i = 0; i < lm_pipeline_technique_count(p); i++) {
    if (!technique_field(p, i, NULL)) {
      lm_error_set(err, "%s: Techniques[%d] must be a name or a row { \"name\", ... }", desc->path, i + 1);
      lm_pipeline_destroy(p);
      return NULL;
    }
  }
  snprintf(p->technique, sizeof p->technique, "%s", lm_pipeline_technique_name(p, 0));
  return p;
}

void lm_pipeline_destroy(lm_pipeline *p) {
  if (!p) return;
  if (p->L) lua_close(p->L);
  free(p->shadow_levels);
  free(p->shadow_depths);
  free(p);
}

bool lm_pipeline_created(const lm_pipeline *p) { return p->created; }

void lm_pipeline_set_scene(lm_pipeline *p, const lm_scene *scene, const lm_frame_data *camera,
                           lm_shadow_plan *shadows, lm_still_frames still) {
  p->still = still;
  p->scene = scene;
  p->camera = camera;
  p->shadows = shadows;
}

void lm_pipeline_set_front_lit(lm_pipeline *p, unsigned lights) { p->front_lit = lights; }

const char *lm_pipeline_present_where(const lm_pipeline *p) { return p->present_where; }
bool lm_pipeline_present_display(const lm_pipeline *p) { return p->present_display; }
float lm_pipeline_light_peak(const lm_pipeline *p) { return p->light_peak; }
bool lm_pipeline_keeps_exposure(const lm_pipeline *p) { return p->keep_exposure; }
int lm_pipeline_metered(const lm_pipeline *p) { return p->metered; }

bool lm_pipeline_record(lm_pipeline *p, lm_graph *g, int *presented, lm_error *err) {
  static unsigned serial;
  lua_State *L = p->L;
  p->graph = g;
  p->presented = p->metered = -1;
  bool ok = true;
  if (!p->created) {
    p->in_create = true;
    p->frame = 0;
    lua_getglobal(L, "OnCreate");
    if (lua_isfunction(L, -1))
      ok = pcall(p, 0, err);
    else
      lua_pop(L, 1);
    p->in_create = false;
    p->created = ok;
  }
  if (ok) {
    p->frame = ++serial ? serial : ++serial; /* never 0: that marks OnCreate's targets */
    p->light_peak = 0;
    p->keep_exposure = false;
    lua_getglobal(L, "OnRender");
    lua_rawgeti(L, LUA_REGISTRYINDEX, p->options_ref);
    deep_copy(L, -1);
    lua_remove(L, -2);
    lua_pushstring(L, p->technique);
    lua_setfield(L, -2, "name");
    ok = pcall(p, 1, err);
  }
  if (ok && p->presented < 0) {
    lm_error_set(err, "%s: OnRender presented nothing (call present(target))", p->path);
    ok = false;
  }
  *presented = p->presented;
  p->graph = NULL;
  return ok;
}
