/* limn view: a window on a scene through a pipeline script, reloading the
 * script, its modules, shaders and the scene file as they are saved. Keys
 * follow the seed viewer (F2-F5 techniques, F6-F12 effects); the overlay
 * shows per-pass times, the inspector steps through the frame graph's targets. */
#define _GNU_SOURCE
#include <getopt.h>
#include <malloc.h>
#ifdef __SANITIZE_ADDRESS__
/* libasan's (GCC ships no allocator_interface.h to declare it). */
size_t __sanitizer_get_current_allocated_bytes(void);
#endif
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "capture_render.h"
#include "image/image.h"
#include "render/render.h"
#include "scene/gltf.h"
#include "tools.h"
#include "view.h"

static const char view_usage[] =
    "usage: limn view [options]\n"
    "\n"
    "Opens a window on a scene rendered through a pipeline script. Saving the\n"
    "script (or a module it requires), a shader (or a file it includes) or the\n"
    "scene file takes effect at once; on an error the last good pipeline keeps\n"
    "running and the error (file:line) shows on screen and on stderr.\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE    built-in scene or a .gltf/.glb file (default cornell)\n"
    "  --script FILE        pipeline script (default scripts/pp.lua)\n"
    "  --tech NAME          technique to start with (default: the script's first)\n"
    "  --set NAME=VALUE     set an option the script declares (repeatable)\n"
    "  --size WxH           window size (default 512x384)\n"
    "  --camera N           scene camera to start from (default 0)\n"
    "  --animation NAME|INDEX|all  the glTF animation to play (default all)\n"
    "  --time SECONDS       time to start at (default: the animation's first key)\n"
    "  --fps N              frames a second of Left/Right steps and of the frame\n"
    "                       number on the overlay (default 24; a sequence job's)\n"
    "  --overlay on|off     show the overlay at start (default on; F1/Tab toggles)\n"
    "  --panel on|off       show the panel of options at start (default on; M toggles)\n"
    "  --compare TECH       A/B: the frame also through technique TECH, shown right\n"
    "                       of a split a left drag moves (B toggles the wipe)\n"
    "  --compare-set NAME=VALUE  an option of the --compare side alone (repeatable)\n"
    "  --job FILE           start at a view of a capture job: its script, scene,\n"
    "                       camera, size, technique, time and options\n"
    "  --view N             which view of --job (default 0; as capture numbers them)\n"
    "  --refs DIR           the job's references (default out/reference): at a view\n"
    "                       of the job whose reference limn reference cached, E shows\n"
    "                       the error against it\n"
    "  --capture-dir DIR    where P writes images (default .)\n"
    "  --exit-after N       close after N frames\n"
    "  --screenshot FILE    write the window's content at exit (PNG)\n"
    "  --script-keys LIST   press keys at frames, e.g. \"5:F5,10:F3\" (for tests);\n"
    "                       also resize=WxH, hold=W|A|S|D, release=W|A|S|D and\n"
    "                       drag=DX;DY (a left-button drag, pixels) and time=SECONDS;\n"
    "                       camera and animation steps are then 1/60 s a frame;\n"
    "                       mouse=X;Y and button=down|up drive the panel's mouse,\n"
    "                       widgets prints the panel's widgets and where they are,\n"
    "                       inspect=NAME shows a target of the frame graph\n"
    "  --reload-test N      test hook: N edits of a copy of the script, each one\n"
    "                       reloaded through the file watch; prints GL object and\n"
    "                       heap counts and fails when any grew\n"
    "  --quiet | --verbose  errors only | debug messages\n"
    "  --help               this text\n"
    "\n"
    "keys:\n"
    "  W/S/A/D move, left mouse drag looks around, 1-9 the scene's cameras\n"
    "  Space pauses and plays, Left/Right step a frame (and pause); an animated\n"
    "  camera follows its animation until moved, 0 gives it back\n"
    "  F2-F5, F10 the techniques whose rows name them (pp.lua's F2 isr+esm  F3 isr\n"
    "  F4 dl+esm  F5 dl; a script of names alone gets these four)\n"
    "  F6 bloom  F7 dof  F8 glass  F9 radial_blur  F11 sepia  F12 tiles (options\n"
    "  the script declares, a boolean or a table with `enabled`)\n"
    "  F1/Tab overlay; PageDown/PageUp step through targets, Home the frame again;\n"
    "  C channel (rgb r g b a), V false colour, Up/Down exposure;\n"
    "  P writes the shown target (EXR) and the frame (PNG); M the panel;\n"
    "  J writes the technique and changed options as a capture job (and the\n"
    "  limn capture command line); B the A/B wipe (--compare); E the error view at\n"
    "  a job's view with a reference (a wipe with the reference, with the error\n"
    "  heat map, off); Escape quits\n"
    "\n"
    "environment: LIMN_FONT, the overlay's font file (default DejaVu Sans Mono)\n"
    "exit codes: 0 closed, 1 failed (the script's first load, the font, window or\n"
    "renderer), 2 bad usage or a bad technique, option, scene, camera or animation.\n";

/* ---- command line ------------------------------------------------------ */
static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("view", fmt, arg); }

/* "5:F5,10:F3,12:resize=1x1" */
static bool parse_script_keys(const char *list, view_args *a) {
  char buf[4096];
  snprintf(buf, sizeof buf, "%s", list);
  for (char *save = NULL, *item = strtok_r(buf, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
    char *colon = strchr(item, ':');
    if (!colon || a->key_count == MAX_SCRIPT_KEYS) return false;
    *colon = '\0';
    script_key *k = &a->keys[a->key_count++];
    int frame;
    if (!limn_parse_int(item, 0, 1 << 30, &frame) || !colon[1]) return false;
    k->frame = frame;
    snprintf(k->key, sizeof k->key, "%s", colon + 1);
    int w, h;
    double t, x, y;
    if (!strncmp(k->key, "resize=", 7) && !limn_parse_size(k->key + 7, &w, &h)) return false;
    if (!strncmp(k->key, "mouse=", 6) && sscanf(k->key + 6, "%lf;%lf", &x, &y) != 2) return false;
    if (!strncmp(k->key, "button=", 7) && strcmp(k->key + 7, "down") && strcmp(k->key + 7, "up")) return false;
    if (!strncmp(k->key, "time=", 5) && !limn_parse_double(k->key + 5, &t)) return false;
  }
  return true;
}

static void free_args(view_args *a) {
  for (int i = 0; i < a->set_count; i++) free(a->sets[i]);
  for (int i = 0; i < a->compare_set_count; i++) free(a->compare_sets[i]);
  for (int i = 0; i < a->job_set_count; i++) free(a->job_sets[i]);
  a->set_count = a->compare_set_count = a->job_set_count = 0;
  free(a->places);
  a->places = NULL;
  lm_scene_destroy(a->job_loaded); /* not adopted: the run stopped before the scene */
  a->job_loaded = NULL;
}

/* Returns 0 to go on, -1 when done (help), else the exit code. */
static int parse_args(int argc, char **argv, view_args *a) {
  *a = (view_args){.common = {.scene = "cornell", .width = 512, .height = 384}, .capture_dir = ".", .overlay = true,
                   .panel = true, .animation = "all", .fps = 24};
  static const struct option opts[] = {
      {"scene", required_argument, 0, 's'},      {"script", required_argument, 0, 'p'},
      {"tech", required_argument, 0, 't'},       {"set", required_argument, 0, 'D'},
      {"size", required_argument, 0, 'z'},       {"camera", required_argument, 0, 'c'},
      {"overlay", required_argument, 0, 'o'},    {"capture-dir", required_argument, 0, 'C'},
      {"exit-after", required_argument, 0, 'n'}, {"screenshot", required_argument, 0, 'S'},
      {"script-keys", required_argument, 0, 'k'}, {"reload-test", required_argument, 0, 'R'},
      {"animation", required_argument, 0, 'A'},  {"time", required_argument, 0, 'T'},
      {"fps", required_argument, 0, 'F'},        {"panel", required_argument, 0, 'P'},
      {"job", required_argument, 0, 'J'},        {"view", required_argument, 0, 'V'},
      {"refs", required_argument, 0, 'r'},
      {"compare", required_argument, 0, 'B'},    {"compare-set", required_argument, 0, 'E'},
      {"quiet", no_argument, 0, 'q'},            {"verbose", no_argument, 0, 'v'},
      {"help", no_argument, 0, 'h'},             {0, 0, 0, 0}};
  opterr = 0;
  optind = 1;
  int c, n;
  bool view_given = false;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    switch (c) {
    case 'B': a->compare = optarg; break;
    case 'E':
      if (!strchr(optarg, '=') || optarg[0] == '=')
        return usage_error("--compare-set wants NAME=VALUE, not '%s'", optarg);
      if (a->compare_set_count == MAX_SETS) return usage_error("%s", "at most 64 --compare-set flags");
      a->compare_sets[a->compare_set_count++] = lm_strdup(optarg);
      break;
    case 'o':
      if (!limn_parse_on_off(optarg, &a->overlay)) return usage_error("--overlay wants on or off, not '%s'", optarg);
      break;
    case 'C': a->capture_dir = optarg; break;
    case 'P':
      if (!limn_parse_on_off(optarg, &a->panel)) return usage_error("--panel wants on or off, not '%s'", optarg);
      break;
    case 'J': a->job = optarg; break;
    case 'r': a->refs = optarg; break;
    case 'V':
      if (!limn_parse_int(optarg, 0, 1 << 30, &a->job_view)) return usage_error("--view wants a view number, not '%s'", optarg);
      view_given = true;
      break;
    case 'A': a->animation = optarg; break;
    case 'T':
      if (!limn_parse_double(optarg, &a->time)) return usage_error("--time wants seconds, not '%s'", optarg);
      a->time_given = true;
      break;
    case 'F':
      if (!limn_parse_double(optarg, &a->fps) || !(a->fps > 0) || a->fps > 1000)
        return usage_error("--fps wants frames a second in (0, 1000], not '%s'", optarg);
      a->fps_given = true;
      break;
    case 'n':
      if (!limn_parse_int(optarg, 1, 1 << 30, &n)) return usage_error("--exit-after wants a frame count, not '%s'", optarg);
      a->exit_after = n;
      break;
    case 'S': {
      const char *dot = strrchr(optarg, '.');
      if (!dot || strcasecmp(dot, ".png")) return usage_error("--screenshot '%s': give a .png file", optarg);
      a->screenshot = optarg;
      break;
    }
    case 'k':
      if (!parse_script_keys(optarg, a))
        return usage_error("--script-keys wants FRAME:KEY,... (e.g. 5:F5,10:resize=64x48), not '%s'", optarg);
      break;
    case 'R':
      if (!limn_parse_int(optarg, 1, 1000000, &n)) return usage_error("--reload-test wants a count, not '%s'", optarg);
      a->reload_test = n;
      break;
    case 'q': a->quiet = true; break;
    case 'v': a->verbose = true; break;
    case 'h': fputs(view_usage, stdout); return -1;
    default:
      if (limn_common_flag("view", c, argv, &a->common)) return 2;
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  /* The viewer's own copies: toggles and the panel replace entries. */
  for (int i = 0; i < a->common.set_count; i++) a->sets[a->set_count++] = lm_strdup(a->common.sets[i]);
  if (view_given && !a->job) return usage_error("%s", "--view N needs --job FILE");
  if (a->refs && !a->job) return usage_error("%s", "--refs DIR needs --job FILE");
  if (a->compare_set_count && !a->compare) return usage_error("%s", "--compare-set needs --compare TECH");
  return a->job && !load_view_job(a) ? 2 : 0;
}

static volatile sig_atomic_t stop_requested;
static void on_signal(int sig) {
  (void)sig;
  stop_requested = 1;
}

/* ---- camera ------------------------------------------------------------ */
static int camera_node(const viewer *v) {
  return v->camera < v->scene->camera_count ? v->scene->cameras[v->camera].node : -1;
}

static void fly_from_camera(viewer *v) {
  int node = camera_node(v);
  if (node < 0) return;
  const float *m = v->scene->nodes[node].world;
  float f[3] = {-m[8], -m[9], -m[10]}, len = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (len > 1e-12f)
    for (int i = 0; i < 3; i++) f[i] /= len;
  memcpy(v->cam.pos, m + 12, sizeof v->cam.pos);
  v->cam.yaw = atan2f(-f[0], -f[2]);
  v->cam.pitch = asinf(fmaxf(-1.0f, fminf(1.0f, f[1])));
}

static void fly_to_camera(viewer *v) {
  int node = camera_node(v);
  if (node < 0) return;
  float cy = cosf(v->cam.yaw), sy = sinf(v->cam.yaw), cp = cosf(v->cam.pitch), sp = sinf(v->cam.pitch);
  float f[3] = {-sy * cp, sp, -cy * cp};
  float r[3] = {cy, 0, -sy}; /* cross(f, +Y), normalized: pitch stays below the poles */
  float u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
  /* Keep the node's scale: a camera under a scaled root scales near and far with it. */
  const float *w = v->scene->nodes[node].world;
  float det = w[0] * (w[5] * w[10] - w[9] * w[6]) - w[4] * (w[1] * w[10] - w[9] * w[2]) +
              w[8] * (w[1] * w[6] - w[5] * w[2]);
  float k = cbrtf(fabsf(det));
  if (!(k > 0) || !isfinite(k)) k = 1;
  float m[16] = {k * r[0], k * r[1], k * r[2], 0, k * u[0], k * u[1], k * u[2], 0, -k * f[0], -k * f[1], -k * f[2], 0,
                 v->cam.pos[0], v->cam.pos[1], v->cam.pos[2], 1};
  lm_scene_node_set_world(v->scene, node, m);
}

/* A key held on the keyboard or by --script-keys hold=K. */
static bool key_down(const viewer *v, const char *key) {
  for (int i = 0; i < 4; i++)
    if (v->held[i] && !strcmp(key, (const char *[]){"W", "A", "S", "D"}[i])) return true;
  return lm_window_key_down(v->window, key);
}

/* A left drag that starts on the wipe's split (A/B or the reference; within 6 pixels) moves
 * it; true while it does. The window reports a held button only as motion. */
static bool drag_split(viewer *v, double dx, double dy) {
  if (!v->compare_on && !reference_shown(v)) return false;
  double x, y;
  bool down;
  if (v->mouse_scripted) {
    x = v->mouse[0], down = v->mouse_down;
  } else {
    lm_window_cursor(v->window, &x, &y);
    down = dx || dy;
  }
  if (!down) {
    v->split_held = false;
    return false;
  }
  if (!v->split_held && fabs(x - dx - v->split * v->width) > 6) return false;
  v->split_held = true;
  v->split = (float)fmax(0.0, fmin(1.0, x / v->width));
  return true;
}

static void move_camera(viewer *v, double dt_ms) {
  double dx, dy;
  lm_window_mouse_drag(v->window, &dx, &dy);
  if (v->panel_on && panel_wants_mouse(v->panel)) dx = dy = 0; /* a drag on the panel moves its widget */
  else if (drag_split(v, dx, dy)) dx = dy = 0;                 /* one on the A/B line moves it */
  dx += v->drag[0], dy += v->drag[1];
  v->drag[0] = v->drag[1] = 0;
  /* 0.45 of the scene's diagonal a second (1.5 units in the Cornell box), in
   * any unit; scripted runs (tests) step 1/60 s a frame so they repeat. */
  if (v->args->key_count) dt_ms = 1000.0 / 60.0;
  float lo[3], hi[3];
  lm_scene_bounds(v->scene, lo, hi);
  float size = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
  float step = (float)(fmin(dt_ms, 100.0) * 0.45e-3) * size;
  float ahead = (key_down(v, "W") ? 1.0f : 0.0f) - (key_down(v, "S") ? 1.0f : 0.0f);
  float side = (key_down(v, "D") ? 1.0f : 0.0f) - (key_down(v, "A") ? 1.0f : 0.0f);
  if (!ahead && !side && !dx && !dy) return; /* the scene's own transform stays exact */
  if (!v->camera_user && camera_node(v) >= 0)
    memcpy(v->camera_local, v->scene->nodes[camera_node(v)].local, sizeof v->camera_local);
  if (v->camera_animated && !v->camera_user)
    say(v, "camera %d is yours now (0 gives it back to the animation)", v->camera + 1);
  v->camera_user = true;
  v->cam.yaw -= (float)dx * 0.005f;
  v->cam.pitch = fmaxf(-1.5f, fminf(1.5f, v->cam.pitch - (float)dy * 0.005f));
  float cy = cosf(v->cam.yaw), sy = sinf(v->cam.yaw), cp = cosf(v->cam.pitch), sp = sinf(v->cam.pitch);
  float f[3] = {-sy * cp, sp, -cy * cp}, r[3] = {cy, 0, -sy};
  for (int i = 0; i < 3; i++) v->cam.pos[i] += step * (ahead * f[i] + side * r[i]);
  fly_to_camera(v);
}

/* ---- time ------------------------------------------------------------- */
/* One line a test can parse: "time 1.250000 s, frame 30, animation 'all', paused (why)". */
static void report_time(const viewer *v, const char *why) {
  char time[LIMN_TIME_TEXT];
  lm_info("time %s s, frame %ld, animation '%s'%s (%s)", limn_time_text(v->time, 6, time), view_frame(v),
          view_animation_name(v), v->paused ? ", paused" : "", why);
}

/* Is the node, or one of its ancestors, moved by a channel of the viewer's animation? */
static bool node_animated(const viewer *v, int node) {
  const lm_scene *s = v->scene;
  for (int n = node; n >= 0 && n < s->node_count; n = s->nodes[n].parent)
    for (int a = 0; a < s->animation_count; a++)
      for (int c = 0; (v->anim == LM_ANIM_ALL || v->anim == a) && c < s->animations[a].channel_count; c++)
        if (s->animations[a].channels[c].node == n && s->animations[a].channels[c].path != LM_ANIM_WEIGHTS)
          return true;
  return false;
}

/* The animation --animation names, in the scene as it is now (at start and
 * after the scene file reloads); false with err when the scene lacks it. */
static bool find_animation(viewer *v, lm_error *err) {
  int anim = lm_scene_find_animation(v->scene, v->args->animation, err);
  if (anim < LM_ANIM_ALL) return false;
  v->anim = anim;
  lm_scene_animation_range(v->scene, anim, &v->anim_range[0], &v->anim_range[1]);
  v->camera_animated = node_animated(v, camera_node(v));
  return true;
}

/* Poses the scene at the viewer's time; an animated camera the user has
 * not taken over follows it, one the user has keeps the user's view (the
 * node's local transform goes back to the animation's for the pose, so that
 * giving the camera back finds the animation's view at once). */
static void pose(viewer *v) {
  if (!lm_scene_animated(v->scene)) return; /* a still scene: nothing moves */
  int node = camera_node(v);
  float *local = node >= 0 ? v->scene->nodes[node].local : NULL;
  if (v->camera_user && local) memcpy(local, v->camera_local, sizeof v->camera_local);
  lm_scene_set_time(v->scene, v->anim, v->time);
  if (v->camera_user && local) {
    memcpy(v->camera_local, local, sizeof v->camera_local);
    fly_to_camera(v);
  } else if (v->camera_animated) {
    fly_from_camera(v);
  }
}

/* The animation drives the camera the user moved again. */
static void give_camera_back(viewer *v) {
  int node = camera_node(v);
  if (v->camera_user && node >= 0) {
    memcpy(v->scene->nodes[node].local, v->camera_local, sizeof v->camera_local);
    lm_scene_update(v->scene);
    fly_from_camera(v);
  }
  v->camera_user = false;
}

/* Moves the time by dt seconds, looping over the animation's range (a time
 * before its start, as --time may give, plays on into it). */
static void advance(viewer *v, double dt) {
  double lo = v->anim_range[0], hi = v->anim_range[1], t = v->time + dt;
  if (hi > lo) {
    if (dt > 0 && t >= hi) t = lo + fmod(t - lo, hi - lo);
    else if (dt < 0 && t < lo && v->time >= lo) t += hi - lo;
  }
  v->time = t;
}

/* ---- options and techniques -------------------------------------------- */
/* Records NAME=VALUE in a list of them (--set's, --compare-set's) so a
 * reloaded script gets it again. */
static void remember_set(char **sets, int *count, const char *name, const char *value) {
  size_t n = strlen(name);
  char *entry = lm_alloc(n + strlen(value) + 2);
  sprintf(entry, "%s=%s", name, value);
  for (int i = 0; i < *count; i++) {
    if (!strncmp(sets[i], name, n) && sets[i][n] == '=') {
      free(sets[i]);
      sets[i] = entry;
      return;
    }
  }
  if (*count < MAX_SETS)
    sets[(*count)++] = entry;
  else
    free(entry);
}

/* Applies NAME=VALUE entries; returns false (err) on the first bad one. */
static bool apply_set_list(lm_pipeline *p, char *const *sets, int count, lm_error *err) {
  for (int i = 0; i < count; i++)
    if (!capture_set_option(p, sets[i], err)) return false;
  return true;
}

/* The script with technique `tech` (NULL: the script's first) and the
 * viewer's options (--set, the job's, toggles), loaded as capture, bench and
 * graph load theirs; *rc as capture_load_pipeline's. */
static lm_pipeline *load_pipeline(viewer *v, const char *tech, int *rc, lm_error *err) {
  _Static_assert((int)MAX_SETS <= (int)LIMN_MAX_SETS, "the viewer's options fit the shared loader's");
  limn_common_args c = {.script = v->script, .tech = tech, .set_count = v->args->set_count};
  for (int i = 0; i < c.set_count; i++) c.sets[i] = v->args->sets[i];
  return capture_load_pipeline(&c, rc, err);
}

/* The A/B wipe's other side: the script again with the --compare technique,
 * the viewer's options, then --compare-set's; NULL with err. */
static lm_pipeline *load_compare(viewer *v, lm_error *err) {
  int rc;
  lm_pipeline *p = load_pipeline(v, v->compare_tech, &rc, err);
  if (p && !apply_set_list(p, v->args->compare_sets, v->args->compare_set_count, err)) {
    lm_pipeline_destroy(p);
    return NULL;
  }
  return p;
}

/* The A/B wipe's other side with technique `tech`, turned on: its pipeline
 * and renderer made the first time (--compare, or a technique the panel's
 * A/B picks), the technique set on them after. False with err. */
static bool start_compare(viewer *v, const char *tech, lm_error *err) {
  if (v->compare_pipeline) {
    if (!lm_pipeline_set_technique(v->compare_pipeline, tech, err)) return false;
    snprintf(v->compare_tech, sizeof v->compare_tech, "%s", tech);
  } else {
    snprintf(v->compare_tech, sizeof v->compare_tech, "%s", tech);
    lm_texture_desc d = {LM_FORMAT_RGBA8, v->width, v->height, false};
    if (!(v->compare_pipeline = load_compare(v, err)) ||
        !(v->compare_renderer = lm_renderer_create(&(lm_renderer_desc){.scene = v->scene,
                                                                       .pipeline = v->compare_pipeline,
                                                                       .width = v->width, .height = v->height,
                                                                       .camera = v->camera}, err)) ||
        !lm_texture_create(&v->compare_shown, &d, "viewer frame (compare)", err)) {
      lm_renderer_destroy(v->compare_renderer);
      lm_pipeline_destroy(v->compare_pipeline);
      v->compare_renderer = NULL, v->compare_pipeline = NULL;
      return false;
    }
    lm_texture_clear(v->compare_shown);
  }
  v->compare_on = true;
  v->options_stale = true;
  return true;
}

/* An option of the other side alone, kept for reloads as --compare-set's. */
static void set_compare_option(viewer *v, const char *name, const char *value) {
  lm_error err;
  if (!v->compare_pipeline || !lm_pipeline_set_option(v->compare_pipeline, name, value, &err)) {
    say(v, "A/B: %s", v->compare_pipeline ? err.msg : "no other side: pick its technique first");
    return;
  }
  remember_set(v->args->compare_sets, &v->args->compare_set_count, name, value);
  v->options_stale = true;
  say(v, "A/B: %s = %s on the right", name, value);
}

/* Does --compare-set give the other side its own value of this option? */
static bool compare_sets_option(const viewer *v, const char *name) {
  size_t n = strlen(name);
  for (int i = 0; i < v->args->compare_set_count; i++)
    if (!strncmp(v->args->compare_sets[i], name, n) && v->args->compare_sets[i][n] == '=') return true;
  return false;
}

/* Sets an option as --set does (and keeps it for a reloaded script). */
static void set_option(viewer *v, const char *name, const char *value) {
  lm_error err;
  if (!lm_pipeline_set_option(v->pipeline, name, value, &err)) {
    say(v, "%s", err.msg);
    return;
  }
  remember_set(v->args->sets, &v->args->set_count, name, value);
  /* The other side follows the edit unless it compares that very option. */
  if (v->compare_pipeline && !compare_sets_option(v, name) &&
      !lm_pipeline_set_option(v->compare_pipeline, name, value, &err))
    say(v, "--compare side: %s", err.msg);
  v->options_stale = true;
  say(v, "%s = %s", name, value);
}

static void toggle_option(viewer *v, const char *name) {
  char value[64], field[128];
  snprintf(field, sizeof field, "%s", name);
  if (lm_pipeline_get_option(v->pipeline, name, value, sizeof value) && !strcmp(value, "table"))
    snprintf(field, sizeof field, "%s.enabled", name);
  if (!lm_pipeline_get_option(v->pipeline, field, value, sizeof value) ||
      (strcmp(value, "true") && strcmp(value, "false"))) {
    say(v, "%s declares no option '%s' (a boolean, or a table with enabled)", v->script, name);
    return;
  }
  set_option(v, field, strcmp(value, "true") ? "true" : "false");
}

static void set_technique(viewer *v, const char *name) {
  lm_error err;
  if (!lm_pipeline_set_technique(v->pipeline, name, &err)) {
    say(v, "%s", err.msg);
    return;
  }
  v->options_stale = true; /* a row may name a module new to Options */
  say(v, "technique %s", name);
}

/* The settings as a capture job and a command line (J, the panel's button). */
static void write_job(viewer *v) {
  char path[1024];
  lm_error err;
  if (!write_view_job(v, path, sizeof path, &err)) {
    say(v, "%s", err.msg);
    return;
  }
  snprintf(v->status, sizeof v->status, "wrote %s (and its limn capture line beside it)", path);
  say(v, "%s", v->status);
}

static panel_edits no_edits(void) {
  return (panel_edits){.technique = -1, .inspect = -1, .error_view = -1, .compare_technique = -1, .compare_pick = -1};
}

/* What the user did in the panel last frame, applied before this frame renders. */
static void apply_panel(viewer *v) {
  panel_edits *e = &v->edits;
  if (e->option) set_option(v, e->option_name, e->option_value);
  if (e->technique >= 0 && e->technique < lm_pipeline_technique_count(v->pipeline))
    set_technique(v, lm_pipeline_technique_name(v->pipeline, e->technique));
  if (e->play) {
    v->paused = !v->paused;
    report_time(v, "play button");
  }
  if (e->scrub) {
    v->time = e->scrub_time;
    v->paused = true;
    report_time(v, "scrubbed");
  }
  if (e->write_job) write_job(v);
  if (e->error_view >= 0 && v->place >= 0) v->error_view = e->error_view;
  lm_error err;
  if (e->compare_technique >= 0 && e->compare_technique < lm_pipeline_technique_count(v->pipeline)) {
    const char *tech = lm_pipeline_technique_name(v->pipeline, e->compare_technique);
    if (start_compare(v, tech, &err)) say(v, "A/B: %s on the right", tech);
    else say(v, "A/B %s: %s", tech, err.msg);
  }
  if (e->compare_toggle && v->compare_renderer) v->compare_on = !v->compare_on;
  if (e->compare_pick >= 0 && e->compare_pick < v->option_count) {
    /* Set apart from this side at its value now: edits here no longer reach it there. */
    const lm_option_info *o = &v->options[e->compare_pick];
    snprintf(v->compare_option, sizeof v->compare_option, "%s", o->name);
    set_compare_option(v, o->name, o->value);
  }
  if (e->compare_set) set_compare_option(v, e->compare_name, e->compare_value);
  if (e->inspect >= 0) {
    v->inspect = e->inspect;
    lm_renderer_set_sharing(v->renderer, false); /* every target readable after the frame */
  }
  *e = no_edits();
}

/* ---- reloading --------------------------------------------------------- */
/* Loads the script again and swaps it in when its first frame renders. The
 * technique shown stays when the script still has it; when not, the
 * script's first is taken and said (the shared loader would refuse it). */
static bool reload_script(viewer *v) {
  lm_error err;
  int rc;
  lm_pipeline *p = load_pipeline(v, NULL, &rc, &err);
  bool ok = p != NULL;
  if (ok) {
    lm_error ignore;
    const char *tech = lm_pipeline_technique(v->pipeline);
    if (!lm_pipeline_set_technique(p, tech, &ignore))
      say(v, "technique %s is gone from %s: %s", tech, v->script, lm_pipeline_technique(p));
    ok = lm_renderer_swap_pipeline(v->renderer, p, &err);
  }
  if (!ok) {
    lm_pipeline_destroy(p);
    set_error(v->script_error, sizeof v->script_error, err.msg, "");
    return false;
  }
  lm_pipeline_destroy(v->pipeline);
  v->pipeline = p;
  if (v->compare_renderer) { /* the other side reloads too; on an error it keeps its last good pipeline */
    lm_pipeline *b = load_compare(v, &err);
    if (b && lm_renderer_swap_pipeline(v->compare_renderer, b, &err)) {
      lm_pipeline_destroy(v->compare_pipeline);
      v->compare_pipeline = b;
      set_error(v->compare_error, sizeof v->compare_error, "", "--compare side reloaded: error cleared");
    } else {
      lm_pipeline_destroy(b);
      set_error(v->compare_error, sizeof v->compare_error, err.msg, "");
    }
  }
  v->options_stale = true;
  v->frame_error[0] = '\0';
  set_error(v->script_error, sizeof v->script_error, "", "script reloaded: error cleared");
  lm_info("reloaded %s", v->script);
  report_time(v, "script reloaded");
  return true;
}

static void reload_scene(viewer *v) {
  lm_error err;
  lm_scene *s = lm_scene_load(v->args->common.scene, &err);
  if (s && !lm_scene_upload(s, &err)) {
    lm_scene_destroy(s);
    s = NULL;
  }
  if (!s) {
    set_error(v->scene_error, sizeof v->scene_error, err.msg, "");
    return;
  }
  set_error(v->scene_error, sizeof v->scene_error, "", "scene reloaded: error cleared");
  /* The renderer borrows the scene pointer; re-creating the renderer would
   * drop the frame graph and its history, so the contents are swapped. */
  lm_scene tmp = *v->scene;
  *v->scene = *s;
  *s = tmp;
  lm_scene_destroy(s);
  if (v->camera >= v->scene->camera_count) v->camera = 0;
  lm_renderer_set_camera(v->renderer, v->camera);
  if (v->compare_renderer) lm_renderer_set_camera(v->compare_renderer, v->camera);
  if (!find_animation(v, &err)) { /* the file lost it: play them all */
    say(v, "%s: playing all", err.msg);
    v->args->animation = "all";
    find_animation(v, &err);
  }
  v->camera_user = false; /* the file's camera again, as for a still scene; its animation drives it */
  fly_from_camera(v);
  pose(v);
  lm_info("reloaded scene %s", v->args->common.scene);
  report_time(v, "scene reloaded");
}

static bool has_suffix(const char *s, const char *suffix) {
  size_t n = strlen(s), k = strlen(suffix);
  return n >= k && !strcmp(s + n - k, suffix);
}

/* Drains the watch. Returns true when a frame was rendered (a reloaded script's first). */
static bool handle_changes(viewer *v) {
  bool script = false, shaders = false, scene = false;
  char path[4096];
  while (lm_watch_next(v->watch, path, sizeof path)) {
    const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    lm_debug("changed: %s", path);
    if (name[0] == '.') continue; /* editors' temporary files */
    if (has_suffix(name, ".lua")) script = true;
    else if (has_suffix(name, ".glsl") || has_suffix(name, ".frag") || has_suffix(name, ".vert")) shaders = true;
    else if (lm_scene_is_gltf_name(v->args->common.scene) && !strcmp(name, strrchr(v->args->common.scene, '/') ? strrchr(v->args->common.scene, '/') + 1 : v->args->common.scene)) scene = true;
  }
  if (shaders) {
    lm_programs_invalidate();
    lm_info("shaders changed: rebuilding");
  }
  if (scene) reload_scene(v);
  return script && reload_script(v);
}

/* ---- keys -------------------------------------------------------------- */
static void handle_key(viewer *v, const char *key) {
  /* A technique's row names its key (pp.lua's `key`); a key no row names
   * picks the seed viewer's technique for it. */
  static const struct { const char *key, *tech; } techs[] = {
      {"F2", "isr+esm"}, {"F3", "isr"}, {"F4", "dl+esm"}, {"F5", "dl"}};
  static const struct { const char *key, *option; } toggles[] = {
      {"F6", "bloom"}, {"F7", "dof"},   {"F8", "glass"}, {"F9", "radial_blur"},
      {"F11", "sepia"}, {"F12", "tiles"}};
  for (int i = 0; i < lm_pipeline_technique_count(v->pipeline); i++) {
    const char *row_key = lm_pipeline_technique_key(v->pipeline, i);
    if (row_key && !strcmp(key, row_key)) return set_technique(v, lm_pipeline_technique_name(v->pipeline, i));
  }
  for (size_t i = 0; i < sizeof techs / sizeof *techs; i++)
    if (!strcmp(key, techs[i].key)) return set_technique(v, techs[i].tech);
  for (size_t i = 0; i < sizeof toggles / sizeof *toggles; i++)
    if (!strcmp(key, toggles[i].key)) return toggle_option(v, toggles[i].option);
  int targets = lm_graph_target_count(lm_renderer_graph(v->renderer));
  if (!strncmp(key, "resize=", 7)) {
    int w, h;
    if (limn_parse_size(key + 7, &w, &h)) lm_window_resize(v->window, w, h);
  } else if (!strncmp(key, "hold=", 5) || !strncmp(key, "release=", 8)) {
    const char *k = strchr(key, '=') + 1;
    for (int i = 0; i < 4; i++)
      if (!strcmp(k, (const char *[]){"W", "A", "S", "D"}[i])) v->held[i] = key[0] == 'h';
  } else if (!strncmp(key, "mouse=", 6) || !strncmp(key, "button=", 7)) {
    v->mouse_scripted = true;
    if (!strncmp(key, "mouse=", 6)) sscanf(key + 6, "%lf;%lf", &v->mouse[0], &v->mouse[1]);
    else v->mouse_down = !strcmp(key + 7, "down");
    if (v->panel) panel_set_mouse(v->panel, v->mouse[0], v->mouse[1], v->mouse_down);
  } else if (!strcmp(key, "widgets")) {
    if (v->panel) panel_list_widgets(v->panel, stdout);
  } else if (!strcmp(key, "B")) {
    if (!v->compare_renderer) {
      say(v, "%s", "no A/B wipe: start with --compare TECH, or pick the right side's technique in the panel's A/B");
      return;
    }
    v->compare_on = !v->compare_on;
    say(v, "A/B wipe %s", v->compare_on ? "on" : "off");
  } else if (!strcmp(key, "E")) {
    if (v->place < 0) {
      say(v, "%s", v->reference_text[0] ? v->reference_text : "no reference here");
      return;
    }
    v->error_view = (v->error_view + 1) % ERROR_VIEWS;
    say(v, "error view: %s", (const char *[]){"off", "wipe with the reference", "wipe with the error heat map"}[v->error_view]);
  } else if (!strcmp(key, "M")) {
    v->panel_on = !v->panel_on;
  } else if (!strcmp(key, "J")) {
    write_job(v);
  } else if (!strncmp(key, "drag=", 5)) {
    double dx, dy;
    if (sscanf(key + 5, "%lf;%lf", &dx, &dy) == 2) v->drag[0] += dx, v->drag[1] += dy;
  } else if (!strcmp(key, "Space")) {
    v->paused = !v->paused;
    report_time(v, "Space");
  } else if (!strcmp(key, "Left") || !strcmp(key, "Right")) {
    v->paused = true;
    advance(v, (key[0] == 'L' ? -1.0 : 1.0) / v->args->fps);
    report_time(v, key);
  } else if (!strncmp(key, "time=", 5)) {
    if (limn_parse_double(key + 5, &v->time)) report_time(v, "scrubbed");
  } else if (!strcmp(key, "0")) {
    if (!v->camera_animated) {
      say(v, "camera %d is not animated", v->camera + 1);
      return;
    }
    give_camera_back(v);
    say(v, "camera %d follows the animation", v->camera + 1);
  } else if (key[0] >= '1' && key[0] <= '9' && !key[1]) {
    int c = key[0] - '1';
    if (c >= v->scene->camera_count) {
      say(v, "scene %s has %d camera(s)", v->scene->name, v->scene->camera_count);
      return;
    }
    if (v->camera_animated) give_camera_back(v);
    v->camera = c;
    lm_renderer_set_camera(v->renderer, c);
    if (v->compare_renderer) lm_renderer_set_camera(v->compare_renderer, c);
    v->camera_user = false;
    v->camera_animated = node_animated(v, camera_node(v));
    fly_from_camera(v);
    say(v, "camera %d (%s)", c + 1, v->scene->cameras[c].name);
  } else if (!strcmp(key, "F1") || !strcmp(key, "Tab")) {
    v->overlay_on = !v->overlay_on;
  } else if (!strcmp(key, "PageDown") || !strcmp(key, "PageUp")) {
    /* From the frame: its output first; then through the targets the frame
     * used, and last those it did not (inspect_order). */
    int *order = lm_alloc(sizeof *order * (size_t)(targets > 0 ? targets : 1)), n = inspect_order(v, order, targets);
    int at = 0;
    while (at < n && order[at] != v->inspect) at++;
    if (n > 0)
      v->inspect = v->inspect < 0 ? order[0] : order[(at + (!strcmp(key, "PageDown") ? 1 : n - 1)) % n];
    free(order);
    lm_renderer_set_sharing(v->renderer, false); /* every target readable after the frame */
  } else if (!strncmp(key, "inspect=", 8)) { /* tests: a target by name */
    int t = lm_graph_find_target(lm_renderer_graph(v->renderer), key + 8);
    if (t < 0) {
      say(v, "the frame graph has no target '%s'", key + 8);
      return;
    }
    v->inspect = t;
    lm_renderer_set_sharing(v->renderer, false);
  } else if (!strcmp(key, "Home")) {
    v->inspect = -1;
    lm_renderer_set_sharing(v->renderer, true);
  } else if (!strcmp(key, "C")) {
    v->channel = (v->channel + 1) % 5;
  } else if (!strcmp(key, "V")) {
    v->false_colour = !v->false_colour;
  } else if (!strcmp(key, "Up") || !strcmp(key, "Down")) {
    v->exposure += !strcmp(key, "Up") ? 0.5f : -0.5f;
  } else if (!strcmp(key, "P")) {
    write_captures(v);
  } else if (!strcmp(key, "Escape")) {
    stop_requested = 1;
  }
}

/* ---- one frame --------------------------------------------------------- */
static void render(viewer *v, bool already_rendered) {
  lm_error err;
  double t0 = lm_now_ms();
  bool ok = already_rendered || lm_renderer_frame(v->renderer, &err);
  if (!already_rendered) v->render_ms = lm_now_ms() - t0;
  set_error(v->frame_error, sizeof v->frame_error, ok ? "" : err.msg, "frame error cleared");
  const char *shader = lm_programs_error();
  set_error(v->shader_error, sizeof v->shader_error, shader, "shaders rebuilt: error cleared");
  lm_texture out;
  int w, h;
  if (ok && lm_renderer_output(v->renderer, &out, &w, &h) && w == v->width && h == v->height) {
    lm_texture_copy(v->shown, out, w, h);
  }
  if (ok && v->compare_on) {
    bool b = lm_renderer_frame(v->compare_renderer, &err);
    set_error(v->compare_error, sizeof v->compare_error, b ? "" : err.msg, "--compare side: frame error cleared");
    if (b && lm_renderer_output(v->compare_renderer, &out, &w, &h) && w == v->width && h == v->height)
      lm_texture_copy(v->compare_shown, out, w, h);
  }
}

/* Follows the window's framebuffer; false while it is 0x0 (minimized). */
static bool follow_size(viewer *v) {
  int w, h;
  lm_window_size(v->window, &w, &h);
  if (w < 1 || h < 1) return false; /* nothing to draw into: skip the frame, never a 0x0 target */
  if (w == v->width && h == v->height) return true;
  v->width = w, v->height = h;
  lm_renderer_resize(v->renderer, w, h);
  if (v->compare_renderer) lm_renderer_resize(v->compare_renderer, w, h);
  lm_error err;
  if (!make_window_textures(v, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return false;
  }
  lm_info("window %dx%d", w, h);
  return true;
}

/* ---- the reload test hook ---------------------------------------------- */
/* Bytes the program has allocated and not freed: glibc's count, or
 * AddressSanitizer's when it replaces malloc (glibc's then reads 0). */
static long heap_in_use(void) {
#ifdef __SANITIZE_ADDRESS__
  return (long)__sanitizer_get_current_allocated_bytes();
#else
  struct mallinfo2 m = mallinfo2();
  return (long)m.uordblks + (long)m.hblkhd;
#endif
}

/* N edits of a copy of the script next to it (every tenth with a syntax
 * error, every hundredth a shader rebuild too), each reloaded through the
 * real watch. GL objects and heap bytes are counted after a warm-up and at
 * the end; any growth fails. */
static int reload_test(viewer *v, long n) {
  char *text = lm_read_file(v->script, NULL, NULL);
  if (!text) return 1;
  char dir[2048], copy[4096];
  lm_dirname(v->script, dir, sizeof dir);
  snprintf(copy, sizeof copy, "%s/limn-reload-test.lua", dir);
  snprintf(v->script, sizeof v->script, "%s", copy);
  lm_gfx_counts before = {0};
  long heap_before = 0, failed = 0;
  enum { WARM_UP = 20 };
  for (long i = 0; i < n + WARM_UP; i++) {
    if (i == WARM_UP) {
      before = lm_gfx_stats();
      heap_before = heap_in_use();
    }
    FILE *f = fopen(copy, "w");
    if (!f) break;
    bool bad = i % 10 == 9;
    fprintf(f, "%s\n-- edit %ld\n%s\n", text, i, bad ? "local broken = = 1" : "");
    fclose(f);
    if (i % 100 == 99) lm_programs_invalidate();
    bool rendered = handle_changes(v);
    render(v, rendered);
    if (bad == rendered) failed++; /* a bad edit must not load; a good one must */
    display(v); /* no swap: the counts are the point, not the pace */
  }
  unlink(copy);
  free(text);
  lm_gfx_counts after = lm_gfx_stats();
  long heap_after = heap_in_use();
  printf("reload test: %ld edits, %ld reloads that went the wrong way\n", n, failed);
  printf("  GL textures %d -> %d, framebuffers %d -> %d, programs %d -> %d\n", before.textures,
         after.textures, before.framebuffers, after.framebuffers, before.programs, after.programs);
  printf("  heap bytes in use %ld -> %ld (%+ld)\n", heap_before, heap_after, heap_after - heap_before);
  /* Heap: a little slack for allocator bookkeeping; a leak of even 100 bytes
   * an edit would pass 64 KiB well before the end. */
  bool grew = after.textures > before.textures || after.framebuffers > before.framebuffers ||
              after.programs > before.programs || heap_after - heap_before > 65536;
  return failed || grew ? 1 : 0;
}

/* ---- main -------------------------------------------------------------- */
static bool watch_dirs(viewer *v, lm_error *err) {
  char dir[2048];
  v->watch = lm_watch_create(err);
  if (!v->watch || !lm_watch_dir(v->watch, lm_shader_dir(), err)) return false;
  snprintf(dir, sizeof dir, "%s/scripts", lm_root_dir());
  if (lm_file_exists(dir) && !lm_watch_dir(v->watch, dir, err)) return false;
  lm_dirname(v->script, dir, sizeof dir);
  if (!lm_watch_dir(v->watch, dir, err)) return false;
  if (lm_scene_is_gltf_name(v->args->common.scene)) {
    lm_dirname(v->args->common.scene, dir, sizeof dir);
    if (!lm_watch_dir(v->watch, dir, err)) return false;
  }
  return true;
}

/* Everything the viewer made, freed one by one: destroy functions read alike. */
static void viewer_free(viewer *v) {
  lm_texture_destroy(&v->shown);
  lm_texture_destroy(&v->overlay_tex);
  lm_texture_destroy(&v->probe);
  lm_texture_destroy(&v->compare_shown);
  free(v->overlay);
  lm_buf_free(&v->overlay_lines);
  lm_buf_free(&v->overlay_drawn);
  free(v->options);
  free(v->compare_options);
  reference_free(v);
  panel_destroy(v->panel); /* before the window: it restores the window's callbacks */
  lm_renderer_destroy(v->renderer);
  lm_renderer_destroy(v->compare_renderer);
  lm_pipeline_destroy(v->compare_pipeline);
  lm_programs_clear();
  lm_scene_destroy(v->scene);
  lm_pipeline_destroy(v->pipeline);
  lm_watch_destroy(v->watch);
  lm_font_close(v->font);
  lm_window_destroy(v->window);
}

static int run(viewer *v) {
  view_args *a = v->args;
  lm_error err;
  int rc;
  if (!(v->pipeline = load_pipeline(v, a->common.tech, &rc, &err))) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return rc;
  }
  v->scene = a->job_loaded ? a->job_loaded : lm_scene_load(a->common.scene, &err);
  a->job_loaded = NULL;
  if (!v->scene) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 2;
  }
  if (a->common.camera > 0 && a->common.camera >= v->scene->camera_count) {
    lm_log(LM_LOG_ERROR, "--camera %d: scene '%s' has %d camera(s)", a->common.camera, a->common.scene, v->scene->camera_count);
    return 2;
  }
  v->camera = a->common.camera;
  if (!find_animation(v, &err)) {
    lm_log(LM_LOG_ERROR, "--animation: %s", err.msg);
    return 2;
  }
  v->time = a->time_given ? a->time : v->anim_range[0];
  v->font = lm_font_open(11, &err);
  if (!v->font || !watch_dirs(v, &err) ||
      !(v->window = lm_window_create("limn view", a->common.width, a->common.height, &err))) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 1;
  }
  lm_window_size(v->window, &v->width, &v->height);
  if (v->width < 1 || v->height < 1) v->width = a->common.width, v->height = a->common.height;
  v->renderer = lm_renderer_create(&(lm_renderer_desc){.scene = v->scene, .pipeline = v->pipeline,
                                                       .width = v->width, .height = v->height,
                                                       .camera = v->camera}, &err);
  if (!v->renderer) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 1;
  }
  if (a->compare && !start_compare(v, a->compare, &err)) {
    lm_log(LM_LOG_ERROR, "--compare %s: %s", a->compare, err.msg);
    return 2;
  }
  if (!make_window_textures(v, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 1;
  }
  if (!(v->panel = panel_create(v->window, &err))) lm_warn("no panel: %s", err.msg);
  v->options_stale = true;
  fly_from_camera(v);
  lm_info("renderer: %s (%s); scene %s; script %s; technique %s; %dx%d", lm_gl_renderer(), lm_gl_version(),
          a->common.scene, v->script, lm_pipeline_technique(v->pipeline), v->width, v->height);
  if (lm_scene_animated(v->scene))
    lm_info("animation '%s': keys %.6g..%.6g s%s", view_animation_name(v), v->anim_range[0], v->anim_range[1],
            v->camera_animated ? "; it moves the camera" : "");
  if (a->reload_test) return reload_test(v, a->reload_test);

  double last = lm_now_ms(), last_cpu = lm_cpu_ms();
  bool drawn_on = false; /* the panel drawn in the last frame */
  for (v->frame = 0; !stop_requested && !lm_window_should_close(v->window); v->frame++) {
    lm_window_poll(v->window);
    char key[64];
    while (lm_window_next_key(v->window, key, sizeof key))
      if (!panel_wants_keyboard(v->panel) || !v->panel_on) handle_key(v, key); /* text typed into the panel */
    apply_panel(v);
    for (int i = 0; i < a->key_count; i++)
      if (a->keys[i].frame == v->frame) handle_key(v, a->keys[i].key);
    double now = lm_now_ms(), now_cpu = lm_cpu_ms();
    v->frame_ms = now - last;
    /* The panel's share: the last frame's times, with the panel on or off
     * as it drew, but for the frames its own timing stalls (glFinish, the
     * display's extra draw: one in PANEL_EVERY), on and off alike. */
    if (v->frame > 1 && (v->frame - 1) % PANEL_EVERY != 0) {
      v->frame_ms_sum[drawn_on] += v->frame_ms;
      v->frame_cpu_sum[drawn_on] += now_cpu - last_cpu;
      v->frames_timed[drawn_on]++;
    }
    last_cpu = now_cpu;
    /* Real time, a frame's stall (a shader rebuild) counted at most 0.25 s;
     * scripted runs (tests) 1/60 s a frame. The first frame shows --time. */
    if (!v->paused && v->frame > 0) advance(v, a->key_count ? 1.0 / 60.0 : fmin(now - last, 250.0) * 1e-3);
    pose(v);
    move_camera(v, now - last);
    last = now;
    if (!follow_size(v)) {
      usleep(16000); /* minimized: nothing to draw */
      if (a->exit_after && v->frame + 1 >= a->exit_after) break;
      continue;
    }
    render(v, handle_changes(v));
    update_reference(v);
    display(v);
    drawn_on = v->panel && v->panel_on;
    if (a->exit_after && v->frame + 1 >= a->exit_after) break;
    lm_window_swap(v->window);
  }
  if (stop_requested || lm_window_should_close(v->window)) display(v); /* the back buffer after a swap is undefined */
  lm_info("%ld frames", v->frame + 1);
  if (v->frames_timed[1] > 0) {
    char cost[200];
    panel_cost(v, cost, sizeof cost);
    lm_info("%s; %ld frames on, %ld off (glFinish + CLOCK_MONOTONIC; CPU: CLOCK_PROCESS_CPUTIME_ID)", cost,
            v->frames_timed[1], v->frames_timed[0]);
  }
  report_time(v, "at exit");
  if (v->live_ok) describe_reference(v, true);
  if (a->screenshot && !screenshot(v, a->screenshot)) return 1;
  return 0;
}

int limn_view(int argc, char **argv) {
  view_args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) {
    free_args(&a);
    return rc < 0 ? 0 : rc;
  }
  if (a.verbose) lm_log_set_level(LM_LOG_DEBUG);
  if (a.quiet) lm_log_set_level(LM_LOG_WARN);
  signal(SIGINT, on_signal);
  signal(SIGTERM, on_signal);
  viewer v = {.args = &a, .inspect = -1, .inspect_logged = -1, .channel = 4, .overlay_on = a.overlay, .panel_on = a.panel,
              .range = {0, 1}, .edits = no_edits(), .place = -1, .split = 0.5f, .cursor_logged = {-1, -1, -1}};
  capture_resolve(a.common.script, v.script, sizeof v.script);
  rc = run(&v);
  viewer_free(&v);
  free_args(&a);
  return rc;
}
