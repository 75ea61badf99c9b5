/* limn capture --job FILE: many views of many scenes through one GL context
 * and one pipeline. The job file is Lua data (evaluated with no library but
 * math's pure functions: math.pi, math.huge, math.floor...; not random):
 *
 *   return {
 *     script = "scripts/pp.lua",                  -- default scripts/pp.lua
 *     scenes = { "data/scenes/cornell.glb",       -- views from cornell.cams beside it
 *                { scene = "data/scenes/office.glb", cameras = "data/scenes/office.cams" } },
 *     techniques = { "dl", "isr" },               -- default: the script's first
 *     sizes = { "96x72" },                        -- default 256x192
 *     set = { ambient = 0.05, ["isr.samples"] = 8 },
 *     frames = 1,
 *     output = "out/{scene}/{camera}_{technique}_{size}.png",
 *     manifest = "out/manifest.json",             -- default: beside the images
 *     time = { 0, 2, 24 },                        -- a sequence: start, stop (seconds), fps;
 *                                                 -- or time = 1.5, a still at that time
 *     animation = "walk",                         -- name or index (default all)
 *     renderer = "cycles",                        -- the references' (limn reference, report):
 *                                                 -- "pov" (default) or "cycles"
 *     references = { sky = "0.1,0.15,0.3:0.3,0.32,0.35:1", materials = "pbr", approximate = true },
 *                                                 -- as --sky, --materials, --approximate (which win)
 *     path = { { t = 0, eye = { 0, 1, 5 }, target = { 0, 1, 0 }, fov = 45 }, ... },
 *                                                 -- or "file.cams" / { cameras = "file.cams",
 *                                                 -- times = {...} }; or instead
 *     turntable = { turns = 1, elevation = 20, distance = "auto" },
 *   }
 *
 * Views are numbered scene by scene, then size, technique, camera and frame
 * (a sequence's frames are consecutive views); a shard I/N renders views I,
 * I+N, ... of a still job and the I-th of N contiguous runs of a sequence's
 * views (job_shard_of). A shard starts its run cold: it does not render the
 * frames before it to warm temporal histories up, so that shards cost the
 * same and never render a frame twice (it poses the scene at the frame
 * before first, for velocities). An image that exists is skipped unless
 * --force. The manifest is rewritten (whole, renamed into place) after each
 * image, so a killed job leaves it consistent with the files on disk. */
#define _GNU_SOURCE
#include <dirent.h>
#include <glob.h>
#include <signal.h>
#include <lauxlib.h>
#include <lualib.h>
#include <lua.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "job.h"
#include "tools.h"
#include "scene/gltf.h"

/* ---- reading the job file ---------------------------------------------- */

static void hook_budget(lua_State *L, lua_Debug *ar) {
  (void)ar;
  luaL_error(L, "the job file runs too long (it should be a table of data)");
}

/* A path named in the job: beside the job file, else under the engine's root, else as given. */
static void resolve(const job *j, const char *given, char *out, size_t cap) {
  if (given[0] == '/') {
    snprintf(out, cap, "%s", given);
    return;
  }
  snprintf(out, cap, "%s/%s", j->dir, given);
  if (!lm_file_exists(out)) capture_resolve(given, out, cap);
}

static bool field_string(lua_State *L, int t, const char *key, char *out, size_t cap, const char *path,
                         lm_error *err) {
  lua_getfield(L, t, key);
  bool ok = true;
  if (lua_type(L, -1) == LUA_TSTRING) {
    snprintf(out, cap, "%s", lua_tostring(L, -1));
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: %s: a string, not a %s", path, key, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}


/* Refuses a key of the table at the top of the stack that is neither in
 * `known` (NULL-ended) nor an index 1 .. max_index: a misspelt field
 * ("fvo") is an error naming it, not a default taken in silence. */
static bool known_fields(lua_State *L, const char *const *known, int max_index, const char *what, lm_error *err) {
  bool ok = true;
  lua_pushnil(L);
  while (ok && lua_next(L, -2)) {
    lua_pop(L, 1);
    bool found = lua_isinteger(L, -1) && lua_tointeger(L, -1) >= 1 && lua_tointeger(L, -1) <= max_index;
    for (const char *const *k = known; *k && !found && lua_type(L, -1) == LUA_TSTRING; k++)
      found = !strcmp(*k, lua_tostring(L, -1));
    if (found) continue;
    lm_buf names = {0};
    for (const char *const *k = known; *k; k++) lm_buf_printf(&names, "%s%s", k == known ? "" : ", ", *k);
    if (max_index > 0 && known[0]) lm_buf_printf(&names, ", or %d in a list", max_index);
    else if (!known[0]) lm_buf_printf(&names, "none: a list of %d", max_index);
    lua_pushvalue(L, -1); /* tostring on a copy */
    const char *key = lua_type(L, -1) == LUA_TSTRING || lua_type(L, -1) == LUA_TNUMBER ? lua_tostring(L, -1)
                                                                                    : luaL_typename(L, -1);
    lm_error_set(err, "%s: unknown field '%s' (known: %s)", what, key, names.data);
    lm_buf_free(&names);
    lua_pop(L, 2); /* the copy and lua_next's key */
    ok = false;
  }
  return ok;
}

/* Reads the list at key: each element through `each` (index from 1). */
static bool read_list(lua_State *L, int t, const char *key, const char *path, int *count, lm_error *err,
                      bool (*each)(lua_State *L, job *j, int i, lm_error *err), job *j) {
  lua_getfield(L, t, key);
  bool ok = true;
  if (lua_type(L, -1) == LUA_TSTRING) { /* one element, not a list */
    ok = each(L, j, 1, err);
    *count = ok;
  } else if (lua_istable(L, -1)) {
    int n = (int)lua_rawlen(L, -1);
    static const char *const none[] = {NULL};
    char what[1100];
    snprintf(what, sizeof what, "%s: %s", path, key);
    if (n > MAX_LIST) {
      lm_error_set(err, "%s: %s: at most %d entries", path, key, MAX_LIST);
      ok = false;
    } else {
      ok = known_fields(L, none, n, what, err);
    }
    for (int i = 1; i <= n && ok; i++) {
      lua_rawgeti(L, -1, i);
      ok = each(L, j, i, err);
      lua_pop(L, 1);
      if (ok) *count = i;
    }
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: %s: a list, not a %s", path, key, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}

static bool each_scene(lua_State *L, job *j, int i, lm_error *err) {
  job_scene *s = &j->scenes[i - 1];
  char given[1024] = "", cams[1024] = "";
  if (lua_type(L, -1) == LUA_TSTRING) {
    snprintf(given, sizeof given, "%s", lua_tostring(L, -1));
  } else if (lua_istable(L, -1)) {
    char what[64];
    snprintf(what, sizeof what, "%s: scenes[%d]", j->path, i);
    static const char *const known[] = {"scene", "cameras", NULL};
    if (!known_fields(L, known, 0, what, err) || !field_string(L, -1, "scene", given, sizeof given, what, err) ||
        !field_string(L, -1, "cameras", cams, sizeof cams, what, err))
      return false;
  } else {
    lm_error_set(err, "%s: scenes[%d]: a file name or { scene = FILE, cameras = FILE }, not a %s", j->path, i,
                 luaL_typename(L, -1));
    return false;
  }
  if (!given[0] || !lm_scene_is_gltf_name(given)) {
    lm_error_set(err, "%s: scenes[%d]: '%s' is not a .gltf or .glb file", j->path, i, given);
    return false;
  }
  resolve(j, given, s->path, sizeof s->path);
  s->cameras_given = cams[0] != '\0';
  if (cams[0]) {
    resolve(j, cams, s->cameras, sizeof s->cameras);
  } else { /* beside the scene, .cams for .glb/.gltf */
    memcpy(s->cameras, s->path, sizeof s->cameras);
    char *dot = strrchr(s->cameras, '.'); /* there is one: the name ends in .gltf or .glb */
    if ((size_t)(dot - s->cameras) + 6 <= sizeof s->cameras) memcpy(dot, ".cams", 6);
  }
  const char *base = strrchr(s->path, '/');
  snprintf(s->name, sizeof s->name, "%s", base ? base + 1 : s->path);
  char *dot = strrchr(s->name, '.');
  if (dot) *dot = '\0';
  return true;
}

static bool each_technique(lua_State *L, job *j, int i, lm_error *err) {
  if (lua_type(L, -1) != LUA_TSTRING) {
    lm_error_set(err, "%s: techniques[%d]: a name, not a %s", j->path, i, luaL_typename(L, -1));
    return false;
  }
  snprintf(j->techniques[i - 1], sizeof j->techniques[0], "%s", lua_tostring(L, -1));
  return true;
}

/* events = { 12, 30 }: frame numbers (limn report checks them against the
 * job's sequences). */
static bool each_event(lua_State *L, job *j, int i, lm_error *err) {
  lua_Integer f = lua_isinteger(L, -1) ? lua_tointeger(L, -1) : -1;
  if (f >= 0 && f <= INT_MAX) {
    j->events[i - 1] = (int)f;
    return true;
  }
  if (lua_type(L, -1) == LUA_TNUMBER)
    lm_error_set(err, "%s: events[%d]: %g is not a frame number (0, 1, ...)", j->path, i, lua_tonumber(L, -1));
  else lm_error_set(err, "%s: events[%d]: a frame number (0, 1, ...), not a %s", j->path, i, luaL_typename(L, -1));
  return false;
}

static bool each_size(lua_State *L, job *j, int i, lm_error *err) {
  int *wh = j->sizes[i - 1];
  if (lua_type(L, -1) != LUA_TSTRING || !limn_parse_size(lua_tostring(L, -1), &wh[0], &wh[1])) {
    lm_error_set(err, "%s: sizes[%d]: want \"WxH\" within 1x1 .. 16384x16384, not %s", j->path, i,
                 lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : luaL_typename(L, -1));
    return false;
  }
  return true;
}

static bool read_sets(lua_State *L, job *j, lm_error *err) {
  lua_getfield(L, -1, "set");
  bool ok = true;
  if (lua_istable(L, -1)) {
    lua_pushnil(L);
    while (ok && lua_next(L, -2)) {
      int vt = lua_type(L, -1);
      if (lua_type(L, -2) != LUA_TSTRING) {
        lm_error_set(err, "%s: set: option names are strings (set = { ambient = 0.1 })", j->path);
        ok = false;
      } else if (j->set_count == MAX_LIST) {
        lm_error_set(err, "%s: set: at most %d options", j->path, MAX_LIST);
        ok = false;
      } else if (vt != LUA_TNUMBER && vt != LUA_TSTRING && vt != LUA_TBOOLEAN) {
        lm_error_set(err, "%s: set.%s: a number, string or boolean, not a %s", j->path, lua_tostring(L, -2),
                     luaL_typename(L, -1));
        ok = false;
      } else {
        snprintf(j->set_names[j->set_count], sizeof j->set_names[0], "%s", lua_tostring(L, -2));
        if (vt == LUA_TBOOLEAN) {
          snprintf(j->set_values[j->set_count], sizeof j->set_values[0], "%s", lua_toboolean(L, -1) ? "true" : "false");
        } else {
          lua_pushvalue(L, -1); /* tostring on a copy keeps lua_next's key intact */
          snprintf(j->set_values[j->set_count], sizeof j->set_values[0], "%s", lua_tostring(L, -1));
          lua_pop(L, 1);
        }
        j->set_count++;
      }
      lua_pop(L, 1);
    }
    if (!ok) lua_pop(L, 1); /* the key lua_next left */
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: set: a table { option = value }, not a %s", j->path, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}

/* A finite number at t[key] (or t[index] when key is NULL) into *out; nil
 * leaves *out. */
static bool field_number(lua_State *L, int t, const char *key, int index, double *out, const char *what,
                         lm_error *err) {
  if (key) lua_getfield(L, t, key);
  else lua_rawgeti(L, t, index);
  bool ok = true;
  if (lua_type(L, -1) == LUA_TNUMBER && isfinite(lua_tonumber(L, -1))) {
    *out = lua_tonumber(L, -1);
  } else if (lua_type(L, -1) == LUA_TNUMBER) {
    lm_error_set(err, "%s: %g is not a finite number", what, lua_tonumber(L, -1));
    ok = false;
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: a number, not a %s", what, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}

/* time = seconds | { start, stop, fps } (or named). */
static bool read_time(lua_State *L, job *j, lm_error *err) {
  char what[1100];
  lua_getfield(L, -1, "time");
  int type = lua_type(L, -1);
  bool ok = true;
  j->timed = type != LUA_TNIL;
  j->frame_count = 1;
  if (type == LUA_TNUMBER) {
    snprintf(what, sizeof what, "%s: time", j->path);
    lua_pop(L, 1);
    ok = field_number(L, -1, "time", 0, &j->time_start, what, err);
    j->time_stop = j->time_start;
    return ok;
  }
  if (type == LUA_TTABLE) {
    static const char *const names[4] = {"start", "stop", "fps", NULL};
    double v[3] = {NAN, NAN, NAN};
    snprintf(what, sizeof what, "%s: time", j->path);
    ok = known_fields(L, names, 3, what, err);
    for (int i = 0; i < 3 && ok; i++) {
      snprintf(what, sizeof what, "%s: time.%s", j->path, names[i]);
      ok = field_number(L, -1, NULL, i + 1, &v[i], what, err) && field_number(L, -1, names[i], 0, &v[i], what, err);
      if (ok && isnan(v[i])) {
        lm_error_set(err, "%s: missing (time = { start, stop, fps }, seconds and frames a second)", what);
        ok = false;
      }
    }
    if (ok && v[1] < v[0]) {
      lm_error_set(err, "%s: time.stop: %g is before time.start %g", j->path, v[1], v[0]);
      ok = false;
    } else if (ok && !(v[2] > 0)) {
      lm_error_set(err, "%s: time.fps: %g frames a second; want a number above 0", j->path, v[2]);
      ok = false;
    } else if (ok && (v[1] - v[0]) * v[2] >= MAX_FRAMES) {
      lm_error_set(err, "%s: time: %g s at %g fps is more than %d frames", j->path, v[1] - v[0], v[2], MAX_FRAMES);
      ok = false;
    }
    if (ok) {
      j->time_start = v[0], j->time_stop = v[1], j->fps = v[2];
      j->frame_count = (int)floor((v[1] - v[0]) * v[2] + 1e-9) + 1;
    }
  } else if (type != LUA_TNIL) {
    lm_error_set(err, "%s: time: seconds, or { start, stop, fps }, not a %s", j->path, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}

/* path[i]'s eye or target: three numbers within 1e9 (a camera further out
 * has no depth range floats can hold with the scene's). */
static bool read_point(lua_State *L, const char *key, float out[3], const char *what, lm_error *err) {
  lua_getfield(L, -1, key);
  bool ok = lua_istable(L, -1) && lua_rawlen(L, -1) == 3;
  if (!ok) lm_error_set(err, "%s.%s: needs 3 numbers", what, key);
  for (int k = 0; k < 3 && ok; k++) {
    lua_rawgeti(L, -1, k + 1);
    double v = lua_tonumber(L, -1);
    if (lua_type(L, -1) != LUA_TNUMBER) lm_error_set(err, "%s.%s: needs 3 numbers, not a %s", what, key,
                                                      luaL_typename(L, -1)), ok = false;
    else if (!(fabs(v) < 1e9)) lm_error_set(err, "%s.%s[%d]: %g is not within +-1e9", what, key, k + 1, v), ok = false;
    out[k] = (float)v;
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return ok;
}

/* The keys of a camera list (engine/scene/camlist.c): each view's eye, a
 * target one unit along its direction (the list keeps directions, not
 * distances) and its fov, at `times` or evenly over the job's time. */
static bool read_path_list(lua_State *L, job *j, const char *given, lm_error *err) {
  char file[1024];
  resolve(j, given, file, sizeof file);
  lm_scene *scratch = lm_scene_create("path");
  int count = 0, first = lm_scene_add_camera_list(scratch, file, &count, err);
  bool ok = first >= 0;
  if (!ok) lm_error_prefix(err, "%s: path", j->path);
  if (ok && count > MAX_PATH_KEYS) {
    lm_error_set(err, "%s: path: %s has %d views; at most %d", j->path, file, count, MAX_PATH_KEYS);
    ok = false;
  }
  bool has_times = false;
  if (ok && lua_istable(L, -1)) {
    lua_getfield(L, -1, "times");
    has_times = !lua_isnil(L, -1);
    if (!has_times) lua_pop(L, 1);
  }
  if (has_times && (!lua_istable(L, -1) || (int)lua_rawlen(L, -1) != count)) {
    lm_error_set(err, "%s: path.times: a list of %d times (one for each view of %s)", j->path, count, file);
    ok = false;
  }
  for (int i = 0; i < count && ok; i++) {
    camera_key *k = &j->keys[i];
    const float *w = scratch->nodes[scratch->cameras[first + i].node].world;
    for (int c = 0; c < 3; c++) k->eye[c] = w[12 + c], k->target[c] = w[12 + c] - w[8 + c];
    k->fov = scratch->cameras[first + i].fov_y * (float)(180 / M_PI);
    k->t = count == 1 ? j->time_start : j->time_start + (j->time_stop - j->time_start) * i / (count - 1);
    if (has_times) {
      char what[1100];
      snprintf(what, sizeof what, "%s: path.times[%d]", j->path, i + 1);
      k->t = NAN;
      ok = field_number(L, -1, NULL, i + 1, &k->t, what, err);
      if (ok && !isfinite(k->t)) lm_error_set(err, "%s: a number of seconds", what), ok = false;
    }
  }
  if (has_times) lua_pop(L, 1);
  j->key_count = ok ? count : 0;
  lm_scene_destroy(scratch);
  return ok;
}

/* One key of a path's list: path[i] = { t = SECONDS, eye = {x,y,z}, target = {x,y,z}, fov = DEGREES }. */
static bool read_key(lua_State *L, job *j, int i, lm_error *err) {
  char what[1100], field[1120];
  snprintf(what, sizeof what, "%s: path[%d]", j->path, i);
  camera_key *k = &j->keys[i - 1];
  lua_rawgeti(L, -1, i);
  bool ok = lua_istable(L, -1);
  if (!ok)
    lm_error_set(err, "%s: a key { t = SECONDS, eye = {x,y,z}, target = {x,y,z}, fov = DEGREES }, not a %s", what,
                 luaL_typename(L, -1));
  double t = NAN, fov = i > 1 ? j->keys[i - 2].fov : 45; /* fov: the previous key's */
  static const char *const known[] = {"t", "eye", "target", "fov", NULL};
  ok = ok && known_fields(L, known, 0, what, err);
  snprintf(field, sizeof field, "%s.t", what);
  ok = ok && field_number(L, -1, "t", 0, &t, field, err);
  snprintf(field, sizeof field, "%s.fov", what);
  ok = ok && field_number(L, -1, "fov", 0, &fov, field, err);
  ok = ok && read_point(L, "eye", k->eye, what, err) && read_point(L, "target", k->target, what, err);
  lua_pop(L, 1);
  if (ok && isnan(t)) lm_error_set(err, "%s.t: missing (the key's time in seconds)", what), ok = false;
  k->t = t, k->fov = (float)fov;
  return ok;
}

/* path = { key, ... }, "file.cams" or { cameras = "file.cams", times = {...} }. */
static bool read_path(lua_State *L, job *j, lm_error *err) {
  lua_getfield(L, -1, "path");
  bool ok = true;
  if (lua_type(L, -1) == LUA_TSTRING) {
    char given[1024];
    snprintf(given, sizeof given, "%s", lua_tostring(L, -1));
    ok = read_path_list(L, j, given, err);
  } else if (lua_istable(L, -1)) {
    lua_getfield(L, -1, "cameras");
    char given[1024] = "";
    if (lua_type(L, -1) == LUA_TSTRING) snprintf(given, sizeof given, "%s", lua_tostring(L, -1));
    lua_pop(L, 1);
    int n = (int)lua_rawlen(L, -1);
    static const char *const list_fields[] = {"cameras", "times", NULL}, *const none[] = {NULL};
    char what[1100];
    snprintf(what, sizeof what, "%s: path", j->path);
    if (given[0]) {
      ok = known_fields(L, list_fields, 0, what, err) && read_path_list(L, j, given, err);
    } else if (n < 1 || n > MAX_PATH_KEYS) {
      lm_error_set(err, "%s: path: 1 to %d keys { t = SECONDS, eye = {x,y,z}, target = {x,y,z}, fov = DEGREES }, "
                   "or { cameras = FILE, times = {...} }", j->path, MAX_PATH_KEYS);
      ok = false;
    } else {
      ok = known_fields(L, none, n, what, err);
    }
    for (int i = 1; i <= n && ok && !given[0]; i++) ok = read_key(L, j, i, err);
    if (ok && !given[0]) j->key_count = n;
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: path: a list of keys or a camera list file, not a %s", j->path, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  for (int i = 0; i < j->key_count && ok; i++) {
    const camera_key *k = &j->keys[i];
    float d[3] = {k->target[0] - k->eye[0], k->target[1] - k->eye[1], k->target[2] - k->eye[2]};
    if (!(fabs(k->t) < 1e9)) /* the curve divides by key intervals: 1e308 - -1e308 overflows */
      lm_error_set(err, "%s: path[%d].t: %g s is not within +-1e9", j->path, i + 1, k->t), ok = false;
    else if (i > 0 && !(k->t > k[-1].t))
      lm_error_set(err, "%s: path[%d].t: %g is not after path[%d].t (%g)", j->path, i + 1, k->t, i, k[-1].t), ok = false;
    else if (!(k->fov > 0.1f && k->fov < 179))
      lm_error_set(err, "%s: path[%d].fov: %g degrees is outside (0.1, 179)", j->path, i + 1, k->fov), ok = false;
    else if (!(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0))
      lm_error_set(err, "%s: path[%d]: the eye is at the target", j->path, i + 1), ok = false;
  }
  return ok;
}

/* Keys apart, a path's eye can still fly through the point it looks at
 * between them (eye and target crossing), where the view has no direction:
 * each frame's eye must stay off its target by a millionth of the keys'
 * largest eye-to-target distance. */
/* A view's eye-to-target distance, in doubles. */
static double eye_to_target(const float eye[3], const float target[3]) {
  double d2 = 0;
  for (int c = 0; c < 3; c++) d2 += ((double)target[c] - eye[c]) * ((double)target[c] - eye[c]);
  return sqrt(d2);
}

static bool path_frames_check(const job *j, lm_error *err) {
  double reach = 0;
  for (int i = 0; i < j->key_count; i++) reach = fmax(reach, eye_to_target(j->keys[i].eye, j->keys[i].target));
  for (int f = 0; f < j->frame_count && j->key_count > 1; f++) {
    double t = j->fps > 0 ? j->time_start + f / j->fps : j->time_start; /* as job_views times it */
    float eye[3], target[3], fov;
    camera_path_eval(j->keys, j->key_count, t, eye, target, &fov);
    if (eye_to_target(eye, target) > 1e-6 * reach) continue;
    int i = 0;
    while (i < j->key_count - 2 && t >= j->keys[i + 1].t) i++;
    char seconds[LIMN_TIME_TEXT];
    lm_error_set(err, "%s: path: frame %d at %s s: the eye reaches the target between path[%d] and path[%d] "
                 "(the path flies through the point it looks at: no view direction there)", j->path, f,
                 limn_time_text(t, 3, seconds), i + 1, i + 2);
    return false;
  }
  return true;
}

/* turntable = { turns = 1, elevation = 20, distance = "auto" | number }. */
static bool read_turntable(lua_State *L, job *j, lm_error *err) {
  lua_getfield(L, -1, "turntable");
  bool ok = true;
  j->turns = 1, j->elevation = 20, j->distance = 0;
  if (lua_istable(L, -1)) {
    char what[1100];
    j->turntable = true;
    static const char *const known[] = {"turns", "elevation", "distance", NULL};
    snprintf(what, sizeof what, "%s: turntable", j->path);
    ok = known_fields(L, known, 0, what, err);
    snprintf(what, sizeof what, "%s: turntable.turns", j->path);
    ok = ok && field_number(L, -1, "turns", 0, &j->turns, what, err);
    snprintf(what, sizeof what, "%s: turntable.elevation", j->path);
    ok = ok && field_number(L, -1, "elevation", 0, &j->elevation, what, err);
    if (ok && !(fabs(j->elevation) < 89)) {
      lm_error_set(err, "%s: %g degrees; want one within (-89, 89)", what, j->elevation);
      ok = false;
    }
    lua_getfield(L, -1, "distance");
    bool is_auto = lua_isnil(L, -1) || (lua_type(L, -1) == LUA_TSTRING && !strcmp(lua_tostring(L, -1), "auto"));
    lua_pop(L, 1);
    snprintf(what, sizeof what, "%s: turntable.distance", j->path);
    if (ok && !is_auto) ok = field_number(L, -1, "distance", 0, &j->distance, what, err);
    if (ok && !is_auto && !(j->distance > 0 && j->distance < 1e9)) {
      lm_error_set(err, "%s: %g; want \"auto\" or a distance in (0, 1e9)", what, j->distance);
      ok = false;
    }
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: turntable: a table { turns = 1, elevation = 20, distance = \"auto\" }, not a %s",
                 j->path, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}

/* references = { sky = "Z:H[:I]", materials = "pbr" | "phong", approximate = true }: the
 * references' settings kept with the views they judge, so that a sky-lit job is never compared
 * with sky-less references because a flag was left off a command line. */
static bool read_references(lua_State *L, job *j, lm_error *err) {
  job_references *r = &j->references;
  *r = (job_references){.pbr_materials = -1, .approximate = -1};
  lua_getfield(L, -1, "references");
  bool ok = true;
  if (lua_istable(L, -1)) {
    lua_pushnil(L);
    while (ok && lua_next(L, -2)) {
      const char *key = lua_type(L, -2) == LUA_TSTRING ? lua_tostring(L, -2) : "?";
      const char *value = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : NULL;
      if (!strcmp(key, "sky")) {
        ok = value && limn_parse_sky(value, &r->sky);
        r->has_sky = ok;
        if (!ok) lm_error_set(err, "%s: references.sky: \"ZENITH:HORIZON[:INTENSITY]\" (colours r,g,b or one grey "
                              "number in 0 .. 1e6), not %s", j->path, value ? value : luaL_typename(L, -1));
      } else if (!strcmp(key, "materials")) {
        ok = value && (!strcmp(value, "pbr") || !strcmp(value, "phong"));
        r->pbr_materials = ok && !strcmp(value, "pbr");
        if (!ok) lm_error_set(err, "%s: references.materials: \"phong\" or \"pbr\", not %s", j->path,
                              value ? value : luaL_typename(L, -1));
      } else if (!strcmp(key, "approximate")) {
        ok = lua_isboolean(L, -1);
        r->approximate = lua_toboolean(L, -1);
        if (!ok) lm_error_set(err, "%s: references.approximate: true or false, not a %s", j->path, luaL_typename(L, -1));
      } else {
        lm_error_set(err, "%s: references: unknown field '%s' (known: sky, materials, approximate)", j->path, key);
        ok = false;
      }
      lua_pop(L, ok ? 1 : 2);
    }
  } else if (!lua_isnil(L, -1)) {
    lm_error_set(err, "%s: references: a table { sky = \"Z:H[:I]\", materials = \"pbr\", approximate = true }, "
                 "not a %s", j->path, luaL_typename(L, -1));
    ok = false;
  }
  lua_pop(L, 1);
  return ok;
}

static int compare_sets(const void *a, const void *b) { return strcmp(a, b); }

bool job_read(job *j, const char *path, lm_error *err) {
  memset(j, 0, sizeof *j);
  snprintf(j->path, sizeof j->path, "%s", path);
  lm_dirname(path, j->dir, sizeof j->dir);
  size_t len;
  char *text = lm_read_file(path, &len, err);
  if (!text) return false;
  j->hash = lm_hash(text, len, LM_HASH_SEED);
  lua_State *L = luaL_newstate();
  char chunk[1100];
  snprintf(chunk, sizeof chunk, "@%s", path); /* messages say "job.lua:3:" */
  bool ok = luaL_loadbufferx(L, text, len, chunk, "t") == LUA_OK;
  free(text);
  if (ok) {
    /* The environment: data and math's functions alone (no I/O, os or require); math.random and
     * randomseed left out, so that a job's views follow from its text (its hash keys its outputs). */
    lua_newtable(L);
    luaL_requiref(L, LUA_MATHLIBNAME, luaopen_math, 0);
    lua_pushnil(L), lua_setfield(L, -2, "random");
    lua_pushnil(L), lua_setfield(L, -2, "randomseed");
    lua_setfield(L, -2, LUA_MATHLIBNAME);
    lua_setupvalue(L, -2, 1);
    lua_sethook(L, hook_budget, LUA_MASKCOUNT, 1000000);
    ok = lua_pcall(L, 0, 1, 0) == LUA_OK;
  }
  if (!ok) {
    lm_error_set(err, "%s", lua_tostring(L, -1));
    lua_close(L);
    return false;
  }
  if (!lua_istable(L, -1)) {
    lm_error_set(err, "%s: the job file must return a table: return { scenes = {...}, output = \"...\" }", path);
    lua_close(L);
    return false;
  }
  static const char *const known[] = {"script", "scenes", "techniques", "sizes", "set", "frames", "output",
                                      "manifest", "time", "animation", "path", "turntable", "events",
                                      "renderer", "references", NULL};
  ok = known_fields(L, known, 0, path, err);
  char script[1024] = "scripts/pp.lua", manifest[1024] = "";
  ok = ok && field_string(L, -1, "script", script, sizeof script, path, err) &&
       field_string(L, -1, "output", j->output, sizeof j->output, path, err) &&
       field_string(L, -1, "manifest", manifest, sizeof manifest, path, err) &&
       field_string(L, -1, "renderer", j->renderer, sizeof j->renderer, path, err) &&
       read_list(L, -1, "scenes", path, &j->scene_count, err, each_scene, j) &&
       read_list(L, -1, "techniques", path, &j->technique_count, err, each_technique, j) &&
       read_list(L, -1, "sizes", path, &j->size_count, err, each_size, j) && read_sets(L, j, err) &&
       read_list(L, -1, "events", path, &j->event_count, err, each_event, j) && read_time(L, j, err) &&
       read_path(L, j, err) && read_turntable(L, j, err) && read_references(L, j, err);
  if (ok) { /* a name, or an index as a number */
    lua_getfield(L, -1, "animation");
    if (lua_isinteger(L, -1)) lua_pushfstring(L, "%d", (int)lua_tointeger(L, -1)), lua_setfield(L, -3, "animation");
    lua_pop(L, 1);
    ok = field_string(L, -1, "animation", j->animation, sizeof j->animation, path, err);
    j->timed |= j->animation[0] != '\0';
  }
  if (ok) {
    lua_getfield(L, -1, "frames");
    j->frames = lua_isnil(L, -1) ? 1 : (int)lua_tointeger(L, -1);
    if (!lua_isinteger(L, -1) && !lua_isnil(L, -1)) j->frames = 0;
    lua_pop(L, 1);
    if (j->frames < 1 || j->frames > 1000) {
      lm_error_set(err, "%s: frames: a whole number in 1 .. 1000", path);
      ok = false;
    }
  }
  lua_close(L);
  if (!ok) return false;
  if (j->renderer[0] && strcmp(j->renderer, "pov") && strcmp(j->renderer, "cycles")) {
    lm_error_set(err, "%s: renderer: \"pov\" or \"cycles\", not \"%s\"", path, j->renderer);
    return false;
  }
  if (!j->scene_count) {
    lm_error_set(err, "%s: scenes: the job names no scene", path);
    return false;
  }
  if (!j->output[0]) {
    lm_error_set(err, "%s: output: missing (a pattern like \"out/{scene}_{camera}_{technique}.png\")", path);
    return false;
  }
  bool linear;
  if (!capture_known_extension(j->output, &linear)) {
    lm_error_set(err, "%s: output '%s': end it in .png, .exr, .jpg, .tif or .hdr", path, j->output);
    return false;
  }
  if (j->key_count && j->turntable) {
    lm_error_set(err, "%s: path and turntable: one camera motion at a time", path);
    return false;
  }
  if ((j->key_count || j->turntable) && !j->timed) {
    lm_error_set(err, "%s: %s: needs time = { start, stop, fps } (or time = SECONDS)", path,
                 j->turntable ? "turntable" : "path");
    return false;
  }
  const camera_key *first = &j->keys[0], *last = &j->keys[j->key_count > 0 ? j->key_count - 1 : 0];
  if (j->key_count > 1 && (last->t < j->time_start || first->t > j->time_stop)) { /* keys in frames, not seconds? */
    lm_error_set(err, "%s: path: its keys' times %g .. %g s are all outside the job's time %g .. %g s (the camera "
                 "would hold path[%d] throughout)", path, first->t, last->t, j->time_start, j->time_stop,
                 last->t < j->time_start ? j->key_count : 1);
    return false;
  }
  if (j->key_count && !path_frames_check(j, err)) return false;
  if (j->frame_count > 1 && !strstr(j->output, "{frame}")) {
    lm_error_set(err, "%s: output: a sequence of %d frames needs {frame} in the pattern (\"%s\")", path,
                 j->frame_count, j->output);
    return false;
  }
  if (!j->size_count) j->sizes[0][0] = 256, j->sizes[0][1] = 192, j->size_count = 1;
  resolve(j, script, j->script, sizeof j->script);
  if (manifest[0]) {
    snprintf(j->manifest, sizeof j->manifest, "%s", manifest);
  } else { /* the fixed folder of the output pattern */
    char prefix[1024];
    snprintf(prefix, sizeof prefix, "%s", j->output);
    char *brace = strchr(prefix, '{');
    if (brace) *brace = '\0';
    char *slash = strrchr(prefix, '/');
    if (slash) slash[1] = '\0';
    else prefix[0] = '\0';
    snprintf(j->manifest, sizeof j->manifest, "%smanifest.json", prefix);
  }
  /* Table order varies between runs: sort, so hashes and messages do not. */
  char sorted[MAX_LIST][384];
  for (int i = 0; i < j->set_count; i++) snprintf(sorted[i], sizeof sorted[i], "%s=%s", j->set_names[i], j->set_values[i]);
  qsort(sorted, (size_t)j->set_count, sizeof sorted[0], compare_sets);
  for (int i = 0; i < j->set_count; i++) {
    char *eq = strchr(sorted[i], '=');
    *eq = '\0';
    snprintf(j->set_names[i], sizeof j->set_names[0], "%s", sorted[i]);
    snprintf(j->set_values[i], sizeof j->set_values[0], "%s", eq + 1);
  }
  return true;
}

/* ---- output names -------------------------------------------------------- */

/* Fills the pattern's {scene} {camera} {view} {technique} {size} {width} {height} {frame} {time}. */
static bool expand(const job *j, const job_view *v, int index, char *out, size_t cap, lm_error *err) {
  const job_scene *s = &j->scenes[v->scene];
  lm_buf b = {0};
  char seconds[LIMN_TIME_TEXT];
  bool ok = true;
  for (const char *p = j->output; *p && ok; p++) {
    if (*p != '{') {
      lm_buf_append(&b, p, 1);
      continue;
    }
    const char *close = strchr(p, '}');
    char key[32] = "";
    if (close && close - p - 1 < (int)sizeof key) snprintf(key, sizeof key, "%.*s", (int)(close - p - 1), p + 1);
    if (!strcmp(key, "scene")) lm_buf_printf(&b, "%s", s->name);
    else if (!strcmp(key, "camera")) lm_buf_printf(&b, "%s", s->scene->cameras[v->camera].name);
    else if (!strcmp(key, "view")) lm_buf_printf(&b, "%d", index);
    else if (!strcmp(key, "technique")) lm_buf_printf(&b, "%s", j->techniques[v->technique]);
    else if (!strcmp(key, "size")) lm_buf_printf(&b, "%dx%d", j->sizes[v->size][0], j->sizes[v->size][1]);
    else if (!strcmp(key, "width")) lm_buf_printf(&b, "%d", j->sizes[v->size][0]);
    else if (!strcmp(key, "height")) lm_buf_printf(&b, "%d", j->sizes[v->size][1]);
    else if (!strcmp(key, "frame")) lm_buf_printf(&b, CAPTURE_FRAME_FORMAT, v->frame);
    else if (!strcmp(key, "time")) lm_buf_append(&b, limn_time_text(v->time, 3, seconds), -1);
    else {
      lm_error_set(err, "%s: output: unknown placeholder '{%s}' (known: {scene} {camera} {view} {technique} "
                   "{size} {width} {height} {frame} {time})", j->path, key);
      ok = false;
    }
    if (close) p = close;
  }
  if (ok) snprintf(out, cap, "%s", b.data ? b.data : "");
  lm_buf_free(&b);
  return ok;
}

/* mkdir -p of the file's folder. */
bool job_make_parent(const char *file, lm_error *err) {
  char dir[1024];
  lm_dirname(file, dir, sizeof dir);
  for (char *p = dir + 1;; p++) {
    char c = *p;
    if (c == '/' || c == '\0') {
      *p = '\0';
      if (access(dir, F_OK) != 0 && mkdir(dir, 0777) != 0 && access(dir, F_OK) != 0) {
        lm_error_set(err, "%s: cannot make folder %s", file, dir);
        return false;
      }
      *p = c;
    }
    if (!c) break;
  }
  return true;
}

/* A killed run can leave its temporary files (lm_image_write's
 * "<stem>.tmp-<pid><ext>"): remove those of this output. */
static void remove_stale_temps(const char *output) {
  char pattern[1200];
  const char *dot = strrchr(output, '.'), *slash = strrchr(output, '/');
  if (!dot || (slash && dot < slash)) return;
  snprintf(pattern, sizeof pattern, "%.*s.tmp-*%s", (int)(dot - output), output, dot);
  glob_t g;
  if (glob(pattern, GLOB_NOSORT, NULL, &g) == 0)
    for (size_t i = 0; i < g.gl_pathc; i++) remove(g.gl_pathv[i]);
  globfree(&g);
}

/* ---- hashes -------------------------------------------------------------- */

static int compare_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* Every file of a folder (sorted, names and bytes), with `ext` ending. */
static uint64_t hash_folder(const char *dir, const char *ext, uint64_t h) {
  DIR *d = opendir(dir);
  if (!d) return h;
  char **names = NULL;
  int n = 0, cap = 0;
  for (struct dirent *e; (e = readdir(d));) {
    size_t len = strlen(e->d_name), el = strlen(ext);
    if (e->d_name[0] == '.' || len < el || strcmp(e->d_name + len - el, ext)) continue;
    *LM_PUSH(names, n, cap) = lm_strdup(e->d_name);
  }
  closedir(d);
  qsort(names, (size_t)n, sizeof *names, compare_names);
  for (int i = 0; i < n; i++) {
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    size_t len;
    lm_error err;
    char *text = lm_read_file(path, &len, &err);
    h = lm_hash(names[i], strlen(names[i]), h);
    if (text) h = lm_hash(text, len, h);
    free(text);
    free(names[i]);
  }
  free(names);
  return h;
}

static uint64_t hash_file(const char *path, uint64_t h) {
  size_t len;
  lm_error err;
  char *text = lm_read_file(path, &len, &err);
  if (text) h = lm_hash(text, len, h);
  free(text);
  return h;
}

/* ---- the manifest ------------------------------------------------------ */


/* The entries a previous run left, one line each, keyed by "file". */
bool job_manifest_load(const char *path, const job_view *views, int view_count, job_manifest *m) {
  size_t len;
  lm_error err;
  char *text = lm_read_file(path, &len, &err);
  if (!text) return false;
  const char *images = strstr(text, "  \"images\": [");
  if (images) m->header = lm_strdup(text), m->header[images - text] = '\0';
  const char *run = strstr(text, "\"run\": ");
  if (run && (!images || run < images)) m->run = atoi(run + 7);
  for (char *line = text, *next; line; line = next) {
    next = strchr(line, '\n');
    if (next) *next++ = '\0';
    const char *f = strstr(line, "{\"file\": \"");
    if (!f) continue;
    size_t n = strlen(line);
    while (n && (line[n - 1] == ',' || line[n - 1] == ' ')) line[--n] = '\0';
    /* The view the entry names first (a sequence has many), then any whose output it is. */
    const char *number = strstr(f, "\"view\": ");
    int named = number ? atoi(number + 8) : -1;
    for (int k = -1; k < view_count; k++) {
      int i = k < 0 ? named : k;
      if (i < 0 || i >= view_count || (k >= 0 && i == named)) continue;
      lm_buf key = {0};
      lm_buf_append(&key, "{\"file\": ", -1);
      limn_json_append(&key, views[i].output);
      lm_buf_append(&key, ",", 1);
      bool match = !strncmp(f, key.data, (size_t)key.len);
      if (match && !m->entries[i]) m->entries[i] = lm_strdup(f);
      lm_buf_free(&key);
      if (match) break; /* outputs are unique */
    }
  }
  free(text);
  return true;
}

bool job_manifest_field(const job_manifest *m, const char *key, char *out, size_t cap) {
  char pattern[128];
  snprintf(pattern, sizeof pattern, "\n  \"%s\": ", key);
  const char *p = m->header ? strstr(m->header, pattern) : NULL;
  if (!p) return false;
  p += strlen(pattern);
  if (*p == '"') p++;
  size_t n = strcspn(p, "\",\n");
  snprintf(out, cap, "%.*s", (int)n, p);
  return true;
}

bool job_manifest_write(const char *path, const job_manifest *m, int view_count, lm_error *err) {
  lm_buf b = {0};
  lm_buf_append(&b, m->header, -1);
  lm_buf_append(&b, "  \"images\": [\n", -1);
  bool first = true;
  for (int i = 0; i < view_count; i++) {
    if (!m->entries[i]) continue;
    lm_buf_printf(&b, "%s    %s", first ? "" : ",\n", m->entries[i]);
    first = false;
  }
  lm_buf_append(&b, "\n  ]\n}\n", -1);
  bool ok = limn_write_whole(path, b.data, (size_t)b.len, err);
  lm_buf_free(&b);
  return ok;
}

void job_manifest_path(const job *j, int shard, int shards, char *out, size_t cap) {
  snprintf(out, cap, "%s", j->manifest);
  if (shards <= 1) return;
  char *dot = strrchr(out, '.');
  char tail[64];
  snprintf(tail, sizeof tail, ".shard-%d-of-%d.json", shard, shards);
  if (dot && !strchr(dot, '/')) *dot = '\0';
  strncat(out, tail, cap - strlen(out) - 1);
}

uint64_t job_hash_with(const job *j, const char *const *sets, int set_count) {
  uint64_t h = j->hash;
  for (int i = 0; i < set_count; i++) h = lm_hash(sets[i], strlen(sets[i]), h);
  return h;
}

static char *manifest_entry(const job *j, const job_view *v, int index, const capture_result *res, int run) {
  const job_scene *s = &j->scenes[v->scene];
  lm_buf b = {0};
  lm_buf_append(&b, "{\"file\": ", -1);
  limn_json_append(&b, v->output);
  lm_buf_printf(&b, ", \"view\": %d, \"run\": %d, \"scene\": ", index, run);
  limn_json_append(&b, s->path);
  lm_buf_printf(&b, ", \"scene_hash\": \"%016llx\", \"camera\": ", (unsigned long long)s->hash);
  limn_json_append(&b, s->scene->cameras[v->camera].name);
  lm_buf_append(&b, ", \"technique\": ", -1);
  limn_json_append(&b, j->techniques[v->technique]);
  if (j->timed) lm_buf_printf(&b, ", \"frame\": %d, \"time\": %.6f", v->frame, v->time);
  lm_buf_printf(&b, ", \"width\": %d, \"height\": %d, \"frames\": %d, \"drawn\": %d, \"culled\": %d, "
                "\"triangles\": %ld, \"total_ms\": %.3f, \"passes\": [",
                j->sizes[v->size][0], j->sizes[v->size][1], j->frames, res->stats.drawn, res->stats.culled,
                res->stats.triangles, res->total_ms);
  for (int i = 0; i < res->pass_count; i++) {
    lm_buf_append(&b, i ? ", {\"name\": " : "{\"name\": ", -1);
    limn_json_append(&b, res->passes[i].name);
    lm_buf_printf(&b, ", \"kind\": \"%s\", \"ms\": %.3f}", res->passes[i].kind, res->passes[i].ms);
  }
  lm_buf_append(&b, "]}", -1);
  return b.data;
}

static int compare_outputs(const void *a, const void *b) {
  const job_view *x = *(const job_view *const *)a, *y = *(const job_view *const *)b;
  int c = strcmp(x->output, y->output);
  return c ? c : (x > y) - (x < y); /* ties in view order */
}

/* The placeholder that would tell views x and y apart: the first field in
 * which they differ, {view} where that field's names are equal (a scene
 * listed twice, two cameras of one name). */
static const char *telling_apart(const job *j, const job_view *x, const job_view *y) {
  const job_scene *a = &j->scenes[x->scene], *b = &j->scenes[y->scene];
  if (x->scene != y->scene) return strcmp(a->name, b->name) ? "{scene}" : "{view}";
  if (x->camera != y->camera)
    return strcmp(a->scene->cameras[x->camera].name, a->scene->cameras[y->camera].name) ? "{camera}" : "{view}";
  if (x->technique != y->technique) return "{technique}";
  if (x->size != y->size) return "{size}";
  return "{frame}";
}

/* False, naming two views, when two views write one file (sorted: a long
 * sequence's views are many). */
static bool unique_outputs(const job *j, const job_view *views, int n, lm_error *err) {
  const job_view **sorted = lm_alloc(sizeof *sorted * (size_t)(n + 1));
  for (int i = 0; i < n; i++) sorted[i] = &views[i];
  qsort(sorted, (size_t)n, sizeof *sorted, compare_outputs);
  bool ok = true;
  for (int i = 1; i < n && ok; i++)
    if (!strcmp(sorted[i - 1]->output, sorted[i]->output)) {
      lm_error_set(err, "%s: output: views %d and %d both write %s (add %s to the pattern)", j->path,
                   (int)(sorted[i - 1] - views), (int)(sorted[i] - views), sorted[i]->output,
                   telling_apart(j, sorted[i - 1], sorted[i]));
      ok = false;
    }
  free(sorted);
  return ok;
}

/* Scene s's views: its camera list's, or the one camera a path or turntable
 * moves (job_pose); and the job's animation in it. */
static bool add_cameras(const job *j, job_scene *s, lm_error *err) {
  lm_scene *sc = s->scene;
  s->path_camera = -1;
  s->animation = LM_ANIM_ALL;
  if (j->animation[0] && (s->animation = lm_scene_find_animation(sc, j->animation, err)) < LM_ANIM_NONE) {
    lm_error_prefix(err, "animation");
    return false;
  }
  float lo[3], hi[3], d2 = 0;
  lm_scene_bounds(sc, lo, hi);
  for (int k = 0; k < 3; k++) s->centre[k] = 0.5f * (lo[k] + hi[k]), d2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  s->radius = d2 > 0 ? 0.5f * sqrtf(d2) : 1;
  if (!j->key_count && !j->turntable) {
    if (!s->cameras_given && access(s->cameras, F_OK) != 0) { /* no list beside it: the file's own cameras */
      s->first_camera = 0;
      s->camera_count = sc->camera_count;
      return true;
    }
    s->first_camera = lm_scene_add_camera_list(sc, s->cameras, &s->camera_count, err);
    return s->first_camera >= 0;
  }
  int cam;
  if (j->turntable) { /* its distance, unless given: that of the camera framing the scene */
    cam = lm_scene_add_framing_camera(sc, "turntable", 0);
    const float *w = sc->nodes[sc->cameras[cam].node].world;
    float e[3] = {w[12] - s->centre[0], w[13] - s->centre[1], w[14] - s->centre[2]};
    s->orbit = j->distance > 0 ? (float)j->distance : sqrtf(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  } else {
    lm_camera c = {.name = "path", .fov_y = 0.25f * (float)M_PI};
    const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    c.node = lm_scene_add_node(sc, c.name, -1, identity, -1, -1);
    cam = lm_scene_add_camera(sc, &c);
  }
  s->path_camera = s->first_camera = cam;
  s->camera_count = 1;
  return true;
}

void job_pose(const job *j, const job_view *v) {
  const job_scene *s = &j->scenes[v->scene];
  lm_scene *sc = s->scene;
  if (j->timed) lm_scene_set_time(sc, s->animation, v->time);
  if (s->path_camera < 0 || v->camera != s->path_camera) return;
  float eye[3], target[3], fov = 45, world[16];
  if (j->turntable) { /* one turn (times turns) over the time range, from the framing camera's side (+Z) */
    double span = j->time_stop - j->time_start;
    double a = span > 0 ? 2 * M_PI * j->turns * (v->time - j->time_start) / span : 0;
    double e = j->elevation * M_PI / 180;
    float offset[3] = {(float)(sin(a) * cos(e)), (float)sin(e), (float)(cos(a) * cos(e))};
    for (int k = 0; k < 3; k++) eye[k] = s->centre[k] + s->orbit * offset[k], target[k] = s->centre[k];
  } else {
    camera_path_eval(j->keys, j->key_count, v->time, eye, target, &fov);
  }
  lm_camera_look_at(eye, target, world);
  lm_camera *c = &sc->cameras[s->path_camera];
  lm_scene_node_set_world(sc, c->node, world);
  c->fov_y = fov * (float)(M_PI / 180);
  /* Near and far as a camera list's (engine/scene/camlist.c): far past the whole scene. */
  float d2 = 0;
  for (int k = 0; k < 3; k++) d2 += (eye[k] - s->centre[k]) * (eye[k] - s->centre[k]);
  c->zfar = 1.5f * (sqrtf(d2) + s->radius);
  c->znear = c->zfar * 1e-4f;
}

int job_shard_of(const job *j, int i, int count, int shards) {
  if (j->frame_count <= 1) return i % shards;
  return (int)((long long)i * shards / count);
}

bool job_views(job *j, bool all_techniques, job_view **out, int *count, lm_error *err) {
  *out = NULL;
  *count = 0;
  /* Every scene and camera list is read before anything renders: a bad
   * entry stops the job at once, naming it. */
  int techniques = all_techniques ? j->technique_count : 1;
  long long view_count = 0;
  for (int i = 0; i < j->scene_count; i++) {
    job_scene *s = &j->scenes[i];
    if (!s->scene) {
      s->scene = lm_scene_load_gltf(s->path, err);
      if (s->scene && !add_cameras(j, s, err)) s->first_camera = -1;
      if (!s->scene || s->first_camera < 0) {
        lm_error_prefix(err, "%s: scenes[%d]", j->path, i + 1);
        return false;
      }
      s->hash = hash_file(s->cameras, hash_file(s->path, LM_HASH_SEED));
    }
    view_count += (long long)s->camera_count * j->size_count * techniques * j->frame_count;
  }
  if (view_count > MAX_VIEWS) {
    lm_error_set(err, "%s: %lld views (scenes' cameras x sizes x techniques x frames); at most %d: split the job",
                 j->path, view_count, MAX_VIEWS);
    return false;
  }
  job_view *views = lm_alloc(sizeof *views * (size_t)(view_count + 1));
  int n = 0;
  for (int si = 0; si < j->scene_count; si++)
    for (int z = 0; z < j->size_count; z++)
      for (int t = 0; t < techniques; t++)
        for (int c = 0; c < j->scenes[si].camera_count; c++)
          for (int f = 0; f < j->frame_count; f++) {
            job_view *v = &views[n];
            *v = (job_view){.scene = si, .camera = j->scenes[si].first_camera + c, .size = z, .technique = t,
                            .frame = f, .time = j->fps > 0 ? j->time_start + f / j->fps : j->time_start};
            if (all_techniques && !expand(j, v, n, v->output, sizeof v->output, err)) { /* places: no output */
              free(views);
              return false;
            }
            n++;
          }
  if (all_techniques && !unique_outputs(j, views, n, err)) {
    free(views);
    return false;
  }
  *out = views;
  *count = n;
  return true;
}

void job_free_scenes(job *j) {
  for (int i = 0; i < j->scene_count; i++) {
    lm_scene_destroy(j->scenes[i].scene);
    j->scenes[i].scene = NULL;
  }
}

/* ---- running ------------------------------------------------------------- */

void job_progress(bool quiet, bool tty, int done, int total, const char *what) {
  if (quiet) return;
  if (tty) {
    int width = 30, fill = total ? done * width / total : width;
    printf("\r[%.*s%.*s] %d/%d %-60.60s", fill, "##############################", width - fill,
           "..............................", done, total, what);
    if (done == total) printf("\n");
  } else {
    printf("[%d/%d] %s\n", done, total, what);
  }
  fflush(stdout);
}

static int run(const capture_job_args *a, job *j, lm_pipeline *pipeline) {
  lm_error err;
  job_view *views;
  int view_count;
  if (!job_views(j, true, &views, &view_count, &err)) { /* a bad scene, list, animation or output: usage */
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 2;
  }

  char manifest_path[1100];
  job_manifest_path(j, a->shard, a->shards, manifest_path, sizeof manifest_path);
  job_manifest m = {.entries = calloc((size_t)view_count + 1, sizeof(char *))};
  job_manifest_load(manifest_path, views, view_count, &m);
  free(m.header); /* written anew below */
  m.header = NULL;
  m.run++;

  int rc = 0, mine = 0; /* views in this shard */
  for (int i = 0; i < view_count; i++) mine += job_shard_of(j, i, view_count, a->shards) == a->shard;
  bool any_linear;
  capture_known_extension(j->output, &any_linear);
  if (!lm_context_create_headless(&(lm_context_desc){.platform = a->egl, .debug = a->verbose}, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 1;
  }
  for (int i = 0; i < j->size_count && !rc; i++) /* the entry named, not the first target that fails */
    if (j->sizes[i][0] > lm_texture_max_size() || j->sizes[i][1] > lm_texture_max_size()) {
      lm_log(LM_LOG_ERROR, "%s: sizes[%d]: %dx%d; this GL's textures are at most %d a side", j->path, i + 1,
             j->sizes[i][0], j->sizes[i][1], lm_texture_max_size());
      rc = 2;
    }
  if (!rc && !job_make_parent(manifest_path, &err)) { /* after the checks: a refused job leaves no folder */
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 1;
  }
  lm_renderer *r = NULL;
  if (!rc) {
    r = lm_renderer_create(&(lm_renderer_desc){.scene = j->scenes[0].scene, .pipeline = pipeline, .width = 1,
                                               .height = 1, .clock = a->clock, .linear_output = any_linear}, &err);
    if (!r) lm_log(LM_LOG_ERROR, "%s", err.msg), rc = 1;
  }
  if (!rc) {
    char script_dir[1024], root_scripts[1100], shaders[1100];
    lm_dirname(j->script, script_dir, sizeof script_dir);
    uint64_t scripts = hash_folder(script_dir, ".lua", LM_HASH_SEED);
    snprintf(root_scripts, sizeof root_scripts, "%s/scripts", lm_root_dir());
    snprintf(shaders, sizeof shaders, "%s/shaders", lm_root_dir());
    scripts = hash_folder(root_scripts, ".lua", hash_file(j->script, scripts));
    uint64_t job_hash = job_hash_with(j, a->sets, a->set_count);
    lm_buf h = {0};
    lm_buf_append(&h, "{\n  \"job\": ", -1);
    limn_json_append(&h, j->path);
    lm_buf_printf(&h, ",\n  \"job_hash\": \"%016llx\",\n  \"script\": ", (unsigned long long)job_hash);
    limn_json_append(&h, j->script);
    lm_buf_printf(&h, ",\n  \"script_hash\": \"%016llx\",\n  \"shader_hash\": \"%016llx\",\n  \"renderer\": ",
                  (unsigned long long)scripts, (unsigned long long)hash_folder(shaders, "", LM_HASH_SEED));
    limn_json_append(&h, lm_gl_renderer());
    lm_buf_append(&h, ",\n  \"gl_version\": ", -1);
    limn_json_append(&h, lm_gl_version());
    lm_buf_append(&h, ",\n  \"platform\": ", -1);
    limn_json_append(&h, lm_context_platform());
    /* "views": the images this manifest is to list; fewer in "images" when a run failed, was killed or
     * goes on, so that a sequence cut short never reads as whole. */
    lm_buf_printf(&h, ",\n  \"clock\": \"%s\",\n  \"shard\": \"%d/%d\",\n  \"views\": %d,\n  \"run\": %d,\n"
                  "  \"options\": [", lm_clock_name(lm_renderer_clock(r)), a->shard, a->shards, mine, m.run);
    for (int i = 0; i < j->set_count + a->set_count; i++) {
      char set[400];
      if (i < j->set_count) snprintf(set, sizeof set, "%s=%s", j->set_names[i], j->set_values[i]);
      else snprintf(set, sizeof set, "%s", a->sets[i - j->set_count]);
      lm_buf_append(&h, i ? ", " : "", -1);
      limn_json_append(&h, set);
    }
    lm_buf_append(&h, "],\n", -1);
    m.header = h.data;
  }

  bool tty = isatty(STDOUT_FILENO);
  /* For tests: SIGKILL ourselves after this many images, as an operator's
   * kill would, at a point a timed kill cannot hit reliably. */
  const char *kill_env = getenv("LIMN_JOB_KILL_AFTER");
  int kill_after = kill_env ? atoi(kill_env) : 0;
  int done = 0, rendered = 0, skipped = 0;
  if (!rc && !a->quiet)
    printf("job %s: %d view%s (%d in shard %d/%d); %s; %s\n", j->path, view_count, view_count == 1 ? "" : "s",
           mine, a->shard, a->shards, lm_gl_renderer(), manifest_path);
  lm_scene *current = j->scenes[0].scene;
  int last = -1; /* the view rendered last */
  for (int i = 0; i < view_count && !rc; i++) {
    if (job_shard_of(j, i, view_count, a->shards) != a->shard) continue;
    const job_view *v = &views[i];
    const job_scene *s = &j->scenes[v->scene];
    char what[1200];
    remove_stale_temps(v->output);
    if (!a->force && lm_file_exists(v->output)) {
      skipped++;
      snprintf(what, sizeof what, "%s: exists, skipped", v->output);
      job_progress(a->quiet, tty, ++done, mine, what);
      continue;
    }
    capture_result res = {0};
    bool ok = job_make_parent(v->output, &err) && lm_pipeline_set_technique(pipeline, j->techniques[v->technique], &err);
    if (ok && s->scene != current) ok = lm_renderer_set_scene(r, s->scene, &err), current = s->scene;
    if (ok) {
      /* The next frame of the view rendered last: its temporal histories carry on. */
      const job_view *p = last >= 0 && last == i - 1 ? &views[last] : NULL;
      bool continues = p && p->scene == v->scene && p->size == v->size && p->technique == v->technique &&
                       p->camera == v->camera && p->frame + 1 == v->frame;
      if (!continues && j->timed) { /* posed after the frame before (a still after itself): the */
        job_view before = *v;         /* previous pose, for velocities, though that is not rendered */
        before.time -= j->fps > 0 ? 1 / j->fps : 0;
        job_pose(j, &before);
      }
      job_pose(j, v);
      const char *outs[1] = {v->output};
      capture_view cv = {.camera = v->camera, .width = j->sizes[v->size][0], .height = j->sizes[v->size][1],
                         .frames = j->frames, .outputs = outs, .output_count = 1, .quiet = true,
                         .continues = continues};
      ok = capture_render_write(r, &cv, &res, &err);
    }
    if (ok) {
      free(m.entries[i]);
      m.entries[i] = manifest_entry(j, v, i, &res, m.run);
      ok = job_manifest_write(manifest_path, &m, view_count, &err);
    }
    if (!ok) {
      if (tty && !a->quiet) printf("\n");
      char frame[64] = "";
      char seconds[LIMN_TIME_TEXT];
      if (j->timed) snprintf(frame, sizeof frame, ", frame %d at %s s", v->frame, limn_time_text(v->time, 3, seconds));
      lm_log(LM_LOG_ERROR, "%s: view %d (%s, camera '%s', %s, %dx%d%s): %s", j->path, i, s->name,
             s->scene->cameras[v->camera].name, j->techniques[v->technique], j->sizes[v->size][0],
             j->sizes[v->size][1], frame, err.msg);
      rc = 1;
    } else {
      rendered++;
      last = i;
      snprintf(what, sizeof what, "%s (%.1f ms)", v->output, res.total_ms);
      job_progress(a->quiet, tty, ++done, mine, what);
      if (kill_after > 0 && rendered == kill_after) raise(SIGKILL);
    }
    capture_result_free(&res);
  }
  if (!rc && !a->quiet) printf("job %s: %d rendered, %d skipped (existing; --force redoes them)\n", j->path,
                               rendered, skipped);
  if (!rc && rendered == 0 && m.header) job_manifest_write(manifest_path, &m, view_count, &err);
  lm_renderer_destroy(r);
  lm_programs_clear();
  for (int i = 0; i <= view_count; i++) free(m.entries[i]);
  free(m.entries);
  free(m.header);
  free(views);
  for (int i = 0; i < j->scene_count; i++) { /* GL objects go before the context */
    lm_scene_destroy(j->scenes[i].scene);
    j->scenes[i].scene = NULL;
  }
  lm_context_destroy();
  return rc;
}

lm_pipeline *job_pipeline(job *j, const char *const *sets, int set_count, bool check_techniques) {
  lm_error err;
  int rc = 0;
  lm_pipeline *pipeline = lm_pipeline_load(&(lm_pipeline_desc){.path = j->script}, &err);
  if (!pipeline) {
    lm_log(LM_LOG_ERROR, "%s: script: %s", j->path, err.msg);
    rc = 2;
  }
  for (int i = 0; i < j->technique_count && !rc && check_techniques; i++)
    if (!lm_pipeline_set_technique(pipeline, j->techniques[i], &err)) {
      lm_log(LM_LOG_ERROR, "%s: techniques[%d]: %s", j->path, i + 1, err.msg);
      rc = 2;
    }
  if (!rc && !j->technique_count) {
    snprintf(j->techniques[0], sizeof j->techniques[0], "%s", lm_pipeline_technique_name(pipeline, 0));
    j->technique_count = 1;
  }
  for (int i = 0; i < j->set_count && !rc; i++)
    if (!lm_pipeline_set_option(pipeline, j->set_names[i], j->set_values[i], &err)) {
      lm_log(LM_LOG_ERROR, "%s: set.%s: %s", j->path, j->set_names[i], err.msg);
      rc = 2;
    }
  for (int i = 0; i < set_count && !rc; i++)
    if (!capture_set_option(pipeline, sets[i], &err)) {
      lm_log(LM_LOG_ERROR, "--set %s: %s", sets[i], err.msg);
      rc = 2;
    }
  if (rc) {
    lm_pipeline_destroy(pipeline);
    return NULL;
  }
  return pipeline;
}

int capture_job_run(const capture_job_args *a) {
  job *j = lm_alloc(sizeof *j);
  lm_error err;
  if (!job_read(j, a->path, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    free(j);
    return 2;
  }
  int rc = 0;
  lm_pipeline *pipeline = job_pipeline(j, a->sets, a->set_count, true);
  if (!pipeline) rc = 2;
  if (!rc) rc = run(a, j, pipeline);
  for (int i = 0; i < j->scene_count; i++) lm_scene_destroy(j->scenes[i].scene);
  lm_pipeline_destroy(pipeline);
  free(j);
  return rc;
}
