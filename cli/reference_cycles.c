/* Cycles references (cli/reference.h): a view is a spec, a small JSON
 * file beside the reference, that cli/cycles_render.py reads inside
 * `blender -b`:
 *
 *   blender -b --factory-startup -noaudio --threads T --python-exit-code 1
 *           --python cli/cycles_render.py -- SPEC.json OUT.exr [SPEC.json OUT.exr ...]
 *
 *   {"scene": "/abs/scene.glb", "view": "room/front 160x120",
 *    "camera": {"eye": [x,y,z], "target": [x,y,z], "up": [x,y,z], "fov_y": degrees},
 *    "width": W, "height": H, "samples": N, "bounces": B, "seed": S,
 *    "materials": "phong" | "pbr", "sky": null | {"zenith": [r,g,b], "horizon": [r,g,b], "intensity": I}}
 *
 * The script writes each OUT.exr (linear RGB float) whole (renamed into
 * place) and then the pair's index and a newline to the file descriptor
 * $LIMN_PROGRESS_FD names, or prints a line naming the view; it exits 1
 * when any view failed. The reference's hash covers what
 * decides the image: the scene file's bytes (and its camera list's), the
 * spec less the scene's path and the view's name, the script, and the
 * first line of `blender --version`. An animated scene at a time is
 * Blender's to import posed: it is written as Limn poses it
 * (lm_scene_write_gltf) beside the references, named by its hash, and that
 * file is the scene. */
#define _GNU_SOURCE
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "reference.h"
#include "scene/gltf.h"
#include "tools.h"

#define BLENDER_INSTALL "apt-get install blender (Debian package blender)"

/* `PROGRAM --version`'s first line into out; false when it cannot run. */
static bool blender_version(const char *program, char *out, size_t cap, lm_error *err) {
  int fd[2];
  if (pipe(fd) != 0) {
    lm_error_set(err, "cannot run %s: %s", program, strerror(errno));
    return false;
  }
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    dup2(fd[1], STDOUT_FILENO);
    close(fd[1]);
    if (!freopen("/dev/null", "w", stderr)) _exit(127);
    execlp(program, program, "--version", (char *)NULL);
    _exit(127);
  }
  close(fd[1]);
  char text[4096];
  size_t len = 0;
  for (ssize_t got; pid > 0 && len + 1 < sizeof text && (got = read(fd[0], text + len, sizeof text - 1 - len)) != 0;) {
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) break;
    len += (size_t)got;
  }
  text[len] = '\0';
  close(fd[0]);
  int status = 0;
  while (pid > 0 && waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status) == 127) {
    lm_error_set(err, "cannot run '%s': Cycles references need Blender; install it with: " BLENDER_INSTALL
                 ", or name it with --blender PROGRAM", program);
    return false;
  }
  const char *line = strstr(text, "Blender ");
  if (!line || (line != text && line[-1] != '\n') || WEXITSTATUS(status) != 0) {
    lm_error_set(err, "'%s --version' printed no 'Blender x.y' line (exit status %d): is it Blender? (" BLENDER_INSTALL
                 ")", program, WEXITSTATUS(status));
    return false;
  }
  snprintf(out, cap, "%.*s", (int)strcspn(line, "\r\n"), line);
  return true;
}

bool reference_cycles_prepare(reference_cycles *c, lm_error *err) {
  static char script[PATH_MAX];
  if (!c->script) {
    snprintf(script, sizeof script, "%s/cli/cycles_render.py", lm_root_dir());
    c->script = script;
  }
  size_t len;
  char *text = lm_read_file(c->script, &len, err);
  if (!text) {
    lm_error_prefix(err, "the script Blender runs for Cycles references (--cycles-script)");
    return false;
  }
  c->script_hash = lm_hash(text, len, LM_HASH_SEED);
  free(text);
  return blender_version(c->blender, c->version, sizeof c->version, err);
}

static void json_vec3(lm_buf *b, const char *key, const float v[3]) {
  lm_buf_printf(b, "\"%s\": [%.9g, %.9g, %.9g]", key, v[0], v[1], v[2]);
}

/* v scaled to length 1; false when it has none. */
static bool unit(const float in[3], float out[3]) {
  float len = sqrtf(in[0] * in[0] + in[1] * in[1] + in[2] * in[2]);
  if (!(len > 0) || !isfinite(len)) return false;
  for (int k = 0; k < 3; k++) out[k] = in[k] / len;
  return true;
}

/* The scene of view v posed at its time, as glTF: REFS/<scene>/<scene>-posed-<hash>.glb (written unless
 * there), its absolute path into out (PATH_MAX) and its hash. */
static bool posed_scene(const reference_args *a, const job *j, const job_view *v, char *out, uint64_t *hash,
                        lm_error *err) {
  const job_scene *s = &j->scenes[v->scene];
  char tmp[1100], final[1100];
  snprintf(tmp, sizeof tmp, "%s/%s/%s-posed.tmp-%ld.glb", a->refs, s->name, s->name, (long)getpid());
  lm_buf warnings = {0};
  bool ok = job_make_parent(tmp, err) && lm_scene_write_gltf(s->scene, tmp, &warnings, err);
  for (char *line = warnings.data; ok && v->frame == 0 && line && *line;) { /* once a sequence */
    char *nl = strchr(line, '\n');
    if (nl) *nl = '\0';
    lm_warn("%s: posed for Cycles: %s", s->name, line);
    line = nl ? nl + 1 : line + strlen(line);
  }
  lm_buf_free(&warnings);
  size_t len;
  char *bytes = ok ? lm_read_file(tmp, &len, err) : NULL;
  if (!bytes) {
    remove(tmp);
    return false;
  }
  *hash = lm_hash(bytes, len, LM_HASH_SEED);
  free(bytes);
  snprintf(final, sizeof final, "%s/%s/%s-posed-%016llx.glb", a->refs, s->name, s->name, (unsigned long long)*hash);
  if (lm_file_exists(final)) remove(tmp);
  else if (rename(tmp, final) != 0) {
    lm_error_set(err, "%s: cannot write (%s)", final, strerror(errno));
    remove(tmp);
    return false;
  }
  if (!realpath(final, out)) {
    lm_error_set(err, "%s: %s", final, strerror(errno));
    return false;
  }
  return true;
}

void reference_cycles_view_name(const job *j, const job_view *v, char *out, size_t cap) {
  const job_scene *s = &j->scenes[v->scene];
  int n = snprintf(out, cap, "%s/%s %dx%d", s->name, s->scene->cameras[v->camera].name, j->sizes[v->size][0],
                   j->sizes[v->size][1]);
  if (j->timed && n >= 0 && (size_t)n < cap) snprintf(out + n, cap - (size_t)n, " frame %d", v->frame);
}

bool reference_cycles_spec(const reference_args *a, const job *j, const job_view *v, lm_buf *spec, uint64_t *hash,
                           lm_error *err) {
  const job_scene *s = &j->scenes[v->scene];
  const lm_scene *sc = s->scene;
  const lm_camera *cam = &sc->cameras[v->camera];
  int w = j->sizes[v->size][0], h = j->sizes[v->size][1];
  if (!lm_scene_camera_check(sc, v->camera, err)) return false;
  char scene[PATH_MAX];
  uint64_t scene_hash = s->hash;
  if (j->timed && lm_scene_animated(sc)) {
    if (!posed_scene(a, j, v, scene, &scene_hash, err)) return false;
  } else if (!realpath(s->path, scene)) {
    lm_error_set(err, "%s: %s", s->path, strerror(errno));
    return false;
  }
  /* The camera as the renderer sees it (lm_scene_frame_data, as the POV-Ray
   * export takes it): its place, the rays to the far plane's centre and up,
   * tan(fov_y / 2) in clip[3]. */
  lm_frame_data f;
  lm_scene_frame_data(sc, v->camera, w, h, &f);
  float eye[3] = {f.camera_pos[0], f.camera_pos[1], f.camera_pos[2]}, centre[3], forward[3], up[3], target[3];
  for (int k = 0; k < 3; k++) centre[k] = f.frustum_o[k] + 0.5f * (f.frustum_u[k] + f.frustum_v[k]);
  if (!unit(centre, forward) || !unit(f.frustum_v, up)) {
    lm_error_set(err, "camera '%s': its node's transform has no direction (a zero scale)", cam->name);
    return false;
  }
  for (int k = 0; k < 3; k++) target[k] = eye[k] + forward[k];
  /* The settings: what the hash covers beside the files. */
  lm_buf settings = {0};
  lm_buf_append(&settings, "\"camera\": {", -1);
  json_vec3(&settings, "eye", eye);
  lm_buf_append(&settings, ", ", -1);
  json_vec3(&settings, "target", target);
  lm_buf_append(&settings, ", ", -1);
  json_vec3(&settings, "up", up);
  lm_buf_printf(&settings, ", \"fov_y\": %.9g},\n  \"width\": %d, \"height\": %d, \"samples\": %d, \"bounces\": %d, "
                "\"seed\": %d, \"materials\": \"%s\",\n  \"sky\": ", 2 * atan(f.clip[3]) * 180.0 / M_PI, w, h,
                a->cycles.samples, a->cycles.bounces, a->cycles.seed, a->pov.pbr_materials ? "pbr" : "phong");
  if (a->pov.has_sky) {
    lm_buf_append(&settings, "{", 1);
    json_vec3(&settings, "zenith", a->pov.sky.zenith);
    lm_buf_append(&settings, ", ", -1);
    json_vec3(&settings, "horizon", a->pov.sky.horizon);
    lm_buf_printf(&settings, ", \"intensity\": %.9g}", a->pov.sky.intensity);
  } else {
    lm_buf_append(&settings, "null", -1);
  }
  char view[LM_NAME_MAX * 2 + 128], files[128];
  reference_cycles_view_name(j, v, view, sizeof view);
  lm_buf_append(spec, "{\"scene\": ", -1);
  limn_json_append(spec, scene);
  lm_buf_append(spec, ", \"view\": ", -1);
  limn_json_append(spec, view);
  lm_buf_printf(spec, ",\n  %s}\n", settings.data);
  snprintf(files, sizeof files, "scene %016llx script %016llx ", (unsigned long long)scene_hash,
           (unsigned long long)a->cycles.script_hash);
  uint64_t hh = lm_hash(files, strlen(files), LM_HASH_SEED);
  hh = lm_hash(a->cycles.version, strlen(a->cycles.version), hh);
  *hash = lm_hash(settings.data, (size_t)settings.len, hh);
  lm_buf_free(&settings);
  return true;
}

void reference_cycles_argv(const reference_cycles *c, const char *threads, const char *argv[REFERENCE_CYCLES_ARGS]) {
  const char *args[REFERENCE_CYCLES_ARGS] = {c->blender, "-b",         "--factory-startup", "-noaudio", "--threads", threads,
                                             "--python-exit-code", "1", "--python", c->script, "--"};
  memcpy(argv, args, sizeof args);
}
