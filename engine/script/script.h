/* script: Lua pipeline scripts. A script defines OnCreate() (once: declares
 * persistent targets) and OnRender(tech) (each frame: records passes into the
 * frame graph; it never touches GL). Scripts run in a sandbox: no io, no os
 * beyond clocks, no C modules, `require` only from the script's folder and
 * <root>/scripts, and an instruction budget per call. */
#ifndef LIMN_SCRIPT_H
#define LIMN_SCRIPT_H

#include "shadow/shadow.h"

typedef struct lm_pipeline lm_pipeline;

typedef struct lm_pipeline_desc {
  const char *path;           /* the pipeline script */
  long instruction_budget;    /* per OnCreate/OnRender call; 0: 100 million */
} lm_pipeline_desc;

/* Runs the script's top level and reads its Techniques and Options tables. */
lm_pipeline *lm_pipeline_load(const lm_pipeline_desc *desc, lm_error *err);
void lm_pipeline_destroy(lm_pipeline *p);
/* The script's file, as lm_pipeline_load was given it. */
const char *lm_pipeline_path(const lm_pipeline *p);

/* Techniques the script lists in `Techniques`, names or rows { name, ... };
 * the first is the default. A row's `key` is the viewer's key for it ("F2"),
 * NULL when it names none. */
int lm_pipeline_technique_count(const lm_pipeline *p);
const char *lm_pipeline_technique_name(const lm_pipeline *p, int i);
const char *lm_pipeline_technique_key(const lm_pipeline *p, int i);
bool lm_pipeline_set_technique(lm_pipeline *p, const char *name, lm_error *err);
const char *lm_pipeline_technique(const lm_pipeline *p);

/* Sets an option of the script's `Options` table by dotted name ("dof.focus"),
 * the value parsed by the default's type. Unknown names are an error that
 * lists the known ones. */
bool lm_pipeline_set_option(lm_pipeline *p, const char *name, const char *value, lm_error *err);
/* A boolean option's text as lm_pipeline_set_option reads it: true, 1, on,
 * yes or false, 0, off, no; false when it is none of them. */
bool lm_option_bool(const char *v, bool *out);
/* The current value of an option by dotted name, as text ("true", "0.5",
 * "table" for a table of options); false when the script declares none. */
bool lm_pipeline_get_option(const lm_pipeline *p, const char *name, char *value, size_t cap);
/* "name=default" lines of every option. */
void lm_pipeline_list_options(const lm_pipeline *p, lm_buf *out);

/* Each option as a tool shows it (the viewer's panel): its value's type and
 * text, and what its rule asks when the script's `options` module describes
 * it (scripts/options.lua's options.describe). */
typedef enum lm_option_type { LM_OPTION_BOOLEAN, LM_OPTION_NUMBER, LM_OPTION_STRING, LM_OPTION_OTHER } lm_option_type;
typedef enum lm_option_rule {
  LM_RULE_NONE, LM_RULE_NUMBER, LM_RULE_WHOLE, LM_RULE_BOOLEAN, LM_RULE_ONE_OF, LM_RULE_COLOUR
} lm_option_rule;
#define LM_OPTION_CHOICES 16
typedef struct lm_option_info {
  char name[128];       /* dotted, as --set takes it */
  lm_option_type type;
  char value[256];      /* as text (LM_OPTION_OTHER: Lua's name of its type, "table", "function") */
  lm_option_rule rule;
  double lo, hi, step;  /* NUMBER, WHOLE (step > 0), COLOUR (each channel); hi may be HUGE_VAL */
  int choice_count;     /* ONE_OF */
  char choices[LM_OPTION_CHOICES][64];
} lm_option_info;
/* Every option the script declares, in lm_pipeline_list_options' order, and
 * lists (tables without names) too; *out is malloc'd. Returns the count. */
int lm_pipeline_options(lm_pipeline *p, lm_option_info **out);

/* How many frames in a row before this one drew the same world (world:
 * still_frames(), a script's GI may then keep a converged result), the
 * same without the camera (scene: still_frames("scene"), a light's view,
 * such as the RSM, changed only when it is 0), and the same light (light:
 * still_frames("light"), the lights and emission; a GI history restarts
 * when it changes, temporal.lua). */
typedef struct lm_still_frames {
  int world, scene, light;
} lm_still_frames;

/* What shadow_plan() plans from: the scene, the camera's frame block, and
 * where the plan goes (owned by the caller, kept until the frame executes);
 * still: how long its world, scene and light have stayed the same. */
void lm_pipeline_set_scene(lm_pipeline *p, const lm_scene *scene, const lm_frame_data *camera,
                           lm_shadow_plan *shadows, lm_still_frames still);
/* The lights whose shadow tiles hold no back face (lm_shadow_front_lit's
 * mask), which light_set() passes on as LIGHT_FRONT_LIT; 0 until set. */
void lm_pipeline_set_front_lit(lm_pipeline *p, unsigned lights);

/* Records one frame into g (lm_graph_begin already called): OnCreate the
 * first time, then OnRender(tech). *presented gets the target passed to
 * present(). Errors carry script:line and a traceback on later lines. */
bool lm_pipeline_record(lm_pipeline *p, lm_graph *g, int *presented, lm_error *err);
/* Where the last frame called present() ("scripts/pp.lua:30"). */
const char *lm_pipeline_present_where(const lm_pipeline *p);
/* Did it present display values (present(t, "display"): tone mapped), which
 * the output stage takes as they are, or pre-exposed radiance (the default),
 * which it divides by the frame's exposure (common.glsl's exposed())? */
bool lm_pipeline_present_display(const lm_pipeline *p);
/* The largest radiance the last frame's script adds besides the scene's
 * lights (light_peak(), sky_sh{}): the renderer's pre-exposure keeps it
 * within half floats too. */
float lm_pipeline_light_peak(const lm_pipeline *p);
/* Did the last frame's script call keep_exposure()? It shows results kept
 * from an earlier frame (a settled GI result, temporal.lua), pre-exposed as
 * they were made, so the renderer keeps the last frame's pre-exposure. */
bool lm_pipeline_keeps_exposure(const lm_pipeline *p);
/* The target the last frame's script named with meter(t): pre-exposed
 * radiance whose brightness sets the next frame's pre-exposure; -1: none
 * (the renderer meters what it presented, unless display values). */
int lm_pipeline_metered(const lm_pipeline *p);
/* True once OnCreate has run. */
bool lm_pipeline_created(const lm_pipeline *p);

#endif
