/* What `limn capture` (cli/capture.c), capture jobs (cli/job.c), `limn
 * report` and the viewer share (cli/capture_render.c): one path that renders
 * a view and writes its images; and the pipeline capture, bench and graph
 * load from their flags. */
#ifndef LIMN_CAPTURE_RENDER_H
#define LIMN_CAPTURE_RENDER_H

#include <signal.h>

#include "render/render.h"

typedef struct capture_view {
  int camera, width, height, frames;
  int warmup; /* frames rendered first, untimed */
  const char *const *outputs; /* .png (sRGB), .exr (linear), ... */
  int output_count;
  bool quiet;
  /* The next frame of a sequence through the same camera and size: the
   * renderer keeps its temporal histories (no lm_renderer_set_view). */
  bool continues;
  /* A signal's flag (NULL: none): set, the frames stop before the next one
   * and nothing is written. */
  const volatile sig_atomic_t *stop;
} capture_view;

/* How outputs name a sequence's frame ({frame}; {time} is limn_time_text's, 3 places). */
#define CAPTURE_FRAME_FORMAT "%04d"

typedef struct capture_pass_time {
  const char *name, *kind;
  double ms; /* median over the frames */
} capture_pass_time;

typedef struct capture_result {
  capture_pass_time *passes;
  int pass_count;
  double total_ms;
  lm_scene_draw_stats stats; /* the last frame's */
} capture_result;

/* Points the renderer at the view, renders its frames and writes each
 * output whole or not at all (lm_image_write). */
bool capture_render_write(lm_renderer *r, const capture_view *v, capture_result *res, lm_error *err);
void capture_result_free(capture_result *res);
/* True for an image extension capture writes; *linear for float formats (EXR, HDR). */
bool capture_known_extension(const char *path, bool *linear);
/* Sets NAME=VALUE, as --set and a job's `set` give an option, on p. */
bool capture_set_option(lm_pipeline *p, const char *name_value, lm_error *err);
/* A relative path that does not exist here is looked up under the engine's root. */
void capture_resolve(const char *given, char *out, size_t cap);
/* The pipeline capture, bench and graph's flags name: --script (pp.lua
 * without it; capture_resolve), --tech, then each --set. *rc the exit
 * status: 0, or with NULL and err 1 when the script does not load, 2 for a
 * bad technique or option (the user's flags). */
struct limn_common_args;
lm_pipeline *capture_load_pipeline(const struct limn_common_args *a, int *rc, lm_error *err);
/* --clock of capture and bench: auto, gpu or cpu; false when s is none. */
bool capture_parse_clock(const char *s, lm_clock *out);

#endif
