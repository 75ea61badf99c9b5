/* limn reference --job FILE: references of a capture job's views from
 * POV-Ray or Cycles (cli/reference.h). This file is the part they share
 * (flags, file names, the cache, running at most --jobs renders at once,
 * renaming finished ones into place) and POV-Ray's own part; Cycles' is
 * cli/reference_cycles.c. POV-Ray runs in the reference's folder, since
 * Debian's povray.conf lets it write only below the current directory. A
 * renderer's output goes to a log beside its input, shown when it fails. */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <glob.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "reference.h"
#include "tools.h"
#include "script/script.h"

static const char reference_usage[] =
    "usage: limn reference --job FILE [--refs DIR] [--force] [--jobs N] [--shard I/N|auto[/N]]\n"
    "                      [--renderer pov|cycles] [Cycles flags] [export-pov flags]\n"
    "\n"
    "Renders a reference (linear OpenEXR) of every view of a capture job: each\n"
    "scene, camera and size (techniques do not matter here), with POV-Ray\n"
    "radiosity (the default) or Blender's Cycles path tracer (--renderer cycles,\n"
    "or the job's renderer = \"cycles\"). A POV-Ray reference is\n"
    "DIR/<scene>/<camera>_<WxH>-<hash>.exr, the hash that of the exported scene\n"
    "text; a Cycles one DIR/<scene>/<camera>_<WxH>-cycles-<hash>.exr, the hash\n"
    "that of the scene file, the camera, size, samples, bounces, seed, materials\n"
    "and sky, cli/cycles_render.py and Blender's version. A view whose hash\n"
    "has not changed is not rendered again. A sequence's frames are posed at\n"
    "their times, each DIR/<scene>/<camera>_<WxH>-<frame>-<time>-...exr.\n"
    "POV-Ray runs in parallel, up to the core count; Blender renders a scene's\n"
    "missing views in one run on every core (its start is seconds), each view's\n"
    "reference in place as soon as it is complete.\n"
    "\n"
    "options:\n"
    "  --job FILE           the capture job (docs/capture-jobs.md)\n"
    "  --refs DIR           where the references go (default out/reference)\n"
    "  --force              render again even what exists\n"
    "  --jobs N             renders at once (default: POV-Ray the core count,\n"
    "                       Cycles 1, its threads the cores; N Blender runs\n"
    "                       share a scene's views)\n"
    "  --povray PROGRAM     the POV-Ray program (default povray)\n"
    REFERENCE_OPTIONS_HELP
    "  --shard I/N          views I, I+N, I+2N ... only (numbered as capture's,\n"
    "                       without techniques: scene, size, camera, frame; a\n"
    "                       sequence's in N contiguous runs, as capture's)\n"
    "  --shard auto[/N]     the shard from a job array (as limn capture --shard)\n"
    "  --quiet              no progress\n"
    "  --radiosity, --count, --error-bound, --pretrace-start, --pretrace-end,\n"
    "  --recursion-limit, --brightness, --shadows, --approximate: as export-pov\n"
    "                       (defaults: the seed's radiosity settings)\n"
    "  --materials, --sky   as export-pov, for either renderer\n"
    "\n"
    "exit codes: 0 all references there, 1 an export or a render failed, 2 bad usage.\n";

void reference_defaults(reference_args *a) {
  *a = (reference_args){.refs = "out/reference", .povray = "povray", .shards = 1,
                        .cycles = {.blender = "blender", .samples = REFERENCE_CYCLES_SAMPLES, .bounces = 8}};
  limn_pov_defaults(&a->pov);
}

const char *reference_renderer_name(reference_renderer r) { return r == REFERENCE_CYCLES ? "Cycles" : "POV-Ray"; }

void reference_describe(const reference_args *a, char *out, size_t cap) {
  if (a->renderer == REFERENCE_CYCLES)
    snprintf(out, cap, "Cycles (%d samples, %d bounces, seed %d, materials %s%s)", a->cycles.samples,
             a->cycles.bounces, a->cycles.seed, a->pov.pbr_materials ? "pbr" : "phong", a->pov.has_sky ? ", sky" : "");
  else if (a->pov.radiosity)
    snprintf(out, cap, "POV-Ray (radiosity count %d, recursion limit %d, materials %s)", a->pov.rad.count,
             a->pov.rad.recursion_limit, a->pov.pbr_materials ? "pbr" : "phong");
  else snprintf(out, cap, "POV-Ray (direct light only, materials %s)", a->pov.pbr_materials ? "pbr" : "phong");
}

enum { RENDERER_FLAG = 0x200, SAMPLES_FLAG, BOUNCES_FLAG, SEED_FLAG, BLENDER_FLAG, SCRIPT_FLAG };

const struct option reference_options[] = {
    {"renderer", required_argument, 0, RENDERER_FLAG}, {"samples", required_argument, 0, SAMPLES_FLAG},
    {"bounces", required_argument, 0, BOUNCES_FLAG},   {"seed", required_argument, 0, SEED_FLAG},
    {"blender", required_argument, 0, BLENDER_FLAG},   {"cycles-script", required_argument, 0, SCRIPT_FLAG},
    {0, 0, 0, 0}};
_Static_assert(sizeof reference_options / sizeof *reference_options == REFERENCE_OPTION_COUNT,
               "REFERENCE_OPTION_COUNT (reference.h) counts reference_options");

static bool parse_renderer(const char *s, reference_renderer *out) {
  if (!strcmp(s, "pov") || !strcmp(s, "povray")) *out = REFERENCE_POV;
  else if (!strcmp(s, "cycles")) *out = REFERENCE_CYCLES;
  else return false;
  return true;
}

int reference_flag(const char *cmd, int c, const char *arg, reference_args *a) {
  int pov = limn_pov_flag(cmd, c, arg, &a->pov);
  if (pov != 1) {
    for (const struct option *o = limn_pov_options; pov == 0 && o->name; o++) {
      if (o->val != c) continue;
      a->sky_given |= !strcmp(o->name, "sky");
      a->materials_given |= !strcmp(o->name, "materials");
      a->approximate_given |= !strcmp(o->name, "approximate");
    }
    return pov;
  }
  reference_cycles *y = &a->cycles;
  const char *bad = NULL;
  switch (c) {
  case RENDERER_FLAG:
    if (parse_renderer(arg, &a->renderer)) a->renderer_given = true;
    else bad = "--renderer wants pov or cycles, not '%s'";
    break;
  case SAMPLES_FLAG: if (!limn_parse_int(arg, 1, 1 << 20, &y->samples)) bad = "--samples wants 1..1048576, not '%s'"; break;
  case BOUNCES_FLAG: if (!limn_parse_int(arg, 0, 1024, &y->bounces)) bad = "--bounces wants 0..1024, not '%s'"; break;
  case SEED_FLAG: if (!limn_parse_int(arg, 0, 1 << 30, &y->seed)) bad = "--seed wants 0..1073741824, not '%s'"; break;
  case BLENDER_FLAG: y->blender = arg; break;
  case SCRIPT_FLAG: y->script = arg; break;
  default: return 1;
  }
  return bad ? limn_usage_error(cmd, bad, arg) : 0;
}

/* The job turns sky.enabled on (its last word on it, read as the pipeline reads it): its views are lit by the sky. */
static bool job_has_sky(const job *j) {
  bool on = false, v;
  for (int i = 0; i < j->set_count; i++)
    if (!strcmp(j->set_names[i], "sky.enabled") && lm_option_bool(j->set_values[i], &v)) on = v;
  return on;
}

bool reference_prepare(reference_args *a, const job *j, lm_error *err) {
  if (!a->renderer_given && j->renderer[0]) parse_renderer(j->renderer, &a->renderer); /* job_read checked it */
  const job_references *r = &j->references;
  if (!a->sky_given && r->has_sky) a->pov.has_sky = true, a->pov.sky = r->sky;
  if (!a->materials_given && r->pbr_materials >= 0) a->pov.pbr_materials = r->pbr_materials;
  if (!a->approximate_given && r->approximate >= 0) a->pov.strict = !r->approximate;
  if (job_has_sky(j) && !a->pov.has_sky) {
    lm_error_set(err, "%s: its views are lit by the sky (set sky.enabled) but the references would have none: "
                 "give the job references = { sky = \"ZENITH:HORIZON[:INTENSITY]\" } (scripts/sky.lua's "
                 "sky.zenith, sky.horizon, sky.intensity) or --sky", j->path);
    return false;
  }
  if (a->renderer == REFERENCE_POV) return true;
  /* What only POV-Ray has: refused rather than ignored, so no one compares with a reference they did not ask for. */
  if (!a->pov.radiosity) {
    lm_error_set(err, "--radiosity off is POV-Ray's; Cycles' direct light only is --bounces 0");
    return false;
  }
  if (!a->pov.shadows) {
    lm_error_set(err, "--shadows off is POV-Ray's; Cycles' lights always cast shadows");
    return false;
  }
  return reference_cycles_prepare(&a->cycles, err);
}

bool reference_direct(const reference_args *a, reference_args *direct, const char **flags) {
  *direct = *a;
  if (a->renderer == REFERENCE_CYCLES) {
    direct->cycles.bounces = 0;
    *flags = " --renderer cycles --bounces 0";
    return a->cycles.bounces > 0;
  }
  direct->pov.radiosity = false;
  *flags = " --radiosity off";
  return a->pov.radiosity;
}

/* A name part without slashes or spaces. */
static void clean(const char *s, char *out, size_t cap) {
  size_t i = 0;
  for (; s[i] && i + 1 < cap; i++) out[i] = (s[i] == '/' || s[i] == ' ' || s[i] == '\\') ? '_' : s[i];
  out[i] = '\0';
}

/* ---- POV-Ray's part ------------------------------------------------------ */

/* POV-Ray's input: the exported scene text; its hash covers that and the command line's settings. */
static bool pov_export(const reference_args *a, const job *j, const job_view *v, lm_buf *sdl, uint64_t *hash,
                       lm_error *err) {
  const job_scene *s = &j->scenes[v->scene];
  lm_pov_desc d = a->pov;
  d.camera = v->camera;
  d.width = j->sizes[v->size][0];
  d.height = j->sizes[v->size][1];
  lm_buf warnings = {0};
  bool ok = lm_pov_export(s->scene, &d, sdl, &warnings, err);
  for (char *line = warnings.data; line && *line;) {
    char *nl = strchr(line, '\n');
    if (nl) *nl = '\0';
    lm_warn("%s: %s", s->name, line);
    line = nl ? nl + 1 : line + strlen(line);
  }
  lm_buf_free(&warnings);
  if (!ok) {
    lm_error_prefix(err, "%s", s->path);
    return false;
  }
  char cmd[64];
  snprintf(cmd, sizeof cmd, "+FE +W%d +H%d -A", d.width, d.height);
  *hash = lm_hash(sdl->data, (size_t)sdl->len, lm_hash(cmd, strlen(cmd), LM_HASH_SEED));
  return true;
}

static const char *file_part(const char *p) {
  const char *s = strrchr(p, '/');
  return s ? s + 1 : p;
}

/* Starts argv[0] with argv, its output into `log`, in folder dir (NULL:
 * here), holding `progress` (a pipe's write end, named by
 * $LIMN_PROGRESS_FD) until it exits; the child dies with this process. -1
 * when it cannot fork. */
static pid_t reference_spawn(const char *const *argv, const char *dir, const char *log, int progress) {
  fflush(stdout);
  fflush(stderr);
  pid_t parent = getpid(), pid = fork();
  if (pid != 0) return pid;
  /* A killed limn takes its renders with it: nothing renders on into a file no one will rename. */
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(127);
  int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0666);
  if (fd >= 0) {
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    close(fd);
  }
  char number[16];
  snprintf(number, sizeof number, "%d", progress);
  if (fcntl(progress, F_SETFD, 0) != 0 || setenv("LIMN_PROGRESS_FD", number, 1) != 0) _exit(127);
  if (dir && chdir(dir) != 0) {
    fprintf(stderr, "cannot enter %s: %s\n", dir, strerror(errno));
    _exit(127);
  }
  execvp(argv[0], (char *const *)argv);
  fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
  _exit(127);
}

/* POV-Ray on <base>.pov in the reference's folder, writing tmp. */
static pid_t start_povray(const reference_args *a, const char *base, const char *tmp, int width, int height,
                          int threads, int progress) {
  char dir[1024], in[1100], out[1100], log[1100], w[32], h[32], wt[32];
  lm_dirname(base, dir, sizeof dir);
  snprintf(in, sizeof in, "+I%s.pov", file_part(base));
  snprintf(out, sizeof out, "+O%s", file_part(tmp));
  snprintf(log, sizeof log, "%s.log", base);
  snprintf(w, sizeof w, "+W%d", width);
  snprintf(h, sizeof h, "+H%d", height);
  snprintf(wt, sizeof wt, "+WT%d", threads);
  const char *argv[] = {a->povray, "-D", "-V", in, out, "+FE", w, h, "-A", wt, NULL};
  return reference_spawn(argv, dir, log, progress);
}

/* ---- the renderers' shared part --------------------------------------- */

bool reference_export(const reference_args *a, const job *j, const job_view *v, lm_buf *input, char *path,
                      size_t cap, lm_error *err) {
  const job_scene *s = &j->scenes[v->scene];
  job_pose(j, v); /* the scene and a path's camera at the view's time */
  uint64_t h;
  bool cycles = a->renderer == REFERENCE_CYCLES;
  if (!(cycles ? reference_cycles_spec(a, j, v, input, &h, err) : pov_export(a, j, v, input, &h, err)))
    return false;
  /* A sequence's frames: each its own file, the frame in its name and hash. */
  char frame[64] = "";
  if (j->timed) {
    char seconds[LIMN_TIME_TEXT];
    snprintf(frame, sizeof frame, "-" CAPTURE_FRAME_FORMAT "-%s", v->frame, limn_time_text(v->time, 3, seconds));
    h = lm_hash(frame, strlen(frame), h);
  }
  char scene[LM_NAME_MAX], camera[LM_NAME_MAX];
  clean(s->name, scene, sizeof scene);
  clean(s->scene->cameras[v->camera].name, camera, sizeof camera);
  snprintf(path, cap, "%s/%s/%s_%dx%d%s-%s%016llx.exr", a->refs, scene, camera[0] ? camera : "camera",
           j->sizes[v->size][0], j->sizes[v->size][1], j->frame_count > 1 ? frame : "", cycles ? "cycles-" : "",
           (unsigned long long)h);
  return true;
}


/* The renderer's error lines: from the first line that holds `needle`
 * (NULL: none), else the first that mentions an error, to the end (at most
 * 20), else its last 10 lines. */
static void show_log(const char *log, const char *needle) {
  size_t len;
  lm_error err;
  char *text = lm_read_file(log, &len, &err);
  if (!text) return;
  char *lines[4096];
  int n = 0, first = -1, named = -1;
  for (char *p = text; *p && n < 4096;) {
    lines[n] = p;
    char *nl = strchr(p, '\n');
    if (nl) *nl = '\0';
    if (named < 0 && needle && strstr(p, needle)) named = n;
    if (first < 0 && (strstr(p, "rror") || strstr(p, "cannot "))) first = n;
    n++;
    if (!nl) break;
    p = nl + 1;
  }
  int from = named >= 0 ? named : first >= 0 ? first : (n > 10 ? n - 10 : 0);
  int to = from + 20 < n ? from + 20 : n;
  for (int i = from; i < to; i++)
    if (lines[i][0]) fprintf(stderr, "  | %s\n", lines[i]);
  free(text);
}

/* A view to render: its place and its reference's path less ".exr". */
typedef struct render_view {
  int place;
  bool done;
  char base[1024];
} render_view;

/* One renderer process and the views it renders, todo[first .. first + count). */
typedef struct render_run {
  pid_t pid;
  int progress;    /* the read end of the pipe it holds: Blender writes "K\n" as its view K is complete */
  int first, count;
  double last_ms;  /* lm_now_ms at its start or its last view's end: each view's time is printed */
  char tmp[1100];  /* <first base>.tmp-<pid>: POV-Ray's output (.exr), or Blender's folder (its outputs) */
  char line[32];   /* a progress line read in part */
  int line_len;
} render_run;

/* SIGINT or SIGTERM while renders run: they are killed here, and the loop,
 * woken from poll(), removes their partial files and stops. */
static volatile sig_atomic_t stop_signal;
static render_run *volatile running_runs;
static volatile int running_count;

static void on_stop(int sig) {
  stop_signal = sig;
  for (int k = 0; k < running_count; k++) kill(running_runs[k].pid, SIGKILL);
}

/* A render's temporary: a file, or a folder with what the renderer left in it. */
static void remove_temp(const char *path) {
  DIR *d = opendir(path);
  for (struct dirent *e; d && (e = readdir(d));) {
    char file[2400];
    snprintf(file, sizeof file, "%s/%s", path, e->d_name);
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) remove(file);
  }
  if (d) closedir(d);
  remove(path); /* a file, or the folder now empty */
}

/* Every temporary of the reference at base: a failed or stopped render's, and any a killed run left. */
static void clear_temps(const char *base) {
  char pattern[1100];
  snprintf(pattern, sizeof pattern, "%s.tmp-*", base);
  glob_t g;
  if (glob(pattern, GLOB_NOSORT, NULL, &g) == 0)
    for (size_t i = 0; i < g.gl_pathc; i++) remove_temp(g.gl_pathv[i]);
  globfree(&g);
}

static void view_error(const job *j, const job_view *places, int place, bool newline, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static void view_error(const job *j, const job_view *places, int place, bool newline, const char *fmt, ...) {
  const job_view *v = &places[place];
  const job_scene *s = &j->scenes[v->scene];
  char what[1536];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  if (newline) printf("\n");
  char frame[64] = "";
  char seconds[LIMN_TIME_TEXT];
  if (j->timed) snprintf(frame, sizeof frame, ", frame %d at %s s", v->frame, limn_time_text(v->time, 3, seconds));
  lm_log(LM_LOG_ERROR, "%s: view %d (%s, camera '%s', %dx%d%s): %s", j->path, place, s->name,
         s->scene->cameras[v->camera].name, j->sizes[v->size][0], j->sizes[v->size][1], frame, what);
}

/* What reference_run shares with the helpers below. */
typedef struct render_state {
  const reference_args *a;
  const job *j;
  const job_view *places;
  render_view *todo;
  int done, mine, rendered, rc;
  bool cycles, tty;
} render_state;

/* Where run r's renderer writes its view k (k counted within the run). */
static void run_output(const render_state *st, const render_run *r, int k, char *out, size_t cap) {
  if (st->cycles) snprintf(out, cap, "%s/%d.exr", r->tmp, k);
  else snprintf(out, cap, "%s", r->tmp);
}

/* View k of run r is complete: into place, with its time. */
static void view_done(render_state *st, render_run *r, int k) {
  render_view *t = &st->todo[r->first + k];
  char out[1200], final[1100], what[1200];
  run_output(st, r, k, out, sizeof out);
  snprintf(final, sizeof final, "%s.exr", t->base);
  if (rename(out, final) != 0) {
    view_error(st->j, st->places, t->place, st->tty && !st->a->quiet, "cannot rename %s to %s: %s", out, final,
               strerror(errno));
    st->rc = 1;
    return;
  }
  t->done = true;
  double now = lm_now_ms();
  st->rendered++;
  snprintf(what, sizeof what, "%s (%.1f s)", final, (now - r->last_ms) / 1000);
  r->last_ms = now;
  job_progress(st->a->quiet, st->tty, ++st->done, st->mine, what);
}

/* Reads run r's progress; false at its end (the renderer has exited or closed it). */
static bool read_progress(render_state *st, render_run *r) {
  char buf[256];
  ssize_t got = read(r->progress, buf, sizeof buf);
  if (got < 0 && (errno == EINTR || errno == EAGAIN)) return true;
  for (ssize_t i = 0; i < got; i++) {
    if (buf[i] != '\n') {
      if (r->line_len + 1 < (int)sizeof r->line) r->line[r->line_len++] = buf[i];
      continue;
    }
    r->line[r->line_len] = '\0';
    r->line_len = 0;
    int k;
    if (limn_parse_int(r->line, 0, r->count - 1, &k) && !st->todo[r->first + k].done) view_done(st, r, k);
  }
  return got > 0;
}

/* Run r has ended (its exit status): POV-Ray's view is complete when it
 * exited 0 and wrote its file; each view Blender did not report failed. The
 * log goes with the first failed view (a rerun of it replaces it), or away. */
static void run_end(render_state *st, render_run *r, int status) {
  const char *name = reference_renderer_name(st->a->renderer);
  bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  char out[1200], log[1100], kept[1100] = "";
  run_output(st, r, 0, out, sizeof out);
  if (!st->cycles && !stop_signal && ok && lm_file_exists(out)) view_done(st, r, 0);
  snprintf(log, sizeof log, "%s.log", st->todo[r->first].base);
  for (int k = 0; k < r->count && !kept[0]; k++)
    if (!st->todo[r->first + k].done) snprintf(kept, sizeof kept, "%s.log", st->todo[r->first + k].base);
  if (!kept[0] || stop_signal) remove(log);
  else if (strcmp(kept, log) != 0 && rename(log, kept) != 0) snprintf(kept, sizeof kept, "%s", log);
  for (int k = 0; k < r->count && !stop_signal; k++) {
    render_view *t = &st->todo[r->first + k];
    if (t->done) continue;
    if (ok)
      view_error(st->j, st->places, t->place, st->tty && !st->a->quiet, "%s exited 0 but wrote no image; its log %s:",
                 name, kept);
    else
      view_error(st->j, st->places, t->place, st->tty && !st->a->quiet, "%s failed (%s %d); its log %s:", name,
                 WIFEXITED(status) ? "exit status" : "signal",
                 WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), kept);
    char view[LM_NAME_MAX * 2 + 128], needle[LM_NAME_MAX * 2 + 160];
    if (st->cycles) { /* the script's lines name the view as its spec does */
      reference_cycles_view_name(st->j, &st->places[t->place], view, sizeof view);
      snprintf(needle, sizeof needle, "view '%s'", view);
    }
    show_log(kept, st->cycles ? needle : NULL);
    st->rc = 1;
  }
  remove_temp(r->tmp);
}

/* Starts the renderer on todo[first .. first + count) into *r; false (the views named) when it cannot. */
static bool run_start(render_state *st, render_run *r, int first, int count, int threads) {
  const reference_args *a = st->a;
  render_view *t = &st->todo[first];
  *r = (render_run){.first = first, .count = count, .progress = -1};
  snprintf(r->tmp, sizeof r->tmp, "%s.tmp-%ld%s", t->base, (long)getpid(), st->cycles ? "" : ".exr");
  char log[1100], why[1400] = "";
  snprintf(log, sizeof log, "%s.log", t->base);
  int fd[2];
  /* Blender's own folder: whatever it writes beside its outputs goes with it. */
  if (st->cycles && mkdir(r->tmp, 0777) != 0) snprintf(why, sizeof why, "%s: cannot make folder (%s)", r->tmp, strerror(errno));
  else if (pipe2(fd, O_CLOEXEC) != 0) snprintf(why, sizeof why, "cannot make a pipe: %s", strerror(errno));
  if (!why[0]) {
    r->last_ms = lm_now_ms();
    if (st->cycles) {
      char number[32], (*files)[1200] = lm_alloc(sizeof *files * 2 * (size_t)count);
      const char **argv = lm_alloc(sizeof *argv * (REFERENCE_CYCLES_ARGS + 2 * (size_t)count + 1));
      snprintf(number, sizeof number, "%d", threads);
      reference_cycles_argv(&a->cycles, number, argv);
      for (int k = 0; k < count; k++) {
        snprintf(files[2 * k], sizeof files[0], "%s.json", t[k].base);
        run_output(st, r, k, files[2 * k + 1], sizeof files[0]);
        argv[REFERENCE_CYCLES_ARGS + 2 * k] = files[2 * k];
        argv[REFERENCE_CYCLES_ARGS + 2 * k + 1] = files[2 * k + 1];
      }
      argv[REFERENCE_CYCLES_ARGS + 2 * count] = NULL;
      r->pid = reference_spawn(argv, NULL, log, fd[1]);
      free(argv);
      free(files);
    } else {
      const job_view *v = &st->places[t->place];
      r->pid = start_povray(a, t->base, r->tmp, st->j->sizes[v->size][0], st->j->sizes[v->size][1], threads, fd[1]);
    }
    close(fd[1]);
    r->progress = fd[0];
    if (r->pid < 0) {
      snprintf(why, sizeof why, "cannot start %s: %s", reference_renderer_name(a->renderer), strerror(errno));
      close(fd[0]);
    }
  }
  if (!why[0]) return true;
  for (int k = 0; k < count; k++) view_error(st->j, st->places, t[k].place, st->tty && !a->quiet, "%s", why);
  if (st->cycles) remove_temp(r->tmp);
  st->rc = 1;
  return false;
}

int reference_run(const reference_args *a, const job *j, const job_view *places, int n, char (*paths)[1024]) {
  lm_error err;
  render_state st = {.a = a, .j = j, .places = places, .cycles = a->renderer == REFERENCE_CYCLES,
                     .tty = isatty(STDOUT_FILENO)};
  int cached = 0, running = 0, count = 0;
  int cores = lm_cpu_count(), jobs = a->jobs > 0 ? a->jobs : st.cycles ? 1 : cores;
  int threads = cores > jobs ? cores / jobs : 1;
  render_run *runs = lm_alloc(sizeof *runs * (size_t)jobs);
  struct pollfd *polls = lm_alloc(sizeof *polls * (size_t)jobs);
  st.todo = lm_alloc(sizeof *st.todo * (size_t)(n > 0 ? n : 1));
  char what[1200], describe[256];
  reference_describe(a, describe, sizeof describe);
  for (int i = 0; i < n; i++) st.mine += job_shard_of(j, i, n, a->shards) == a->shard;
  char in_shard[64] = "";
  if (a->shards > 1) snprintf(in_shard, sizeof in_shard, " (%d in shard %d/%d)", st.mine, a->shard, a->shards);
  if (!a->quiet) printf("references of %s: %d view%s%s, %s, up to %d run%s at once; %s\n", j->path, n,
                        n == 1 ? "" : "s", in_shard, describe, jobs, jobs == 1 ? "" : "s", a->refs);
  /* Each view of the shard: named, cached or its renderer's input written beside its reference. */
  for (int i = 0; i < n; i++) {
    if (job_shard_of(j, i, n, a->shards) != a->shard) continue;
    lm_buf input = {0};
    char path[1024], in[1100];
    bool ok = reference_export(a, j, &places[i], &input, path, sizeof path, &err);
    if (ok && paths) snprintf(paths[i], sizeof paths[i], "%s", path);
    if (ok) { /* what a killed run left, which may be named after a view it finished */
      char base[1024];
      snprintf(base, sizeof base, "%.*s", (int)(strlen(path) - 4), path);
      clear_temps(base);
    }
    if (ok && !a->force && lm_file_exists(path)) {
      cached++;
      snprintf(what, sizeof what, "%s: unchanged, cached", path);
      job_progress(a->quiet, st.tty, ++st.done, st.mine, what);
    } else if (ok) {
      render_view *t = &st.todo[count];
      *t = (render_view){.place = i};
      snprintf(t->base, sizeof t->base, "%.*s", (int)(strlen(path) - 4), path);
      snprintf(in, sizeof in, "%s.%s", t->base, st.cycles ? "json" : "pov");
      ok = job_make_parent(path, &err) && limn_write_whole(in, input.data, (size_t)input.len, &err);
      count += ok;
    }
    lm_buf_free(&input);
    if (!ok) {
      view_error(j, places, i, st.tty && !a->quiet, "%s", err.msg);
      st.rc = 1;
    }
  }
  /* Blender takes a scene's views in one run, at most an even share of them a run so that every job has work. */
  int share = st.cycles ? (count + jobs - 1) / jobs : 1;
  struct sigaction stop = {.sa_handler = on_stop}, old_int, old_term; /* no SA_RESTART: poll() wakes */
  sigemptyset(&stop.sa_mask);
  stop_signal = 0;
  running_runs = runs;
  running_count = 0;
  sigaction(SIGINT, &stop, &old_int);
  sigaction(SIGTERM, &stop, &old_term);
  for (int next = 0; (next < count && !stop_signal) || running > 0;) {
    while (running < jobs && next < count && !stop_signal) {
      int views = 1, scene = places[st.todo[next].place].scene;
      while (views < share && next + views < count && places[st.todo[next + views].place].scene == scene) views++;
      if (run_start(&st, &runs[running], next, views, threads)) running_count = ++running;
      next += views;
    }
    if (running == 0) continue;
    nfds_t watched = 0;
    for (int k = 0; k < running; k++) polls[watched++] = (struct pollfd){.fd = runs[k].progress, .events = POLLIN};
    if (!stop_signal && poll(polls, watched, -1) < 0 && errno != EINTR) break;
    for (int k = running - 1; k >= 0; k--) {
      render_run *r = &runs[k];
      if (!stop_signal && !(polls[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      if (!stop_signal && read_progress(&st, r)) continue;
      /* Its end, or a stop (killed here too, should it have started after on_stop ran). */
      if (stop_signal) kill(r->pid, SIGKILL);
      int status = 0;
      while (waitpid(r->pid, &status, 0) < 0 && errno == EINTR) {}
      close(r->progress);
      run_end(&st, r, status);
      *r = runs[--running];
      running_count = running;
    }
  }
  sigaction(SIGINT, &old_int, NULL);
  sigaction(SIGTERM, &old_term, NULL);
  running_count = 0;
  free(runs);
  free(polls);
  free(st.todo);
  if (stop_signal) { /* the renders are gone and so are their files: die of the signal, as without the handler */
    if (st.tty && !a->quiet) printf("\n");
    lm_log(LM_LOG_ERROR, "%s: stopped by signal %d; no partial reference left", j->path, (int)stop_signal);
    raise(stop_signal);
    return 1;
  }
  if (!a->quiet) printf("references of %s: %d rendered, %d cached (unchanged; --force redoes them)%s\n", j->path,
                        st.rendered, cached, st.rc ? ", some failed" : "");
  return st.rc;
}

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("reference", fmt, arg); }

int limn_reference(int argc, char **argv) {
  reference_args a;
  reference_defaults(&a);
  const char *job_path = NULL;
  char shard_from[256] = "";
  struct option opts[8 + LIMN_POV_OPTION_COUNT - 1 + REFERENCE_OPTION_COUNT] = {
      {"job", required_argument, 0, 'J'},    {"refs", required_argument, 0, 'R'},
      {"force", no_argument, 0, 'F'},        {"jobs", required_argument, 0, 'j'},
      {"povray", required_argument, 0, 'P'}, {"quiet", no_argument, 0, 'q'},
      {"help", no_argument, 0, 'h'},         {"shard", required_argument, 0, 'I'}};
  memcpy(opts + 8, limn_pov_options, sizeof(struct option) * (LIMN_POV_OPTION_COUNT - 1));
  memcpy(opts + 8 + LIMN_POV_OPTION_COUNT - 1, reference_options, sizeof(struct option) * REFERENCE_OPTION_COUNT);
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    int pov = reference_flag("reference", c, optarg, &a);
    if (pov == 2) return 2;
    if (pov == 0) continue;
    switch (c) {
    case 'J': job_path = optarg; break;
    case 'R': a.refs = optarg; break;
    case 'F': a.force = true; break;
    case 'j':
      if (!limn_parse_int(optarg, 1, 1024, &a.jobs)) return usage_error("--jobs wants 1..1024, not '%s'", optarg);
      break;
    case 'P': a.povray = optarg; break;
    case 'I':
      if (!limn_parse_shard(optarg, &a.shard, &a.shards, shard_from, sizeof shard_from))
        return usage_error("%s", shard_from);
      break;
    case 'q': a.quiet = true; break;
    case 'h': fputs(reference_usage, stdout); return 0;
    case ':': return usage_error("%s needs a value", argv[optind - 1]);
    default: return usage_error("unknown flag '%s'", argv[optind - 1]);
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (!job_path) return usage_error("%s", "--job FILE is required");
  const char *bad = a.pov.radiosity ? lm_pov_radiosity_check(&a.pov.rad) : NULL;
  if (bad) return usage_error("radiosity setting out of range: %s", bad);
  if (shard_from[0]) lm_info("shard %d/%d from %s", a.shard, a.shards, shard_from);
  job *j = lm_alloc(sizeof *j);
  lm_error err;
  job_view *places = NULL;
  int n = 0, rc = 0;
  if (!job_read(j, job_path, &err) || !job_views(j, false, &places, &n, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 2;
  }
  if (!rc && !reference_prepare(&a, j, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 1;
  }
  if (!rc) rc = reference_run(&a, j, places, n, NULL);
  free(places);
  job_free_scenes(j);
  free(j);
  return rc;
}
