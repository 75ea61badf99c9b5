/* Shared by script.c (state, sandbox, options) and script_api.c (the
 * functions scripts call to record a frame). script.c opens the API;
 * the API finds its pipeline here, never by calling back into script.c. */
#ifndef LIMN_SCRIPT_INTERNAL_H
#define LIMN_SCRIPT_INTERNAL_H

#include "scene/sky.h"
#include "script/script.h"

#include <lauxlib.h>
#include <lua.h>

struct lm_pipeline {
  lua_State *L;
  char path[1024], dir[1024];
  char technique[64];
  long budget, executed;
  /* while recording */
  lm_graph *graph;
  unsigned frame;     /* serial of the frame being recorded; 0 inside OnCreate */
  bool in_create, created;
  int presented;
  char present_where[256];
  bool present_display; /* present(t, "display") */
  int metered;        /* meter(t)'s target, -1: none */
  int options_ref;    /* registry: the Options table with overrides applied */
  const lm_scene *scene;
  const lm_frame_data *camera;
  lm_shadow_plan *shadows;
  unsigned shadows_frame; /* frame serial of the plan in *shadows */
  int *shadow_levels;     /* the last plan's levels (lm_shadow_settings.last_levels), one a light */
  int shadow_level_count;
  float (*shadow_depths)[2]; /* the last plan's cascade rows (lm_shadow_settings.last_depths), taken from it */
  unsigned front_lit;     /* lm_pipeline_set_front_lit */
  lm_still_frames still;  /* frames in a row before this one that drew the same world, scene, light */
  float light_peak;       /* the largest radiance the script's own light reaches this frame (light_peak, sky_sh) */
  bool keep_exposure;     /* keep_exposure(): this frame shows results kept under the last one's pre-exposure */
  char sky_map[1024];     /* the sky map sky_sh{} read last ("" none) and its coefficients */
  float sky_map_sh[LM_SKY_SH];
};

/* Registers target, scene, pass, cpu, points, present, output_size, shadow_plan, sky_sh, scene_reflective,
 * scene_blended, scene_bounds and camera_view in the global table. */
void lm_script_open_api(lua_State *L);
/* The registry key under which lm_pipeline_load keeps the pipeline that owns L. */
#define LM_SCRIPT_PIPELINE_KEY "limn.pipeline"

/* The pipeline that owns L. */
static inline lm_pipeline *lm_script_pipeline(lua_State *L) {
  lua_getfield(L, LUA_REGISTRYINDEX, LM_SCRIPT_PIPELINE_KEY);
  lm_pipeline *p = lua_touserdata(L, -1);
  lua_pop(L, 1);
  return p;
}

#endif
