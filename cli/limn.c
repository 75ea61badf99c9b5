/* limn: the command-line front end. */
#include <stdio.h>
#include <string.h>

#include "tools.h"

static const char usage[] =
    "usage: limn <command> [options]\n"
    "\n"
    "Limn renders scenes through Lua pipeline scripts (scripts/pp.lua).\n"
    "\n"
    "commands:\n"
    "  capture   render headless (EGL, no window) to PNG or EXR and print per-pass times\n"
    "  export-pov  one view of a scene as POV-Ray 3.7 scene description (references)\n"
    "  export-gltf  a scene as Limn loads it, as glTF (for Blender: Cycles references)\n"
    "  compare   mean error, RMSE, PSNR, Pearson, SSIM of two images; difference image\n"
    "  reference  POV-Ray (radiosity) or Cycles references of a capture job's views, cached by hash\n"
    "  report    error against POV-Ray or Cycles references and run time for a sweep of techniques\n"
    "  farm      a capture job (and its references) as a Slurm job array: limn farm slurm\n"
    "  manifest  merge the manifests of a sharded capture job: limn manifest merge\n"
    "  bench     compositor overhead per frame and pass times against resolution\n"
    "  view      a window with live reload of scripts and shaders, timings, target inspector\n"
    "  graph     one frame's frame graph (passes, targets, culled passes, times) as SVG or DOT\n"
    "  help      this text; `limn <command> --help` describes a command's flags\n"
    "\n"
    "example:\n"
    "  limn capture --scene cornell --script scripts/pp.lua --tech dl --size 256x192 --output out.png\n"
    "\n"
    "every command and flag, with what lies behind them: docs/commands.md\n";

int main(int argc, char **argv) {
  if (argc < 2) {
    fputs(usage, stderr);
    return 2;
  }
  const char *cmd = argv[1];
  if (!strcmp(cmd, "help") || !strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
    fputs(usage, stdout);
    return 0;
  }
  if (!strcmp(cmd, "capture")) return limn_capture(argc - 1, argv + 1);
  if (!strcmp(cmd, "view")) return limn_view(argc - 1, argv + 1);
  if (!strcmp(cmd, "graph")) return limn_graph(argc - 1, argv + 1);
  if (!strcmp(cmd, "export-pov")) return limn_export_pov(argc - 1, argv + 1);
  if (!strcmp(cmd, "export-gltf")) return limn_export_gltf(argc - 1, argv + 1);
  if (!strcmp(cmd, "compare")) return limn_compare(argc - 1, argv + 1);
  if (!strcmp(cmd, "reference")) return limn_reference(argc - 1, argv + 1);
  if (!strcmp(cmd, "report")) return limn_report(argc - 1, argv + 1);
  if (!strcmp(cmd, "farm")) return limn_farm(argc - 1, argv + 1);
  if (!strcmp(cmd, "manifest")) return limn_manifest(argc - 1, argv + 1);
  if (!strcmp(cmd, "bench")) return limn_bench(argc - 1, argv + 1);
  fprintf(stderr, "limn: unknown command '%s'\n\n%s", cmd, usage);
  return 2;
}
