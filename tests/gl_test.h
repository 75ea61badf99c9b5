/* Shared by the GL tests: a headless context, the built-in Cornell box and a
 * scratch engine root for test shaders and scripts; frames of a pipeline
 * script over a scene, kept open so a test can look at any target
 * afterwards; where the box's camera sees a world point; option errors. */
#ifndef LIMN_GL_TEST_H
#define LIMN_GL_TEST_H

#include "render/render.h"

typedef struct gl_run {
  lm_scene *scene;          /* borrowed; NULL: gl_cornell() */
  const char *script;       /* NULL: scripts/pp.lua; a relative path is under the root (LIMN_ROOT) */
  const char *tech;         /* NULL: the script's default */
  const char *const *sets;  /* "name=value" options, NULL-terminated (may be NULL) */
  int width, height;        /* 0: 256 x 192 */
  int frames;               /* 0: 1 */
  bool check_finite;        /* the renderer's NaN/Inf attribution */
  bool no_light_culling;    /* every pixel evaluates every light */
  bool no_culling;          /* every node drawn in every view (lm_renderer_desc.no_culling) */
  float exposure;           /* a fixed pre-exposure (lm_renderer_desc.exposure); 0: the scene's */
  bool keep_targets;        /* sharing off: every target readable after the frame (gl_read_target) */
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

/* Makes the context (fails the test run when there is none), the Cornell
 * box and a scratch engine root in /tmp: the real shaders linked in one by
 * one (so a test can add its own) and scripts/ linked whole; LIMN_ROOT
 * points at it from then on. A cmocka group setup; teardown undoes it. */
int gl_test_setup(void **state);
int gl_test_teardown(void **state);
/* The scratch root's folder (LIMN_ROOT); shaders/ and scripts/ in it are
 * links into the source tree: write new files there, never over theirs. */
const char *gl_root(void);
/* The built-in Cornell box (a test that changes it puts it back). */
lm_scene *gl_cornell(void);
/* Writes text to the file `rel` under the scratch root; false when it cannot. */
bool gl_write_file(const char *rel, const char *text);
gl_result gl_render(const gl_run *run);
/* gl_render that fails the test, naming the technique, when the frame fails
 * or a pixel is NaN, Inf or negative. */
gl_result gl_render_ok(const gl_run *run);
/* Sets a "name=value" option for the next frame; false with the message in r->err. */
bool gl_set(gl_result *r, const char *assignment);
/* Renders one more frame with the same pipeline (after moving a camera, say). */
bool gl_render_again(gl_result *r);
/* Temporal reuse on a still camera: `run` (its scene, technique, size;
 * sets and frames are replaced) with the options `on` for frames 1..last,
 * then one frame with `off` (no reuse) and one with `ref` (many samples).
 * early and late: the mean absolute change of the linear RGB from frame 2
 * to 3 and from last - 1 to last; mean: the last frame's; e_acc and e_one:
 * the mean absolute error against ref's frame of the last frame and of
 * off's. Printed after `label`; fails the test when a frame fails or a
 * value of the accumulation is NaN, Inf or negative. */
typedef struct gl_convergence {
  double early, late, mean, e_acc, e_one;
} gl_convergence;
gl_convergence gl_temporal_convergence(gl_run run, const char *const *on, const char *const *off,
                                       const char *const *ref, int last, const char *label);
/* Mean |a[i] - b[i]| over n values. */
double gl_mean_abs_diff(const float *a, const float *b, int n);
void gl_result_free(gl_result *r);
/* The passes of the last frame that ran, space separated, into out. */
void gl_pass_names(const gl_result *r, char *out, size_t cap);
/* Was a pass whose name starts with `prefix` recorded (culled or not)? */
bool gl_has_pass(const gl_result *r, const char *prefix);
/* How many passes whose names start with `prefix` ("": any) were recorded and culled. */
int gl_culled(const gl_result *r, const char *prefix);
/* Mean linear RGB over x0..x1, y0..y1 (rows from the top). */
void gl_region(const gl_result *r, int x0, int y0, int x1, int y1, float out[3]);
float gl_luminance(const float rgb[3]);
/* Every value finite and not negative. */
bool gl_all_finite(const gl_result *r);
/* A used target of the last frame as RGBA floats, rows top first (caller
 * frees); NULL when the frame has none of that name, or when a target that
 * shares its texture was written after it (render with sharing off). */
float *gl_read_target(gl_result *r, const char *name, int *width, int *height);
/* gl_read_target of a G-buffer normal target (gbuffer.nrm: rgba8 as
 * common.glsl's gbuffer_normal_encode writes it), each texel decoded as
 * gbuffer_normal_decode does: (unit normal, shininess). */
float *gl_read_normals(gl_result *r, const char *name, int *width, int *height);
/* Does that target hold only finite values that are not negative? (It is
 * read before the output stage, which would hide a NaN.) */
bool gl_target_finite(gl_result *r, const char *name);

/* Scenes built in code: a quad a b c d (counter-clockwise seen from its
 * normal n) as a mesh node of material `material`; a Lambertian material
 * (rho 0.5, k_a = k_d = 1, no specular) of colour r g b, returning its
 * index; a camera at (0, y, 0) looking straight up. */
void gl_quad(lm_scene *s, const char *name, int material, const float c[4][3], const float n[3]);
int gl_material(lm_scene *s, const char *name, float r, float g, float b);
void gl_camera_up(lm_scene *s, float y);
/* data/scenes/reference/<name>.glb with the first view of its .cams list as
 * camera 0 (the one a frame renders); fails the test when either cannot be read. */
lm_scene *gl_reference_scene(const char *name);
/* A UV sphere of radius r at the origin, 32 segments by 16 rings (position,
 * normal, uv), as mesh `name`: the mesh's index. */
int gl_uv_sphere(lm_scene *s, const char *name, float r);
/* Adds camera `name` at eye looking at target (up +y), fov_y in degrees,
 * near 0.01, far 100; view_proj gets its view-projection at aspect
 * width / height. */
void gl_look_camera(lm_scene *s, const char *name, const float eye[3], const float target[3], float fov_y, int width,
                    int height, float view_proj[16]);
/* An outdoor corner: open grey ground, two 4-high walls meeting at the
 * origin (facing +x and +z), a sun casting shadows and a camera looking
 * into the corner from (9, 6, 9); view_proj gets the camera's, at aspect
 * width / height. */
lm_scene *gl_sunlit_corner(int width, int height, float view_proj[16]);

/* The same scene in a unit `unit` times smaller: a root node scaled by unit
 * above everything (cameras under it scale near and far with it), and the
 * lights' ranges and inverse-square intensities, which glTF keeps out of node
 * scale, written in the new unit. */
void gl_rescale(lm_scene *s, float unit);

/* The pixel of world point (x, y, z) for the camera of the built-in Cornell
 * box (cornell.c: eye (0, 1, 3.4) looking down -z, fov_y 45 degrees) in a
 * width x height image, rows from the top. */
void gl_project(int width, int height, float x, float y, float z, int *col, int *row);
/* Mean linear RGB of the (2 radius + 1)^2 pixels around a world point of the box. */
void gl_mean_around(const gl_result *r, float x, float y, float z, int radius, float out[3]);

/* An option that must stop the frame: `set` alone with technique `tech` of
 * pp.lua fails with a message holding `expect`. */
typedef struct gl_bad_option {
  const char *tech, *set, *expect;
} gl_bad_option;
/* Fails the test unless each case fails so and its message also holds
 * `where` (the line to blame, "pp.lua:" say). */
void gl_assert_bad_options(const gl_bad_option *cases, size_t n, const char *where);

#endif
