/* graph: the frame graph. A frame is recorded as targets and passes (what
 * each pass reads and writes); compiling validates the recording, leaves out
 * every pass whose results do not reach an output, and plans which transient
 * targets share a texture; executing allocates from a pool kept across
 * frames, runs and times each pass. */
#ifndef LIMN_GRAPH_H
#define LIMN_GRAPH_H

#include "gfx/gfx.h"

typedef struct lm_graph lm_graph;

/* ---- recording --------------------------------------------------------- */
typedef struct lm_target_desc {
  const char *name;
  lm_format format;
  float scale;       /* size as a scale of the output (0 means 1) ... */
  int width, height; /* ... or absolute, when both are > 0 */
  bool mips;
  bool persistent;   /* keeps its texture and contents across frames */
} lm_target_desc;

/* A target's size for an output of out_w x out_h: never below 1x1. */
void lm_target_size(const lm_target_desc *d, int out_w, int out_h, int *w, int *h);

/* A CPU pass runs C code between GPU passes (seed 003's hybrid tracer: rays
 * read back, traced, hit records uploaded): `shader` names the function
 * (lm_graph_exec_desc.run_cpu), which gets its inputs' texels and fills its
 * outputs'. It takes no depth target and no views; its parameters go to the
 * function in the description.
 * A points pass scatters: `count` points from no vertex data, each placed by
 * the `vertex` shader (which reads its inputs by gl_VertexID) on one texel
 * of the outputs and coloured by `shader`, into outputs cleared to zero and
 * blended additively (seed 003's injection of light into a volume). It
 * takes no depth target and no views. */
typedef enum lm_pass_kind { LM_PASS_FULLSCREEN, LM_PASS_SCENE, LM_PASS_CPU, LM_PASS_POINTS } lm_pass_kind;
/* "fullscreen", "scene", "cpu", "points" (timing tables). */
const char *lm_pass_kind_name(lm_pass_kind k);

typedef struct lm_pass_input {
  const char *name; /* sampler uniform */
  int target;
} lm_pass_input;

typedef enum lm_param_kind { LM_PARAM_NUMBER, LM_PARAM_BOOL } lm_param_kind;
typedef struct lm_pass_param {
  const char *name; /* uniform */
  lm_param_kind kind;
  int count;        /* 1 .. 16 numbers */
  double v[16];
} lm_pass_param;

/* A scene pass drawn from another point of view into part of its targets
 * (a shadow map tile): the pass's program gets `pass_view_proj` and
 * `pass_depth` (light position and 1 / range; w = 0 for orthographic). */
typedef struct lm_pass_view {
  int x, y, width, height; /* viewport, pixels */
  float view_proj[16];
  float depth[4];
  float cull[16]; /* nodes wholly outside this clip volume are not drawn (view_proj, or a tighter one) */
} lm_pass_view;
/* A scene pass's override of a material parameter (scene{ materials = ...}):
 * the scene checks the names when it draws. */
typedef struct lm_pass_material_param {
  const char *material, *name;
  int count; /* 1 .. 4 numbers */
  float v[4];
} lm_pass_material_param;

#define LM_MAX_PASS_INPUTS 16
#define LM_MAX_PASS_PARAMS 64
#define LM_MAX_POINTS (1 << 26)

typedef struct lm_pass_desc {
  lm_pass_kind kind;
  const char *name;
  const char *where;   /* where it was recorded ("scripts/pp.lua:12"), for messages */
  const char *shader;  /* full-screen, points: fragment shader file; scene: material technique */
  const char *vertex;  /* points: vertex shader file */
  int count;           /* points: how many, 0 .. LM_MAX_POINTS */
  const char *defines; /* "NAME=VALUE;NAME2" */
  const lm_pass_input *inputs;
  int input_count;
  const lm_pass_param *params;
  int param_count;
  const int *outputs; /* colour targets */
  int output_count;
  int depth;          /* depth target, or -1 */
  bool clear;         /* full-screen passes always cover every pixel */
  float clear_color[4];
  double fetches;     /* texture fetches a pixel, as the script declares (0: not said); for bench */
  const lm_pass_view *views; /* scene passes: draw once per view; none: the camera */
  int view_count;
  int view_set; /* which list of the shadow plan the views are: 0 its shadow tiles, 1 its RSM views */
  /* Scene passes with views: a target the engine reads on the CPU just before
   * the pass to fit the views again (lm_graph_exec_desc.fit_views), e.g. the
   * depth range the camera saw for shadow cascades. Kept alive and ordered
   * like an input. */
  bool fits_views;
  int fit_target;
  /* Fit to the previous frame's target instead (read without a stall; this
   * frame's is read on the first frame of a view), its range widened by
   * fit_margin while the world or camera moves. */
  bool fit_previous;
  float fit_margin;
  const lm_pass_material_param *material_params; /* scene passes */
  int material_param_count;
  /* Scene passes: draws the alphaMode BLEND materials alone, back to front,
   * over what its one output holds (it does not clear): the output becomes
   * colour + transmittance * output (dual-source blending: the technique's
   * second output, index 1, is the transmittance), depth tested, not written. */
  bool blend;
  /* Scene passes with views (shadow tiles): 1 + the index of the output
   * that blended casters multiply with their transmittance (rgb; alpha: the
   * least depth, lm_set_caster_layer), drawn after the opaque ones and into
   * it alone; 0: none, they cast as opaque ones do. */
  int transmit;
  /* Camera scene passes: a node whose mesh has simplified copies
   * (lm_scene_mesh.lods) draws the coarsest that errs by at most this many
   * pixels of the pass's outputs where the node comes nearest the camera;
   * 0: every mesh whole. */
  float simplify;
  /* Full-screen passes: the engine's output stage may run in this pass
   * (lm_graph_fold_output; its shader then writes through output.glsl). */
  bool fold_output;
} lm_pass_desc;

lm_graph *lm_graph_create(void);
void lm_graph_destroy(lm_graph *g);
/* Starts recording a frame for an output of width x height. Transient
 * targets and passes of the last frame are forgotten; persistent ones stay. */
void lm_graph_begin(lm_graph *g, int width, int height);
void lm_graph_output_size(const lm_graph *g, int *width, int *height);
/* Returns the target's handle, or -1 with a message. */
int lm_graph_add_target(lm_graph *g, const lm_target_desc *d, lm_error *err);
/* Whether the target has the output's size this frame (scaled by 1, or absolute and equal). */
bool lm_graph_target_output_sized(const lm_graph *g, int target);
/* Copies the description. Returns the pass index, or -1 with a message. */
int lm_graph_add_pass(lm_graph *g, const lm_pass_desc *d, lm_error *err);
/* Marks a target as a result of the frame: what reaches it is kept. */
void lm_graph_mark_output(lm_graph *g, int target);
/* Folds a last stage into the pass that writes `target`, so that the image
 * is not written and read again at full size: when the last pass writing
 * `target` is a full-screen pass that allows it (lm_pass_desc.fold_output),
 * writes `target` alone, and no pass reads `target` or is recorded after it,
 * and `target` is transient and output-sized, that pass writes `outputs`
 * instead with `defines` added to its own. Returns the pass, or -1 when
 * nothing changed (the caller adds its stage as a pass of its own). */
int lm_graph_fold_output(lm_graph *g, int target, const int *outputs, int output_count, const char *defines);

/* ---- compiling (no GL) ------------------------------------------------- */
/* Validates (reads with no writer, feedback loops, formats, sizes), culls
 * and plans texture sharing. Logs "left out: ..." for each culled pass. */
bool lm_graph_compile(lm_graph *g, lm_error *err);

typedef struct lm_graph_pass_info {
  const char *name, *where, *shader;
  lm_pass_kind kind;
  bool culled;
  double ms;        /* last execution, -1 when not run */
  double fetches;   /* texture fetches a pixel the script declared, 0: not said */
  int width, height; /* its first output's size */
  const lm_pass_desc *desc; /* as recorded: its inputs, outputs and depth target (the frame graph drawn) */
} lm_graph_pass_info;
int lm_graph_pass_count(const lm_graph *g);
lm_graph_pass_info lm_graph_pass(const lm_graph *g, int i);
/* The pass whose output input k of pass i reads: the last before i that
 * writes its target; -1 when none does (a persistent target's last frame). */
int lm_graph_input_writer(const lm_graph *g, int i, int k);
/* Each pass's depth into depth[lm_graph_pass_count]: 0 when it reads no
 * earlier pass's output, else one more than the deepest whose output it
 * reads (the column a drawing of the graph puts it in). */
void lm_graph_pass_depths(const lm_graph *g, int *depth);

typedef struct lm_graph_target_info {
  const char *name;
  lm_format format;
  int width, height;
  bool persistent, used;
  int slot;         /* shared texture slot (transient, used targets), else -1 */
  bool alone;       /* one pass that runs writes it and no other target shares its texture: what
                     * that pass leaves stays until it runs again (if it gets the same texture) */
  lm_texture texture; /* after execution */
} lm_graph_target_info;
int lm_graph_target_count(const lm_graph *g);
lm_graph_target_info lm_graph_target(const lm_graph *g, int i);
int lm_graph_find_target(const lm_graph *g, const char *name);
/* Distinct texture slots the plan needs for transient targets. */
int lm_graph_slot_count(const lm_graph *g);

/* ---- executing --------------------------------------------------------- */
/* What a scene pass hands the code that draws the scene. */
typedef struct lm_scene_pass {
  const lm_pass_desc *desc;  /* shader = the material technique */
  const lm_program *program; /* bound, with the pass's inputs and parameters */
  lm_graph *graph;
  const lm_pass_view *view;  /* the tile being drawn; NULL: the camera */
} lm_scene_pass;
/* The technique's program with `defines` added to the pass's (a material's
 * variant: "BASE_COLOR_TEXTURE"), bound, with the pass's inputs and
 * parameters applied. NULL with a message naming the pass and shader file. */
const lm_program *lm_scene_pass_variant(const lm_scene_pass *sp, const char *defines, lm_error *err);

/* A CPU pass's images: RGBA floats, rows top first (any target format; an
 * rgba8 output's values are clamped to [0, 1] on upload). */
typedef struct lm_cpu_image {
  const char *name; /* the input's sampler name, or the output target's name */
  int width, height;
  float *rgba;
} lm_cpu_image;
typedef struct lm_cpu_pass {
  const lm_pass_desc *desc;
  const lm_cpu_image *inputs; /* read back, in desc->inputs' order */
  int input_count;
  lm_cpu_image *outputs;      /* zeroed; uploaded after the call; in desc->outputs' order */
  int output_count;
} lm_cpu_pass;

typedef struct lm_graph_exec_desc {
  lm_clock clock;
  /* Draws the scene for a scene pass (once per view); false with a message
   * stops the frame. */
  bool (*draw_scene)(void *user, const lm_scene_pass *sp, lm_error *err);
  /* Before a scene pass that fits its views: `fit` is the texture of the
   * pass's fit_target (w x h); the callback may read it and rewrite the
   * views' matrices. NULL: the views stay as recorded. */
  bool (*fit_views)(void *user, const lm_pass_desc *d, lm_texture fit, int w, int h, lm_pass_view *views,
                    lm_error *err);
  /* Before a scene pass with views that clears (after fit_views): true when
   * the callback keeps what the outputs hold, so that the pass clears
   * nothing and draw_scene clears each tile it draws itself. NULL or false:
   * the outputs are cleared whole first. */
  bool (*keeps_views)(void *user, const lm_scene_pass *sp);
  /* Runs a CPU pass (desc->shader names the function); false with a message
   * stops the frame. NULL: a CPU pass is an error naming it. Its time, with
   * the read-back and upload, is the pass's time (wall clock; the process's
   * CPU time with LM_CLOCK_PROCESS). */
  bool (*run_cpu)(void *user, const lm_cpu_pass *cp, lm_error *err);
  /* Uniforms the scene sets on each draw (not bindable from a script). */
  bool (*scene_owns_uniform)(const char *name);
  void *user;
  /* Debug: read back every float output after its pass and fail at the first
   * NaN or Inf, naming the pass, the target and the pixel. Slow. */
  bool check_finite;
} lm_graph_exec_desc;
bool lm_graph_execute(lm_graph *g, const lm_graph_exec_desc *x, lm_error *err);
/* Moves the textures (and contents) of `from`'s persistent targets into the
 * persistent targets of `to` that have the same name, format, mips and size
 * rule (scale or absolute size) and no texture yet. A reloaded pipeline
 * keeps its history this way: record its first frame into a new graph,
 * take from the old one, execute. Returns how many moved. */
int lm_graph_take_persistent(lm_graph *to, lm_graph *from);
/* Off: every transient target gets a texture of its own, so each can be
 * read after the frame (the viewer's inspector); costs memory. On by default. */
void lm_graph_set_sharing(lm_graph *g, bool on);
/* Pooled textures alive now, and their bytes. */
void lm_graph_pool_stats(const lm_graph *g, int *textures, double *bytes);

#endif
