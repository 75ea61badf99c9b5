/* limn bench: the compositor's own cost per frame; how each pass's time
 * grows with the output's pixel count and with an option's value (a
 * least-squares line per pass); and each pass's texture fetch rate against a
 * calibration pass of known fetches, all measured in one run. */
#define _GNU_SOURCE
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "capture_render.h"
#include "render/render.h"
#include "scene/gltf.h"
#include "trace/trace.h"
#include "tools.h"

static const char bench_usage[] =
    "usage: limn bench [options]\n"
    "\n"
    "Renders one scene through a pipeline at several sizes and prints, per size,\n"
    "the frame's wall time, the CPU time of Lua (OnRender) plus frame-graph\n"
    "compilation against it (the compositor's overhead), and each pass's time;\n"
    "then per pass a line ms = a + b * pixels fitted over the sizes. Medians\n"
    "over --frames after --warmup frames; the pass clock is named. A calibration\n"
    "pass (scripts/calibrate.lua: 8 and 64 texel fetches a pixel) at the largest\n"
    "size gives the machine's fetch rate; a pass whose script declares its\n"
    "fetches (pass{ fetches = N }) is shown as a share of that rate, any other\n"
    "as the fetches a pixel its time would allow. With shadows fitted to the\n"
    "depths the frame sees, the cost of that fit (the depth-range reduction\n"
    "passes plus reading their result back) is shown as a share of the frame.\n"
    "CPU passes (cpu{}, e.g. reflections' ray tracing, with their read-back and\n"
    "upload) are shown against the rest of the frame as a ratio.\n"
    "The shader programs the run compiled are counted, with the wall time their\n"
    "compiles and links took, and among them the lighting passes' variants for the\n"
    "scene's light set (light_set(), pp.lua's light_variants; one per light set).\n"
    "With --trace, the CPU ray tracer (engine/trace) on the scene: its build, its\n"
    "rate on the reflection rays of a view where every surface is a mirror at\n"
    "800x450 (the seed's quarter of 1600x900), and the same at a quarter of the\n"
    "largest size against that size's frame time, as a ratio.\n"
    "With --motion, at the largest size, the frame while things move: three\n"
    "renderers, each with its own scene and pipeline, take turns frame by frame\n"
    "(so that the machine's load falls on all three): `still` holds the path's\n"
    "first view, `moving` follows the path with every cache on and histories\n"
    "carried, `alone` renders each moving frame again with every cache off: its\n"
    "pipeline with shadow.cache=false and every NAME.temporal.enabled=false (no\n"
    "shadow tile kept, no temporal history, no settled skip), its renderer's view\n"
    "set again before each frame (no previous frame; textures stay allocated, as\n"
    "in the sequence: lm_renderer_set_view). Prints per pass the\n"
    "three medians, moving / still and moving / alone, the shadow tiles drawn a\n"
    "frame, the triangles and draw calls of the camera's passes and the shadow\n"
    "tiles' triangles, each frame's times (wall and the process's CPU time, every thread's)\n"
    "with the passes that cost most more than alone, and the target: each frame\n"
    "of a sequence within 1.2x of the same frame alone: PASS when the ratio of\n"
    "the frame medians and every frame's ratio are within it, a frame judged on\n"
    "the process's CPU time where the GL renderer is a software one (llvmpipe:\n"
    "its GPU work is the process's, and CPU time does not count waiting for a\n"
    "core on a loaded machine, as the wall time does), on the wall time elsewhere.\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE   (default cornell)\n"
    "  --script FILE       (default scripts/pp.lua)\n"
    "  --tech NAME         technique (default: the script's first)\n"
    "  --set NAME=VALUE    set a script option, as limn capture does (repeatable)\n"
    "  --sizes LIST        comma-separated WxH (default 64x48,128x96,256x192)\n"
    "  --frames N          timed frames per size (default 5)\n"
    "  --warmup N          untimed frames first (default 2)\n"
    "  --vary NAME=V1,V2,...  at the largest size, also render with each value of\n"
    "                      a script option (e.g. isr.samples=8,16,32,64) and fit\n"
    "                      each pass's time against it\n"
    "  --lights N1,N2,...  at the largest size, also render with N small point lights\n"
    "                      scattered over the scene (ascending counts; a fixed\n"
    "                      sequence, so each count adds to the last), with light\n"
    "                      culling on and off; prints the lights a covered pixel\n"
    "                      evaluates and fits each pass's time against it and\n"
    "                      against N\n"
    "  --light-reach F     those lights' range, a fraction of the scene's\n"
    "                      bounding-box diagonal (default 0.08)\n"
    "  --clock auto|gpu|cpu|process   how passes are timed (capture's; process:\n"
    "                      every thread's CPU time, steadier on a loaded machine)\n"
    "  --trace             also measure the ray tracer (see above)\n"
    "  --trace-threads N   its threads (default 2)\n"
    "  --motion            the moving frame (see above); the path is an orbit\n"
    "                      around the centre of the scene's bounds (default 2\n"
    "                      degrees a frame, at the distance and 20 degrees above\n"
    "                      as the framing camera), or with --time and a scene\n"
    "                      whose camera the animation moves, that camera\n"
    "  --walk STEP         the path is a walk instead (implies --motion): the\n"
    "                      scene's camera (the framing camera where it has none)\n"
    "                      flies forward, STEP of the scene's bounding-box diagonal\n"
    "                      a frame (0.0075: the viewer's W, --script-keys hold=W)\n"
    "  --orbit STEP[,RADIUS[,ELEVATION]]  that orbit (implies --motion): degrees a\n"
    "                      frame (0..360), radius in scene units (0: the framing\n"
    "                      camera's), elevation in degrees (-89..89); with --time,\n"
    "                      --orbit 0 holds the camera while the animation plays\n"
    "  --time START:STOP   play the scene's animation over the moving frames at\n"
    "                      --fps (implies --motion; sets the timed frames'\n"
    "                      count; warm-up frames come before START): its pose\n"
    "                      (lm_scene_set_time, timed as \"animate (cpu)\") before\n"
    "                      each frame; the deformed vertices' upload is the\n"
    "                      renderer's, in \"outside the passes\"\n"
    "  --fps N             frames a second of --time (default 24)\n"
    "  --animation NAME|INDEX|all  which animation --time plays (default all)\n"
    "  --rounds N          the --motion sequence N times from new renderers (implies\n"
    "                      --motion); each frame keeps its least time over the\n"
    "                      rounds (the work repeats, the machine's load does not);\n"
    "                      the passes' medians are over every round's frames\n"
    "                      (default 1)\n"
    "  --json              one JSON object on stdout instead of the tables\n"
    "  --help              this text\n";

enum { MAX_SIZES = 16, MAX_PASSES = 64 };

/* The --motion run's renderers (see the usage text). */
enum { STREAM_STILL, STREAM_MOVING, STREAM_ALONE, STREAMS };
static const char *const stream_names[STREAMS] = {"still", "moving", "alone"};
#define MOTION_TARGET 1.2 /* issue 29: a sequence's frame within 1.2x of the same frame alone */

typedef struct bench_pass {
  char name[64];
  double ms[MAX_SIZES];     /* median per size; -1 when not run at that size */
  double vary_ms[MAX_SIZES]; /* median per --vary value at the largest size */
  double lights_ms[2][MAX_SIZES]; /* median per --lights count: culled, every light everywhere */
  double fetches;           /* declared fetches a pixel (0: not said) */
  double motion_ms[STREAMS]; /* --motion: median per renderer; -1 when it did not run */
  bool cpu;                 /* a CPU pass (cpu{}: the ray tracer's step) */
  int width, height;        /* its output at the largest size */
} bench_pass;

enum { DRAW_TRIANGLES, DRAW_CALLS, DRAW_SHADOW_TRIANGLES, DRAW_FIGURES };
static const char *const draw_names[DRAW_FIGURES] = {"camera triangles", "camera draw calls", "shadow triangles"};
static const char *const draw_keys[DRAW_FIGURES] = {"camera_triangles", "camera_draw_calls", "shadow_triangles"};

typedef struct motion {
  bool on, orbit_given, timed;
  double step, radius, elevation; /* the orbit: degrees a frame, scene units (0: the framing camera's), degrees */
  double walk;                    /* --walk: the share of the scene's diagonal a frame (0: no walk) */
  double start, stop, fps;        /* --time and --fps */
  const char *animation;          /* --animation */
  int frames;                     /* timed frames: --frames, or those of --time */
  /* what the run used and measured */
  bool orbit;            /* the path is the orbit, else the scene's camera (walking, or moved by the animation) */
  char camera[LM_NAME_MAX];
  char caches_off[512];  /* the alone pipeline's options turned off */
  int anim;              /* lm_scene_find_animation's index */
  float centre[3];
  double frame_ms[STREAMS], animate_ms[STREAMS], tiles[STREAMS], scrolled[STREAMS]; /* medians; tiles: shadow tiles
                                                                      drawn, scrolled: of them, cascades scrolled */
  double *tiles_drawn;   /* per timed frame and renderer: the shadow tiles drawn */
  /* per timed frame and renderer, then their medians: the camera passes' triangles and draw calls, the
   * shadow tiles' triangles (lm_scene_draw_stats: where the rasterizer's work goes) */
  double *draws, draw_median[STREAMS][DRAW_FIGURES];
  double outside_ms[STREAMS]; /* median of the frame's wall time less its passes' (record, compile, uploads) */
  double ratio_worst;    /* the largest moving / alone of one frame */
  double cpu_ratio, cpu_worst; /* median and largest over frames of moving / alone in process CPU time */
  int rounds;            /* --rounds: the sequence this many times, each frame's least time kept */
  bool software;         /* a software GL renderer (llvmpipe): frames judged on the process's CPU time */
  /* per timed frame and renderer: wall and CPU ms, programs compiled and their ms, each pass's ms (by slot) */
  double *wall, *cpu, *compiles, *compile_ms, *by_pass;
  float (*eye)[3];       /* the moving camera's position each timed frame */
  int moved;             /* timed frames whose camera is not the previous one's */
} motion;

/* What the scene's meshes share and the copies made of them at load
 * (issue 33: instanced draws, simplified casters and camera copies). */
typedef struct mesh_figures {
  int meshes, nodes;           /* meshes, and the mesh nodes drawing them */
  int shared, shared_nodes;    /* meshes drawn by two nodes or more, and those nodes (instanced draws) */
  int casters, lods;           /* meshes with simplified copies for shadow tiles, for the camera */
  long triangles;              /* of every mesh once */
  long caster_triangles, lod_triangles; /* of those meshes' coarsest copies, and of the meshes themselves */
  long caster_full, lod_full;
} mesh_figures;

typedef struct bench {
  int sizes[MAX_SIZES][2], size_count, frames, warmup;
  limn_common_args common; /* --scene, --script, --tech, --set (--sizes is bench's own) */
  char vary_name[128];
  char vary_text[MAX_SIZES][64];
  double vary[MAX_SIZES];
  int vary_count, largest;  /* largest: index of the size with the most pixels */
  int lights[MAX_SIZES], lights_count, scene_lights;
  double light_reach;
  double per_pixel[2][MAX_SIZES]; /* lights a covered pixel evaluates: culled, not */
  double ns_per_fetch;      /* calibrated; 0 when the calibration failed */
  int calibration_size[2];
  lm_clock clock;
  bool json;
  double frame_ms[MAX_SIZES], overhead_ms[MAX_SIZES];
  double readback_ms[MAX_SIZES]; /* the shadow fit's read-back and refit (wall clock) */
  bench_pass passes[MAX_PASSES];
  int pass_count;
  bool trace;
  int trace_threads;
  lm_trace_stats trace_stats;
  int trace_rays, frame_rays;  /* reflection rays at 800x450, and at a quarter of the largest size */
  double trace_ms, frame_trace_ms; /* medians of tracing them (wall clock) */
  double trace_cpu_ms;         /* median CPU time (all threads) of the 800x450 rays */
  motion motion;
  /* Loading (wall clock from the command's start): the scene read, the first
   * frame finished (glFinish), the peak resident memory then (KiB), and the
   * most GPU memory the driver reported in use (MiB; -1: it reports none). */
  double start_ms, load_ms, first_frame_ms, gpu_mib;
  long first_frame_rss_kib;
  mesh_figures meshes;
} bench;

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("bench", fmt, arg); }

static int parse_args(int argc, char **argv, bench *b) {
  *b = (bench){.frames = 5, .warmup = 2, .common = {.scene = "cornell"}, .light_reach = 0.08, .trace_threads = 2};
  const char *sizes = "64x48,128x96,256x192";
  static const struct option opts[] = {
      {"scene", required_argument, 0, 's'}, {"script", required_argument, 0, 'p'},
      {"tech", required_argument, 0, 't'},  {"sizes", required_argument, 0, 'Z'},
      {"frames", required_argument, 0, 'n'}, {"warmup", required_argument, 0, 'w'},
      {"clock", required_argument, 0, 'k'}, {"json", no_argument, 0, 'j'},
      {"vary", required_argument, 0, 'V'},  {"help", no_argument, 0, 'h'},
      {"set", required_argument, 0, 'D'},   {"lights", required_argument, 0, 'L'}, {"light-reach", required_argument, 0, 'R'},
      {"trace", no_argument, 0, 'r'},       {"trace-threads", required_argument, 0, 'T'},
      {"motion", no_argument, 0, 'M'},      {"orbit", required_argument, 0, 'O'},
      {"time", required_argument, 0, 'I'},  {"fps", required_argument, 0, 'F'},
      {"animation", required_argument, 0, 'A'}, {"rounds", required_argument, 0, 'U'},
      {"walk", required_argument, 0, 'W'},  {0, 0, 0, 0}};
  motion *m = &b->motion;
  *m = (motion){.step = 2, .elevation = 20, .fps = 24, .animation = "all", .rounds = 1};
  bool fps_given = false, animation_given = false;
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    switch (c) {
    case 'Z': sizes = optarg; break;
    case 'n':
      if (!limn_parse_int(optarg, 1, 10000, &b->frames)) return usage_error("--frames wants 1..10000, not '%s'", optarg);
      break;
    case 'w':
      if (!limn_parse_int(optarg, 0, 10000, &b->warmup)) return usage_error("--warmup wants 0..10000, not '%s'", optarg);
      break;
    case 'k':
      if (!capture_parse_clock(optarg, &b->clock)) return usage_error("--clock wants auto, gpu, cpu or process, not '%s'", optarg);
      break;
    case 'j': b->json = true; break;
    case 'r': b->trace = true; break;
    case 'T':
      if (!limn_parse_int(optarg, 1, 256, &b->trace_threads))
        return usage_error("--trace-threads wants 1..256, not '%s'", optarg);
      break;
    case 'V': {
      const char *eq = strchr(optarg, '=');
      if (!eq || eq == optarg || !eq[1]) return usage_error("--vary wants NAME=V1,V2,..., not '%s'", optarg);
      snprintf(b->vary_name, sizeof b->vary_name, "%.*s", (int)(eq - optarg), optarg);
      char values[1024];
      snprintf(values, sizeof values, "%s", eq + 1);
      b->vary_count = 0;
      for (char *save = NULL, *tok = strtok_r(values, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (b->vary_count == MAX_SIZES) return usage_error("%s", "--vary takes at most 16 values");
        if (!limn_parse_double(tok, &b->vary[b->vary_count]))
          return usage_error("--vary wants numbers, not '%s'", tok);
        snprintf(b->vary_text[b->vary_count++], sizeof b->vary_text[0], "%s", tok);
      }
      break;
    }
    case 'L': {
      char values[1024];
      snprintf(values, sizeof values, "%s", optarg);
      b->lights_count = 0;
      for (char *save = NULL, *tok = strtok_r(values, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int *v = &b->lights[b->lights_count];
        if (b->lights_count == MAX_SIZES) return usage_error("%s", "--lights takes at most 16 counts");
        if (!limn_parse_int(tok, 0, 200, v) || (b->lights_count && *v < v[-1]))
          return usage_error("--lights wants ascending counts 0..200, not '%s'", tok);
        b->lights_count++;
      }
      break;
    }
    case 'R':
      if (!limn_parse_double(optarg, &b->light_reach) || !(b->light_reach > 0 && b->light_reach <= 10))
        return usage_error("--light-reach wants a fraction in (0, 10], not '%s'", optarg);
      break;
    case 'M': m->on = true; break;
    case 'O': {
      char text[256], *parts[4] = {0};
      int n = 0;
      snprintf(text, sizeof text, "%s", optarg);
      for (char *save = NULL, *tok = strtok_r(text, ",", &save); tok && n < 4; tok = strtok_r(NULL, ",", &save))
        parts[n++] = tok;
      double v[3] = {m->step, 0, m->elevation};
      bool ok = n >= 1 && n <= 3;
      for (int i = 0; i < n && ok; i++) ok = limn_parse_double(parts[i], &v[i]);
      if (!ok || v[0] < 0 || v[0] > 360 || v[1] < 0 || v[1] >= 1e9 || v[2] < -89 || v[2] > 89)
        return usage_error("--orbit wants STEP[,RADIUS[,ELEVATION]]: degrees a frame 0..360, a radius in [0, 1e9) "
                           "(a job's turntable distance's bound), an elevation -89..89, not '%s'", optarg);
      m->step = v[0], m->radius = v[1], m->elevation = v[2];
      m->on = m->orbit_given = true;
      break;
    }
    case 'W':
      if (!limn_parse_double(optarg, &m->walk) || !(m->walk > 0 && m->walk <= 1))
        return usage_error("--walk wants a share of the scene's diagonal a frame in (0, 1], not '%s'", optarg);
      m->on = true;
      break;
    case 'I':
      if (!strchr(optarg, ':') || !limn_parse_time(optarg, &m->start, &m->stop) || m->stop < m->start)
        return usage_error("--time wants START:STOP in seconds, STOP >= START, not '%s'", optarg);
      m->on = m->timed = true;
      break;
    case 'F':
      if (!limn_parse_double(optarg, &m->fps) || !(m->fps > 0 && m->fps <= 1000))
        return usage_error("--fps wants frames a second in (0, 1000], not '%s'", optarg);
      fps_given = true;
      break;
    case 'A': m->animation = optarg, animation_given = true; break;
    case 'U':
      if (!limn_parse_int(optarg, 1, 100, &m->rounds)) return usage_error("--rounds wants 1..100, not '%s'", optarg);
      m->on = true;
      break;
    case 'h': fputs(bench_usage, stdout); return -1;
    default:
      if (limn_common_flag("bench", c, argv, &b->common)) return 2;
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (m->walk > 0 && m->orbit_given) return usage_error("%s", "--walk and --orbit are two paths: give one");
  if ((fps_given || animation_given) && !m->timed)
    return usage_error("%s plays an animation: it needs --time START:STOP", fps_given ? "--fps" : "--animation");
  if (m->timed) {
    double frames = floor((m->stop - m->start) * m->fps + 1e-9) + 1;
    if (frames > 10000) return usage_error("%s: more than 10000 frames", "--time at --fps");
    m->frames = (int)frames;
  } else if (m->on && !(m->step > 0) && !(m->walk > 0)) {
    return usage_error("%s", "--orbit with a step of 0 and no --time: nothing moves");
  }
  if (!m->timed) m->frames = b->frames;
  char list[1024];
  snprintf(list, sizeof list, "%s", sizes);
  for (char *save = NULL, *tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
    if (b->size_count == MAX_SIZES) return usage_error("%s", "at most 16 sizes");
    int *s = b->sizes[b->size_count++];
    if (!limn_parse_size(tok, &s[0], &s[1])) return usage_error("--sizes wants WxH,WxH,..., not '%s'", tok);
  }
  if (b->size_count == 0) return usage_error("%s", "--sizes is empty");
  for (int s = 1; s < b->size_count; s++)
    if ((double)b->sizes[s][0] * b->sizes[s][1] > (double)b->sizes[b->largest][0] * b->sizes[b->largest][1])
      b->largest = s;
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
  for (int s = 0; s < MAX_SIZES; s++) p->ms[s] = p->vary_ms[s] = p->lights_ms[0][s] = p->lights_ms[1][s] = -1;
  for (int k = 0; k < STREAMS; k++) p->motion_ms[k] = -1;
  return p;
}

/* Which series a configuration fills: the sizes, --vary, --lights culled or not. */
enum { SERIES_SIZES, SERIES_VARY, SERIES_LIGHTS, SERIES_LIGHTS_ALL };

static double *series_ms(bench_pass *p, int series) {
  return series == SERIES_SIZES ? p->ms
         : series == SERIES_VARY ? p->vary_ms
                                 : p->lights_ms[series - SERIES_LIGHTS];
}

/* Mean count of lights a covered pixel of r's last frame evaluates (the G-buffer's depth and the light grid). */
static double lights_per_pixel(lm_renderer *r, int light_count) {
  lm_graph *g = lm_renderer_graph(r);
  int id = lm_graph_find_target(g, "gbuffer.dpt"), mid = lm_graph_find_target(g, "gbuffer.mat");
  if (id < 0 || mid < 0) return -1;
  lm_graph_target_info t = lm_graph_target(g, id), m = lm_graph_target(g, mid);
  if (!t.used || !t.texture.id || !m.used || !m.texture.id) return -1;
  size_t px = (size_t)t.width * (size_t)t.height;
  float *depth = lm_alloc(sizeof(float) * 4 * px), *mat = lm_alloc(sizeof(float) * 4 * px);
  lm_texture_read(t.texture, t.width, t.height, true, depth);
  lm_texture_read(m.texture, m.width, m.height, true, mat);
  const lm_light_grid *grid = lm_renderer_light_grid(r);
  double sum = 0, covered = 0;
  for (int row = 0; row < t.height; row++)
    for (int x = 0; x < t.width; x++) {
      size_t i = (size_t)row * (size_t)t.width + (size_t)x;
      if (mat[4 * i + 3] < 0.5f) continue; /* background: no light evaluated */
      float y = (float)(t.height - 1 - row) + 0.5f; /* rows were read top first */
      sum += lm_light_grid_count(grid, lm_light_grid_cluster(grid, (float)x + 0.5f, y, depth[4 * i]), light_count);
      covered++;
    }
  free(depth);
  free(mat);
  return covered > 0 ? sum / covered : 0;
}

/* Appends the last frame's time of each pass that ran to that pass's row of
 * pass_ms (`cap` a row, counts in pass_n) and, when `row` is given, adds it
 * to row[the pass's slot]; `largest` also keeps its declared fetches and
 * output size. Returns the sum of those times. */
static double collect_passes(bench *b, lm_renderer *r, bool largest, double *pass_ms, int *pass_n, int cap,
                             double *row) {
  double sum = 0;
  lm_graph *g = lm_renderer_graph(r);
  for (int i = 0; i < lm_graph_pass_count(g); i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    if (p.culled || p.ms < 0) continue;
    bench_pass *bp = find_pass(b, p.name);
    if (!bp) continue;
    if (largest) bp->fetches = p.fetches, bp->width = p.width, bp->height = p.height;
    bp->cpu = p.kind == LM_PASS_CPU;
    int slot = (int)(bp - b->passes);
    if (pass_n[slot] < cap) pass_ms[slot * cap + pass_n[slot]++] = p.ms;
    if (row) row[slot] += p.ms;
    sum += p.ms;
  }
  return sum;
}

/* The process's peak resident memory so far, KiB (getrusage's ru_maxrss: on
 * llvmpipe the GPU's buffers and textures are in it too); -1 when unknown. */
static long peak_rss_kib(void) {
  struct rusage u;
  return getrusage(RUSAGE_SELF, &u) == 0 ? u.ru_maxrss : -1;
}

/* One configuration (size si, or column si of another series): warm-up,
 * then medians of frame wall time, overhead and passes. */
static bool run_size(bench *b, int si, int series, lm_scene *scene, lm_pipeline *pipe, lm_clock *used,
                     lm_error *err) {
  bool vary = series != SERIES_SIZES;
  int size = vary ? b->largest : si;
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = pipe,
                                                          .width = b->sizes[size][0], .height = b->sizes[size][1],
                                                          .clock = b->clock,
                                                          .no_light_culling = series == SERIES_LIGHTS_ALL}, err);
  if (!r) return false;
  if (series >= SERIES_LIGHTS) lm_renderer_set_sharing(r, false); /* the G-buffer stays readable */
  *used = lm_renderer_clock(r);
  double *wall = lm_alloc(sizeof(double) * (size_t)b->frames), *over = lm_alloc(sizeof(double) * (size_t)b->frames);
  double *readback = lm_alloc(sizeof(double) * (size_t)b->frames);
  double *pass_ms = lm_alloc(sizeof(double) * (size_t)b->frames * MAX_PASSES);
  int pass_n[MAX_PASSES] = {0};
  bool ok = true;
  for (int f = 0; f < b->warmup + b->frames && ok; f++) {
    lm_finish(); /* nothing of the last frame left in flight */
    double t0 = lm_now_ms();
    ok = lm_renderer_frame(r, err);
    if (!ok) /* which frame, as capture names it: a script may fail on a later one */
      lm_error_prefix(err, "%dx%d, frame %d (%d warm-up, %d timed)", b->sizes[size][0], b->sizes[size][1], f,
                      b->warmup, b->frames);
    lm_finish();
    double t1 = lm_now_ms();
    if (ok && !b->first_frame_ms) b->first_frame_ms = t1 - b->start_ms, b->first_frame_rss_kib = peak_rss_kib();
    if (!ok || f < b->warmup) continue;
    int k = f - b->warmup;
    double rec, comp;
    lm_renderer_overhead(r, &rec, &comp);
    wall[k] = t1 - t0;
    over[k] = rec + comp;
    readback[k] = lm_renderer_fit_ms(r);
    collect_passes(b, r, !vary && size == b->largest, pass_ms, pass_n, b->frames, NULL);
  }
  b->gpu_mib = fmax(b->gpu_mib, lm_gpu_memory_used_mib());
  if (ok && !vary) {
    b->frame_ms[si] = median(wall, b->frames);
    b->overhead_ms[si] = median(over, b->frames);
    b->readback_ms[si] = median(readback, b->frames);
  }
  if (ok && series >= SERIES_LIGHTS)
    b->per_pixel[series - SERIES_LIGHTS][si] = lights_per_pixel(r, b->scene_lights + b->lights[si]);
  for (int i = 0; i < b->pass_count && ok; i++)
    if (pass_n[i]) series_ms(&b->passes[i], series)[si] = median(pass_ms + i * b->frames, pass_n[i]);
  free(wall);
  free(over);
  free(readback);
  free(pass_ms);
  lm_renderer_destroy(r);
  return ok;
}

/* Least squares y = a + b * x over the points with y >= 0; false with
 * fewer than two distinct x. */
static bool fit_line(const double *xs, const double *ys, int count, double *a, double *slope, double *r2) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  for (int s = 0; s < count; s++) {
    double x = xs[s], y = ys[s];
    if (y < 0 || x < 0) continue;
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

/* A pass's time against the pixel count of each size, or each --vary value. */
static bool fit(const bench *b, const bench_pass *p, bool vary, double *a, double *slope, double *r2) {
  double xs[MAX_SIZES];
  int n = vary ? b->vary_count : b->size_count;
  for (int s = 0; s < n; s++) xs[s] = vary ? b->vary[s] : (double)b->sizes[s][0] * b->sizes[s][1];
  return fit_line(xs, vary ? p->vary_ms : p->ms, n, a, slope, r2);
}

/* A pass's fetches against the calibration at the largest size: *rate in
 * fetches a second and *share of the calibrated rate when it declares its
 * fetches, else *equivalent fetches a pixel its time would allow. False
 * when there is no calibration or no time. */
static bool fetch_figures(const bench *b, const bench_pass *p, double *rate, double *share, double *equivalent) {
  double ms = p->ms[b->largest], pixels = (double)p->width * p->height;
  if (!(b->ns_per_fetch > 0) || !(ms > 0) || !(pixels > 0)) return false;
  *rate = p->fetches > 0 ? p->fetches * pixels / (ms * 1e-3) : -1;
  *share = p->fetches > 0 ? *rate / (1e9 / b->ns_per_fetch) : -1;
  *equivalent = ms * 1e6 / (b->ns_per_fetch * pixels);
  return true;
}

/* The shadow fit at size s: its reduction passes (shadow.range*) and the
 * read-back; false when the frame fits no shadows. */
static bool shadow_fit_ms(const bench *b, int s, double *passes, double *readback) {
  *passes = 0, *readback = b->readback_ms[s];
  bool any = false;
  for (int i = 0; i < b->pass_count; i++)
    if (!strncmp(b->passes[i].name, "shadow.range", 12) && b->passes[i].ms[s] >= 0)
      *passes += b->passes[i].ms[s], any = true;
  return any;
}

/* Reflection rays as the GPU's ray pass writes them for a view in which every
 * surface is a mirror (the seed's worst case, 003 Table 7.2): a primary ray a
 * pixel finds the surface, the reflected ray leaves it, nudged off along the
 * normal by a fraction of the scene's size (scale-free). Returns the count. */
static int mirror_rays(const lm_trace *t, const lm_scene *s, int threads, int w, int h, lm_trace_ray *out) {
  lm_frame_data f;
  lm_scene_frame_data(s, 0, w, h, &f);
  float lo[3], hi[3];
  lm_scene_bounds(s, lo, hi);
  float eps = 1e-5f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                            (hi[2] - lo[2]) * (hi[2] - lo[2]));
  int n = w * h;
  lm_trace_ray *prim = lm_alloc(sizeof *prim * (size_t)n);
  lm_trace_hit *hits = lm_alloc(sizeof *hits * (size_t)n);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      lm_trace_ray *r = &prim[y * w + x];
      *r = (lm_trace_ray){.tmax = INFINITY};
      for (int k = 0; k < 3; k++)
        r->origin[k] = f.camera_pos[k], r->dir[k] = f.frustum_o[k] + f.frustum_u[k] * u + f.frustum_v[k] * v;
    }
  lm_trace_rays(t, prim, hits, n, threads);
  int count = 0;
  for (int i = 0; i < n; i++) {
    if (hits[i].tri < 0) continue;
    lm_trace_surface sf;
    lm_trace_surface_at(t, &prim[i], &hits[i], &sf);
    const float *d = prim[i].dir, *nn = sf.normal;
    float dn = d[0] * nn[0] + d[1] * nn[1] + d[2] * nn[2];
    lm_trace_ray *r = &out[count++];
    *r = (lm_trace_ray){.tmax = INFINITY};
    for (int k = 0; k < 3; k++) r->origin[k] = sf.position[k] + eps * nn[k], r->dir[k] = d[k] - 2 * dn * nn[k];
  }
  free(prim);
  free(hits);
  return count;
}

/* Median wall time of tracing `n` rays over the bench's frames, and of the
 * process's CPU time (every thread's) in *cpu_ms. */
static double trace_median_ms(const bench *b, const lm_trace *t, const lm_trace_ray *rays, int n, double *cpu_ms) {
  lm_trace_hit *hits = lm_alloc(sizeof *hits * (size_t)(n ? n : 1));
  double *ms = lm_alloc(sizeof(double) * 2 * (size_t)(b->warmup + b->frames)), *cpu = ms + b->warmup + b->frames;
  for (int f = 0; f < b->warmup + b->frames; f++) {
    double t0 = lm_now_ms(), c0 = lm_cpu_ms();
    lm_trace_rays(t, rays, hits, n, b->trace_threads);
    ms[f] = lm_now_ms() - t0;
    cpu[f] = lm_cpu_ms() - c0;
  }
  double m = median(ms + b->warmup, b->frames);
  *cpu_ms = median(cpu + b->warmup, b->frames);
  free(ms);
  free(hits);
  return m;
}

static void trace_figures(bench *b, lm_scene *s) {
  lm_scene_restore_geometry(s);
  lm_trace *t = lm_trace_create(s, &b->trace_stats);
  lm_trace_ray *rays = lm_alloc(sizeof *rays * 800 * 450);
  b->trace_rays = mirror_rays(t, s, b->trace_threads, 800, 450, rays);
  b->trace_ms = trace_median_ms(b, t, rays, b->trace_rays, &b->trace_cpu_ms);
  int w = b->sizes[b->largest][0] / 2, h = b->sizes[b->largest][1] / 2;
  w = w > 1 ? w : 1, h = h > 1 ? h : 1;
  lm_trace_ray *frame = lm_alloc(sizeof *frame * (size_t)w * (size_t)h);
  b->frame_rays = mirror_rays(t, s, b->trace_threads, w, h, frame);
  double cpu;
  b->frame_trace_ms = trace_median_ms(b, t, frame, b->frame_rays, &cpu);
  free(frame);
  free(rays);
  lm_trace_destroy(t);
}

static double rays_per_s(int rays, double ms) { return ms > 0 ? rays / (ms * 1e-3) : 0; }

static void print_trace(const bench *b) {
  const lm_trace_stats *st = &b->trace_stats;
  double frame = b->frame_ms[b->largest];
  printf("ray tracer (engine/trace on Embree, %d threads): %d triangles (%d skipped), %d meshes as %d instances, "
         "built in %.1f ms\n", b->trace_threads, st->triangles, st->skipped, st->meshes, st->instances, st->build_ms);
  printf("  every surface a mirror, 800x450: %d reflection rays in %.3f ms = %.2f million rays/s (wall clock)\n",
         b->trace_rays, b->trace_ms, rays_per_s(b->trace_rays, b->trace_ms) * 1e-6);
  /* on a shared machine the wall clock counts other processes' time too */
  printf("  CPU time %.3f ms: %.2f million rays/s a core, %.2f on %d dedicated cores\n", b->trace_cpu_ms,
         rays_per_s(b->trace_rays, b->trace_cpu_ms) * 1e-6,
         rays_per_s(b->trace_rays, b->trace_cpu_ms) * 1e-6 * b->trace_threads, b->trace_threads);
  printf("  at %dx%d (rays at %dx%d): %d rays in %.3f ms against the frame's %.3f ms: ratio %.3f\n",
         b->sizes[b->largest][0], b->sizes[b->largest][1], b->sizes[b->largest][0] / 2, b->sizes[b->largest][1] / 2,
         b->frame_rays, b->frame_trace_ms, frame, frame > 0 ? b->frame_trace_ms / frame : 0);
}

/* CPU passes' time at size s; false when the frame has none. */
static bool cpu_pass_ms(const bench *b, int s, double *ms) {
  *ms = 0;
  bool any = false;
  for (int i = 0; i < b->pass_count; i++)
    if (b->passes[i].cpu && b->passes[i].ms[s] >= 0) *ms += b->passes[i].ms[s], any = true;
  return any;
}

static mesh_figures count_meshes(const lm_scene *s) {
  mesh_figures f = {.meshes = s->mesh_count};
  int *users = lm_alloc(sizeof *users * (size_t)(s->mesh_count + 1));
  memset(users, 0, sizeof *users * (size_t)(s->mesh_count + 1));
  for (int i = 0; i < s->node_count; i++)
    if (s->nodes[i].mesh >= 0 && s->nodes[i].mesh < s->mesh_count) users[s->nodes[i].mesh]++, f.nodes++;
  for (int m = 0; m < s->mesh_count; m++) {
    const lm_scene_mesh *mesh = &s->meshes[m];
    long tris = mesh->index_count / 3;
    f.triangles += tris;
    if (users[m] > 1) f.shared++, f.shared_nodes += users[m];
    if (mesh->caster_levels > 0)
      f.casters++, f.caster_full += tris, f.caster_triangles += mesh->casters[mesh->caster_levels - 1].count / 3;
    if (mesh->lod_levels > 0)
      f.lods++, f.lod_full += tris, f.lod_triangles += mesh->lods[mesh->lod_levels - 1].count / 3;
  }
  free(users);
  return f;
}

static double share(long part, long whole) { return whole > 0 ? 100.0 * (double)part / (double)whole : 0; }

static void print_meshes(const mesh_figures *f) {
  printf("meshes: %d (%ld triangles) for %d mesh nodes; %d drawn by several nodes (%d nodes: one instanced draw a "
         "run of one mesh and material)\n", f->meshes, f->triangles, f->nodes, f->shared, f->shared_nodes);
  printf("  simplified copies (meshoptimizer, made at load; level k errs by at most %.4g%% x 4^k of its mesh's "
         "extent): for shadow tiles of %d of the meshes (the coarsest %.1f%% of their triangles), for the camera of %d "
         "(%.1f%%)\n",
         100.0 * LM_LOD_ERROR, f->casters, share(f->caster_triangles, f->caster_full), f->lods,
         share(f->lod_triangles, f->lod_full));
}

static void print_tables(const bench *b, lm_clock clock) {
  printf("peak memory: %.1f MiB resident (getrusage ru_maxrss, the whole run; with llvmpipe GPU memory is in it)\n",
         (double)peak_rss_kib() / 1024);
  printf("time to first frame: %.1f ms, of which reading the scene %.1f ms (wall clock, from the command's start to "
         "the first frame's glFinish); peak memory by then %.1f MiB resident\n", b->first_frame_ms, b->load_ms,
         (double)b->first_frame_rss_kib / 1024);
  if (b->gpu_mib >= 0) printf("GPU memory: %.1f MiB in use at most (the driver's GL_NVX_gpu_memory_info, whole GPU)\n", b->gpu_mib);
  else printf("GPU memory: not reported by this driver (llvmpipe's textures and buffers are in the resident memory)\n");
  print_meshes(&b->meshes);
  printf("frame (wall clock, glFinish before and after) and compositor overhead (CPU: Lua + graph compile);\n"
         "passes: clock %s; medians of %d frames after %d warm-up\n", lm_clock_name(clock), b->frames, b->warmup);
  printf("  %-12s %10s %12s %12s %9s\n", "size", "pixels", "frame ms", "overhead ms", "overhead");
  for (int s = 0; s < b->size_count; s++)
    printf("  %5dx%-6d %10d %12.3f %12.3f %8.1f%%\n", b->sizes[s][0], b->sizes[s][1], b->sizes[s][0] * b->sizes[s][1],
           b->frame_ms[s], b->overhead_ms[s], b->frame_ms[s] > 0 ? 100 * b->overhead_ms[s] / b->frame_ms[s] : 0);
  double all_ms, set_ms;
  int all = lm_programs_stats(NULL, &all_ms), sets = lm_programs_stats("LIGHT_SET", &set_ms);
  printf("  programs: %d compiled and linked in %.1f ms (wall clock), of which light-set variants %d in %.1f ms\n",
         all, all_ms, sets, set_ms);
  double fp, fr;
  for (int s = 0; s < b->size_count; s++)
    if (shadow_fit_ms(b, s, &fp, &fr))
      printf("  shadow fit at %dx%d: reduction %.3f ms + read-back %.3f ms = %.1f%% of the frame\n", b->sizes[s][0],
             b->sizes[s][1], fp, fr, b->frame_ms[s] > 0 ? 100 * (fp + fr) / b->frame_ms[s] : 0);
  double cpu;
  for (int s = 0; s < b->size_count; s++)
    if (cpu_pass_ms(b, s, &cpu))
      printf("  CPU passes at %dx%d: %.3f ms against the rest of the frame's %.3f ms: ratio %.3f\n", b->sizes[s][0],
             b->sizes[s][1], cpu, b->frame_ms[s] - cpu, b->frame_ms[s] > cpu ? cpu / (b->frame_ms[s] - cpu) : 0);
  printf("  %-24s", "pass (ms)");
  for (int s = 0; s < b->size_count; s++) printf(" %9dx%-4d", b->sizes[s][0], b->sizes[s][1]);
  printf("  fit: a ms + b ns/pixel (r^2)\n");
  for (int i = 0; i < b->pass_count; i++) {
    const bench_pass *p = &b->passes[i];
    printf("  %-24s", p->name);
    for (int s = 0; s < b->size_count; s++) printf(" %14.3f", p->ms[s]);
    double a, sl, r2;
    if (fit(b, p, false, &a, &sl, &r2)) printf("  %.3f + %.3f (%.3f)\n", a, sl * 1e6, r2);
    else printf("  -\n");
  }
  if (b->vary_count) {
    printf("  %-24s", b->vary_name);
    for (int v = 0; v < b->vary_count; v++) printf(" %14s", b->vary_text[v]);
    printf("  fit: a ms + b ms/unit (r^2), at %dx%d\n", b->sizes[b->largest][0], b->sizes[b->largest][1]);
    for (int i = 0; i < b->pass_count; i++) {
      const bench_pass *p = &b->passes[i];
      printf("  %-24s", p->name);
      for (int v = 0; v < b->vary_count; v++) printf(" %14.3f", p->vary_ms[v]);
      double a, sl, r2;
      if (fit(b, p, true, &a, &sl, &r2)) printf("  %.3f + %.4f (%.3f)\n", a, sl, r2);
      else printf("  -\n");
    }
  }
  if (!(b->ns_per_fetch > 0)) {
    printf("fetch calibration: no result (the calibration pass did not slow with more fetches)\n");
    return;
  }
  printf("fetch calibration at %dx%d: %.4f ns a fetch (%.3g fetches/s)\n", b->calibration_size[0],
         b->calibration_size[1], b->ns_per_fetch, 1e9 / b->ns_per_fetch);
  printf("  %-24s %12s %14s %10s %16s\n", "pass", "fetches/px", "fetches/s", "of calib.", "time = fetches/px");
  for (int i = 0; i < b->pass_count; i++) {
    const bench_pass *p = &b->passes[i];
    double rate, share, eq;
    if (!fetch_figures(b, p, &rate, &share, &eq)) continue;
    if (p->fetches > 0)
      printf("  %-24s %12.1f %14.3g %9.1f%% %16.1f\n", p->name, p->fetches, rate, 100 * share, eq);
    else
      printf("  %-24s %12s %14s %10s %16.1f\n", p->name, "-", "-", "-", eq);
  }
}

/* ---- --motion -------------------------------------------------------- */

/* One of the --motion run's renderers with its own scene and pipeline (a
 * pipeline's Lua state counts the still frames its temporal reuse sees). */
typedef struct stream {
  lm_scene *scene;
  lm_pipeline *pipe;
  lm_renderer *r;    /* one for the run (alone's view is set again before each frame) */
  int camera, node; /* the camera rendered through and its node */
  float start[16];  /* --walk: the camera node's world where the walk starts */
  float diagonal;   /* --walk: the scene's bounding-box diagonal there (a frame's step is a share of it) */
} stream;

/* Does animation `anim` move node `node` or a node above it? */
static bool node_animated(const lm_scene *s, int anim, int node) {
  for (int n = node; n >= 0; n = s->nodes[n].parent)
    for (int a = 0; a < s->animation_count; a++)
      for (int c = 0; c < s->animations[a].channel_count && (anim == LM_ANIM_ALL || anim == a); c++)
        if (s->animations[a].channels[c].node == n) return true;
  return false;
}

/* The world transform of a camera at `eye` looking at `at`, +Y up (a camera
 * looks along its -Z). The orbit's elevation stays within 89 degrees, so the
 * view is never along Y. */
/* Poses s's scene for frame f of the path (f < 0: the warm-up before its
 * start): the orbit camera at f steps, and the animation at START + f / fps
 * (the renderer uploads the deformed vertices at the frame's start). Returns the milliseconds that
 * lm_scene_set_time took (0 without --time). */
static double pose(const motion *m, stream *s, int f) {
  if (m->walk > 0) { /* forward: along the camera's -Z, as the viewer's W */
    float w[16], z[3];
    memcpy(w, s->start, sizeof w);
    memcpy(z, w + 8, sizeof z);
    float length = sqrtf(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]); /* the node may scale */
    for (int i = 0; i < 3 && length > 0; i++) w[12 + i] -= (float)(m->walk * f) * s->diagonal * z[i] / length;
    lm_scene_node_set_world(s->scene, s->node, w);
  } else if (m->orbit) {
    double az = m->step * f * M_PI / 180, el = m->elevation * M_PI / 180;
    float eye[3] = {m->centre[0] + (float)(m->radius * cos(el) * sin(az)), m->centre[1] + (float)(m->radius * sin(el)),
                    m->centre[2] + (float)(m->radius * cos(el) * cos(az))}, w[16];
    lm_camera_look_at(eye, m->centre, w);
    lm_scene_node_set_world(s->scene, s->node, w);
  }
  if (!m->timed) return 0;
  double t0 = lm_now_ms();
  lm_scene_set_time(s->scene, m->anim, m->start + f / m->fps);
  return lm_now_ms() - t0;
}

/* Turns off what p keeps from frame to frame: shadow.cache and every
 * temporal reuse (options NAME.temporal.enabled), naming them in `off`. */
static bool caches_off(lm_pipeline *p, char *off, size_t cap, lm_error *err) {
  lm_buf list = {0};
  lm_pipeline_list_options(p, &list);
  bool ok = true;
  off[0] = 0;
  /* "name=value" items, ", " between them (a value's own commas give items without '=') */
  for (char *save = NULL, *line = list.data ? strtok_r(list.data, ", ", &save) : NULL; line && ok;
       line = strtok_r(NULL, ", ", &save)) {
    char *eq = strchr(line, '=');
    if (!eq) continue;
    *eq = 0;
    size_t n = strlen(line), t = strlen(".temporal.enabled");
    if (strcmp(line, "shadow.cache") && !(n > t && !strcmp(line + n - t, ".temporal.enabled"))) continue;
    ok = lm_pipeline_set_option(p, line, "false", err);
    snprintf(off + strlen(off), cap - strlen(off), "%s%s=false", off[0] ? " " : "", line);
  }
  lm_buf_free(&list);
  return ok;
}

/* Loads stream k's scene and pipeline and picks its camera (the orbit's is
 * added; its radius, when not given, is the framing camera's distance). */
static bool stream_open(bench *b, int k, stream *s, lm_error *err) {
  motion *m = &b->motion;
  int rc;
  s->scene = lm_scene_load_gpu(b->common.scene, err);
  s->pipe = s->scene ? capture_load_pipeline(&b->common, &rc, err) : NULL;
  if (!s->pipe || !lm_scene_upload(s->scene, err)) return false;
  if (k == STREAM_ALONE && !caches_off(s->pipe, m->caches_off, sizeof m->caches_off, err)) return false;
  if (m->orbit) {
    const int *size = b->sizes[b->largest];
    s->camera = lm_scene_add_framing_camera(s->scene, "bench.orbit", (float)size[0] / (float)size[1]);
    s->node = s->scene->cameras[s->camera].node;
    float lo[3], hi[3];
    lm_scene_bounds(s->scene, lo, hi);
    const float *eye = s->scene->nodes[s->node].world + 12;
    double d = 0;
    for (int i = 0; i < 3; i++) m->centre[i] = 0.5f * (lo[i] + hi[i]), d += (eye[i] - m->centre[i]) * (eye[i] - m->centre[i]);
    if (!(m->radius > 0)) m->radius = sqrt(d);
  } else {
    s->camera = s->scene->camera_count > 0 ? 0 : lm_scene_add_framing_camera(s->scene, "bench.walk",
                                                                               (float)b->sizes[b->largest][0] /
                                                                               (float)b->sizes[b->largest][1]);
    s->node = s->scene->cameras[s->camera].node;
  }
  memcpy(s->start, s->scene->nodes[s->node].world, sizeof s->start);
  if (m->walk > 0) { /* once: lm_scene_bounds visits every node, which pose() would do each frame */
    float lo[3], hi[3];
    lm_scene_bounds(s->scene, lo, hi);
    s->diagonal = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
  }
  snprintf(m->camera, sizeof m->camera, "%s", s->scene->cameras[s->camera].name);
  s->r = lm_renderer_create(&(lm_renderer_desc){.scene = s->scene, .pipeline = s->pipe, .camera = s->camera,
                                                .width = b->sizes[b->largest][0],
                                                .height = b->sizes[b->largest][1], .clock = b->clock}, err);
  if (!s->r) return false;
  if (k == STREAM_STILL) pose(m, s, 0);
  return true;
}

/* a / c, -1 when either is missing (< 0) or c is 0 */
static double ratio_of(double a, double c) { return a >= 0 && c > 0 ? a / c : -1; }

/* The --motion run (see the usage text) at the largest size. */
static bool run_motion(bench *b, const lm_scene *first, lm_error *err) {
  motion *m = &b->motion;
  const lm_camera *cams = first->cameras;
  m->orbit = m->walk <= 0 && (!m->timed || m->orbit_given || first->camera_count == 0 ||
                               !node_animated(first, m->anim, cams[0].node));
  int n = m->frames, cap = n * m->rounds;
  double *wall = lm_alloc(sizeof(double) * STREAMS * 8 * (size_t)n), *anim = wall + STREAMS * n,
         *tiles = anim + STREAMS * n, *outside = tiles + STREAMS * n, *scrolled = outside + STREAMS * n;
  m->wall = wall, m->tiles_drawn = tiles, m->cpu = scrolled + STREAMS * n, m->compiles = m->cpu + STREAMS * n;
  m->compile_ms = m->compiles + STREAMS * n;
  memset(m->compiles, 0, sizeof(double) * STREAMS * 2 * (size_t)n);
  m->by_pass = lm_alloc(sizeof(double) * STREAMS * MAX_PASSES * (size_t)n);
  m->draws = lm_alloc(sizeof(double) * STREAMS * DRAW_FIGURES * (size_t)n);
  double *pass_ms = lm_alloc(sizeof(double) * STREAMS * MAX_PASSES * (size_t)cap);
  int pass_n[STREAMS][MAX_PASSES] = {{0}};
  m->eye = lm_alloc(sizeof *m->eye * (size_t)n);
  bool ok = true;
  /* Each round renders the same sequence from new renderers; a frame keeps its least wall time, CPU time and
   * pass times over the rounds (the work is the same each round, the machine's load is not). */
  for (int round = 0; round < m->rounds && ok; round++) {
    stream st[STREAMS] = {{0}};
    for (int k = 0; k < STREAMS && ok; k++) ok = stream_open(b, k, &st[k], err);
    float last[3] = {0};
    m->moved = 0;
    for (int f = -b->warmup; f < n && ok; f++) {
      for (int j = 0; j < STREAMS && ok; j++) {
        int k = (f + b->warmup + j) % STREAMS; /* who goes first turns each frame */
        stream *s = &st[k];
        /* alone: a frame with no previous one (nothing to reproject, no still frames counted) */
        if (k == STREAM_ALONE) lm_renderer_set_view(s->r, s->camera, b->sizes[b->largest][0], b->sizes[b->largest][1]);
        lm_finish(); /* nothing of the last frame left in flight */
        double built_ms, c0 = lm_cpu_ms(), t0 = lm_now_ms();
        int built = lm_programs_stats(NULL, &built_ms);
        double a = k == STREAM_STILL ? 0 : pose(m, s, f);
        ok = lm_renderer_frame(s->r, err);
        if (!ok) { /* which renderer and frame: a script may fail on a later one */
          char when[64] = "", t[LIMN_TIME_TEXT];
          if (m->timed) snprintf(when, sizeof when, " at %s s", limn_time_text(m->start + f / m->fps, 3, t));
          lm_error_prefix(err, "--motion, the %s renderer's frame %d%s (round %d)", stream_names[k], f, when,
                          round + 1);
        }
        lm_finish();
        double t1 = lm_now_ms(), c1 = lm_cpu_ms(), built_after_ms;
        int built_after = lm_programs_stats(NULL, &built_after_ms);
        if (ok && f >= 0) {
          size_t at = (size_t)k * n + f;
          double row[MAX_PASSES] = {0}, *least = m->by_pass + at * MAX_PASSES;
          double in_passes =
              collect_passes(b, s->r, false, pass_ms + (size_t)k * MAX_PASSES * cap, pass_n[k], cap, row);
          for (int i = 0; i < MAX_PASSES; i++) least[i] = round ? fmin(least[i], row[i]) : row[i];
          wall[at] = round ? fmin(wall[at], t1 - t0) : t1 - t0;
          m->cpu[at] = round ? fmin(m->cpu[at], c1 - c0) : c1 - c0;
          m->compiles[at] += built_after - built;
          m->compile_ms[at] += built_after_ms - built_ms;
          anim[at] = round ? fmin(anim[at], a) : a;
          outside[at] = round ? fmin(outside[at], t1 - t0 - in_passes) : t1 - t0 - in_passes;
          lm_scene_draw_stats ds = lm_renderer_shadow_draw_stats(s->r);
          const lm_shadow_plan *plan = lm_renderer_shadows(s->r); /* shadow tiles and RSM views */
          tiles[at] = plan->view_count + plan->rsm_view_count - ds.kept;
          scrolled[at] = ds.scrolled;
          lm_scene_draw_stats cs = lm_renderer_draw_stats(s->r);
          double *dr = m->draws + at * DRAW_FIGURES; /* the same each round: the same frames */
          dr[DRAW_TRIANGLES] = (double)cs.triangles, dr[DRAW_CALLS] = cs.calls;
          dr[DRAW_SHADOW_TRIANGLES] = (double)ds.triangles;
        }
        if (ok && k == STREAM_MOVING) {
          const float *eye = s->scene->nodes[s->node].world + 12;
          if (f >= 0) {
            memcpy(m->eye[f], eye, sizeof m->eye[f]);
            m->moved += memcmp(eye, last, sizeof last) != 0;
          }
          memcpy(last, eye, sizeof last);
        }
      }
    }
    for (int k = 0; k < STREAMS; k++) {
      lm_renderer_destroy(st[k].r);
      lm_pipeline_destroy(st[k].pipe);
      lm_scene_destroy(st[k].scene);
    }
  }
  if (ok) {
    m->software = lm_clock_choose(LM_CLOCK_AUTO) == LM_CLOCK_CPU;
    m->ratio_worst = m->cpu_worst = 0;
    double *sorted = lm_alloc(sizeof(double) * (size_t)n); /* median sorts: the per-frame rows stay as they are */
    for (int f = 0; f < n; f++) {
      double r = ratio_of(wall[STREAM_MOVING * n + f], wall[STREAM_ALONE * n + f]);
      sorted[f] = ratio_of(m->cpu[STREAM_MOVING * n + f], m->cpu[STREAM_ALONE * n + f]);
      m->ratio_worst = fmax(m->ratio_worst, r), m->cpu_worst = fmax(m->cpu_worst, sorted[f]);
    }
    m->cpu_ratio = median(sorted, n);
    for (int k = 0; k < STREAMS; k++) {
      m->frame_ms[k] = median(memcpy(sorted, wall + k * n, sizeof(double) * (size_t)n), n);
      m->tiles[k] = median(memcpy(sorted, tiles + k * n, sizeof(double) * (size_t)n), n);
      m->animate_ms[k] = median(anim + k * n, n);
      m->scrolled[k] = median(scrolled + k * n, n);
      m->outside_ms[k] = median(outside + k * n, n);
      for (int d = 0; d < DRAW_FIGURES; d++) {
        for (int f = 0; f < n; f++) sorted[f] = m->draws[((size_t)k * n + f) * DRAW_FIGURES + d];
        m->draw_median[k][d] = median(sorted, n);
      }
      for (int i = 0; i < b->pass_count; i++)
        if (pass_n[k][i])
          b->passes[i].motion_ms[k] = median(pass_ms + ((size_t)k * MAX_PASSES + i) * cap, pass_n[k][i]);
    }
    free(sorted);
  }
  free(pass_ms);
  return ok;
}

/* A row of the motion table: the three medians and the two ratios, "-" where one did not run. */
static void motion_row(const char *name, const double t[STREAMS]) {
  double cells[5] = {t[0], t[1], t[2], ratio_of(t[1], t[0]), ratio_of(t[1], t[2])};
  printf("  %-24s", name);
  for (int i = 0; i < 5; i++) {
    if (cells[i] < 0) printf(" %*s", i < 3 ? 10 : 13, "-");
    else printf(" %*.3f", i < 3 ? 10 : 13, cells[i]);
  }
  printf("\n");
}

/* Frame by frame, moving against alone: what makes a frame slower than the
 * median (a compile, more shadow tiles, a pass that costs more there, or the
 * machine: the CPU time, summed over every thread, is not raised by waiting
 * for a core as the wall time is). */
/* The target (see the usage text). */
static bool motion_pass(const motion *m) {
  double r = ratio_of(m->frame_ms[STREAM_MOVING], m->frame_ms[STREAM_ALONE]);
  return r >= 0 && r <= MOTION_TARGET && (m->software ? m->cpu_worst : m->ratio_worst) <= MOTION_TARGET;
}

static void print_motion_frames(const bench *b) {
  const motion *m = &b->motion;
  int n = m->frames;
  printf("  per frame, moving against alone: wall ms, their ratio, process CPU ms (every thread), its ratio,\n"
         "  programs compiled, shadow tiles drawn, and the passes that took most longer moving than alone (ms)\n");
  printf("  %5s %8s %8s %6s %8s %8s %6s %5s %7s  %s\n", "frame", "moving", "alone", "ratio", "cpu mov", "cpu alone",
         "ratio", "built", "tiles", "moving - alone");
  for (int f = 0; f < n; f++) {
    const double *mv = m->by_pass + ((size_t)STREAM_MOVING * n + f) * MAX_PASSES,
                 *al = m->by_pass + ((size_t)STREAM_ALONE * n + f) * MAX_PASSES;
    int top[2] = {-1, -1};
    for (int i = 0; i < b->pass_count; i++) {
      double d = mv[i] - al[i];
      if (top[0] < 0 || d > mv[top[0]] - al[top[0]]) top[1] = top[0], top[0] = i;
      else if (top[1] < 0 || d > mv[top[1]] - al[top[1]]) top[1] = i;
    }
    printf("  %5d %8.2f %8.2f %6.2f %8.2f %8.2f %6.2f %2.0f/%-2.0f %3.0f/%-3.0f", f, m->wall[STREAM_MOVING * n + f],
           m->wall[STREAM_ALONE * n + f], ratio_of(m->wall[STREAM_MOVING * n + f], m->wall[STREAM_ALONE * n + f]),
           m->cpu[STREAM_MOVING * n + f], m->cpu[STREAM_ALONE * n + f],
           ratio_of(m->cpu[STREAM_MOVING * n + f], m->cpu[STREAM_ALONE * n + f]), m->compiles[STREAM_MOVING * n + f],
           m->compiles[STREAM_ALONE * n + f], m->tiles_drawn[STREAM_MOVING * n + f],
           m->tiles_drawn[STREAM_ALONE * n + f]);
    for (int j = 0; j < 2; j++)
      if (top[j] >= 0 && mv[top[j]] > al[top[j]])
        printf("  %s %+.2f", b->passes[top[j]].name, mv[top[j]] - al[top[j]]);
    printf("\n");
  }
  printf("  (built: programs compiled in the frame, moving/alone; tiles: moving/alone; the frame's wall time less\n"
         "  its passes' is the Lua script, the graph and the uploads)\n");
}

static void print_motion(const bench *b) {
  const motion *m = &b->motion;
  printf("motion at %dx%d: medians of %d frames after %d warm-up, the three renderers taking turns frame by frame\n",
         b->sizes[b->largest][0], b->sizes[b->largest][1], m->frames, b->warmup);
  if (m->orbit)
    printf("  camera: an orbit around (%.4g, %.4g, %.4g), radius %.4g, elevation %.4g degrees, %.4g degrees a frame\n",
           m->centre[0], m->centre[1], m->centre[2], m->radius, m->elevation, m->step);
  else if (m->walk > 0)
    printf("  camera: the scene's camera '%s' walking forward, %.4g of the scene's diagonal a frame\n", m->camera,
           m->walk);
  else
    printf("  camera: the scene's camera '%s', moved by the animation\n", m->camera);
  if (m->timed)
    printf("  animation '%s' from %.4g to %.4g s at %.4g fps: lm_scene_set_time "
           "before each frame, in its time\n", b->motion.animation, m->start, m->stop, m->fps);
  printf("  still: the path's first view held; moving: the path, every cache on, histories carried;\n"
         "  alone: each moving frame again with every cache off (every shadow tile drawn, no temporal history\n"
         "  or settled skip) and no previous frame (lm_renderer_set_view); its options:\n    %s\n",
         m->caches_off[0] ? m->caches_off : "none to turn off");
  printf("  %-24s %10s %10s %10s %13s %13s\n", "pass (ms)", "still", "moving", "alone", "moving/still", "moving/alone");
  double still_none[STREAMS] = {-1, m->animate_ms[STREAM_MOVING], m->animate_ms[STREAM_ALONE]};
  motion_row("frame (wall)", m->frame_ms);
  motion_row("outside the passes", m->outside_ms);
  if (m->timed) motion_row("animate (cpu)", still_none);
  for (int i = 0; i < b->pass_count; i++) {
    const double *t = b->passes[i].motion_ms;
    if (t[0] >= 0 || t[1] >= 0 || t[2] >= 0) motion_row(b->passes[i].name, t);
  }
  printf("  %-24s %10.0f %10.0f %10.0f\n", "shadow tiles drawn", m->tiles[0], m->tiles[1], m->tiles[2]);
  printf("  %-24s %10.0f %10.0f %10.0f\n", "  of them scrolled", m->scrolled[0], m->scrolled[1], m->scrolled[2]);
  for (int d = 0; d < DRAW_FIGURES; d++)
    printf("  %-24s %10.0f %10.0f %10.0f\n", draw_names[d], m->draw_median[0][d], m->draw_median[1][d],
           m->draw_median[2][d]);
  printf("  (-: the pass did not run there; outside the passes: the frame's wall time less its passes'\n"
         "  times, with the pass clock cpu: Lua, graph compilation, uploads)\n");
  printf("  the moving camera moved in %d of %d frames\n", m->moved, m->frames);
  print_motion_frames(b);
  double r = ratio_of(m->frame_ms[1], m->frame_ms[2]);
  printf("target: a frame of a sequence within %.1fx of the same frame alone with every cache off: moving / alone "
         "%.3f (frame medians, wall), worst frame %.3f wall, %.3f process CPU time (median %.3f), "
         "judged on the %s: %s\n",
         MOTION_TARGET, r, m->ratio_worst, m->cpu_worst, m->cpu_ratio, m->software ? "CPU time" : "wall time",
         motion_pass(m) ? "PASS" : "FAIL");
}

/* print_motion's figures as JSON: the two read alike. */
static void print_motion_json(const bench *b) {
  const motion *m = &b->motion;
  printf(", \"motion\": {\"width\": %d, \"height\": %d, \"frames\": %d, \"warmup\": %d, \"camera\": ",
         b->sizes[b->largest][0], b->sizes[b->largest][1], m->frames, b->warmup);
  if (m->orbit)
    printf("{\"orbit\": {\"centre\": [%.6g, %.6g, %.6g], \"radius\": %.6g, \"elevation\": %.6g, \"step\": %.6g}}",
           m->centre[0], m->centre[1], m->centre[2], m->radius, m->elevation, m->step);
  else {
    printf("{\"scene\": ");
    limn_json_string(m->camera);
    if (m->walk > 0) printf(", \"walk\": %.6g", m->walk);
    printf("}");
  }
  if (m->timed) {
    printf(", \"time\": {\"animation\": ");
    limn_json_string(m->animation);
    printf(", \"start\": %.6g, \"stop\": %.6g, \"fps\": %.6g}", m->start, m->stop, m->fps);
  } else {
    printf(", \"time\": null");
  }
  for (int k = 0; k < STREAMS; k++) {
    printf(", \"%s\": {\"frame_ms\": %.6g, \"outside_passes_ms\": %.6g, \"shadow_tiles_drawn\": %.6g, \"shadow_tiles_scrolled\": %.6g",
           stream_names[k], m->frame_ms[k], m->outside_ms[k], m->tiles[k], m->scrolled[k]);
    if (m->timed && k != STREAM_STILL) printf(", \"animate_ms\": %.6g", m->animate_ms[k]);
    for (int d = 0; d < DRAW_FIGURES; d++) printf(", \"%s\": %.6g", draw_keys[d], m->draw_median[k][d]);
    printf("}");
  }
  printf(", \"passes\": [");
  bool first = true;
  for (int i = 0; i < b->pass_count; i++) {
    const double *t = b->passes[i].motion_ms;
    if (t[0] < 0 && t[1] < 0 && t[2] < 0) continue;
    printf("%s{\"name\": ", first ? "" : ", ");
    limn_json_string(b->passes[i].name);
    for (int k = 0; k < STREAMS; k++) printf(t[k] < 0 ? ", \"%s\": null" : ", \"%s\": %.6g", stream_names[k], t[k]);
    printf("}");
    first = false;
  }
  printf("], \"camera_positions\": [");
  for (int f = 0; f < m->frames; f++)
    printf("%s[%.6g, %.6g, %.6g]", f ? ", " : "", m->eye[f][0], m->eye[f][1], m->eye[f][2]);
  double r = ratio_of(m->frame_ms[1], m->frame_ms[2]);
  printf("], \"per_frame\": {");
  static const char *const rows[] = {"moving_ms", "alone_ms", "moving_cpu_ms", "alone_cpu_ms"};
  for (int j = 0; j < 4; j++) {
    const double *v = (j < 2 ? m->wall : m->cpu) + (j % 2 ? STREAM_ALONE : STREAM_MOVING) * m->frames;
    printf("%s\"%s\": [", j ? "], " : "", rows[j]);
    for (int f = 0; f < m->frames; f++) printf("%s%.6g", f ? ", " : "", v[f]);
  }
  printf("]}, \"alone_options\": ");
  limn_json_string(m->caches_off);
  printf(", \"moved\": %d, \"target\": {\"limit\": %.6g, \"moving_over_alone\": %.6g, \"worst_frame\": %.6g, "
         "\"worst_frame_cpu\": %.6g, \"cpu_median\": %.6g, \"judged_on\": \"%s\", \"pass\": %s}}", m->moved,
         MOTION_TARGET, r, m->ratio_worst, m->cpu_worst, m->cpu_ratio, m->software ? "cpu" : "wall", motion_pass(m) ? "true" : "false");
}

static void print_json(const bench *b, lm_clock clock) {
  printf("{\"clock\": ");
  limn_json_string(lm_clock_name(clock));
  printf(", \"peak_rss_kib\": %ld, \"first_frame_ms\": %.6g, \"load_ms\": %.6g, \"first_frame_rss_kib\": %ld",
         peak_rss_kib(), b->first_frame_ms, b->load_ms, b->first_frame_rss_kib);
  if (b->gpu_mib >= 0) printf(", \"gpu_memory_mib\": %.6g", b->gpu_mib);
  const mesh_figures *mf = &b->meshes;
  printf(", \"meshes\": {\"count\": %d, \"triangles\": %ld, \"nodes\": %d, \"shared\": %d, \"shared_nodes\": %d, "
         "\"caster_copies\": %d, \"caster_coarsest_share\": %.6g, \"camera_copies\": %d, \"camera_coarsest_share\": %.6g}",
         mf->meshes, mf->triangles, mf->nodes, mf->shared, mf->shared_nodes, mf->casters,
         share(mf->caster_triangles, mf->caster_full) / 100, mf->lods, share(mf->lod_triangles, mf->lod_full) / 100);
  printf(", \"frames\": %d, \"warmup\": %d, \"sizes\": [", b->frames, b->warmup);
  for (int s = 0; s < b->size_count; s++) {
    printf("%s{\"width\": %d, \"height\": %d, \"frame_ms\": %.6g, \"overhead_ms\": %.6g", s ? ", " : "",
           b->sizes[s][0], b->sizes[s][1], b->frame_ms[s], b->overhead_ms[s]);
    double fp, fr;
    if (shadow_fit_ms(b, s, &fp, &fr)) printf(", \"shadow_fit_ms\": %.6g, \"shadow_readback_ms\": %.6g", fp + fr, fr);
    double cpu;
    if (cpu_pass_ms(b, s, &cpu)) printf(", \"cpu_pass_ms\": %.6g", cpu);
    printf("}");
  }
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
    if (fit(b, p, false, &a, &sl, &r2)) printf("], \"fit\": {\"ms\": %.6g, \"ns_per_pixel\": %.6g, \"r2\": %.6g}", a, sl * 1e6, r2);
    else printf("], \"fit\": null");
    if (b->vary_count) {
      printf(", \"vary_ms\": [");
      for (int v = 0; v < b->vary_count; v++)
        printf(p->vary_ms[v] < 0 ? "%snull" : "%s%.6g", v ? ", " : "", p->vary_ms[v]);
      if (fit(b, p, true, &a, &sl, &r2)) printf("], \"vary_fit\": {\"ms\": %.6g, \"ms_per_unit\": %.6g, \"r2\": %.6g}", a, sl, r2);
      else printf("], \"vary_fit\": null");
    }
    double rate, share, eq;
    if (fetch_figures(b, p, &rate, &share, &eq)) {
      printf(", \"fetches_per_pixel_equivalent\": %.6g", eq);
      if (p->fetches > 0)
        printf(", \"fetches_per_pixel\": %.6g, \"fetches_per_second\": %.6g, \"share_of_calibration\": %.6g",
               p->fetches, rate, share);
    }
    printf("}");
  }
  printf("]");
  if (b->vary_count) {
    printf(", \"vary\": {\"option\": ");
    limn_json_string(b->vary_name);
    printf(", \"values\": [");
    for (int v = 0; v < b->vary_count; v++) printf("%s%.6g", v ? ", " : "", b->vary[v]);
    printf("]}");
  }
  if (b->trace) {
    double frame = b->frame_ms[b->largest];
    printf(", \"trace\": {\"threads\": %d, \"triangles\": %d, \"skipped\": %d, \"meshes\": %d, \"instances\": %d, \"build_ms\": %.6g, "
           "\"rays\": %d, \"ms\": %.6g, \"cpu_ms\": %.6g, \"rays_per_second\": %.6g, \"frame_rays\": %d, \"frame_trace_ms\": %.6g, "
           "\"ratio_to_frame\": %.6g}",
           b->trace_threads, b->trace_stats.triangles, b->trace_stats.skipped, b->trace_stats.meshes, b->trace_stats.instances,
           b->trace_stats.build_ms, b->trace_rays, b->trace_ms, b->trace_cpu_ms, rays_per_s(b->trace_rays, b->trace_ms), b->frame_rays,
           b->frame_trace_ms, frame > 0 ? b->frame_trace_ms / frame : 0);
  }
  double all_ms, set_ms;
  int all = lm_programs_stats(NULL, &all_ms), sets = lm_programs_stats("LIGHT_SET", &set_ms);
  printf(", \"programs\": {\"count\": %d, \"build_ms\": %.6g, \"light_set_variants\": %d, \"light_set_build_ms\": %.6g}",
         all, all_ms, sets, set_ms);
  if (b->ns_per_fetch > 0) printf(", \"calibration\": {\"ns_per_fetch\": %.6g}", b->ns_per_fetch);
  else printf(", \"calibration\": null");
  if (b->motion.on) print_motion_json(b);
  printf("}\n");
}

/* The calibration pass with 8 and 64 fetches a pixel: the time per fetch is
 * the difference over 56 fetches a pixel. At the largest size but at least
 * 256x192, after at least 2 warm-up frames (the first compiles), median of
 * at least 3: small or cold runs drown the difference in noise. */
static bool calibrate(bench *b, lm_scene *scene, lm_error *err) {
  static bench cal; /* large: off the stack */
  char path[1100];
  snprintf(path, sizeof path, "%s/scripts/calibrate.lua", lm_root_dir());
  lm_pipeline *pipe = lm_pipeline_load(&(lm_pipeline_desc){.path = path}, err);
  if (!pipe) return false;
  double ms[2] = {-1, -1};
  const char *counts[2] = {"8", "64"};
  bool ok = true;
  for (int k = 0; k < 2 && ok; k++) {
    cal = (bench){.frames = b->frames > 3 ? b->frames : 3, .warmup = b->warmup > 2 ? b->warmup : 2,
                  .clock = b->clock, .size_count = 1};
    memcpy(cal.sizes[0], b->sizes[b->largest], sizeof cal.sizes[0]);
    if ((double)cal.sizes[0][0] * cal.sizes[0][1] < 256.0 * 192.0) cal.sizes[0][0] = 256, cal.sizes[0][1] = 192;
    lm_clock used;
    ok = lm_pipeline_set_option(pipe, "fetches", counts[k], err) && run_size(&cal, 0, SERIES_SIZES, scene, pipe, &used, err);
    for (int i = 0; i < cal.pass_count && ok; i++)
      if (!strcmp(cal.passes[i].name, "calibrate")) ms[k] = cal.passes[i].ms[0];
  }
  lm_pipeline_destroy(pipe);
  double pixels = (double)cal.sizes[0][0] * cal.sizes[0][1];
  b->calibration_size[0] = cal.sizes[0][0], b->calibration_size[1] = cal.sizes[0][1];
  b->ns_per_fetch = ok && ms[1] > ms[0] && ms[0] >= 0 ? (ms[1] - ms[0]) * 1e6 / (56.0 * pixels) : 0;
  return ok;
}

/* Adds lights from..to-1 of a fixed sequence of small white point lights,
 * uniformly over the scene's bounding box, their range `reach` times its
 * diagonal (no unit), casting no shadows. */
static void scatter_lights(lm_scene *s, int from, int to, double reach) {
  float lo[3], hi[3];
  lm_scene_bounds(s, lo, hi);
  float diag = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
  for (int i = from; i < to; i++) {
    uint32_t h = 2166136261u ^ (uint32_t)i;
    float p[3], m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (int c = 0; c < 3; c++) {
      h = h * 1664525u + 1013904223u;
      p[c] = lo[c] + (hi[c] - lo[c]) * (float)(h >> 8) / 16777216.0f;
    }
    memcpy(m + 12, p, sizeof p);
    char name[LM_NAME_MAX];
    snprintf(name, sizeof name, "bench_light_%d", i);
    int node = lm_scene_add_node(s, name, -1, m, -1, -1);
    lm_light l = {.type = LM_LIGHT_POINT, .color = {1, 1, 1}, .power = 1, .radius = (float)reach * diag,
                  .falloff = LM_FALLOFF_WINDOW, .node = node};
    snprintf(l.name, sizeof l.name, "%s", name);
    lm_scene_add_light(s, &l);
  }
  lm_scene_update(s);
}

/* The --lights series: lights a covered pixel evaluates, each pass's time
 * culled and with every light everywhere, and lines fitted to both. */
static void print_lights(const bench *b) {
  printf("--lights at %dx%d: %d scene light(s) plus N small ones (range %.3g of the bounding-box diagonal)\n",
         b->sizes[b->largest][0], b->sizes[b->largest][1], b->scene_lights, b->light_reach);
  printf("  %-24s", "N");
  for (int v = 0; v < b->lights_count; v++) printf(" %13d", b->lights[v]);
  printf("\n  %-24s", "lights/pixel culled");
  for (int v = 0; v < b->lights_count; v++) printf(" %13.2f", b->per_pixel[0][v]);
  printf("\n  %-24s", "lights/pixel all");
  for (int v = 0; v < b->lights_count; v++) printf(" %13.2f", b->per_pixel[1][v]);
  printf("\n  pass: ms culled / all      fits: culled against lights/pixel | culled against N | all against N\n");
  double n[MAX_SIZES];
  for (int v = 0; v < b->lights_count; v++) n[v] = b->lights[v];
  for (int i = 0; i < b->pass_count; i++) {
    const bench_pass *p = &b->passes[i];
    if (p->lights_ms[0][0] < 0) continue;
    printf("  %-24s", p->name);
    for (int v = 0; v < b->lights_count; v++) printf(" %6.1f/%-6.1f", p->lights_ms[0][v], p->lights_ms[1][v]);
    double a, sl, r2;
    const double *fits[3][2] = {{b->per_pixel[0], p->lights_ms[0]}, {n, p->lights_ms[0]}, {n, p->lights_ms[1]}};
    for (int f = 0; f < 3; f++) {
      if (fit_line(fits[f][0], fits[f][1], b->lights_count, &a, &sl, &r2))
        printf("%s%.1f + %.2f x (r2 %.2f)", f ? " | " : "  ", a, sl, r2);
      else
        printf("%s-", f ? " | " : "  ");
    }
    printf("\n");
  }
}

int limn_bench(int argc, char **argv) {
  static bench b; /* large: keep it off the stack */
  int rc = parse_args(argc, argv, &b);
  if (rc) return rc < 0 ? 0 : rc;
  b.start_ms = lm_now_ms();
  b.gpu_mib = -1;
  lm_error err;
  int prc;
  lm_pipeline *pipe = capture_load_pipeline(&b.common, &prc, &err);
  if (!pipe) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return prc;
  }
  if (!lm_context_create_headless(&(lm_context_desc){.platform = "auto"}, &err)) {
    lm_log(LM_LOG_ERROR, "no OpenGL context: %s", err.msg);
    lm_pipeline_destroy(pipe);
    return 1;
  }
  double t0 = lm_now_ms();
  /* To the GPU as it is read; the tracer's figures read the vertices back (trace_figures). */
  lm_scene *scene = lm_scene_load_gpu(b.common.scene, &err);
  b.load_ms = lm_now_ms() - t0;
  motion *m = &b.motion;
  if (scene && m->timed) {
    m->anim = lm_scene_find_animation(scene, m->animation, &err);
    if (m->anim >= LM_ANIM_ALL && !lm_scene_animated(scene))
      lm_error_set(&err, "--time: scene '%s' has no animation", scene->name), m->anim = -3;
    if (m->anim < LM_ANIM_ALL) lm_scene_destroy(scene), scene = NULL;
  }
  if (!scene) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    lm_pipeline_destroy(pipe);
    lm_context_destroy();
    return 2;
  }
  bool ok = true;
  lm_clock used = LM_CLOCK_AUTO;
  for (int s = 0; s < b.size_count && ok; s++) ok = run_size(&b, s, SERIES_SIZES, scene, pipe, &used, &err);
  for (int v = 0; v < b.vary_count && ok; v++) {
    ok = lm_pipeline_set_option(pipe, b.vary_name, b.vary_text[v], &err);
    if (ok) ok = run_size(&b, v, SERIES_VARY, scene, pipe, &used, &err);
  }
  b.scene_lights = scene->light_count;
  for (int v = 0; v < b.lights_count && ok; v++) {
    scatter_lights(scene, scene->light_count - b.scene_lights, b.lights[v], b.light_reach);
    ok = run_size(&b, v, SERIES_LIGHTS, scene, pipe, &used, &err) &&
         run_size(&b, v, SERIES_LIGHTS_ALL, scene, pipe, &used, &err);
  }
  if (ok) b.meshes = count_meshes(scene); /* after a frame: the copies are made by then (lm_scene_upload) */
  if (ok && m->on) ok = run_motion(&b, scene, &err);
  if (ok) ok = calibrate(&b, scene, &err);
  if (ok && b.trace) trace_figures(&b, scene);
  if (ok) {
    if (b.json) print_json(&b, used);
    else print_tables(&b, used);
    if (b.lights_count && !b.json) print_lights(&b); /* tables only */
    if (b.trace && !b.json) print_trace(&b);
    if (m->on && !b.json) print_motion(&b);
  } else {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
  }
  free(m->eye);
  free(m->wall);
  free(m->by_pass);
  free(m->draws);
  lm_programs_clear();
  lm_scene_destroy(scene);
  lm_context_destroy();
  lm_pipeline_destroy(pipe);
  return ok ? 0 : 1;
}
