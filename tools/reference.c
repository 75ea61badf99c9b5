/* limn reference --job FILE: POV-Ray references of a capture job's views
 * (tools/reference.h). POV-Ray runs as a child process in the reference's
 * folder, since Debian's povray.conf lets it write only below the current
 * directory; its output goes to a log beside the .pov, shown when it fails. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "reference.h"
#include "tools.h"

static const char reference_usage[] =
    "usage: limn reference --job FILE [--refs DIR] [--force] [--jobs N] [--shard I/N|auto[/N]]\n"
    "                      [export-pov flags]\n"
    "\n"
    "Renders a POV-Ray reference (radiosity on, OpenEXR, linear) of every view of\n"
    "a capture job: each scene, camera and size (techniques do not matter here).\n"
    "Each reference is DIR/<scene>/<camera>_<WxH>-<hash>.exr, the hash that of\n"
    "the exported scene text: a view whose export has not changed is not\n"
    "rendered again. A sequence's frames are posed at their times, each\n"
    "DIR/<scene>/<camera>_<WxH>-<frame>-<time>-<hash>.exr. POV-Ray runs in\n"
    "parallel, up to the core count.\n"
    "\n"
    "options:\n"
    "  --job FILE           the capture job (README: Scenes and capture jobs)\n"
    "  --refs DIR           where the references go (default out/reference)\n"
    "  --force              render again even what exists\n"
    "  --jobs N             POV-Ray runs at once (default: the core count)\n"
    "  --povray PROGRAM     the POV-Ray program (default povray)\n"
    "  --shard I/N          views I, I+N, I+2N ... only (numbered as capture's,\n"
    "                       without techniques: scene, size, camera, frame; a\n"
    "                       sequence's in N contiguous runs, as capture's)\n"
    "  --shard auto[/N]     the shard from a job array (as limn capture --shard)\n"
    "  --quiet              no progress\n"
    "  --radiosity, --count, --error-bound, --pretrace-start, --pretrace-end,\n"
    "  --recursion-limit, --brightness, --shadows, --approximate: as export-pov\n"
    "                       (defaults: the seed's radiosity settings)\n"
    "\n"
    "exit codes: 0 all references there, 1 an export or POV-Ray run failed, 2 bad usage.\n";

void reference_defaults(reference_args *a) {
  *a = (reference_args){.refs = "out/reference", .povray = "povray", .shards = 1};
  limn_pov_defaults(&a->pov);
  a->jobs = lm_cpu_count();
}

/* A name part without slashes or spaces. */
static void clean(const char *s, char *out, size_t cap) {
  size_t i = 0;
  for (; s[i] && i + 1 < cap; i++) out[i] = (s[i] == '/' || s[i] == ' ' || s[i] == '\\') ? '_' : s[i];
  out[i] = '\0';
}

bool reference_export(const reference_args *a, const job *j, const job_view *v, lm_buf *sdl, char *path,
                      size_t cap, lm_error *err) {
  const job_scene *s = &j->scenes[v->scene];
  job_pose(j, v); /* the scene and a path's camera at the view's time */
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
  /* The hash covers what POV-Ray is given: the text and the command line's settings. */
  char cmd[64];
  snprintf(cmd, sizeof cmd, "+FE +W%d +H%d -A", d.width, d.height);
  uint64_t h = lm_hash(sdl->data, (size_t)sdl->len, lm_hash(cmd, strlen(cmd), LM_HASH_SEED));
  /* A sequence's frames: each its own file, the frame in its name and hash. */
  char frame[64] = "";
  if (j->timed) {
    snprintf(frame, sizeof frame, "-" CAPTURE_FRAME_FORMAT "-" CAPTURE_TIME_FORMAT, v->frame, v->time);
    h = lm_hash(frame, strlen(frame), h);
  }
  char scene[LM_NAME_MAX], camera[LM_NAME_MAX];
  clean(s->name, scene, sizeof scene);
  clean(s->scene->cameras[v->camera].name, camera, sizeof camera);
  snprintf(path, cap, "%s/%s/%s_%dx%d%s-%016llx.exr", a->refs, scene, camera[0] ? camera : "camera", d.width,
           d.height, j->frame_count > 1 ? frame : "", (unsigned long long)h);
  return true;
}

typedef struct pov_run {
  pid_t pid;
  int place;
  char base[1024]; /* the reference's path without .exr */
  char tmp[1100];
} pov_run;

static const char *file_part(const char *p) {
  const char *s = strrchr(p, '/');
  return s ? s + 1 : p;
}

static pid_t start_povray(const reference_args *a, const pov_run *r, int width, int height, int threads) {
  char dir[1024], in[1100], out[1100], log[1100], w[32], h[32], wt[32];
  lm_dirname(r->base, dir, sizeof dir);
  snprintf(in, sizeof in, "+I%s.pov", file_part(r->base));
  snprintf(out, sizeof out, "+O%s", file_part(r->tmp));
  snprintf(log, sizeof log, "%s.log", r->base);
  snprintf(w, sizeof w, "+W%d", width);
  snprintf(h, sizeof h, "+H%d", height);
  snprintf(wt, sizeof wt, "+WT%d", threads);
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid != 0) return pid;
  int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0666);
  if (fd >= 0) {
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    close(fd);
  }
  if (chdir(dir) != 0) {
    fprintf(stderr, "cannot enter %s: %s\n", dir, strerror(errno));
    _exit(127);
  }
  execlp(a->povray, a->povray, "-D", "-V", in, out, "+FE", w, h, "-A", wt, (char *)NULL);
  fprintf(stderr, "cannot run %s: %s\n", a->povray, strerror(errno));
  _exit(127);
}

/* POV-Ray's error lines: from its first line that mentions an error to the
 * end (at most 20), else its last 10 lines. */
static void show_log(const char *log) {
  size_t len;
  lm_error err;
  char *text = lm_read_file(log, &len, &err);
  if (!text) return;
  char *lines[4096];
  int n = 0, first = -1;
  for (char *p = text; *p && n < 4096;) {
    lines[n] = p;
    char *nl = strchr(p, '\n');
    if (nl) *nl = '\0';
    if (first < 0 && (strstr(p, "rror") || strstr(p, "cannot "))) first = n;
    n++;
    if (!nl) break;
    p = nl + 1;
  }
  int from = first >= 0 ? first : (n > 10 ? n - 10 : 0);
  int to = from + 20 < n ? from + 20 : n;
  for (int i = from; i < to; i++)
    if (lines[i][0]) fprintf(stderr, "  | %s\n", lines[i]);
  free(text);
}

int reference_run(const reference_args *a, const job *j, const job_view *places, int n, char (*paths)[1024]) {
  lm_error err;
  int rc = 0, done = 0, rendered = 0, cached = 0, running = 0, mine = 0;
  int jobs = a->jobs > 0 ? a->jobs : 1;
  int cores = lm_cpu_count(), threads = cores > jobs ? cores / jobs : 1;
  bool tty = isatty(STDOUT_FILENO);
  pov_run *runs = lm_alloc(sizeof *runs * (size_t)jobs);
  char what[1200];
  for (int i = 0; i < n; i++) mine += job_shard_of(j, i, n, a->shards) == a->shard;
  char in_shard[64] = "";
  if (a->shards > 1) snprintf(in_shard, sizeof in_shard, " (%d in shard %d/%d)", mine, a->shard, a->shards);
  if (!a->quiet) printf("references of %s: %d view%s%s, up to %d POV-Ray run%s at once; %s\n", j->path, n,
                        n == 1 ? "" : "s", in_shard, jobs, jobs == 1 ? "" : "s", a->refs);
  for (int i = 0; i <= n; i++) {
    /* Start place i when a slot is free; after the last, wait for the rest. */
    while (running > 0 && (running == jobs || i == n)) {
      int status;
      pid_t pid = wait(&status);
      if (pid < 0) break;
      pov_run *r = NULL;
      for (int k = 0; k < running && !r; k++)
        if (runs[k].pid == pid) r = &runs[k];
      if (!r) continue;
      const job_view *v = &places[r->place];
      const job_scene *s = &j->scenes[v->scene];
      char final[1100], log[1100];
      snprintf(final, sizeof final, "%s.exr", r->base);
      snprintf(log, sizeof log, "%s.log", r->base);
      bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && lm_file_exists(r->tmp) &&
                rename(r->tmp, final) == 0;
      if (ok) {
        remove(log);
        rendered++;
        snprintf(what, sizeof what, "%s", final);
        job_progress(a->quiet, tty, ++done, mine, what);
      } else {
        remove(r->tmp);
        if (tty && !a->quiet) printf("\n");
        lm_log(LM_LOG_ERROR, "%s: view %d (%s, camera '%s', %dx%d): POV-Ray failed (%s %d); its log %s:", j->path,
               r->place, s->name, s->scene->cameras[v->camera].name, j->sizes[v->size][0], j->sizes[v->size][1],
               WIFEXITED(status) ? "exit status" : "signal",
               WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status), log);
        show_log(log);
        rc = 1;
      }
      *r = runs[--running];
    }
    if (i == n) break;
    if (job_shard_of(j, i, n, a->shards) != a->shard) continue;
    const job_view *v = &places[i];
    const job_scene *s = &j->scenes[v->scene];
    lm_buf sdl = {0};
    char path[1024];
    bool ok = reference_export(a, j, v, &sdl, path, sizeof path, &err);
    if (ok && paths) snprintf(paths[i], sizeof paths[i], "%s", path);
    if (ok && !a->force && lm_file_exists(path)) {
      cached++;
      snprintf(what, sizeof what, "%s: unchanged, cached", path);
      job_progress(a->quiet, tty, ++done, mine, what);
      lm_buf_free(&sdl);
      continue;
    }
    pov_run *r = &runs[running];
    *r = (pov_run){.place = i};
    if (ok) {
      snprintf(r->base, sizeof r->base, "%.*s", (int)(strlen(path) - 4), path);
      snprintf(r->tmp, sizeof r->tmp, "%s.tmp-%ld.exr", r->base, (long)getpid());
      char pov[1100];
      snprintf(pov, sizeof pov, "%s.pov", r->base);
      ok = job_make_parent(path, &err) && limn_write_whole(pov, sdl.data, (size_t)sdl.len, &err);
    }
    lm_buf_free(&sdl);
    if (ok) {
      r->pid = start_povray(a, r, j->sizes[v->size][0], j->sizes[v->size][1], threads);
      if (r->pid < 0) lm_error_set(&err, "cannot start %s: %s", a->povray, strerror(errno)), ok = false;
    }
    if (!ok) {
      if (tty && !a->quiet) printf("\n");
      lm_log(LM_LOG_ERROR, "%s: view %d (%s, camera '%s', %dx%d): %s", j->path, i, s->name,
             s->scene->cameras[v->camera].name, j->sizes[v->size][0], j->sizes[v->size][1], err.msg);
      rc = 1;
      continue;
    }
    running++;
  }
  free(runs);
  if (!a->quiet) printf("references of %s: %d rendered, %d cached (unchanged; --force redoes them)%s\n", j->path,
                        rendered, cached, rc ? ", some failed" : "");
  return rc;
}

static int usage_error(const char *fmt, const char *arg) {
  fprintf(stderr, "limn reference: ");
  fprintf(stderr, fmt, arg);
  fprintf(stderr, "\n(see limn reference --help)\n");
  return 2;
}

int limn_reference(int argc, char **argv) {
  reference_args a;
  reference_defaults(&a);
  const char *job_path = NULL;
  char shard_from[256] = "";
  struct option opts[9 + LIMN_POV_OPTION_COUNT] = {
      {"job", required_argument, 0, 'J'},    {"refs", required_argument, 0, 'R'},
      {"force", no_argument, 0, 'F'},        {"jobs", required_argument, 0, 'j'},
      {"povray", required_argument, 0, 'P'}, {"quiet", no_argument, 0, 'q'},
      {"help", no_argument, 0, 'h'},         {"shard", required_argument, 0, 'I'}};
  memcpy(opts + 8, limn_pov_options, sizeof(struct option) * LIMN_POV_OPTION_COUNT);
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    int pov = limn_pov_flag("reference", c, optarg, &a.pov);
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
  if (!rc) rc = reference_run(&a, j, places, n, NULL);
  free(places);
  job_free_scenes(j);
  free(j);
  return rc;
}
