/* limn graph: one frame's frame graph (its passes, the targets each reads
 * and writes, the passes culled, each pass's time) as SVG or Graphviz DOT,
 * for docs and reviews; what the viewer's panel shows under "frame graph". */
#define _GNU_SOURCE
#include <getopt.h>
#include <math.h>
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

/* Does a pass after pass i read what it wrote to target t? */
static bool read_later(lm_graph *g, int i, int t) {
  for (int j = i + 1; j < lm_graph_pass_count(g); j++) {
    const lm_pass_desc *d = lm_graph_pass(g, j).desc;
    for (int k = 0; k < d->input_count; k++)
      if (d->inputs[k].target == t && lm_graph_input_writer(g, j, k) == i) return true;
  }
  return false;
}

/* A target as a DOT node (once): what a pass reads of the last frame, or
 * writes that no later pass reads (the presented frame, a history). */
static void dot_target(FILE *f, lm_graph *g, int t, bool *seen) {
  if (seen[t]) return;
  lm_graph_target_info info = lm_graph_target(g, t);
  fprintf(f, "  t%d [shape=ellipse, label=\"", t);
  escaped(f, info.name, true);
  fprintf(f, "\\n%s %dx%d\"];\n", lm_format_name(info.format), info.width, info.height);
  seen[t] = true;
}

/* Passes as boxes, an edge labelled with the target from each output to
 * each later pass that reads it; targets as ellipses where the frame begins
 * (read of the last frame) or ends (written, read by no later pass). */
static void write_dot(FILE *f, lm_graph *g) {
  fprintf(f, "digraph frame {\n  rankdir=LR;\n  node [fontname=\"DejaVu Sans Mono\", fontsize=10];\n");
  int count = lm_graph_target_count(g);
  bool *seen = calloc((size_t)count + 1, 1);
  int ends[LM_MAX_PASS_INPUTS + LM_MAX_COLOR_OUTPUTS + 1];
  for (int i = 0; i < lm_graph_pass_count(g); i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    const char *grey = p.culled ? " [color=gray70, fontcolor=gray55]" : "";
    fprintf(f, "  p%d [shape=box, label=\"", i);
    escaped(f, p.name, true);
    if (p.culled) fprintf(f, "\\n(culled)\", style=filled, fillcolor=gray92, fontcolor=gray55, color=gray70];\n");
    else fprintf(f, "\\n%.3f ms\", style=filled, fillcolor=lightsteelblue1];\n", p.ms > 0 ? p.ms : 0);
    int n = pass_targets(p.desc, true, ends);
    for (int k = 0; k < n; k++) {
      int w = lm_graph_input_writer(g, i, k);
      if (w < 0) {
        dot_target(f, g, ends[k], seen);
        fprintf(f, "  t%d -> p%d%s;\n", ends[k], i, grey);
        continue;
      }
      fprintf(f, "  p%d -> p%d [label=\"", w, i);
      escaped(f, lm_graph_target(g, ends[k]).name, true);
      fprintf(f, "\"%s];\n", p.culled || lm_graph_pass(g, w).culled ? ", color=gray70, fontcolor=gray55" : "");
    }
    n = pass_targets(p.desc, false, ends);
    for (int k = 0; k < n; k++) {
      if (read_later(g, i, ends[k])) continue;
      dot_target(f, g, ends[k], seen);
      fprintf(f, "  p%d -> t%d%s;\n", i, ends[k], grey);
    }
  }
  fprintf(f, "}\n");
  free(seen);
}

/* The graph as the viewer's panel draws it: a column for each depth
 * (lm_graph_pass_depths), each pass a box with its name, its time as a bar
 * of the longest pass's, the targets it reads down its left edge and those
 * it writes down its right, and an edge from each output to each later pass
 * that reads it; culled passes and their edges grey. */
static void write_svg(FILE *f, lm_graph *g) {
  enum { LINE = 16, PAD = 6, GAP = 48 };
  const double advance = 7.3; /* DejaVu Sans Mono at 12 px */
  int n = lm_graph_pass_count(g), columns = 1, ends[LM_MAX_PASS_INPUTS + LM_MAX_COLOR_OUTPUTS + 1];
  int *depth = lm_alloc(sizeof *depth * (size_t)(n + 1));
  double *box = lm_alloc(sizeof *box * 4 * (size_t)(n + 1)); /* x, y, width, height of each */
  lm_graph_pass_depths(g, depth);
  for (int i = 0; i < n; i++) columns = depth[i] + 1 > columns ? depth[i] + 1 : columns;
  double *width = calloc((size_t)columns, sizeof *width), *bottom = calloc((size_t)columns, sizeof *bottom);
  double longest = 0;
  for (int i = 0; i < n; i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    size_t chars = strlen(p.name) > 12 ? strlen(p.name) : 12; /* at least "1234.567 ms" */
    int rows = 0;
    for (int side = 0; side < 2; side++) {
      int count = pass_targets(p.desc, side == 0, ends);
      for (int k = 0; k < count; k++) {
        size_t len = strlen(lm_graph_target(g, ends[k]).name);
        chars = len > chars ? len : chars;
      }
      rows += count;
    }
    box[4 * i + 2] = (double)chars * advance + 4 * PAD;
    box[4 * i + 3] = (2 + rows) * LINE + 2 * PAD;
    if (box[4 * i + 2] > width[depth[i]]) width[depth[i]] = box[4 * i + 2];
    if (!p.culled && p.ms > longest) longest = p.ms;
  }
  double x = PAD, height = 0;
  for (int c = 0; c < columns; c++) {
    for (int i = 0; i < n; i++) {
      if (depth[i] != c) continue;
      box[4 * i] = x, box[4 * i + 1] = bottom[c] + PAD;
      bottom[c] = box[4 * i + 1] + box[4 * i + 3] + LINE;
    }
    height = bottom[c] > height ? bottom[c] : height;
    x += width[c] + GAP;
  }
  fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
             "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
             "font-family=\"DejaVu Sans Mono, monospace\" font-size=\"12\">\n",
          x - GAP + PAD, height + PAD);
  /* Edges first, under the boxes: from the writer's row of the target to the reader's. */
  for (int i = 0; i < n; i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    for (int k = 0; k < p.desc->input_count; k++) {
      int w = lm_graph_input_writer(g, i, k), t = p.desc->inputs[k].target, row = 0;
      if (w < 0) continue;
      lm_graph_pass_info from = lm_graph_pass(g, w);
      int outs = pass_targets(from.desc, false, ends);
      while (row < outs - 1 && ends[row] != t) row++;
      double ax = box[4 * w] + box[4 * w + 2], ay = box[4 * w + 1] + PAD + (2 + from.desc->input_count + row + 0.5) * LINE;
      double bx = box[4 * i], by = box[4 * i + 1] + PAD + (2 + k + 0.5) * LINE;
      double bend = fabs(bx - ax) * 0.4 > GAP ? fabs(bx - ax) * 0.4 : GAP;
      bool grey = p.culled || from.culled;
      fprintf(f, "  <path class=\"edge%s\" data-from=\"p%d\" data-to=\"p%d\" data-target=\"", grey ? " culled" : "",
              w, i);
      escaped(f, lm_graph_target(g, t).name, false);
      fprintf(f, "\" d=\"M%.1f %.1f C%.1f %.1f %.1f %.1f %.1f %.1f\" fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\">"
                 "<title>", ax, ay, ax + bend, ay, bx - bend, by, bx, by, grey ? "#cccccc" : "#6688aa");
      escaped(f, from.name, false);
      fputs(" -> ", f);
      escaped(f, p.name, false);
      fputs(": ", f);
      escaped(f, lm_graph_target(g, t).name, false);
      fprintf(f, "</title></path>\n");
    }
  }
  for (int i = 0; i < n; i++) {
    lm_graph_pass_info p = lm_graph_pass(g, i);
    double bx = box[4 * i], by = box[4 * i + 1], bw = box[4 * i + 2], bh = box[4 * i + 3];
    const char *ink = p.culled ? "#999999" : "#000000";
    fprintf(f, "  <g class=\"%s\" id=\"p%d\">\n", p.culled ? "pass culled" : "pass", i);
    fprintf(f, "    <rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" rx=\"4\" fill=\"%s\" stroke=\"%s\"/>\n",
            bx, by, bw, bh, p.culled ? "#eeeeee" : "#dde8f6", p.culled ? "#bbbbbb" : "#6688aa");
    fprintf(f, "    <text class=\"name\" x=\"%.1f\" y=\"%.1f\" fill=\"%s\">", bx + PAD, by + PAD + 12, ink);
    escaped(f, p.name, false);
    fprintf(f, "</text>\n");
    double bar_y = by + PAD + LINE;
    if (p.culled) {
      fprintf(f, "    <text x=\"%.1f\" y=\"%.1f\" fill=\"%s\">culled</text>\n", bx + PAD, bar_y + 12, ink);
    } else {
      double share = longest > 0 && p.ms > 0 ? p.ms / longest : 0;
      fprintf(f, "    <rect class=\"time\" x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%d\" fill=\"#e0a020\"/>\n",
              bx + PAD, bar_y + 2, share * (bw - 2 * PAD), LINE - 4);
      fprintf(f, "    <text x=\"%.1f\" y=\"%.1f\">%.3f ms</text>\n", bx + PAD + 2, bar_y + 12, p.ms > 0 ? p.ms : 0);
    }
    int row = 0;
    for (int side = 0; side < 2; side++) {
      int count = pass_targets(p.desc, side == 0, ends);
      for (int k = 0; k < count; k++, row++) {
        fprintf(f, "    <text class=\"%s\" x=\"%.1f\" y=\"%.1f\" fill=\"%s\"%s>", side ? "write" : "read",
                side ? bx + bw - PAD : bx + PAD, by + PAD + (2 + row) * LINE + 12, p.culled ? "#999999" : "#333333",
                side ? " text-anchor=\"end\"" : "");
        escaped(f, lm_graph_target(g, ends[k]).name, false);
        fprintf(f, "</text>\n");
      }
    }
    fprintf(f, "  </g>\n");
  }
  fprintf(f, "</svg>\n");
  free(depth);
  free(box);
  free(width);
  free(bottom);
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
