/* The viewer's panel: a widget for every option of the script, chosen by its
 * rule (options.lua), grouped by module; the techniques as a list; the time
 * (play, pause, scrub); a button that writes the settings as a capture job.
 * Dear ImGui (Debian's libimgui-dev, with its GLFW and OpenGL 3 backends)
 * behind this C header, in view_panel.cpp. The panel knows nothing of
 * pipelines: the viewer hands it a model each frame and applies the edit it
 * returns as --set would. */
#ifndef LIMN_VIEW_PANEL_H
#define LIMN_VIEW_PANEL_H

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "gfx/gfx.h"
#include "script/script.h"

typedef struct lm_panel lm_panel;

/* A pass of the frame graph as the panel draws it: its targets are indices
 * into panel_model.targets. */
typedef struct panel_pass {
  const char *name;
  bool culled;
  double ms;                      /* its time last frame, < 0: not run */
  const int *inputs, *outputs;    /* outputs: colour targets, then the depth target */
  int input_count, output_count;
  const int *writers;             /* each input's writer (a pass index; -1: last frame's), lm_graph_input_writer */
  int column;                     /* its depth, lm_graph_pass_depths */
} panel_pass;

/* What the panel shows this frame (borrowed for the call). */
typedef struct panel_model {
  const lm_option_info *options;
  int option_count;
  const char *const *techniques;
  int technique_count, technique; /* the current one's index */
  bool animated;                  /* the time controls show */
  double time, time_lo, time_hi;  /* seconds: now and the animation's keys' range */
  const char *time_text;          /* the time as the overlay prints it (limn_time_text) */
  bool paused;
  const char *status;             /* a line under the buttons ("wrote out/view.lua"), or NULL */
  const char *cost;               /* the panel's share of the frame, or NULL */
  const panel_pass *passes;       /* the frame graph, in recording order */
  int pass_count;
  const char *const *targets;
  int target_count;
  /* A/B: the wipe's other side, its technique (-1: none yet) and the one
   * option it sets apart from this side (NULL: none), as that side has it. */
  int compare_technique;
  bool compare_on;
  const lm_option_info *compare_option;
  const char *reference;          /* the error against the reference here, or why there is none; NULL: no job */
  bool reference_here;            /* the error view's choice shows */
  int error_view;                 /* ERROR_VIEW_* */
} panel_model;

/* What the user did this frame (at most one of each: one widget is active at a time). */
typedef struct panel_edits {
  bool option;                    /* option_name = option_value, as --set takes it */
  char option_name[128], option_value[256];
  int technique;                  /* a technique picked, or -1 */
  bool play, write_job;           /* the play/pause and job buttons */
  bool scrub;                     /* the time slider moved to scrub_time */
  double scrub_time;
  int inspect;                    /* a target clicked in the frame graph, or -1 */
  int error_view;                 /* the error view picked (ERROR_VIEW_*), or -1 */
  int compare_technique;          /* a technique picked for the A/B wipe's other side, or -1 */
  bool compare_toggle;            /* the wipe's checkbox clicked */
  int compare_pick;               /* an option (index into options) picked to differ on that side, or -1 */
  bool compare_set;               /* that side's value of it: compare_name = compare_value */
  char compare_name[128], compare_value[256];
} panel_edits;

lm_panel *panel_create(lm_window *w, lm_error *err);
void panel_destroy(lm_panel *p);
/* The panel's image and where it goes over the display. */
typedef struct panel_image {
  lm_texture texture;  /* RGBA8, premultiplied alpha, the window's size; id 0 on a GL error */
  int cover[4];        /* what it draws: x, y from the bottom left, width, height */
  int column;          /* its window covers x >= column at every height, opaque */
} panel_image;
/* Lays the panel out along the right edge of a width x height window, fills
 * *edits, and returns its image (drawn again only when it changed). While
 * neither the input nor the model changes (after a few frames to settle) the
 * layout is skipped and the last image returned. */
panel_image panel_frame(lm_panel *p, const panel_model *m, int width, int height, panel_edits *edits);
/* Scripted mouse input (tests): from this call on the panel sees the cursor
 * at (x, y) window pixels and the left button as `down`, not the real mouse. */
void panel_set_mouse(lm_panel *p, double x, double y, bool down);
/* Does the panel take the mouse or the keyboard now (the cursor over it, a
 * widget dragged, text typed)? The viewer then leaves them alone. */
bool panel_wants_mouse(const lm_panel *p);
bool panel_wants_keyboard(const lm_panel *p);
/* One line per option of the last frame's model: "panel widget NAME KIND
 * GROUP X Y W H" (the rectangle 0 0 0 0 where a closed group hides it),
 * then "panel technique NAME X Y W H" per technique, "panel control NAME X Y
 * W H" for the buttons, the time slider and the frame graph's header ("job",
 * "play", "time", "graph", the A/B section's "ab", "ab=TECHNIQUE" for each
 * of its list, "ab-option", "ab-value", and the reference's "error") and, while the
 * frame graph is open, "panel target NAME X Y W H" for each target button of
 * each pass (0 0 0 0 where it is scrolled out of sight). */
void panel_list_widgets(const lm_panel *p, FILE *out);

#ifdef __cplusplus
}
#endif

#endif
