/* limn bench: the compositor's own cost per frame, and how each pass's time
 * grows with the output's pixel count (a least-squares line per pass). */
#define _GNU_SOURCE
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/render.h"
#include "scene/gltf.h"
#include "tools.h"

static const char bench_usage[] =
    "usage: limn bench [options]\n"
    "\n"
    "Renders one scene through a pipeline at several sizes and prints, per size,\n"
    "the frame's wall time, the CPU time of Lua (OnRender) plus frame-graph\n"
    "compilation against it (the compositor's overhead), and each pass's time;\n"
    "then per pass a line ms = a + b * pixels fitted over the sizes. Medians\n"
    "over --frames after --warmup frames; the pass clock is named.\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE   (default cornell)\n"
    "  --script FILE       (default scripts/pp.lua)\n"
    "  --tech NAME         technique (default: the script's first)\n"
    "  --sizes LIST        comma-separated WxH (default 64x48,128x96,256x192)\n"
    "  --frames N          timed frames per size (default 5)\n"
    "  --warmup N          untimed frames first (default 2)\n"
    "  --clock auto|gpu|cpu\n"
    "  --json              one JSON object on stdout instead of the tables\n"
    "  --help              this text\n";

enum { MAX_SIZES = 16, MAX_PASSES = 64 };

typedef struct bench_pass {
  char name[64];
  double ms[MAX_SIZES]; /* median per size; -1 when not run at that size */
} bench_pass;

typedef struct bench {
  int sizes[MAX_SIZES][2], size_count, frames, warmup;
  const char *scene, *script, *tech;
  lm_clock clock;
  bool json;
  double frame_ms[MAX_SIZES], overhead_ms[MAX_SIZES];
  bench_pass passes[MAX_PASSES];
  int pass_count;
} bench;

static int usage_error(const char *fmt, const char *arg) {
  fprintf(stderr, "limn bench: ");
  fprintf(stderr, fmt, arg);
  fprintf(stderr, "\n(see limn bench --help)\n");
  return 2;
}

static int parse_args(int argc, char **argv, bench *b) {
  *b = (bench){.frames = 5, .warmup = 2, .scene = "cornell"};
  const char *sizes = "64x48,128x96,256x192";
  static const struct option opts[] = {
      {"scene", required_argument, 0, 's'}, {"script", required_argument, 0, 'p'},
      {"tech", required_argument, 0, 't'},  {"sizes", required_argument, 0, 'z'},
      {"frames", required_argument, 0, 'n'}, {"warmup", required_argument, 0, 'w'},
      {"clock", required_argument, 0, 'k'}, {"json", no_argument, 0, 'j'},
      {"help", no_argument, 0, 'h'},        {0, 0, 0, 0}};
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    switch (c) {
    case 's': b->scene = optarg; break;
    case 'p': b->script = optarg; break;
    case 't': b->tech = optarg; break;
    case 'z': sizes = optarg; break;
    case 'n':
      if (!limn_parse_int(optarg, 1, 10000, &b->frames)) return usage_error("--frames wants 1..10000, not '%s'", optarg);
      break;
    case 'w':
      if (!limn_parse_int(optarg, 0, 10000, &b->warmup)) return usage_error("--warmup wants 0..10000, not '%s'", optarg);
      break;
    case 'k':
      if (!strcmp(optarg, "auto")) b->clock = LM_CLOCK_AUTO;
      else if (!strcmp(optarg, "gpu")) b->clock = LM_CLOCK_GPU;
      else if (!strcmp(optarg, "cpu")) b->clock = LM_CLOCK_CPU;
      else return usage_error("--clock wants auto, gpu or cpu, not '%s'", optarg);
      break;
    case 'j': b->json = true; break;
    case 'h': fputs(bench_usage, stdout); return -1;
    case ':': return usage_error("%s needs a value", argv[optind - 1]);
    default: return usage_error("unknown flag '%s'", argv[optind - 1]);
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  char list[1024];
  snprintf(list, sizeof list, "%s", sizes);
  for (char *save = NULL, *tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
    if (b->size_count == MAX_SIZES) return usage_error("%s", "at most 16 sizes");
    int *s = b->sizes[b->size_count++];
    if (!limn_parse_size(tok, &s[0], &s[1])) return usage_error("--sizes wants WxH,WxH,..., not '%s'", tok);
  }
  if (b->size_count == 0) return usage_error("%s", "--sizes is empty");
  return 0;
}

static int cmp_double(const void *x, const void *y) {
  double a = *(const double *)x, c = *(const double *)y;
  return (a > c) - (a < c);
}
static double median(double *v, int n) {
  if (n <= 0) return -1;
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static bench_pass *find_pass(bench *b, const char *name) {
  for (int i = 0; i < b->pass_count; i++)
    if (!strcmp(b->passes[i].name, name)) return &b->passes[i];
  if (b->pass_count == MAX_PASSES) return NULL;
  bench_pass *p = &b->passes[b->pass_count++];
  snprintf(p->name, sizeof p->name, "%s", name);
  for (int s = 0; s < MAX_SIZES; s++) p->ms[s] = -1;
  return p;
}

/* One size: warm-up, then medians of frame wall time, overhead and passes. */
static bool run_size(bench *b, int si, lm_scene *scene, lm_pipeline *pipe, lm_clock *used, lm_error *err) {
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = pipe,
                                                          .width = b->sizes[si][0], .height = b->sizes[si][1],
                                                          .clock = b->clock}, err);
  if (!r) return false;
  *used = lm_renderer_clock(r);
  double *wall = lm_alloc(sizeof(double) * (size_t)b->frames), *over = lm_alloc(sizeof(double) * (size_t)b->frames);
  double *pass_ms = lm_alloc(sizeof(double) * (size_t)b->frames * MAX_PASSES);
  int pass_n[MAX_PASSES] = {0};
  bool ok = true;
  for (int f = 0; f < b->warmup + b->frames && ok; f++) {
    lm_finish(); /* nothing of the last frame left in flight */
    double t0 = lm_now_ms();
    ok = lm_renderer_frame(r, err);
    lm_finish();
    double t1 = lm_now_ms();
    if (!ok || f < b->warmup) continue;
    int k = f - b->warmup;
    double rec, comp;
    lm_renderer_overhead(r, &rec, &comp);
    wall[k] = t1 - t0;
    over[k] = rec + comp;
    lm_graph *g = lm_renderer_graph(r);
    for (int i = 0; i < lm_graph_pass_count(g); i++) {
      lm_graph_pass_info p = lm_graph_pass(g, i);
      if (p.culled || p.ms < 0) continue;
      bench_pass *bp = find_pass(b, p.name);
      if (!bp) continue;
      int slot = (int)(bp - b->passes);
      if (pass_n[slot] < b->frames) pass_ms[slot * b->frames + pass_n[slot]++] = p.ms;
    }
  }
  if (ok) {
    b->frame_ms[si] = median(wall, b->frames);
    b->overhead_ms[si] = median(over, b->frames);
    for (int i = 0; i < b->pass_count; i++)
      if (pass_n[i]) b->passes[i].ms[si] = median(pass_ms + i * b->frames, pass_n[i]);
  }
  free(wall);
  free(over);
  free(pass_ms);
  lm_renderer_destroy(r);
  return ok;
}

/* Least squares ms = a + b * pixels over the sizes where the pass ran;
 * false with fewer than two distinct pixel counts. */
static bool fit(const bench *b, const bench_pass *p, double *a, double *slope, double *r2) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  for (int s = 0; s < b->size_count; s++) {
    if (p->ms[s] < 0) continue;
    double x = (double)b->sizes[s][0] * b->sizes[s][1], y = p->ms[s];
    n++, sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y;
  }
  double den = n * sxx - sx * sx;
  if (n < 2 || !(den > 0)) return false;
  *slope = (n * sxy - sx * sy) / den;
  *a = (sy - *slope * sx) / n;
  double vy = n * syy - sy * sy;
  *r2 = vy > 0 ? (*slope * (n * sxy - sx * sy)) / vy : 1.0; /* all times equal: the flat line fits */
  return true;
}

static void print_tables(const bench *b, lm_clock clock) {
  printf("frame (wall clock, glFinish before and after) and compositor overhead (CPU: Lua + graph compile);\n"
         "passes: clock %s; medians of %d frames after %d warm-up\n", lm_clock_name(clock), b->frames, b->warmup);
  printf("  %-12s %10s %12s %12s %9s\n", "size", "pixels", "frame ms", "overhead ms", "overhead");
  for (int s = 0; s < b->size_count; s++)
    printf("  %5dx%-6d %10d %12.3f %12.3f %8.1f%%\n", b->sizes[s][0], b->sizes[s][1], b->sizes[s][0] * b->sizes[s][1],
           b->frame_ms[s], b->overhead_ms[s], b->frame_ms[s] > 0 ? 100 * b->overhead_ms[s] / b->frame_ms[s] : 0);
  printf("  %-24s", "pass (ms)");
  for (int s = 0; s < b->size_count; s++) printf(" %9dx%-4d", b->sizes[s][0], b->sizes[s][1]);
  printf("  fit: a ms + b ns/pixel (r^2)\n");
  for (int i = 0; i < b->pass_count; i++) {
    const bench_pass *p = &b->passes[i];
    printf("  %-24s", p->name);
    for (int s = 0; s < b->size_count; s++) printf(" %14.3f", p->ms[s]);
    double a, sl, r2;
    if (fit(b, p, &a, &sl, &r2)) printf("  %.3f + %.3f (%.3f)\n", a, sl * 1e6, r2);
    else printf("  -\n");
  }
}

static void print_json(const bench *b, lm_clock clock) {
  printf("{\"clock\": ");
  limn_json_string(lm_clock_name(clock));
  printf(", \"frames\": %d, \"warmup\": %d, \"sizes\": [", b->frames, b->warmup);
  for (int s = 0; s < b->size_count; s++)
    printf("%s{\"width\": %d, \"height\": %d, \"frame_ms\": %.6g, \"overhead_ms\": %.6g}", s ? ", " : "",
           b->sizes[s][0], b->sizes[s][1], b->frame_ms[s], b->overhead_ms[s]);
  printf("], \"passes\": [");
  for (int i = 0; i < b->pass_count; i++) {
    const bench_pass *p = &b->passes[i];
    printf("%s{\"name\": ", i ? ", " : "");
    limn_json_string(p->name);
    printf(", \"ms\": [");
    for (int s = 0; s < b->size_count; s++) {
      if (p->ms[s] < 0) printf("%snull", s ? ", " : "");
      else printf("%s%.6g", s ? ", " : "", p->ms[s]);
    }
    double a, sl, r2;
    if (fit(b, p, &a, &sl, &r2)) printf("], \"fit\": {\"ms\": %.6g, \"ns_per_pixel\": %.6g, \"r2\": %.6g}}", a, sl * 1e6, r2);
    else printf("], \"fit\": null}");
  }
  printf("]}\n");
}

int limn_bench(int argc, char **argv) {
  static bench b; /* large: keep it off the stack */
  int rc = parse_args(argc, argv, &b);
  if (rc) return rc < 0 ? 0 : rc;
  char script[2048];
  if (b.script) snprintf(script, sizeof script, "%s", b.script);
  else snprintf(script, sizeof script, "%s/scripts/pp.lua", lm_root_dir());
  lm_error err;
  lm_pipeline *pipe = lm_pipeline_load(&(lm_pipeline_desc){.path = script}, &err);
  if (!pipe) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 1;
  }
  if (b.tech && !lm_pipeline_set_technique(pipe, b.tech, &err)) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    lm_pipeline_destroy(pipe);
    return 2;
  }
  lm_scene *scene = lm_scene_load(b.scene, &err);
  if (!scene) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    lm_pipeline_destroy(pipe);
    return 2;
  }
  bool ok = lm_context_create_headless(&(lm_context_desc){.platform = "auto"}, &err);
  lm_clock used = LM_CLOCK_AUTO;
  for (int s = 0; s < b.size_count && ok; s++) ok = run_size(&b, s, scene, pipe, &used, &err);
  if (ok) {
    if (b.json) print_json(&b, used);
    else print_tables(&b, used);
  } else {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
  }
  lm_programs_clear();
  lm_scene_destroy(scene);
  lm_context_destroy();
  lm_pipeline_destroy(pipe);
  return ok ? 0 : 1;
}
