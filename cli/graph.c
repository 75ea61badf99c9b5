/* limn graph: one frame's frame graph (its passes, the targets each reads
 * and writes, the passes culled, each pass's time) as SVG or Graphviz DOT,
 * for docs and reviews; what the viewer's panel shows under "frame graph". */
#define _GNU_SOURCE
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "capture_render.h"
#include "scene/gltf.h"
#include "tools.h"

static const char graph_usage[] =
    "usage: limn graph --output FILE.svg|FILE.dot [options]\n"
    "\n"
    "Renders frames of a scene through a pipeline script (headless) and writes\n"
    "the last frame's graph: each pass as a box with the targets it reads and\n"
    "writes, passes the frame culled in grey, each pass's time as a bar (SVG)\n"
    "or in its label (DOT, for Graphviz).\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE    built-in scene or a .gltf/.glb file (default cornell)\n"
    "  --script FILE        pipeline script (default scripts/pp.lua)\n"
    "  --tech NAME          technique (default: the script's first)\n"
    "  --set NAME=VALUE     set an option the script declares (repeatable)\n"
    "  --size WxH           output size (default 256x192)\n"
    "  --camera N           camera index of the scene (default 0)\n"
    "  --frames N           frames to render first; the last one's graph and\n"
    "                       times are written (default 2: the first compiles)\n"
    "  --output FILE        .svg or .dot (required)\n"
    "  --quiet              errors only\n"
    "  --help               this text\n"
    "\n"
    "exit codes: 0 written, 1 failed (script, shader or GL error), 2 bad usage.\n";

typedef struct graph_args {
  limn_common_args common; /* --scene, --script, --tech, --set, --size, --camera */
  const char *output;
  int frames;
  bool dot, quiet;
} graph_args;

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("graph", fmt, arg); }

/* Returns 0 to go on, -1 when done (help), else the exit code. */
static int parse_args(int argc, char **argv, graph_args *a) {
  *a = (graph_args){.common = {.scene = "cornell", .script = "scripts/pp.lua", .width = 256, .height = 192},
                    .frames = 2};
  static const struct option opts[] = {
      {"scene", required_argument, 0, 's'}, {"script", required_argument, 0, 'p'},
      {"tech", required_argument, 0, 't'},  {"set", required_argument, 0, 'D'},
      {"size", required_argument, 0, 'z'},  {"camera", required_argument, 0, 'c'},
      {"frames", required_argument, 0, 'n'}, {"output", required_argument, 0, 'o'},
      {"quiet", no_argument, 0, 'q'},       {"help", no_argument, 0, 'h'},
      {0, 0, 0, 0}};
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    switch (c) {
    case 'n':
      if (!limn_parse_int(optarg, 1, 1000, &a->frames)) return usage_error("--frames wants 1..1000, not '%s'", optarg);
      break;
    case 'o': {
      const char *dot = strrchr(optarg, '.');
      if (!dot || (strcasecmp(dot, ".svg") && strcasecmp(dot, ".dot")))
        return usage_error("--output '%s': give a .svg or .dot file", optarg);
      a->output = optarg;
      a->dot = !strcasecmp(dot, ".dot");
      break;
    }
    case 'q': a->quiet = true; break;
    case 'h': fputs(graph_usage, stdout); return -1;
    default:
      if (limn_common_flag("graph", c, argv, &a->common)) return 2;
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (!a->output) return usage_error("%s", "--output FILE.svg|FILE.dot is required");
  return 0;
}

/* Text for XML (SVG) or a DOT string: the few characters each reserves escaped. */
static void escaped(FILE *f, const char *s, bool dot) {
  for (; *s; s++) {
    if (dot && (*s == '"' || *s == '\\')) fprintf(f, "\\%c", *s);
    else if (!dot && *s == '<') fputs("&lt;", f);
    else if (!dot && *s == '>') fputs("&gt;", f);
    else if (!dot && *s == '&') fputs("&amp;", f);
    else if (!dot && *s == '"') fputs("&quot;", f);
    else fputc(*s, f);
  }
}

/* The targets pass i reads (inputs) or writes (colour outputs, then depth) into out; their count. */
static int pass_targets(const lm_pass_desc *d, bool inputs, int *out) {
  int n = 0;
  if (inputs) {
    for (int k = 0; k < d->input_count; k++) out[n++] = d->inputs[k].target;
  } else {
    for (int k = 0; k < d->output_count; k++) out[n++] = d->outputs[k];
    if (d->depth >= 0) out[n++] = d->depth;
  }
  return n;
}

static void write_dot(FILE *f, lm_graph *g) {
  fprintf(f, "digraph frame {\n  rankdir=LR;\n  node [fontname=\"DejaVu Sans Mono\", fontsize=10];\n");
  int count = lm_graph_target_count(g);
  bool *seen = calloc((size_t)count + 1, 1);
  int ends[LM_MAX_PASS_INPUTS + LM_MAX_COLOR_OUTPUTS + 1];
  for (int i = 0; i < lm_graph_pass_count(g); i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    fprintf(f, "  p%d [shape=box, label=\"", i);
    escaped(f, p.name, true);
    if (p.culled) fprintf(f, "\\n(culled)\", style=filled, fillcolor=gray92, fontcolor=gray55, color=gray70];\n");
    else fprintf(f, "\\n%.3f ms\", style=filled, fillcolor=lightsteelblue1];\n", p.ms > 0 ? p.ms : 0);
    for (int side = 0; side < 2; side++) {
      int n = pass_targets(p.desc, side == 0, ends);
      for (int k = 0; k < n; k++) {
        if (ends[k] < 0 || ends[k] >= count) continue;
        if (!seen[ends[k]]) {
          lm_graph_target_info t = lm_graph_target(g, ends[k]);
          fprintf(f, "  t%d [shape=ellipse, label=\"", ends[k]);
          escaped(f, t.name, true);
          fprintf(f, "\\n%s %dx%d\"];\n", lm_format_name(t.format), t.width, t.height);
          seen[ends[k]] = true;
        }
        if (side == 0) fprintf(f, "  t%d -> p%d%s;\n", ends[k], i, p.culled ? " [color=gray70]" : "");
        else fprintf(f, "  p%d -> t%d%s;\n", i, ends[k], p.culled ? " [color=gray70]" : "");
      }
    }
  }
  fprintf(f, "}\n");
  free(seen);
}

/* Passes top to bottom in recording order, each a box: its name and time, a
 * bar of its share of the longest pass, the targets it reads and writes. */
static void write_svg(FILE *f, lm_graph *g) {
  enum { WIDTH = 760, ROW = 58, BAR = 300 };
  int passes = lm_graph_pass_count(g);
  double longest = 0;
  for (int i = 0; i < passes; i++) longest = lm_graph_pass(g, i).ms > longest ? lm_graph_pass(g, i).ms : longest;
  fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
             "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
             "font-family=\"DejaVu Sans Mono, monospace\" font-size=\"12\">\n",
          WIDTH, ROW * passes + 8);
  int ends[LM_MAX_PASS_INPUTS + LM_MAX_COLOR_OUTPUTS + 1];
  for (int i = 0; i < passes; i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    int y = 4 + i * ROW;
    fprintf(f, "  <g class=\"%s\">\n", p.culled ? "pass culled" : "pass");
    fprintf(f, "    <rect x=\"4\" y=\"%d\" width=\"%d\" height=\"%d\" rx=\"4\" fill=\"%s\" stroke=\"%s\"/>\n", y,
            WIDTH - 8, ROW - 6, p.culled ? "#eeeeee" : "#dde8f6", p.culled ? "#bbbbbb" : "#6688aa");
    fprintf(f, "    <text class=\"name\" x=\"12\" y=\"%d\" fill=\"%s\">", y + 16, p.culled ? "#999999" : "#000000");
    escaped(f, p.name, false);
    fprintf(f, "</text>\n");
    if (p.culled) {
      fprintf(f, "    <text x=\"%d\" y=\"%d\" fill=\"#999999\">culled: nothing it writes reaches the output</text>\n",
              WIDTH - 8 - BAR, y + 16);
    } else {
      double share = longest > 0 && p.ms > 0 ? p.ms / longest : 0;
      fprintf(f, "    <rect class=\"time\" x=\"%d\" y=\"%d\" width=\"%.1f\" height=\"10\" fill=\"#e0a020\"/>\n",
              WIDTH - 8 - BAR, y + 7, share * (BAR - 80));
      fprintf(f, "    <text x=\"%d\" y=\"%d\" text-anchor=\"end\">%.3f ms</text>\n", WIDTH - 14, y + 16,
              p.ms > 0 ? p.ms : 0);
    }
    for (int side = 0; side < 2; side++) {
      int n = pass_targets(p.desc, side == 0, ends);
      fprintf(f, "    <text class=\"%s\" x=\"12\" y=\"%d\" fill=\"%s\">%s", side ? "writes" : "reads",
              y + 32 + 14 * side, p.culled ? "#999999" : "#333333", side ? "out:" : " in:");
      for (int k = 0; k < n; k++) {
        if (ends[k] < 0 || ends[k] >= lm_graph_target_count(g)) continue;
        fputc(' ', f);
        escaped(f, lm_graph_target(g, ends[k]).name, false);
      }
      fprintf(f, "</text>\n");
    }
    fprintf(f, "  </g>\n");
  }
  fprintf(f, "</svg>\n");
}

int limn_graph(int argc, char **argv) {
  graph_args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc < 0 ? 0 : rc;
  const limn_common_args *o = &a.common;
  if (a.quiet) lm_log_set_level(LM_LOG_WARN);
  lm_error err;
  lm_pipeline *pipeline = capture_load_pipeline(o, &rc, &err);
  if (!pipeline) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return rc;
  }
  lm_scene *scene = lm_scene_load(o->scene, &err);
  if (!rc && !scene) rc = 2;
  if (!rc && o->camera > 0 && o->camera >= scene->camera_count) {
    lm_error_set(&err, "--camera %d: scene '%s' has %d camera(s)", o->camera, o->scene, scene->camera_count);
    rc = 2;
  }
  if (!rc && !lm_context_create_headless(&(lm_context_desc){0}, &err)) rc = 1;
  lm_renderer *r = NULL;
  if (!rc && !(r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = pipeline, .width = o->width,
                                                           .height = o->height, .camera = o->camera}, &err)))
    rc = 1;
  for (int i = 0; i < a.frames && !rc; i++)
    if (!lm_renderer_frame(r, &err)) rc = 1;
  /* Whole or not at all: a temporary file renamed. */
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp", a.output);
  FILE *f = rc ? NULL : fopen(tmp, "w");
  if (!rc && !f) {
    lm_error_set(&err, "cannot write %s", a.output);
    rc = 1;
  }
  if (f) {
    if (a.dot) write_dot(f, lm_renderer_graph(r));
    else write_svg(f, lm_renderer_graph(r));
    if (fclose(f) != 0 || rename(tmp, a.output) != 0) {
      remove(tmp);
      lm_error_set(&err, "cannot write %s", a.output);
      rc = 1;
    } else if (!a.quiet) {
      lm_info("wrote %s: %d passes of %s on %s at %dx%d", a.output, lm_graph_pass_count(lm_renderer_graph(r)),
              lm_pipeline_technique(pipeline), o->scene, o->width, o->height);
    }
  }
  if (rc) lm_log(LM_LOG_ERROR, "%s", err.msg);
  lm_renderer_destroy(r);
  lm_programs_clear();
  lm_scene_destroy(scene);
  lm_pipeline_destroy(pipeline);
  lm_context_destroy();
  return rc;
}
