/* limn export-gltf: a scene as Limn loads it, written as glTF
 * (engine/scene/gltf.h: lm_scene_write_gltf), for another renderer to import:
 * the built-in scenes, and a file's scene posed at a time. */
#define _GNU_SOURCE
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "scene/gltf.h"
#include "tools.h"

static const char export_gltf_usage[] =
    "usage: limn export-gltf [--scene NAME|FILE] [--time SECONDS [--animation NAME|INDEX|all]]\n"
    "                        --output FILE.glb|FILE.gltf\n"
    "\n"
    "Writes the scene as Limn loads it (a built-in one, or a glTF file posed at a\n"
    "time) as glTF 2.0: nodes at their pose, meshes as posed, materials as glTF\n"
    "metallic-roughness with Limn's Phong values in each material's extras.limn,\n"
    "lights as KHR_lights_punctual in glTF's units (candela, lux), cameras.\n"
    "What glTF cannot hold as Limn has it (a window falloff, a Phong material no\n"
    "metallic-roughness one reads back as, animations) is written in its nearest\n"
    "form with a warning naming it. Textures go beside the file as PNG.\n"
    "Blender imports the file (File > Import > glTF 2.0), as limn reference\n"
    "--renderer cycles does.\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE    built-in scene or .gltf/.glb file (default cornell;\n"
    "                       built in: %s)\n"
    "  --time SECONDS       pose the scene's animation at that time (default: the\n"
    "                       rest pose as loaded)\n"
    "  --animation NAME|INDEX|all   the animation posed (default all)\n"
    "  --output FILE        .glb (binary) or .gltf (buffers embedded); written whole\n"
    "                       or not at all\n"
    "  --help               this text\n"
    "\n"
    "exit codes: 0 written, 1 not written, 2 bad usage or a scene that does not load.\n";

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("export-gltf", fmt, arg); }

int limn_export_gltf(int argc, char **argv) {
  const char *scene_name = "cornell", *output = NULL, *animation = NULL, *time_flag = NULL;
  double time = 0, stop;
  struct option opts[] = {{"scene", required_argument, 0, 's'},     {"time", required_argument, 0, 'T'},
                          {"animation", required_argument, 0, 'A'}, {"output", required_argument, 0, 'o'},
                          {"help", no_argument, 0, 'h'},            {0, 0, 0, 0}};
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    switch (c) {
    case 's': scene_name = optarg; break;
    case 'T':
      if (!limn_parse_time(optarg, &time, &stop) || stop != time)
        return usage_error("--time wants SECONDS (a finite number), not '%s'", optarg);
      time_flag = optarg;
      break;
    case 'A': animation = optarg; break;
    case 'o': output = optarg; break;
    case 'h': printf(export_gltf_usage, lm_scene_builtin_list()); return 0;
    case ':': return usage_error("%s needs a value", argv[optind - 1]);
    default: return usage_error("unknown flag '%s'", argv[optind - 1]);
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (!output || !lm_scene_is_gltf_name(output)) return usage_error("%s", "--output FILE.glb or FILE.gltf is required");
  if (animation && !time_flag) return usage_error("%s", "--animation goes with --time SECONDS");
  lm_error err;
  lm_scene *scene = lm_scene_load(scene_name, &err);
  if (!scene) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 2;
  }
  int anim = LM_ANIM_ALL;
  if (animation && (anim = lm_scene_find_animation(scene, animation, &err)) < LM_ANIM_NONE) {
    lm_log(LM_LOG_ERROR, "--animation %s: %s", animation, err.msg);
    lm_scene_destroy(scene);
    return 2;
  }
  if (time_flag) lm_scene_set_time(scene, anim, time);
  lm_buf warnings = {0};
  bool ok = lm_scene_write_gltf(scene, output, &warnings, &err);
  for (char *line = warnings.data; line && *line;) { /* one warning a line */
    char *nl = strchr(line, '\n');
    if (nl) *nl = '\0';
    lm_warn("%s: %s", scene_name, line);
    line = nl ? nl + 1 : line + strlen(line);
  }
  lm_buf_free(&warnings);
  if (ok) lm_info("wrote %s (scene %s%s%s: %d nodes, %d materials, %d lights, %d cameras)", output, scene_name,
                  time_flag ? " at " : "", time_flag ? time_flag : "", scene->node_count, scene->material_count,
                  scene->light_count, scene->camera_count);
  else lm_log(LM_LOG_ERROR, "%s", err.msg);
  lm_scene_destroy(scene);
  return ok ? 0 : 1;
}
