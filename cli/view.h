/* The viewer's state, shared by view.c (command line, keys, reloading, the
 * loop) and view_display.c (messages, inspector, overlay, what reaches the
 * window), which view.c calls and which calls nothing of view.c. */
#ifndef LIMN_VIEW_H
#define LIMN_VIEW_H

#include <stdint.h>

#include "image/metrics.h"
#include "tools.h"
#include "render/render.h"
#include "view_panel.h"
#include "view_text.h"

enum { MAX_SETS = 64, MAX_SCRIPT_KEYS = 256, PANEL_TIMES = 64, PANEL_EVERY = 8 };
enum { ERROR_VIEW_OFF, ERROR_VIEW_REFERENCE, ERROR_VIEW_HEAT, ERROR_VIEWS };

typedef struct script_key {
  long frame;
  char key[32];
} script_key;

/* A view of the --job whose reference is cached (view_reference.c): the
 * viewer shows the error against it while its camera is there. */
typedef struct view_place {
  int view;                  /* the job's view number (--view N) */
  int camera, width, height;
  double time;               /* the view's time, when the job is timed */
  char reference[1024];      /* the reference's file (limn reference) */
  char direct[1024];         /* its direct-only reference, "" when none is cached */
} view_place;

typedef struct view_args {
  limn_common_args common; /* --scene, --script, --tech, --size, --camera; --set as given */
  const char *screenshot, *capture_dir;
  char *sets[MAX_SETS]; /* --set's, owned: toggles add and replace entries */
  int set_count;
  const char *animation; /* NAME, INDEX or "all" */
  double time;           /* --time; with time_given */
  bool time_given;
  double fps;            /* frames a second: what Left/Right step and the overlay counts (--fps, or a
                          * sequence job's time.fps) */
  bool fps_given;
  double frame_zero;     /* the time of frame 0: a sequence job's time.start, so that frames count as its */
  long exit_after, reload_test;
  bool overlay, panel, quiet, verbose;
  const char *job;       /* --job: start at view `job_view` of this capture job */
  int job_view;
  const char *compare;   /* --compare TECH: the A/B wipe's right side */
  char *compare_sets[MAX_SETS]; /* --compare-set NAME=VALUE: that side's own options (owned) */
  int compare_set_count;
  char job_script[1024], job_scene[1024], job_tech[64], job_animation[64]; /* what the job's view names */
  lm_scene *job_loaded;  /* the view's scene as the job loaded it (its camera list's cameras too) */
  const char *refs;      /* --refs: the references' folder (default out/reference) */
  view_place *places;    /* the job's views of that scene with a cached reference (owned) */
  int place_count;
  bool job_timed;        /* the places' times count */
  char *job_sets[MAX_SETS]; /* the job's `set`: the baseline's options, as limn report renders it (owned) */
  int job_set_count;
  char against[32];      /* "POV-Ray" or "Cycles" */
  script_key keys[MAX_SCRIPT_KEYS];
  int key_count;
} view_args;

typedef struct fly {
  float pos[3], yaw, pitch;
} fly;

typedef struct viewer {
  view_args *args;
  char script[2048];
  lm_window *window;
  lm_scene *scene;
  lm_pipeline *pipeline;
  lm_renderer *renderer;
  lm_watch *watch;
  lm_font *font;
  int width, height;        /* the renderer's output (the window's framebuffer) */
  lm_texture shown;         /* the last good frame: shown while a frame fails */
  lm_texture overlay_tex;   /* text, rgba8 */
  uint8_t *overlay;
  lm_buf overlay_lines;     /* this frame's (view_display.c's draw_text) */
  lm_buf overlay_drawn;     /* those overlay_tex holds: none, nothing to blend */
  lm_texture probe;         /* the inspected target's raw values, rgba32f */
  int probe_w, probe_h;
  int camera;
  fly cam;
  /* Time: the scene shows animation `anim` (LM_ANIM_ALL: all) at `time`
   * seconds, looping over its keys' range while it plays. */
  int anim;
  double time;
  float anim_range[2];      /* equal: nothing to loop (time runs on) */
  bool paused;
  bool camera_animated;     /* the camera's node or an ancestor is a channel's target */
  bool camera_user;         /* the user moved it: the animation no longer drives it */
  float camera_local[16];   /* meanwhile, the camera node's local transform as the animation poses it */
  bool held[4];             /* W A S D held by --script-keys */
  double drag[2];           /* a scripted drag not yet applied */
  double mouse[2];          /* the scripted mouse (mouse=, button=) */
  bool mouse_down;
  bool overlay_on;
  /* A/B: the same frame through a second pipeline (--compare), shown right
   * of a split at `split` (a share of the width) that a left drag moves. */
  lm_pipeline *compare_pipeline;
  lm_renderer *compare_renderer;
  lm_texture compare_shown;
  char compare_tech[64];      /* its technique (--compare, or the panel's A/B) */
  char compare_option[128];   /* the option the panel's A/B sets apart there ("" none) */
  lm_option_info *compare_options; /* that side's options, read again when options_stale */
  int compare_option_count;
  bool compare_on, split_held;
  float split;
  char compare_error[2048];
  lm_panel *panel;          /* NULL when it could not start */
  bool panel_on;
  lm_option_info *options;  /* the panel's list, read again when options_stale */
  int option_count;
  bool options_stale;
  panel_edits edits;        /* the panel's last frame: applied before the next */
  char status[1200];        /* the panel's note: the job last written */
  /* The panel's cost: its own milliseconds in its last timed frames (one in
   * PANEL_EVERY, glFinish on both sides) and the frames' with it on and off,
   * wall and the process's CPU time, for the share the overlay prints. */
  double panel_times[2][PANEL_TIMES], frame_ms_sum[2], frame_cpu_sum[2]; /* [0] wall, [1] CPU */
  double panel_spent[2];    /* a timed frame's so far, wall and CPU */
  long panel_timed, frames_timed[2]; /* [0] panel off, [1] on */
  char panel_cost_text[200]; /* the panel's line of it */
  /* Live error against the reference (view_reference.c) while the camera
   * is at a place of the --job: E steps the error view (a wipe with the
   * reference, one with the error heat map, off). The frame's linear
   * output is kept and read back only while the error view is on. */
  int error_view;           /* ERROR_VIEW_* */
  int place;                /* index into args->places the camera is at, -1: none */
  bool place_ready;         /* its reference loaded and its baseline measured */
  lm_image reference;       /* the place's reference, linear */
  lm_texture reference_tex; /* the same, rgba32f, for the wipe */
  lm_texture heat_tex;      /* this frame's error heat map, rgba8 */
  double base_error, floor; /* the baseline's error against the reference and against the direct-only one
                               (floor < 0: no direct-only reference cached) */
  double heat_scale;        /* the heat map's white: the baseline's largest pixel error */
  lm_metrics live;          /* this frame's against the reference; live_ok once measured */
  bool live_ok;
  char reference_text[512]; /* what the panel and the overlay say about it */
  int inspect;              /* target index, -1: the frame */
  int inspect_logged;       /* the target the log last named (a line a test reads) */
  int channel;              /* 0 r, 1 g, 2 b, 3 a, 4 rgb */
  bool false_colour;
  float exposure;
  float range[2];           /* of the inspected target's shown channel (grey and false colour) */
  bool cursor_in;           /* the cursor over the window while inspecting: its texel's value */
  int cursor_px[2];
  float cursor_value[4];
  int cursor_logged[3];     /* the texel and target the debug log last gave the value of */
  bool mouse_scripted;
  char script_error[2048];  /* the last reload's error ("" when it loaded) */
  char frame_error[2048];   /* the current pipeline's last frame error */
  char shader_error[2048];  /* a shader rebuild that failed */
  char scene_error[2048];   /* the scene file's last reload */
  char message[512];        /* a passing note (an unknown technique ...) */
  double message_until;
  double frame_ms;           /* from one frame's start to the next's */
  double render_ms;          /* recording, compiling and running the frame graph */
  long frame;
  int captures;
} viewer;

/* view_display.c */
/* A note on screen for a few seconds and on stderr. */
void say(viewer *v, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* An error shows once on stderr when it appears and once (as `cleared`) when it goes. */
void set_error(char *slot, size_t cap, const char *msg, const char *cleared);

/* The frame number at the viewer's time (fps frames a second from frame_zero) and its animation's name. */
long view_frame(const viewer *v);
const char *view_animation_name(const viewer *v);
bool make_window_textures(viewer *v, lm_error *err);
/* Is the wipe showing the reference or its heat map now (the error view on at a place ready)? */
bool reference_shown(const viewer *v);
/* Draws the frame (or the inspected target) and the overlay into the back buffer. */
void display(viewer *v);
/* "panel 0.61 ms, 0.9% of the frame; CPU 0.70 ms, 1.7% (frames 70.2 ms on, 69.8 off; CPU 41.0, 40.8)". */
void panel_cost(const viewer *v, char *out, size_t cap);
/* The inspected target as EXR and the frame as PNG, into --capture-dir. */
void write_captures(viewer *v);
/* The back buffer as a PNG. */
bool screenshot(viewer *v, const char *path);
/* The inspector's targets in the order PageDown steps: those the frame used
 * first, the frame's output ("output.srgb") among them, then the others. */
int inspect_order(viewer *v, int *order, int cap);
bool target_used(viewer *v, int target);

/* view_job.c: the viewer's settings as a capture job and as a command line,
 * and a capture job's view as the viewer's start. */
bool write_view_job(viewer *v, char *job_path, size_t cap, lm_error *err);
/* Fills a->script, scene, tech, camera, size, time and sets from view
 * a->job_view of job a->job; false (logged) when it has no such view. */
bool load_view_job(view_args *a);

/* view_reference.c: the error against the reference at the job's places. */
struct job;
struct job_view;
/* The places of job j's views of scene `scene` whose references exist
 * under a->refs, into a->places; the job's `set` into a->job_sets. */
void find_places(view_args *a, struct job *j, const struct job_view *views, int count, int scene);
/* After each frame: the place the camera is at (arriving: its reference
 * read and the baseline rendered once), and with the error view on this
 * frame's error against the reference. */
void update_reference(viewer *v);
/* The place's line for the panel and the overlay (reference_text); with
 * log, the figures in full on stderr ("reference error: view N, mean ..."). */
void describe_reference(viewer *v, bool log);
void reference_free(viewer *v);

#endif
