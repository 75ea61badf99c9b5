/* Flag values shared by the limn subcommands. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tools.h"
#include "scene/scene.h"

bool limn_parse_int(const char *s, int lo, int hi, int *out) {
  char *end;
  long v = strtol(s, &end, 10);
  if (end == s || *end || v < lo || v > hi) return false;
  *out = (int)v;
  return true;
}

int limn_subcommand(int argc, char **argv, const char *sub, const char *usage, const char *why) {
  if (argc >= 2 && !strcmp(argv[1], sub)) return -1;
  if (argc >= 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
    fputs(usage, stdout);
    return 0;
  }
  fprintf(stderr, "%s\n\n%s", why, usage);
  return 2;
}

bool limn_parse_double(const char *s, double *out) {
  char *end;
  double v = strtod(s, &end);
  if (end == s || *end || !isfinite(v)) return false;
  *out = v;
  return true;
}

const char *limn_time_text(double seconds, int places, char out[LIMN_TIME_TEXT]) {
  if (fabs(seconds) < 1e6) snprintf(out, LIMN_TIME_TEXT, "%.*f", places, seconds);
  else snprintf(out, LIMN_TIME_TEXT, "%.*g", places + 1, seconds);
  return out;
}

bool limn_parse_time(const char *s, double *start, double *stop) {
  const char *colon = strchr(s, ':');
  char first[64];
  snprintf(first, sizeof first, "%.*s", colon ? (int)(colon - s) : 63, s);
  return limn_parse_double(first, start) && limn_parse_double(colon ? colon + 1 : first, stop);
}

bool limn_parse_size(const char *s, int *w, int *h) {
  char buf[64];
  snprintf(buf, sizeof buf, "%s", s);
  char *x = strchr(buf, 'x');
  if (!x) return false;
  *x = '\0';
  return limn_parse_int(buf, 1, 65536, w) && limn_parse_int(x + 1, 1, 65536, h);
}

bool limn_parse_camera(const char *s, int *out) {
  if (!strcmp(s, "auto")) {
    *out = LIMN_CAMERA_AUTO;
    return true;
  }
  return limn_parse_int(s, 0, 1 << 20, out);
}

int limn_camera_resolve(lm_scene *s, int camera, int width, int height) {
  if (camera != LIMN_CAMERA_AUTO) return camera;
  return lm_scene_add_framing_camera(s, "auto", (float)width / (float)height);
}

bool limn_parse_on_off(const char *s, bool *out) {
  if (!strcmp(s, "on")) *out = true;
  else if (!strcmp(s, "off")) *out = false;
  else return false;
  return true;
}

static bool env_index(const char *name, int *out, bool *set, char *msg, size_t cap) {
  const char *v = getenv(name);
  *set = v != NULL;
  if (v && !limn_parse_int(v, 0, 1 << 24, out)) {
    snprintf(msg, cap, "--shard auto: %s='%s' is not a whole number", name, v);
    return false;
  }
  return true;
}

bool limn_parse_shard(const char *s, int *shard, int *shards, char *msg, size_t cap) {
  char buf[64];
  snprintf(buf, sizeof buf, "%s", s);
  char *count = strchr(buf, '/');
  if (count) *count++ = '\0';
  int n = 0;
  msg[0] = '\0';
  if (strcmp(buf, "auto")) {
    if (!count || !limn_parse_int(count, 1, 1 << 20, &n) || !limn_parse_int(buf, 0, n - 1, shard)) {
      snprintf(msg, cap, "--shard wants I/N with 0 <= I < N, auto or auto/N, not '%s'", s);
      return false;
    }
    *shards = n;
    return true;
  }
  if (count && !limn_parse_int(count, 1, 1 << 20, &n)) {
    snprintf(msg, cap, "--shard auto/N wants a count N >= 1, not '%s'", count);
    return false;
  }
  int id = 0, min = 0, max = 0, total = 0, k8s = 0;
  bool has_id, has_min, has_max, has_total, has_k8s;
  if (!env_index("SLURM_ARRAY_TASK_ID", &id, &has_id, msg, cap) ||
      !env_index("SLURM_ARRAY_TASK_MIN", &min, &has_min, msg, cap) ||
      !env_index("SLURM_ARRAY_TASK_MAX", &max, &has_max, msg, cap) ||
      !env_index("SLURM_ARRAY_TASK_COUNT", &total, &has_total, msg, cap) ||
      !env_index("JOB_COMPLETION_INDEX", &k8s, &has_k8s, msg, cap))
    return false;
  if (has_id && n) {
    *shard = id, *shards = n;
    snprintf(msg, cap, "SLURM_ARRAY_TASK_ID=%d, count %d given", id, n);
  } else if (has_id) {
    if (!has_min || (!has_max && !has_total)) {
      snprintf(msg, cap, "--shard auto: SLURM_ARRAY_TASK_ID is set without SLURM_ARRAY_TASK_MIN and "
               "SLURM_ARRAY_TASK_COUNT or _MAX: give the count, --shard auto/N");
      return false;
    }
    int span = has_max ? max - min + 1 : total;
    if (has_total && has_max && total != span) {
      snprintf(msg, cap, "--shard auto: the array's indices are not a range %d-%d (SLURM_ARRAY_TASK_COUNT=%d): "
               "give the count, --shard auto/N", min, max, total);
      return false;
    }
    *shard = id - min, *shards = span;
    if (has_total) snprintf(msg, cap, "SLURM_ARRAY_TASK_ID=%d less SLURM_ARRAY_TASK_MIN=%d, of SLURM_ARRAY_TASK_COUNT=%d",
                            id, min, total);
    else snprintf(msg, cap, "SLURM_ARRAY_TASK_ID=%d less SLURM_ARRAY_TASK_MIN=%d, of MAX - MIN + 1 = %d", id, min, span);
  } else if (has_k8s) {
    if (!n) {
      snprintf(msg, cap, "--shard auto: JOB_COMPLETION_INDEX=%d (a Kubernetes Indexed Job) gives no count: "
               "--shard auto/N with N the job's completions", k8s);
      return false;
    }
    *shard = k8s, *shards = n;
    snprintf(msg, cap, "JOB_COMPLETION_INDEX=%d, count %d given", k8s, n);
  } else {
    snprintf(msg, cap, "--shard auto: neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor JOB_COMPLETION_INDEX "
             "(a Kubernetes Indexed Job) is set: give --shard I/N");
    return false;
  }
  if (*shard < 0 || *shard >= *shards) {
    char from[256];
    snprintf(from, sizeof from, "%s", msg);
    snprintf(msg, cap, "--shard %s: shard %d is not in 0 .. %d (%s)", s, *shard, *shards - 1, from);
    return false;
  }
  return true;
}

int limn_common_flag(const char *cmd, int c, char **argv, limn_common_args *a) {
  const char *arg = optarg;
  switch (c) {
  case 's': a->scene = arg; return 0;
  case 'p': a->script = arg; return 0;
  case 't': a->tech = arg; return 0;
  case 'D':
    if (!strchr(arg, '=') || arg[0] == '=') return limn_usage_error(cmd, "--set wants NAME=VALUE, not '%s'", arg);
    if (a->set_count == LIMN_MAX_SETS) return limn_usage_error(cmd, "%s", "at most 64 --set flags");
    a->sets[a->set_count++] = arg;
    return 0;
  case 'z':
    if (!limn_parse_size(arg, &a->width, &a->height))
      return limn_usage_error(cmd, "--size wants WxH with both in 1..65536, not '%s'", arg);
    return 0;
  case 'c':
    if (a->camera_auto ? !limn_parse_camera(arg, &a->camera) : !limn_parse_int(arg, 0, 1 << 20, &a->camera))
      return limn_usage_error(cmd, a->camera_auto ? "--camera wants an index or auto, not '%s'"
                                                  : "--camera wants an index, not '%s'", arg);
    return 0;
  case ':': return limn_usage_error(cmd, "%s needs a value", argv[optind - 1]);
  default: return limn_usage_error(cmd, "unknown flag '%s'", argv[optind - 1]);
  }
}

void limn_json_append(lm_buf *b, const char *s) {
  lm_buf_append(b, "\"", 1);
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\') lm_buf_printf(b, "\\%c", c);
    else if (c < 0x20) lm_buf_printf(b, "\\u%04x", c);
    else lm_buf_append(b, s, 1);
  }
  lm_buf_append(b, "\"", 1);
}

void limn_json_string(const char *s) {
  lm_buf b = {0};
  limn_json_append(&b, s);
  fputs(b.data, stdout);
  lm_buf_free(&b);
}

int limn_usage_error(const char *cmd, const char *fmt, const char *arg) {
  fprintf(stderr, "limn %s: ", cmd);
  fprintf(stderr, fmt, arg);
  fprintf(stderr, "\n(see limn %s --help)\n", cmd);
  return 2;
}
