/* render: one frame of a scene through a pipeline script. Records the frame
 * (OnRender), appends the engine's output stage (which never lets a NaN or
 * Inf through and encodes sRGB), compiles and executes the frame graph. */
#ifndef LIMN_RENDER_H
#define LIMN_RENDER_H

#include "scene/scene.h"
#include "script/script.h"

typedef struct lm_renderer lm_renderer;

typedef struct lm_renderer_desc {
  lm_scene *scene;        /* borrowed */
  lm_pipeline *pipeline;  /* borrowed */
  int width, height;
  int camera;             /* index into the scene's cameras */
  lm_clock clock;         /* LM_CLOCK_AUTO picks */
  bool linear_output;     /* also keep a float copy of the output (for EXR) */
  bool check_finite;      /* debug: name the first pass that writes a NaN or Inf */
  bool no_culling;        /* draw every node, even those outside the frustum */
  bool no_light_culling;  /* every pixel evaluates every light (the reference for light culling) */
  float exposure;         /* the lighting passes' pre-exposure, a fixed camera's; 0: from the scene's
                             lights each frame (common.glsl's exposed(); the outputs are radiance either way) */
} lm_renderer_desc;

lm_renderer *lm_renderer_create(const lm_renderer_desc *desc, lm_error *err);
void lm_renderer_destroy(lm_renderer *r);
bool lm_renderer_frame(lm_renderer *r, lm_error *err);
lm_graph *lm_renderer_graph(lm_renderer *r);
/* Another camera and output size for the next frames (a capture job's next
 * view): the pipeline, its persistent targets and the texture pool stay. */
void lm_renderer_set_view(lm_renderer *r, int camera, int width, int height);
/* Another scene (uploaded now if it was not) for the next frames. */
bool lm_renderer_set_scene(lm_renderer *r, lm_scene *scene, lm_error *err);
/* The last frame's scene draws: nodes drawn and culled, triangles. */
lm_scene_draw_stats lm_renderer_draw_stats(const lm_renderer *r); /* camera passes, not shadow tiles */
/* The same for the last frame's shadow tiles, summed over the tiles. */
lm_scene_draw_stats lm_renderer_shadow_draw_stats(const lm_renderer *r);
lm_clock lm_renderer_clock(const lm_renderer *r);
/* The last frame's pre-exposure E (common.glsl's exposed(); frame_exposure in render.c). */
float lm_renderer_exposure(const lm_renderer *r);
/* The last frame's light grid (lm_light_grid_build), read by the lighting shaders. */
const lm_light_grid *lm_renderer_light_grid(const lm_renderer *r);
/* CPU milliseconds of the last frame spent in Lua (OnRender) and in compiling the graph. */
void lm_renderer_overhead(const lm_renderer *r, double *record_ms, double *compile_ms);
/* Wall milliseconds the last frame spent reading back the depth range its
 * shadow views fit to (a wait for the passes before it; 0 when none). */
double lm_renderer_fit_ms(const lm_renderer *r);
/* The last frame's shadow plan (view_count 0 when it drew no shadows). */
const lm_shadow_plan *lm_renderer_shadows(const lm_renderer *r);
/* The last frame's output, top row first: RGB 8-bit sRGB, or RGB float linear
 * (needs linear_output). */
bool lm_renderer_read(lm_renderer *r, bool linear, void *rgb, lm_error *err);

/* Output size from the next frame on (a window resized); never below 1x1.
 * Targets sized by the output follow; absolute ones stay. */
void lm_renderer_resize(lm_renderer *r, int width, int height);
void lm_renderer_set_camera(lm_renderer *r, int camera);
/* Targets share textures where lifetimes allow (default); off keeps every
 * target's content readable after the frame (lm_graph_set_sharing). */
void lm_renderer_set_sharing(lm_renderer *r, bool on);
/* Keep the float linear output (lm_renderer_desc.linear_output) from the
 * next frame on, or stop: a viewer reads it only while it shows an error. */
void lm_renderer_set_linear_output(lm_renderer *r, bool on);
/* Renders a frame with pipeline p (a reloaded script) into a new frame
 * graph. On success p replaces the pipeline (the caller still owns both),
 * and persistent targets with the same name, format and size rule keep their
 * textures and contents (lm_graph_take_persistent); the others start clear.
 * On failure nothing changes and err says why. */
bool lm_renderer_swap_pipeline(lm_renderer *r, lm_pipeline *p, lm_error *err);
/* The last frame's sRGB output texture (rgba8) and its size. */
bool lm_renderer_output(lm_renderer *r, lm_texture *tex, int *width, int *height);

#endif
