/* limn farm slurm: a capture job (and its references) as a Slurm job
 * array. The script it writes is both the array's batch script (a task
 * renders shard SLURM_ARRAY_TASK_ID with `--shard auto/N`) and, run with
 * bash outside Slurm, what submits the array and a merge task that waits for
 * every task (afterany, so that a failed shard is named by the merge). */
#define _GNU_SOURCE
#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/wait.h>
#include <unistd.h>

#include "job.h"
#include "reference.h"
#include "tools.h"

static const char farm_usage[] =
    "usage: limn farm slurm --job FILE --shards N [--partition P] [--time T] [--mem M]\n"
    "                       [--cpus-per-task C] [--gres G] [--account A] [--sbatch FLAG]...\n"
    "                       [--set NAME=VALUE]... [--references [--refs DIR] [--povray PROGRAM]\n"
    "                       [--renderer pov|cycles] [Cycles flags] [export-pov flags]]\n"
    "                       [--dir DIR] [--name NAME] [--submit]\n"
    "\n"
    "Writes DIR/NAME.sbatch, a Slurm job array of N tasks: task I renders shard I/N\n"
    "of the capture job (limn capture --job FILE --shard auto/N, after limn reference\n"
    "--shard auto/N with --references), writing its own manifest; a sequence's\n"
    "frames go to the tasks in contiguous runs. Run with bash,\n"
    "the script submits the array and a merge task that waits for all of it\n"
    "(limn manifest merge); `bash DIR/NAME.sbatch --array=1,4` reruns shards 1\n"
    "and 4 and merges again. Logs go to DIR/logs. The current folder, this limn\n"
    "and the engine's root must be reachable from the nodes (a shared file system).\n"
    "\n"
    "options:\n"
    "  --job FILE           the capture job\n"
    "  --shards N           tasks in the array (Slurm's MaxArraySize bounds it)\n"
    "  --partition P, --time T, --mem M, --cpus-per-task C, --gres G, --account A\n"
    "                       the sbatch options of that name, for every task\n"
    "  --sbatch FLAG        any other sbatch option, as in \"--qos=high\" (repeatable)\n"
    "  --set NAME=VALUE     added to the job's options (repeatable)\n"
    "  --references         render the job's references too (POV-Ray's, or Cycles' with\n"
    "                       --renderer cycles or the job's renderer = \"cycles\"; the\n"
    "                       flags of limn reference pass through)\n"
    "  --refs DIR           where they go (default out/reference)\n"
    "  --povray PROGRAM     the POV-Ray program on the nodes (default povray)\n"
    "  --radiosity, --count, --error-bound, --pretrace-start, --pretrace-end,\n"
    "  --recursion-limit, --brightness, --shadows, --approximate: as export-pov\n"
    "                       (the references')\n"
    "  --dir DIR            the script and its logs (default farm)\n"
    "  --name NAME          the Slurm job name (default limn-<job file's stem>)\n"
    "  --submit             run the script: submit the array and the merge\n"
    "\n"
    "exit codes: 0 written (and submitted), 1 failed, 2 bad usage or a bad job.\n";

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("farm slurm", fmt, arg); }

typedef struct farm_args {
  const char *job, *dir, *name, *refs, *povray;
  const char *sbatch[64]; /* "--partition=P" ... */
  int sbatch_count;
  const char *sets[64];
  int set_count;
  const char *pov_names[64], *pov_values[64]; /* export-pov and renderer flags as given, for reference and merge */
  int pov_count;
  int shards;
  bool references, submit;
} farm_args;

/* s in single quotes for the shell. */
static void quote(lm_buf *b, const char *s) {
  lm_buf_append(b, "'", 1);
  for (; *s; s++) {
    if (*s == '\'') lm_buf_append(b, "'\\''", 4);
    else lm_buf_append(b, s, 1);
  }
  lm_buf_append(b, "'", 1);
}

static void script_text(const farm_args *a, const char *cwd, const char *self, const char *script, int views,
                        lm_buf *b) {
  lm_buf_printf(b, "#!/bin/bash\n"
                "# Written by limn farm slurm for %s: %d views in %d shards.\n"
                "#   bash THIS [sbatch flags]  submits the array and a merge that waits for it;\n"
                "#                             bash THIS --array=1,4 reruns shards 1 and 4 only\n"
                "#   sbatch THIS               submits the array alone\n"
                "# A task renders what its shard misses (images that exist are skipped).\n",
                a->job, views, a->shards);
  lm_buf_printf(b, "#SBATCH --job-name=%s\n#SBATCH --array=0-%d\n#SBATCH --chdir=%s\n#SBATCH --output=%s/logs/%s-%%A_%%a.log\n",
                a->name, a->shards - 1, cwd, a->dir, a->name);
  for (int i = 0; i < a->sbatch_count; i++) lm_buf_printf(b, "#SBATCH %s\n", a->sbatch[i]);
  lm_buf_append(b, "set -u\nlimn=", -1);
  quote(b, self);
  lm_buf_append(b, "\nexport LIMN_ROOT=", -1);
  quote(b, lm_root_dir());
  lm_buf_append(b, "\ncd ", -1);
  quote(b, cwd);
  lm_buf_append(b, " || exit 1\n", -1);

  lm_buf sets = {0}, pov = {0}, job = {0};
  for (int i = 0; i < a->set_count; i++) lm_buf_append(&sets, " --set ", -1), quote(&sets, a->sets[i]);
  for (int i = 0; i < a->pov_count; i++) {
    lm_buf_printf(&pov, " --%s", a->pov_names[i]);
    if (a->pov_values[i]) lm_buf_append(&pov, " ", 1), quote(&pov, a->pov_values[i]);
  }
  quote(&job, a->job);
  lm_buf_append(b, "if [ -z \"${SLURM_ARRAY_TASK_ID:-}\" ]; then\n  array=$(sbatch --parsable \"$@\" ", -1);
  quote(b, script);
  lm_buf_printf(b, ") || exit 1\n  array=${array%%%%;*}\n"
                "  merge=$(sbatch --parsable --dependency=afterany:\"$array\" --array=0 --job-name=%s-merge \\\n"
                "    --output=", a->name);
  lm_buf merge_log = {0};
  lm_buf_printf(&merge_log, "%s/logs/%s-merge-%%j.log", a->dir, a->name);
  quote(b, merge_log.data);
  lm_buf_free(&merge_log);
  lm_buf_append(b, " --export=ALL,LIMN_FARM_STEP=merge ", -1);
  quote(b, script);
  lm_buf_append(b, ") || exit 1\n  echo \"submitted the shards as job $array, the merge as job ${merge%%;*}\"\n"
                "  exit 0\nfi\n", -1);
  lm_buf_printf(b, "if [ \"${LIMN_FARM_STEP:-}\" = merge ]; then\n"
                "  exec \"$limn\" manifest merge --job %s --shards %d%s", job.data, a->shards, sets.data ? sets.data : "");
  if (a->references) lm_buf_append(b, " --refs ", -1), quote(b, a->refs), lm_buf_append(b, pov.data ? pov.data : "", -1);
  lm_buf_append(b, "\nfi\nrc=0\n", -1);
  if (a->references) {
    lm_buf_printf(b, "\"$limn\" reference --job %s --shard auto/%d --refs ", job.data, a->shards);
    quote(b, a->refs);
    if (a->povray) lm_buf_append(b, " --povray ", -1), quote(b, a->povray);
    /* A task cancelled while it renders references (SIGTERM: the reference step dies of it, 128 + 15) stops
     * there: Slurm may signal the shell after it has started the images, which then were written. */
    lm_buf_printf(b, "%s || { s=$?; [ \"$s\" -gt 128 ] && exit \"$s\"; rc=1; }\n", pov.data ? pov.data : "");
  }
  lm_buf_printf(b, "\"$limn\" capture --job %s --shard auto/%d%s || rc=1\n", job.data, a->shards,
                sets.data ? sets.data : "");
  lm_buf_append(b, "exit $rc\n", -1);
  lm_buf_free(&sets);
  lm_buf_free(&pov);
  lm_buf_free(&job);
}

/* Values that go on #SBATCH lines: one line, no control characters. */
static bool one_line(const char *s) {
  for (; *s; s++)
    if ((unsigned char)*s < 0x20) return false;
  return true;
}

/* n digits (1..9) from *s on, advancing it; false without one. */
static bool digits(const char **s) {
  size_t n = strspn(*s, "0123456789");
  *s += n;
  return n > 0 && n < 10;
}

/* sbatch's --time: minutes, minutes:seconds, hours:minutes:seconds, days-hours, days-hours:minutes,
 * days-hours:minutes:seconds, or unlimited / infinite. Checked here, where the job is, rather than
 * refused by sbatch on the cluster. */
static bool slurm_time(const char *t) {
  if (!strcasecmp(t, "unlimited") || !strcasecmp(t, "infinite")) return true;
  const char *s = t;
  if (!digits(&s)) return false;
  bool days = *s == '-';
  if (days && (s++, !digits(&s))) return false;
  for (int fields = 1; *s == ':' && fields < 3; fields++) /* the hours or minutes, then up to two more */
    if (s++, !digits(&s)) return false;
  return !*s;
}

/* sbatch's --mem: a whole number of megabytes, or with a unit K, M, G or T (sbatch reads the unit's
 * letter alone: 8GB is 8G). */
static bool slurm_mem(const char *m) {
  const char *s = m;
  return digits(&s) && (!*s || (strchr("KMGTkmgt", *s) && (!s[1] || ((s[1] | 32) == 'b' && !s[2]))));
}

static int farm(const farm_args *a) {
  job *j = lm_alloc(sizeof *j);
  lm_error err;
  job_view *views = NULL, *places = NULL;
  int n = 0, place_count = 0, rc = 0;
  lm_pipeline *pipeline = NULL;
  /* The job is checked here, before a thousand tasks find it bad. */
  if (!job_read(j, a->job, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 2;
  }
  if (!rc && !(pipeline = job_pipeline(j, a->sets, a->set_count, true))) rc = 2;
  lm_pipeline_destroy(pipeline);
  if (!rc && (!job_views(j, true, &views, &n, &err) ||
              (a->references && !job_views(j, false, &places, &place_count, &err)))) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 2;
  }
  char cwd[PATH_MAX], self[PATH_MAX], script[PATH_MAX + 300];
  ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (!rc && (!getcwd(cwd, sizeof cwd) || len <= 0)) {
    lm_log(LM_LOG_ERROR, "cannot find the current folder or this program's path");
    rc = 1;
  }
  if (!rc) {
    self[len] = '\0';
    snprintf(script, sizeof script, "%s%s%s/%s.sbatch", a->dir[0] == '/' ? "" : cwd, a->dir[0] == '/' ? "" : "/",
             a->dir, a->name);
    char logs[PATH_MAX + 300];
    snprintf(logs, sizeof logs, "%s/logs/x", a->dir);
    lm_buf text = {0};
    script_text(a, cwd, self, script, n, &text);
    if (!job_make_parent(logs, &err) || !limn_write_whole(script, text.data, (size_t)text.len, &err)) {
      lm_log(LM_LOG_ERROR, "%s", err.msg);
      rc = 1;
    }
    lm_buf_free(&text);
  }
  if (!rc) {
    int per = (n + a->shards - 1) / a->shards;
    printf("%s: %d views", j->path, n);
    if (a->references) printf(" and %d references", place_count);
    printf(" in %d shards (at most %d views a task); wrote %s/%s.sbatch\n", a->shards, per, a->dir, a->name);
    if (n < a->shards) lm_warn("%d shards for %d views: %d tasks render nothing", a->shards, n, a->shards - n);
    if (!a->submit) printf("submit it with: bash %s/%s.sbatch\n", a->dir, a->name);
    fflush(stdout);
  }
  if (!rc && a->submit) {
    pid_t pid = fork();
    if (pid == 0) {
      execlp("bash", "bash", script, (char *)NULL);
      perror("limn farm slurm: cannot run bash");
      _exit(127);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status)) {
      lm_log(LM_LOG_ERROR, "submitting %s failed (is sbatch on the PATH?)", script);
      rc = 1;
    }
  }
  free(views);
  free(places);
  job_free_scenes(j);
  free(j);
  return rc;
}

int limn_farm(int argc, char **argv) {
  int sub = limn_subcommand(argc, argv, "slurm", farm_usage,
                            "limn farm: the scheduler is slurm (limn farm slurm --job FILE --shards N)");
  if (sub >= 0) return sub;
  argc--, argv++;
  farm_args a = {.dir = "farm", .refs = "out/reference"};
  char sbatch_flags[6][1100] = {{0}}; /* --partition=P ... (at most one of each) */
  static const char *const named[6] = {"partition", "time", "mem", "cpus-per-task", "gres", "account"};
  reference_args ref; /* the flags checked here, passed on as given */
  reference_defaults(&ref);
  struct option opts[18 + LIMN_POV_OPTION_COUNT - 1 + REFERENCE_OPTION_COUNT] = {
      {"job", required_argument, 0, 'J'},       {"shards", required_argument, 0, 'K'},
      {"partition", required_argument, 0, '0'}, {"time", required_argument, 0, '1'},
      {"mem", required_argument, 0, '2'},       {"cpus-per-task", required_argument, 0, '3'},
      {"gres", required_argument, 0, '4'},      {"account", required_argument, 0, '5'},
      {"sbatch", required_argument, 0, 'B'},    {"set", required_argument, 0, 'D'},
      {"references", no_argument, 0, 'X'},      {"refs", required_argument, 0, 'R'},
      {"dir", required_argument, 0, 'd'},       {"name", required_argument, 0, 'N'},
      {"submit", no_argument, 0, 's'},          {"help", no_argument, 0, 'h'},
      {"povray", required_argument, 0, 'P'}};
  memcpy(opts + 17, limn_pov_options, sizeof(struct option) * (LIMN_POV_OPTION_COUNT - 1));
  memcpy(opts + 17 + LIMN_POV_OPTION_COUNT - 1, reference_options, sizeof(struct option) * REFERENCE_OPTION_COUNT);
  opterr = 0;
  optind = 1;
  int c, rc = -1;
  char name[256];
  while (rc < 0 && (c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    int taken = reference_flag("farm slurm", c, optarg, &ref);
    if (taken == 2) rc = 2;
    if (taken == 0 && a.pov_count == 64) rc = usage_error("%s", "at most 64 export-pov and renderer flags");
    if (taken == 0 && rc < 0) { /* kept as given, for reference and merge */
      for (const struct option *o = limn_pov_options; o->name; o++)
        if (o->val == c) a.pov_names[a.pov_count] = o->name;
      for (const struct option *o = reference_options; o->name; o++)
        if (o->val == c) a.pov_names[a.pov_count] = o->name;
      a.pov_values[a.pov_count++] = optarg;
      continue;
    }
    if (taken == 0) continue;
    if (c >= '0' && c <= '5' && !one_line(optarg)) rc = usage_error("a value on one line, not '%s'", optarg);
    switch (rc < 0 ? c : 0) {
    case 0: break;
    case 'J': a.job = optarg; break;
    case 'K':
      if (!limn_parse_int(optarg, 1, 1 << 20, &a.shards)) rc = usage_error("--shards wants N >= 1, not '%s'", optarg);
      break;
    case '1':
      if (!slurm_time(optarg))
        rc = usage_error("--time wants sbatch's MINUTES, MINUTES:SECONDS, HOURS:MINUTES:SECONDS or "
                         "DAYS-HOURS[:MINUTES[:SECONDS]], not '%s'", optarg);
      else snprintf(sbatch_flags[1], sizeof sbatch_flags[0], "--time=%s", optarg);
      break;
    case '2':
      if (!slurm_mem(optarg))
        rc = usage_error("--mem wants sbatch's megabytes, or a number with K, M, G or T (8G), not '%s'", optarg);
      else snprintf(sbatch_flags[2], sizeof sbatch_flags[0], "--mem=%s", optarg);
      break;
    case '3':
      if (!limn_parse_int(optarg, 1, 1 << 20, &(int){0}))
        rc = usage_error("--cpus-per-task wants N >= 1, not '%s'", optarg);
      else snprintf(sbatch_flags[3], sizeof sbatch_flags[0], "--cpus-per-task=%s", optarg);
      break;
    case '0': case '4': case '5':
      snprintf(sbatch_flags[c - '0'], sizeof sbatch_flags[0], "--%s=%s", named[c - '0'], optarg);
      break;
    case 'B':
      if (!one_line(optarg) || optarg[0] != '-') rc = usage_error("--sbatch wants one sbatch option (--qos=high), not '%s'", optarg);
      else if (a.sbatch_count == 58) rc = usage_error("%s", "at most 58 --sbatch flags");
      else a.sbatch[a.sbatch_count++] = optarg;
      break;
    case 'D':
      if (!strchr(optarg, '=') || optarg[0] == '=') rc = usage_error("--set wants NAME=VALUE, not '%s'", optarg);
      else if (a.set_count == 64) rc = usage_error("%s", "at most 64 --set flags");
      else a.sets[a.set_count++] = optarg;
      break;
    case 'X': a.references = true; break;
    case 'R': a.refs = optarg; break;
    case 'P': a.povray = optarg; break;
    case 'd': a.dir = optarg; break;
    case 'N': a.name = optarg; break;
    case 's': a.submit = true; break;
    case 'h': fputs(farm_usage, stdout); rc = 0; break;
    case ':': rc = usage_error("%s needs a value", argv[optind - 1]); break;
    default: rc = usage_error("unknown flag '%s'", argv[optind - 1]); break;
    }
  }
  if (rc >= 0) return rc;
  const char *bad = ref.pov.radiosity ? lm_pov_radiosity_check(&ref.pov.rad) : NULL;
  if (bad) return usage_error("radiosity setting out of range: %s", bad);
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (!a.job || !a.shards) return usage_error("%s", "--job FILE and --shards N are required");
  if (!one_line(a.dir) || strchr(a.dir, ' ')) return usage_error("--dir wants a folder name without spaces, not '%s'", a.dir);
  for (int i = 0; i < 6; i++)
    if (sbatch_flags[i][0]) a.sbatch[a.sbatch_count++] = sbatch_flags[i];
  if (!a.name) { /* limn-<stem of the job file> */
    const char *base = strrchr(a.job, '/');
    snprintf(name, sizeof name, "limn-%s", base ? base + 1 : a.job);
    char *dot = strrchr(name, '.');
    if (dot) *dot = '\0';
    a.name = name;
  }
  for (const char *p = a.name; *p; p++)
    if (!(*p == '-' || *p == '_' || *p == '.' || (*p >= '0' && *p <= '9') || ((*p | 32) >= 'a' && (*p | 32) <= 'z')))
      return usage_error("--name wants letters, digits, '-', '_' and '.', not '%s'", a.name);
  return farm(&a);
}
