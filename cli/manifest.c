/* limn manifest merge: joins the manifests of a sharded capture job (one a
 * shard, cli/job.c) into the job's manifest, after checking that every
 * view was rendered exactly once, its image is there, and every shard ran
 * with the same job, script and shader hashes; optionally that every view's
 * POV-Ray reference is there. Nothing is written unless all of it holds. */
#define _GNU_SOURCE
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reference.h"
#include "tools.h"

static const char manifest_usage[] =
    "usage: limn manifest merge --job FILE --shards N [--set NAME=VALUE]... [--output FILE]\n"
    "                           [--refs DIR [--renderer pov|cycles] [Cycles flags] [export-pov flags]]\n"
    "                           [--quiet]\n"
    "\n"
    "Joins the shard manifests of `limn capture --job FILE --shard I/N` (beside the\n"
    "job's manifest: <stem>.shard-I-of-N.json) into the job's manifest. It checks\n"
    "that every view of the job was rendered exactly once and its image exists,\n"
    "and that every shard ran the same job (with the same --set flags), scripts\n"
    "and shaders. What is missing or duplicated is named with the shard that\n"
    "renders it; then nothing is written and the exit code is 1. Rerun those\n"
    "shards: they render only what is missing.\n"
    "\n"
    "options:\n"
    "  --job FILE           the capture job\n"
    "  --shards N           the number of shards it ran in\n"
    "  --set NAME=VALUE     the --set flags the shards were given (repeatable)\n"
    "  --output FILE        the merged manifest (default: the job's manifest)\n"
    "  --refs DIR           check too that every view's reference (limn reference)\n"
    "                       is in DIR, made with the renderer and flags given\n"
    REFERENCE_OPTIONS_HELP
    "  --radiosity, --count, --error-bound, --pretrace-start, --pretrace-end,\n"
    "  --recursion-limit, --brightness, --shadows, --approximate: as export-pov\n"
    "                       (the references', with --refs)\n"
    "  --quiet              errors only\n"
    "\n"
    "exit codes: 0 merged, 1 something missing, duplicated or from another run, 2 bad usage.\n";

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("manifest merge", fmt, arg); }

/* At most this many lines of one kind of problem; then a count. */
#define SHOWN 20

typedef struct merge_args {
  const char *job, *output, *sets[64];
  int set_count, shards;
  bool refs, quiet;
  reference_args ref;
} merge_args;

static void describe(const job *j, const job_view *v, int index, bool technique, char *out, size_t cap) {
  const job_scene *s = &j->scenes[v->scene];
  snprintf(out, cap, "view %d (%s, camera '%s'%s%s, %dx%d)", index, s->name, s->scene->cameras[v->camera].name,
           technique ? ", " : "", technique ? j->techniques[v->technique] : "", j->sizes[v->size][0],
           j->sizes[v->size][1]);
}

/* The first shard's header for the whole job: "shards" for its "shard", the job's "views", no "run". */
static char *merged_header(const char *header, int shards, int views) {
  lm_buf b = {0};
  for (const char *line = header; *line;) {
    const char *nl = strchr(line, '\n');
    size_t len = nl ? (size_t)(nl - line + 1) : strlen(line);
    if (!strncmp(line, "  \"shard\": ", 11)) lm_buf_printf(&b, "  \"shards\": %d,\n", shards);
    else if (!strncmp(line, "  \"views\": ", 11)) lm_buf_printf(&b, "  \"views\": %d,\n", views);
    else if (strncmp(line, "  \"run\": ", 9)) lm_buf_append(&b, line, (long)len);
    line += len;
  }
  return b.data;
}

static int merge(const merge_args *a, job *j) {
  lm_error err;
  job_view *views = NULL, *places = NULL;
  int n = 0, place_count = 0, rc = 0;
  lm_pipeline *pipeline = job_pipeline(j, a->sets, a->set_count, false); /* the default technique */
  if (!pipeline) return 2;
  lm_pipeline_destroy(pipeline);
  if (!job_views(j, true, &views, &n, &err) || (a->refs && !job_views(j, false, &places, &place_count, &err))) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    free(views);
    return 2;
  }
  char want_job[32], field[128], first_path[1100] = "", what[256];
  snprintf(want_job, sizeof want_job, "%016llx", (unsigned long long)job_hash_with(j, a->sets, a->set_count));
  job_manifest *m = lm_alloc(sizeof *m * (size_t)a->shards);
  char (*paths)[1100] = lm_alloc(sizeof *paths * (size_t)a->shards);
  int first = -1, bad_shards = 0;
  bool *rerun = lm_alloc(sizeof *rerun * (size_t)a->shards);
  for (int k = 0; k < a->shards; k++) {
    rerun[k] = false;
    m[k] = (job_manifest){.entries = calloc((size_t)n + 1, sizeof(char *))};
    job_manifest_path(j, k, a->shards, paths[k], sizeof paths[k]);
    if (!job_manifest_load(paths[k], views, n, &m[k]) || !m[k].header) {
      lm_log(LM_LOG_ERROR, "shard %d/%d: no manifest %s (the shard has not run, or stopped before its first "
             "image)", k, a->shards, paths[k]);
      rerun[k] = true, bad_shards++;
      continue;
    }
    if (!job_manifest_field(&m[k], "job_hash", field, sizeof field) || strcmp(field, want_job)) {
      lm_log(LM_LOG_ERROR, "shard %d/%d: %s has job_hash %s, the job %s%s hashes to %s: the job changed since "
             "(rerun the shard with --force)", k, a->shards, paths[k], field, j->path,
             a->set_count ? " with these --set flags" : "", want_job);
      rerun[k] = true, bad_shards++;
      continue;
    }
    if (first < 0) {
      first = k;
      snprintf(first_path, sizeof first_path, "%s", paths[k]);
      continue;
    }
    static const char *const same[] = {"script_hash", "shader_hash"};
    for (int f = 0; f < 2; f++) {
      char mine[128] = "", theirs[128] = "";
      job_manifest_field(&m[k], same[f], mine, sizeof mine);
      job_manifest_field(&m[first], same[f], theirs, sizeof theirs);
      if (strcmp(mine, theirs)) {
        lm_log(LM_LOG_ERROR, "shard %d/%d: %s has %s %s, %s has %s: the shards ran different %s (rerun one "
               "with --force)", k, a->shards, paths[k], same[f], mine, first_path, theirs,
               f ? "shaders" : "scripts");
        if (!rerun[k]) bad_shards++;
        rerun[k] = true;
      }
    }
    char mine[256] = "", theirs[256] = "";
    job_manifest_field(&m[k], "renderer", mine, sizeof mine);
    job_manifest_field(&m[first], "renderer", theirs, sizeof theirs);
    if (strcmp(mine, theirs))
      lm_warn("shard %d/%d rendered on '%s', shard %d/%d on '%s': times and images may differ", k, a->shards, mine,
              first, a->shards, theirs);
  }
  if (bad_shards) rc = 1;

  /* Every view once, its image on disk. */
  int missing = 0, duplicated = 0;
  char **entries = lm_alloc(sizeof *entries * (size_t)(n + 1));
  for (int i = 0; i < n; i++) {
    int count = 0;
    lm_buf where = {0};
    entries[i] = NULL;
    for (int k = 0; k < a->shards; k++)
      if (m[k].entries[i]) {
        lm_buf_printf(&where, "%s%s", count ? " and " : "", paths[k]);
        entries[i] = m[k].entries[i];
        count++;
      }
    describe(j, &views[i], i, true, what, sizeof what);
    int shard = job_shard_of(j, i, n, a->shards);
    if (count > 1) {
      if (++duplicated <= SHOWN) lm_log(LM_LOG_ERROR, "%s %s: rendered %d times, in %s", what, views[i].output, count,
                                        where.data);
    } else if (count == 0 || !lm_file_exists(views[i].output)) {
      if (++missing <= SHOWN)
        lm_log(LM_LOG_ERROR, "%s %s: missing%s (shard %d/%d)", what, views[i].output,
               count ? " (in the manifest, not on disk)" : "", shard, a->shards);
      rerun[shard] = true;
    }
    lm_buf_free(&where);
  }

  /* Every view's reference, exported as `limn reference` would. */
  int refs_missing = 0;
  for (int p = 0; p < place_count; p++) {
    lm_buf sdl = {0};
    char path[1024];
    describe(j, &places[p], p, false, what, sizeof what);
    bool ok = reference_export(&a->ref, j, &places[p], &sdl, path, sizeof path, &err);
    lm_buf_free(&sdl);
    if (!ok) {
      lm_log(LM_LOG_ERROR, "reference of %s: %s", what, err.msg);
      refs_missing++;
    } else if (!lm_file_exists(path)) {
      if (++refs_missing <= SHOWN)
        lm_log(LM_LOG_ERROR, "reference of %s %s: missing (shard %d/%d)", what, path,
               job_shard_of(j, p, place_count, a->shards), a->shards);
      rerun[job_shard_of(j, p, place_count, a->shards)] = true;
    }
  }

  if (missing || duplicated || refs_missing) rc = 1;
  if (rc) {
    lm_buf list = {0};
    for (int k = 0; k < a->shards; k++)
      if (rerun[k]) lm_buf_printf(&list, "%s%d", list.len ? "," : "", k);
    lm_log(LM_LOG_ERROR, "%s: %d of %d views missing, %d duplicated, %d of %d references missing: nothing written. "
           "Rerun shards %s (a rerun renders only what is missing; --force where the job, script or shaders "
           "changed), then merge again", j->path, missing, n, duplicated, refs_missing, place_count,
           list.data ? list.data : "-");
    lm_buf_free(&list);
  } else {
    job_manifest out = {.header = merged_header(m[first].header, a->shards, n), .entries = entries};
    const char *output = a->output ? a->output : j->manifest;
    if (!job_make_parent(output, &err) || !job_manifest_write(output, &out, n, &err)) {
      lm_log(LM_LOG_ERROR, "%s", err.msg);
      rc = 1;
    } else if (!a->quiet) {
      printf("%s: %d views from %d shards, each rendered once; %d references there; %s\n", j->path, n, a->shards,
             place_count, output);
    }
    free(out.header);
  }
  for (int k = 0; k < a->shards; k++) {
    for (int i = 0; i < n; i++) free(m[k].entries[i]);
    free(m[k].entries);
    free(m[k].header);
  }
  free(entries);
  free(m);
  free(paths);
  free(rerun);
  free(views);
  free(places);
  return rc;
}

int limn_manifest(int argc, char **argv) {
  int sub = limn_subcommand(argc, argv, "merge", manifest_usage, "limn manifest: the subcommand is merge");
  if (sub >= 0) return sub;
  argc--, argv++;
  merge_args a = {0};
  reference_defaults(&a.ref);
  struct option opts[7 + LIMN_POV_OPTION_COUNT - 1 + REFERENCE_OPTION_COUNT] = {
      {"job", required_argument, 0, 'J'},    {"shards", required_argument, 0, 'K'},
      {"set", required_argument, 0, 'D'},    {"output", required_argument, 0, 'o'},
      {"refs", required_argument, 0, 'R'},   {"quiet", no_argument, 0, 'q'},
      {"help", no_argument, 0, 'h'}};
  memcpy(opts + 7, limn_pov_options, sizeof(struct option) * (LIMN_POV_OPTION_COUNT - 1));
  memcpy(opts + 7 + LIMN_POV_OPTION_COUNT - 1, reference_options, sizeof(struct option) * REFERENCE_OPTION_COUNT);
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    int pov = reference_flag("manifest merge", c, optarg, &a.ref);
    if (pov == 2) return 2;
    if (pov == 0) continue;
    switch (c) {
    case 'J': a.job = optarg; break;
    case 'K':
      if (!limn_parse_int(optarg, 1, 1 << 20, &a.shards)) return usage_error("--shards wants N >= 1, not '%s'", optarg);
      break;
    case 'D':
      if (!strchr(optarg, '=') || optarg[0] == '=') return usage_error("--set wants NAME=VALUE, not '%s'", optarg);
      if (a.set_count == 64) return usage_error("%s", "at most 64 --set flags");
      a.sets[a.set_count++] = optarg;
      break;
    case 'o': a.output = optarg; break;
    case 'R': a.ref.refs = optarg, a.refs = true; break;
    case 'q': a.quiet = true; break;
    case 'h': fputs(manifest_usage, stdout); return 0;
    case ':': return usage_error("%s needs a value", argv[optind - 1]);
    default: return usage_error("unknown flag '%s'", argv[optind - 1]);
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (!a.job || !a.shards) return usage_error("%s", "--job FILE and --shards N are required");
  if (a.quiet) lm_log_set_level(LM_LOG_WARN);
  job *j = lm_alloc(sizeof *j);
  lm_error err;
  int rc = 0;
  if (!job_read(j, a.job, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 2;
  }
  if (!rc && a.refs && !reference_prepare(&a.ref, j, &err)) { /* Cycles' names need Blender's version */
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    rc = 1;
  }
  if (!rc) rc = merge(&a, j);
  job_free_scenes(j);
  free(j);
  return rc;
}
