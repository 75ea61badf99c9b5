/* limn export-pov: one view of a scene as POV-Ray 3.7 SDL (engine/scene/pov.h). */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/gltf.h"
#include "scene/pov.h"
#include "tools.h"

static const char export_usage[] =
    "usage: limn export-pov [options] --output FILE.pov\n"
    "\n"
    "Writes the scene, lights and camera of one view as POV-Ray 3.7 scene\n"
    "description, linear (assumed_gamma 1), with the engine's camera, mesh2\n"
    "geometry in world space and a finish per material that matches the\n"
    "engine's direct light. What POV-Ray cannot match (the window falloff,\n"
    "spot cones of 90 degrees or more, colours outside [0, 1]) is refused,\n"
    "naming the light or material. Render the file with the command in its\n"
    "first lines (povray ... +FE: OpenEXR, one sample a pixel).\n"
    "\n"
    "options:\n"
    "  --scene NAME|FILE      built-in scene or .gltf/.glb file (default cornell;\n"
    "                         built in: %s)\n"
    "  --camera N             camera index of the scene (default 0), or auto:\n"
    "                         one framing the scene's bounds\n"
    "  --size WxH             output size, for the aspect (default 256x192)\n"
    "  --radiosity on|off     radiosity block (default on)\n"
    "  --count N              radiosity count (default 250)\n"
    "  --error-bound X        radiosity error_bound (default 0.25)\n"
    "  --pretrace-start X     radiosity pretrace_start (default 0.08)\n"
    "  --pretrace-end X       radiosity pretrace_end (default 0.01)\n"
    "  --recursion-limit N    radiosity recursion_limit (default 2)\n"
    "  --brightness X         radiosity brightness (default 1)\n"
    "  --shadows on|off       lights cast shadows as the scene says (default on);\n"
    "                         off: no mesh casts shadows, as in the engine's direct\n"
    "                         light without shadow maps\n"
    "  --sky Z:H[:I]          a sky of radiance I (h + (z - h) max(y, 0)) for\n"
    "                         radiosity to gather, as the script's sky option\n"
    "                         (colours r,g,b or one grey number; I default 1)\n"
    "  --approximate          write what cannot match in its nearest form, with a\n"
    "                         warning, instead of refusing\n"
    "  --materials phong|pbr  the finish of the std technique (phong, exact; the\n"
    "                         default) or POV-Ray's closest to the pbr one (pbr,\n"
    "                         with a warning naming what it approximates)\n"
    "  --output FILE          the .pov file to write (written whole or not at all)\n"
    "  --help                 this text\n"
    "\n"
    "exit codes: 0 written, 1 refused or not written, 2 bad usage.\n";

typedef struct export_args {
  const char *scene, *output;
  lm_pov_desc desc;
} export_args;

static int usage_error(const char *fmt, const char *arg) { return limn_usage_error("export-pov", fmt, arg); }

/* "r,g,b" or one grey number, each finite in 0 .. 1e6. */
static bool parse_colour(const char *s, float out[3]) {
  double v[3];
  int n = 0;
  char buf[256];
  snprintf(buf, sizeof buf, "%s", s);
  for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
    if (n == 3 || !limn_parse_double(t, &v[n]) || !(v[n] >= 0 && v[n] <= 1e6)) return false;
    n++;
  }
  if (n == 1) v[1] = v[2] = v[0];
  else if (n != 3) return false;
  for (int i = 0; i < 3; i++) out[i] = (float)v[i];
  return true;
}

bool limn_parse_sky(const char *s, lm_sky *sky) {
  char buf[512];
  snprintf(buf, sizeof buf, "%s", s);
  char *save = NULL, *z = strtok_r(buf, ":", &save), *h = strtok_r(NULL, ":", &save);
  char *i = strtok_r(NULL, ":", &save), *rest = strtok_r(NULL, ":", &save);
  double intensity = 1.0;
  if (!z || !h || rest || !parse_colour(z, sky->zenith) || !parse_colour(h, sky->horizon)) return false;
  if (i && !(limn_parse_double(i, &intensity) && intensity >= 0 && intensity <= 1e6)) return false;
  sky->intensity = (float)intensity;
  return true;
}

/* The flags that set the export (also taken by `limn reference` and `limn report`). */
const struct option limn_pov_options[] = {
    {"radiosity", required_argument, 0, 'r'},      {"count", required_argument, 0, 'n'},
    {"error-bound", required_argument, 0, 'e'},    {"pretrace-start", required_argument, 0, 'S'},
    {"pretrace-end", required_argument, 0, 'E'},   {"recursion-limit", required_argument, 0, 'l'},
    {"brightness", required_argument, 0, 'b'},     {"shadows", required_argument, 0, 'w'},
    {"approximate", no_argument, 0, 'a'},          {"materials", required_argument, 0, 'M'},
    {"sky", required_argument, 0, LIMN_POV_SKY_FLAG},
    {0, 0, 0, 0}};
_Static_assert(sizeof limn_pov_options / sizeof *limn_pov_options == LIMN_POV_OPTION_COUNT,
               "LIMN_POV_OPTION_COUNT (tools.h) counts limn_pov_options");

void limn_pov_defaults(lm_pov_desc *d) {
  *d = (lm_pov_desc){.width = 256, .height = 192, .radiosity = true, .shadows = true, .strict = true};
  lm_pov_radiosity_defaults(&d->rad);
}

int limn_pov_flag(const char *cmd, int c, const char *arg, lm_pov_desc *d) {
  lm_pov_radiosity *r = &d->rad;
  const char *bad = NULL;
  switch (c) {
  case 'r': if (!limn_parse_on_off(arg, &d->radiosity)) bad = "--radiosity wants on or off, not '%s'"; break;
  case 'w': if (!limn_parse_on_off(arg, &d->shadows)) bad = "--shadows wants on or off, not '%s'"; break;
  case 'n': if (!limn_parse_int(arg, 1, 1600, &r->count)) bad = "--count wants 1..1600, not '%s'"; break;
  case 'l':
    if (!limn_parse_int(arg, 1, 20, &r->recursion_limit)) bad = "--recursion-limit wants 1..20, not '%s'";
    break;
  case 'e':
    if (!limn_parse_double(arg, &r->error_bound) || r->error_bound <= 0)
      bad = "--error-bound wants a number > 0, not '%s'";
    break;
  case 'S':
    if (!limn_parse_double(arg, &r->pretrace_start) || r->pretrace_start <= 0 || r->pretrace_start > 1)
      bad = "--pretrace-start wants a number in (0, 1], not '%s'";
    break;
  case 'E':
    if (!limn_parse_double(arg, &r->pretrace_end) || r->pretrace_end <= 0 || r->pretrace_end > 1)
      bad = "--pretrace-end wants a number in (0, 1], not '%s'";
    break;
  case 'b':
    if (!limn_parse_double(arg, &r->brightness) || r->brightness < 0)
      bad = "--brightness wants a number >= 0, not '%s'";
    break;
  case 'a': d->strict = false; break;
  case 'M':
    if (!strcmp(arg, "pbr") || !strcmp(arg, "phong")) d->pbr_materials = !strcmp(arg, "pbr");
    else bad = "--materials wants phong or pbr, not '%s'";
    break;
  case LIMN_POV_SKY_FLAG:
    d->has_sky = limn_parse_sky(arg, &d->sky);
    if (!d->has_sky) bad = "--sky wants ZENITH:HORIZON[:INTENSITY], colours r,g,b or one grey number, not '%s'";
    break;
  default: return 1;
  }
  return bad ? limn_usage_error(cmd, bad, arg) : 0;
}

/* Returns 0 to go on, -1 after --help, else the exit code. */
static int parse_args(int argc, char **argv, export_args *a) {
  *a = (export_args){.scene = "cornell"};
  limn_pov_defaults(&a->desc);
  struct option opts[5 + LIMN_POV_OPTION_COUNT] = {
      {"scene", required_argument, 0, 's'}, {"camera", required_argument, 0, 'c'},
      {"size", required_argument, 0, 'z'},  {"output", required_argument, 0, 'o'},
      {"help", no_argument, 0, 'h'}};
  memcpy(opts + 5, limn_pov_options, sizeof limn_pov_options); /* LIMN_POV_OPTION_COUNT entries with the end */
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
    int pov = limn_pov_flag("export-pov", c, optarg, &a->desc);
    if (pov == 2) return 2;
    if (pov == 0) continue;
    switch (c) {
    case 's': a->scene = optarg; break;
    case 'c':
      if (!limn_parse_camera(optarg, &a->desc.camera))
        return usage_error("--camera wants an index or auto, not '%s'", optarg);
      break;
    case 'z':
      if (!limn_parse_size(optarg, &a->desc.width, &a->desc.height))
        return usage_error("--size wants WxH with both in 1..65536, not '%s'", optarg);
      break;
    case 'o': a->output = optarg; break;
    case 'h': printf(export_usage, lm_scene_builtin_list()); return -1;
    case ':': return usage_error("%s needs a value", argv[optind - 1]);
    default: return usage_error("unknown flag '%s'", argv[optind - 1]);
    }
  }
  if (optind < argc) return usage_error("unexpected argument '%s'", argv[optind]);
  if (!a->output) return usage_error("%s", "--output FILE.pov is required");
  const char *bad = a->desc.radiosity ? lm_pov_radiosity_check(&a->desc.rad) : NULL;
  if (bad) return usage_error("radiosity setting out of range: %s", bad);
  return 0;
}

/* Written under a temporary name and renamed: the file appears whole or not at all. */
bool limn_write_whole(const char *path, const char *data, size_t len, lm_error *err) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
  FILE *f = fopen(tmp, "wb");
  if (!f) {
    lm_error_set(err, "%s: cannot write (%s)", path, strerror(errno));
    return false;
  }
  bool ok = fwrite(data, 1, len, f) == len;
  ok = fclose(f) == 0 && ok;
  if (ok && rename(tmp, path) != 0) ok = false;
  if (!ok) {
    lm_error_set(err, "%s: cannot write (%s)", path, strerror(errno));
    remove(tmp);
  }
  return ok;
}

int limn_export_pov(int argc, char **argv) {
  export_args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc < 0 ? 0 : rc;
  lm_error err;
  lm_scene *scene = lm_scene_load(a.scene, &err);
  if (!scene) {
    lm_log(LM_LOG_ERROR, "%s", err.msg);
    return 2;
  }
  a.desc.camera = limn_camera_resolve(scene, a.desc.camera, a.desc.width, a.desc.height);
  if (a.desc.camera > 0 && a.desc.camera >= scene->camera_count) {
    lm_log(LM_LOG_ERROR, "--camera %d: scene '%s' has %d camera(s)", a.desc.camera, a.scene, scene->camera_count);
    lm_scene_destroy(scene);
    return 2;
  }
  lm_buf sdl = {0}, warnings = {0};
  bool ok = lm_pov_export(scene, &a.desc, &sdl, &warnings, &err);
  for (char *line = warnings.data; line && *line;) { /* one warning a line */
    char *nl = strchr(line, '\n');
    if (nl) *nl = '\0';
    lm_warn("%s", line);
    line = nl ? nl + 1 : line + strlen(line);
  }
  if (!ok) lm_error_prefix(&err, "%s", a.scene);
  if (ok) ok = limn_write_whole(a.output, sdl.data, (size_t)sdl.len, &err);
  if (ok) lm_info("wrote %s (scene %s, camera %d, %dx%d, radiosity %s, shadows %s)", a.output, a.scene,
                  a.desc.camera, a.desc.width, a.desc.height, a.desc.radiosity ? "on" : "off",
                  a.desc.shadows ? "on" : "off");
  else lm_log(LM_LOG_ERROR, "%s", err.msg);
  lm_buf_free(&sdl);
  lm_buf_free(&warnings);
  lm_scene_destroy(scene);
  return ok ? 0 : 1;
}
