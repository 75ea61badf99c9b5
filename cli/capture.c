/* limn capture: render headless and write images, printing per-pass times. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/image.h"
#include "render/render.h"
#include "scene/gltf.h"
#include "capture_render.h"
#include "job.h"
#include "tools.h"

static const char capture_usage[] =
    "usage: limn capture [options]\n"
    "\n"
    "Renders a scene through a pipeline script without a window and writes the\n"
    "last frame. PNG gets 8-bit sRGB; EXR gets linear float RGB. Each file is\n"
    "written under a temporary name and renamed, so a failed run leaves none.\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE    built-in scene, or a .gltf/.glb file (default cornell;\n"
    "                       built in: %s)\n"
    "  --script FILE        pipeline script (default scripts/pp.lua)\n"
    "  --tech NAME          technique of the script (default: the first it lists)\n"
    "  --set NAME=VALUE     set a technique option the script declares in Options\n"
    "                       (repeatable; dotted names reach nested options)\n"
    "  --size WxH           output size (default 256x192)\n"
    "  --frames N           frames to render (default 1); times are medians\n"
    "  --warmup N           frames to render before those, untimed (default 0;\n"
    "                       say a temporal accumulation's convergence)\n"
    "  --camera N           camera index of the scene (default 0), or auto:\n"
    "                       one framing the scene's bounds\n"
    "  --output FILE        image to write, .png or .exr (repeatable); {frame} (0000,\n"
    "                       0001, ...) and {time} (seconds) name a sequence's frames;\n"
    "                       a sequence also goes to .mp4 or .webm video (the ffmpeg\n"
    "                       program encodes it)\n"
    "  --time SECONDS       pose the scene's animation at that time\n"
    "  --time START:STOP    a sequence: frames at START + k / fps up to STOP\n"
    "  --fps N              frames a second of a sequence\n"
    "  --animation NAME|INDEX|all   the animation posed (default all)\n"
    "  --clock auto|gpu|cpu|process   how passes are timed (default auto: GL timer\n"
    "                       queries, or glFinish + CLOCK_MONOTONIC on software\n"
    "                       renderers; process: glFinish + the process's CPU time,\n"
    "                       every thread's: on llvmpipe the rendering's work, which\n"
    "                       a loaded machine disturbs less than the wall clock)\n"
    "  --egl auto|device|surfaceless   EGL platform (default auto)\n"
    "  --check-nan          debug: fail at the first pass that writes a NaN or Inf,\n"
    "                       naming the pass, target and pixel (slow)\n"
    "  --list-options       print the script's techniques and options, and exit\n"
    "  --job FILE           run a capture job (a Lua table of scenes, camera lists,\n"
    "                       techniques, sizes, options and an output pattern; see\n"
    "                       docs/capture-jobs.md); --set adds to the job's options\n"
    "  --force              with --job: render images that exist already\n"
    "  --shard I/N          with --job: render views I, I+N, I+2N ... only; of a\n"
    "                       sequence, the I-th of N contiguous runs of frames\n"
    "  --shard auto[/N]     the shard from a job array: Slurm's SLURM_ARRAY_TASK_ID\n"
    "                       (less _MIN, of _COUNT shards; with /N as it is, of N),\n"
    "                       or Kubernetes' JOB_COMPLETION_INDEX (auto/N)\n"
    "  --quiet              no times, errors only\n"
    "  --verbose            debug messages (targets left out, GL messages)\n"
    "  --help               this text\n"
    "\n"
    "exit codes: 0 done, 1 failed (script, shader or GL error: the first line names\n"
    "script:line or the pass), 2 bad usage (a bad technique, option, scene, camera\n"
    "or animation too).\n";

typedef struct capture_args {
  limn_common_args common; /* --scene, --script, --tech, --set, --size, --camera */
  const char *egl, *job;
  int shard, shards;
  char shard_from[256]; /* where --shard auto found the shard */
  bool force;
  const char *single_flag; /* a flag of single captures (the job names these itself) */
  const char *outputs[16];
  int output_count;
  const char *videos[16]; /* .mp4, .webm */
  int video_count;
  int frames, warmup;
  const char *animation, *time_flag;
  double time_start, time_stop, fps; /* fps 0: one frame at time_start */
  int frame_count;
  lm_clock clock;
  bool list_options, quiet, verbose, check_nan;
} capture_args;

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("capture", fmt, arg); }

/* A {word} in an output name that capture does not fill ({frame}, {time}; a job's outputs know more):
 * false when there is none, else the message naming it in msg. */
static bool unknown_placeholder(const char *name, char *msg, size_t cap) {
  for (const char *p = strchr(name, '{'); p; p = strchr(p + 1, '{')) {
    const char *close = strchr(p, '}');
    if (!close) return false;
    if (strncmp(p, "{frame}", 7) && strncmp(p, "{time}", 6)) {
      snprintf(msg, cap, "--output '%s': unknown placeholder '%.*s' (capture fills {frame} and {time})", name,
               (int)(close - p + 1), p);
      return true;
    }
  }
  return false;
}

/* An output whose folder is no writable folder: false when it is one (or holds a placeholder, a
 * frame's own), else the message in msg. Capture makes no folder (a job does), so without this a
 * sequence rendered its first frame before its first write failed. */
static bool unwritable_folder(const char *name, char *msg, size_t cap) {
  char dir[1100];
  lm_dirname(name, dir, sizeof dir);
  if (strchr(dir, '{')) return false;
  struct stat st;
  if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
    snprintf(msg, cap, "--output '%s': no folder '%s' (capture makes none)", name, dir);
  else if (access(dir, W_OK) != 0)
    snprintf(msg, cap, "--output '%s': folder '%s' is not writable", name, dir);
  else
    return false;
  return true;
}

static bool is_video(const char *path) {
  const char *dot = strrchr(path, '.');
  return dot && !strchr(dot, '/') && (!strcasecmp(dot, ".mp4") || !strcasecmp(dot, ".webm"));
}

/* A sequence as video through Debian's ffmpeg program, raw RGB frames on its
 * standard input. The program, not libavcodec: one pipe instead of a codec,
 * muxer and pixel-format conversion set up by hand, and the codec choices
 * for each container stay ffmpeg's own defaults. Written to a temporary name
 * (the extension kept last: ffmpeg picks the container by it) and renamed
 * when ffmpeg succeeds. */
typedef struct video {
  const char *path;
  char tmp[2100];
  pid_t pid;
  int fd; /* the pipe's writing end; -1 when closed */
} video;

static bool video_open(video *v, const char *path, int width, int height, double fps, lm_error *err) {
  *v = (video){.path = path, .pid = -1, .fd = -1};
  const char *dot = strrchr(path, '.');
  snprintf(v->tmp, sizeof v->tmp, "%.*s.tmp-%ld%s", (int)(dot - path), path, (long)getpid(), dot);
  char size[64], rate[64];
  snprintf(size, sizeof size, "%dx%d", width, height);
  snprintf(rate, sizeof rate, "%.9g", fps);
  char *argv[] = {"ffmpeg", "-hide_banner", "-loglevel", "error", "-nostats", "-y", "-f", "rawvideo",
                  "-pix_fmt", "rgb24", "-s", size, "-r", rate, "-i", "-", "-pix_fmt", "yuv420p", v->tmp, NULL};
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    lm_error_set(err, "%s: cannot make a pipe: %s", path, strerror(errno));
    return false;
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fds[0], STDIN_FILENO);
  fflush(stdout);
  fflush(stderr);
  extern char **environ;
  int rc = posix_spawnp(&v->pid, "ffmpeg", &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fds[0]);
  if (rc != 0) {
    close(fds[1]);
    v->pid = -1;
    lm_error_set(err, "--output %s: video needs the ffmpeg program (Debian package ffmpeg): %s", path,
                 rc == ENOENT ? "not found on the PATH" : strerror(rc));
    return false;
  }
  v->fd = fds[1];
  return true;
}

static bool video_write(video *v, const unsigned char *rgb, size_t bytes, lm_error *err) {
  while (bytes > 0) {
    ssize_t n = write(v->fd, rgb, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      lm_error_set(err, "--output %s: ffmpeg stopped taking frames (%s)", v->path, strerror(errno));
      return false;
    }
    rgb += n, bytes -= (size_t)n;
  }
  return true;
}

/* Ends the stream; renames the file when ffmpeg and `ok` both succeeded, else removes it. */
static bool video_close(video *v, bool ok, lm_error *err) {
  if (v->fd >= 0) close(v->fd);
  v->fd = -1;
  int status = 0;
  if (v->pid > 0) {
    while (waitpid(v->pid, &status, 0) < 0 && errno == EINTR) {}
    if (ok && !(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
      lm_error_set(err, "--output %s: ffmpeg failed (%s %d; its messages above)", v->path,
                   WIFEXITED(status) ? "exit status" : "signal", WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
      ok = false;
    }
  }
  if (ok && rename(v->tmp, v->path) != 0) {
    lm_error_set(err, "--output %s: cannot rename %s: %s", v->path, v->tmp, strerror(errno));
    ok = false;
  }
  if (!ok) remove(v->tmp);
  v->pid = -1;
  return ok;
}

/* SIGINT or SIGTERM while frames render: the run stops before the next
 * rendered frame (a frame being written is finished and renamed into place),
 * removes a video's temporary file and dies of the signal, as without the
 * handler, leaving no temporary file behind. A second signal kills at once. */
static volatile sig_atomic_t stop_signal;
static void on_stop(int sig) { stop_signal = sig; }

/* Returns 0 to go on, else the exit code. */
static int parse_args(int argc, char **argv, capture_args *a) {
  *a = (capture_args){.common = {.scene = "cornell", .width = 256, .height = 192, .camera_auto = true},
                      .egl = "auto", .frames = 1};
  static const struct option opts[] = {
      {"scene", required_argument, 0, 's'},  {"script", required_argument, 0, 'p'},
      {"tech", required_argument, 0, 't'},   {"set", required_argument, 0, 'D'},
      {"size", required_argument, 0, 'z'},   {"frames", required_argument, 0, 'n'},
      {"warmup", required_argument, 0, 'w'},
      {"camera", required_argument, 0, 'c'}, {"output", required_argument, 0, 'o'},
      {"clock", required_argument, 0, 'k'},  {"egl", required_argument, 0, 'e'},
      {"list-options", no_argument, 0, 'l'}, {"quiet", no_argument, 0, 'q'},
      {"verbose", no_argument, 0, 'v'},      {"help", no_argument, 0, 'h'},
      {"check-nan", no_argument, 0, 'N'},
      {"job", required_argument, 0, 'j'},    {"force", no_argument, 0, 'f'},
      {"shard", required_argument, 0, 'S'},
      {"time", required_argument, 0, 'T'},   {"fps", required_argument, 0, 'F'},
      {"animation", required_argument, 0, 'A'},
      {0, 0, 0, 0}};
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    for (const struct option *o = opts; o->name && c && strchr("sptznwcTFA", c); o++)
      if (o->val == c) a->single_flag = o->name;
    switch (c) {
    case 'n':
      if (!limn_parse_int(optarg, 1, 100000, &a->frames)) return usage_error("--frames wants 1..100000, not '%s'", optarg);
      break;
    case 'w':
      if (!limn_parse_int(optarg, 0, 100000, &a->warmup)) return usage_error("--warmup wants 0..100000, not '%s'", optarg);
      break;
    case 'o': {
      bool linear;
      if (a->output_count + a->video_count == 16) return usage_error("%s", "at most 16 --output flags");
      char bad[1100];
      if (unknown_placeholder(optarg, bad, sizeof bad) /* it would be written as it stands */
          || unwritable_folder(optarg, bad, sizeof bad))
        return usage_error("%s", bad);
      for (int i = 0; i < a->output_count + a->video_count; i++)
        if (!strcmp(i < a->output_count ? a->outputs[i] : a->videos[i - a->output_count], optarg))
          return usage_error("--output '%s' is given twice", optarg);
      if (is_video(optarg)) a->videos[a->video_count++] = optarg;
      else if (!capture_known_extension(optarg, &linear))
        return usage_error("--output '%s': use a .png, .exr, .jpg, .tif or .hdr file (or .mp4, .webm for a "
                           "sequence)", optarg);
      else a->outputs[a->output_count++] = optarg;
      break;
    }
    case 'k':
      if (!capture_parse_clock(optarg, &a->clock)) return usage_error("--clock wants auto, gpu, cpu or process, not '%s'", optarg);
      break;
    case 'e':
      if (strcmp(optarg, "auto") && strcmp(optarg, "device") && strcmp(optarg, "surfaceless"))
        return usage_error("--egl wants auto, device or surfaceless, not '%s'", optarg);
      a->egl = optarg;
      break;
    case 'T':
      if (!limn_parse_time(optarg, &a->time_start, &a->time_stop))
        return usage_error("--time wants SECONDS or START:STOP (finite numbers), not '%s'", optarg);
      if (a->time_stop < a->time_start) return usage_error("--time START:STOP wants STOP >= START, not '%s'", optarg);
      a->time_flag = optarg;
      break;
    case 'F':
      if (!limn_parse_double(optarg, &a->fps) || !(a->fps > 0) || a->fps > 1e6)
        return usage_error("--fps wants frames a second in (0, 1e6], not '%s'", optarg);
      break;
    case 'A': a->animation = optarg; break;
    case 'j': a->job = optarg; break;
    case 'f': a->force = true; break;
    case 'S':
      if (!limn_parse_shard(optarg, &a->shard, &a->shards, a->shard_from, sizeof a->shard_from))
        return usage_error("%s", a->shard_from);
      break;
    case 'l': a->list_options = true; break;
    case 'q': a->quiet = true; break;
    case 'v': a->verbose = true; break;
    case 'N': a->check_nan = true; break;
    case 'h': printf(capture_usage, lm_scene_builtin_list()); return -1;
    default:
      if (limn_common_flag("capture", c, argv, &a->common)) return 2;
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (a->job && (a->output_count || a->video_count || a->list_options))
    return usage_error("%s", "--job names its own outputs: no --output or --list-options with it");
  if (a->job && a->single_flag)
    return usage_error("--job names its scenes, script, techniques, sizes and frames: '--%s' does not go with it",
                       a->single_flag);
  if (!a->job && (a->force || a->shards))
    return usage_error("%s", "--force and --shard go with --job");
  bool range = a->time_flag && strchr(a->time_flag, ':');
  if (range && !a->fps) return usage_error("--time %s: a sequence needs --fps N", a->time_flag);
  if (a->fps && !range) return usage_error("%s", "--fps goes with --time START:STOP");
  a->frame_count = 1;
  if (range) {
    double n = floor((a->time_stop - a->time_start) * a->fps + 1e-9) + 1;
    if (n > 100000) return usage_error("--time %s: more than 100000 frames at that --fps", a->time_flag);
    a->frame_count = (int)n;
  }
  if (a->video_count && a->frame_count < 2)
    return usage_error("--output '%s': a video is of a sequence (--time START:STOP --fps N, two frames or more)",
                       a->videos[0]);
  for (int i = 0; i < a->output_count && a->frame_count > 1; i++)
    if (!strstr(a->outputs[i], "{frame}")) {
      fprintf(stderr, "limn capture: --output '%s': a sequence of %d frames (--time %s --fps %g) needs {frame} in "
              "the name\n(see limn capture --help)\n", a->outputs[i], a->frame_count, a->time_flag, a->fps);
      return 2;
    }
  return 0;
}

/* The output name of a sequence's frame: {frame} and {time} filled. */
static void frame_name(const char *pattern, int frame, double time, char *out, size_t cap) {
  lm_buf b = {0};
  char seconds[LIMN_TIME_TEXT];
  for (const char *p = pattern; *p; p++) {
    if (!strncmp(p, "{frame}", 7)) lm_buf_printf(&b, CAPTURE_FRAME_FORMAT, frame), p += 6;
    else if (!strncmp(p, "{time}", 6)) lm_buf_append(&b, limn_time_text(time, 3, seconds), -1), p += 5;
    else lm_buf_append(&b, p, 1);
  }
  snprintf(out, cap, "%s", b.data ? b.data : "");
  lm_buf_free(&b);
}

static void print_times(const capture_result *res, int frames, int warmup, lm_clock clock) {
  printf("pass times (median of %d frame%s", frames, frames == 1 ? "" : "s");
  if (warmup > 0) printf(" after %d untimed", warmup);
  printf("; clock: %s)\n", lm_clock_name(clock));
  for (int i = 0; i < res->pass_count; i++)
    printf("  %-24s %-10s %9.3f ms\n", res->passes[i].name, res->passes[i].kind, res->passes[i].ms);
  printf("  %-24s %-10s %9.3f ms\n", "total", "", res->total_ms);
}

int limn_capture(int argc, char **argv) {
  capture_args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc < 0 ? 0 : rc;
  limn_common_args *o = &a.common;
  if (a.verbose) lm_log_set_level(LM_LOG_DEBUG);
  if (a.quiet) lm_log_set_level(LM_LOG_WARN);
  if (a.shard_from[0]) lm_info("shard %d/%d from %s", a.shard, a.shards, a.shard_from);
  if (a.job)
    return capture_job_run(&(capture_job_args){.path = a.job, .sets = o->sets, .set_count = o->set_count,
                                               .shard = a.shard, .shards = a.shards ? a.shards : 1,
                                               .force = a.force, .quiet = a.quiet, .verbose = a.verbose,
                                               .egl = a.egl, .clock = a.clock});

  lm_error err;
  lm_pipeline *pipeline = capture_load_pipeline(o, &rc, &err);
  if (!pipeline) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return rc;
  }
  if (a.list_options) {
    lm_buf b = {0};
    printf("techniques:");
    for (int i = 0; i < lm_pipeline_technique_count(pipeline); i++)
      printf(" %s", lm_pipeline_technique_name(pipeline, i));
    lm_pipeline_list_options(pipeline, &b);
    printf("\noptions: %s\n", b.data ? b.data : "none");
    lm_buf_free(&b);
    lm_pipeline_destroy(pipeline);
    return 0;
  }

  if (!lm_context_create_headless(&(lm_context_desc){.platform = a.egl, .debug = a.verbose}, &err)) {
    lm_log(LM_LOG_ERROR, "no OpenGL context: %s", err.msg);
    lm_pipeline_destroy(pipeline);
    return 1;
  }
  if (o->width > lm_texture_max_size() || o->height > lm_texture_max_size()) { /* the flag, not a target, named */
    lm_log(LM_LOG_ERROR, "--size %dx%d: this GL's textures are at most %d a side", o->width, o->height,
           lm_texture_max_size());
    lm_pipeline_destroy(pipeline);
    lm_context_destroy();
    return 2;
  }
  /* To the GPU as it is read: a technique that traces reads the vertices back (lm_scene_restore_geometry). */
  lm_scene *scene = lm_scene_load_gpu(o->scene, &err);
  int animation = LM_ANIM_ALL;
  bool bad = true;
  if (!scene)
    lm_log(LM_LOG_ERROR, "%s", err.msg);
  else if (a.animation && (animation = lm_scene_find_animation(scene, a.animation, &err)) < LM_ANIM_NONE)
    lm_log(LM_LOG_ERROR, "--animation %s: %s", a.animation, err.msg);
  else if ((o->camera = limn_camera_resolve(scene, o->camera, o->width, o->height)) > 0 &&
           o->camera >= scene->camera_count)
    lm_log(LM_LOG_ERROR, "--camera %d: scene '%s' has %d camera(s)", o->camera, o->scene, scene->camera_count);
  else
    bad = false;
  if (bad) {
    lm_scene_destroy(scene);
    lm_pipeline_destroy(pipeline);
    lm_context_destroy();
    return 2;
  }
  bool any_linear = false;
  for (int i = 0; i < a.output_count; i++) {
    bool l;
    capture_known_extension(a.outputs[i], &l);
    any_linear |= l;
  }
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = pipeline,
                                                          .width = o->width, .height = o->height,
                                                          .camera = o->camera, .clock = a.clock,
                                                          .linear_output = any_linear,
                                                          .check_finite = a.check_nan}, &err);
  bool ok = r != NULL;
  if (ok && !a.quiet)
    lm_info("renderer: %s (%s, %s); scene %s; script %s; technique %s; %dx%d", lm_gl_renderer(),
            lm_gl_version(), lm_context_platform(), o->scene, lm_pipeline_path(pipeline), lm_pipeline_technique(pipeline),
            o->width, o->height);
  capture_result res = {0};
  /* A sequence renders its frames through one renderer, so that temporal
   * histories carry from frame to frame as they would live. */
  char names[16][2048];
  const char *outputs[16];
  video videos[16];
  unsigned char *rgb = a.video_count ? lm_alloc((size_t)o->width * o->height * 3) : NULL;
  int opened = 0;
  if (a.video_count) signal(SIGPIPE, SIG_IGN); /* a failed ffmpeg is an error from write, not a kill */
  struct sigaction stop = {.sa_handler = on_stop, .sa_flags = SA_RESTART | SA_RESETHAND}, old_int, old_term;
  sigemptyset(&stop.sa_mask);
  stop_signal = 0;
  sigaction(SIGINT, NULL, &old_int);
  sigaction(SIGTERM, NULL, &old_term);
  if (old_int.sa_handler != SIG_IGN) sigaction(SIGINT, &stop, NULL); /* ignored (a background job's): kept so */
  if (old_term.sa_handler != SIG_IGN) sigaction(SIGTERM, &stop, NULL);
  for (int i = 0; i < a.video_count && ok; i++)
    if ((ok = video_open(&videos[i], a.videos[i], o->width, o->height, a.fps, &err))) opened++;
  int written = 0; /* frames */
  char seconds[LIMN_TIME_TEXT], stop_text[LIMN_TIME_TEXT];
  for (int k = 0; k < a.frame_count && ok && !stop_signal; k++) {
    double t = a.frame_count > 1 ? a.time_start + k / a.fps : a.time_start;
    if (a.time_flag || a.animation) {
      if (k == 0) /* the previous pose (velocities): the frame before's, a still's own */
        lm_scene_set_time(scene, animation, a.frame_count > 1 ? t - 1 / a.fps : t);
      lm_scene_set_time(scene, animation, t);
    }
    for (int i = 0; i < a.output_count; i++) {
      frame_name(a.outputs[i], k, t, names[i], sizeof names[i]);
      outputs[i] = names[i];
    }
    capture_view v = {.camera = o->camera, .width = o->width, .height = o->height, .frames = a.frames,
                      .warmup = k ? 0 : a.warmup, .outputs = outputs, .output_count = a.output_count,
                      .quiet = a.quiet, .continues = k > 0, .stop = &stop_signal};
    capture_result_free(&res);
    ok = capture_render_write(r, &v, &res, &err);
    if (ok && a.video_count) ok = lm_renderer_read(r, false, rgb, &err);
    for (int i = 0; i < a.video_count && ok; i++) ok = video_write(&videos[i], rgb, (size_t)o->width * o->height * 3, &err);
    if (!ok && a.frame_count > 1) lm_error_prefix(&err, "frame %d at %s s", k, limn_time_text(t, 3, seconds));
    written += ok;
  }
  if (stop_signal) {
    lm_error_set(&err, "stopped by signal %d after %d of %d frames (those written whole; no partial file left)",
                 (int)stop_signal, written, a.frame_count);
    ok = false;
  }
  for (int i = 0; i < opened; i++) {
    lm_error e;
    if (!video_close(&videos[i], ok, &e) && ok) err = e, ok = false;
    else if (ok && !a.quiet) lm_info("wrote %s", videos[i].path);
  }
  free(rgb);
  if (ok && !a.quiet && a.frame_count > 1)
    printf("%d frames, %s s to %s s at %g fps (times: the last frame's)\n", a.frame_count,
           limn_time_text(a.time_start, 3, seconds), limn_time_text(a.time_stop, 3, stop_text), a.fps);
  if (ok && !a.quiet) print_times(&res, a.frames, a.warmup, lm_renderer_clock(r));
  if (!ok) lm_log(LM_LOG_ERROR, "%s", err.msg);
  capture_result_free(&res);
  lm_renderer_destroy(r);
  lm_programs_clear();
  lm_scene_destroy(scene);
  lm_context_destroy();
  lm_pipeline_destroy(pipeline);
  sigaction(SIGINT, &old_int, NULL);
  sigaction(SIGTERM, &old_term, NULL);
  if (stop_signal) raise(stop_signal);
  return ok ? 0 : 1;
}
