/* Shared by the GL tests: a headless context and frames of a pipeline script
 * over a scene, kept open so a test can look at any target afterwards. */
#ifndef LIMN_GL_TEST_H
#define LIMN_GL_TEST_H

#include "render/render.h"

typedef struct gl_run {
  lm_scene *scene;          /* borrowed */
  const char *script;       /* NULL: <root>/scripts/pp.lua */
  const char *tech;         /* NULL: the script's default */
  const char *const *sets;  /* "name=value" options, NULL-terminated (may be NULL) */
  int width, height;        /* 0: 256 x 192 */
  int frames;               /* 0: 1 */
  bool check_finite;        /* the renderer's NaN/Inf attribution */
} gl_run;

typedef struct gl_result {
  bool ok;
  lm_error err;
  int width, height;
  float *rgb;               /* the output stage's linear RGB, rows top first */
  unsigned char *srgb;      /* and its 8-bit sRGB encoding */
  lm_pipeline *pipeline;
  lm_renderer *renderer;    /* still open: lm_renderer_graph() shows the last frame */
} gl_result;

/* Makes the context (fails the test run when there is none). */
int gl_test_setup(void **state);
int gl_test_teardown(void **state);
gl_result gl_render(const gl_run *run);
/* Renders one more frame with the same pipeline (after moving a camera, say). */
bool gl_render_again(gl_result *r);
void gl_result_free(gl_result *r);
/* The passes of the last frame that ran, space separated, into out. */
void gl_pass_names(const gl_result *r, char *out, size_t cap);
/* Was a pass whose name starts with `prefix` recorded (culled or not)? */
bool gl_has_pass(const gl_result *r, const char *prefix);
/* Mean linear RGB over x0..x1, y0..y1 (rows from the top). */
void gl_region(const gl_result *r, int x0, int y0, int x1, int y1, float out[3]);
float gl_luminance(const float rgb[3]);
/* Every value finite and not negative. */
bool gl_all_finite(const gl_result *r);
/* A target of the last frame as RGBA floats, rows top first (caller frees). */
float *gl_read_target(gl_result *r, const char *name, int *width, int *height);

#endif
