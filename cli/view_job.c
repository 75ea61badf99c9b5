/* Settings that leave the viewer and come back: the technique, the options
 * changed from the script's defaults and the view as a capture job (with a
 * one-view camera list) and as a `limn capture` command line; a capture
 * job's view as the viewer's start (--job FILE --view N). */
#define _GNU_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "job.h"
#include "scene/gltf.h"
#include "view.h"

/* A Lua string literal of s (a job is Lua data). */
static void lua_quoted(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; s++) {
    if (*s == '"' || *s == '\\') fputc('\\', f);
    if (*s == '\n') fputs("\\n", f);
    else fputc(*s, f);
  }
  fputc('"', f);
}

/* A shell word of s, single-quoted where it needs quoting. */
static void shell_word(FILE *f, const char *s) {
  if (s[0] && strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=./,:") == strlen(s)) {
    fputs(s, f);
    return;
  }
  fputc('\'', f);
  for (; *s; s++) {
    if (*s == '\'') fputs("'\\''", f);
    else fputc(*s, f);
  }
  fputc('\'', f);
}

/* The options whose value differs from a fresh load of the script's: "name=value" into *out. */
static int changed_options(viewer *v, char (**out)[400], lm_error *err) {
  lm_pipeline *fresh = lm_pipeline_load(&(lm_pipeline_desc){.path = v->script}, err);
  if (!fresh) return -1;
  lm_option_info *now, *was;
  int n = lm_pipeline_options(v->pipeline, &now), m = lm_pipeline_options(fresh, &was), count = 0;
  *out = lm_alloc(sizeof **out * (size_t)(n > 0 ? n : 1));
  for (int i = 0; i < n; i++) {
    if (now[i].type == LM_OPTION_OTHER) continue; /* not settable: the script's own */
    bool same = false;
    for (int k = 0; k < m && !same; k++) same = !strcmp(now[i].name, was[k].name) && !strcmp(now[i].value, was[k].value);
    if (!same) snprintf((*out)[count++], sizeof **out, "%s=%s", now[i].name, now[i].value);
  }
  free(now);
  free(was);
  lm_pipeline_destroy(fresh);
  return count;
}

bool write_view_job(viewer *v, char *job_path, size_t cap, lm_error *err) {
  char scene[4096], script[4096];
  if (!realpath(v->args->common.scene, scene)) snprintf(scene, sizeof scene, "%s", v->args->common.scene);
  if (!realpath(v->script, script)) snprintf(script, sizeof script, "%s", v->script);
  if (!lm_scene_is_gltf_name(scene)) {
    lm_error_set(err, "a capture job renders glTF files, not the built-in '%s' (data/scenes/%s.glb is its file)",
                 v->args->common.scene, v->args->common.scene);
    return false;
  }
  int camera_node = v->camera < v->scene->camera_count ? v->scene->cameras[v->camera].node : -1;
  if (camera_node < 0) {
    lm_error_set(err, "scene %s has no camera to write", scene);
    return false;
  }
  char (*sets)[400] = NULL;
  int set_count = changed_options(v, &sets, err);
  if (set_count < 0) return false;
  char base[2048], cams[2100], line[2100], image[2100], tmp[2200];
  for (int n = 1;; n++) { /* the first number not taken in --capture-dir */
    snprintf(base, sizeof base, "%s/limn-view-%04d", v->args->capture_dir, n);
    snprintf(job_path, cap, "%s.lua", base);
    if (!lm_file_exists(job_path) || n == 9999) break;
  }
  snprintf(cams, sizeof cams, "%s.cams", base);
  snprintf(line, sizeof line, "%s.sh", base);
  snprintf(image, sizeof image, "%s.png", base);
  const char *cams_name = strrchr(cams, '/') + 1;
  /* The view as the window shows it: the camera's world matrix (the user's
   * flight included), its fov and depth range, in a one-line camera list. */
  const lm_camera *c = &v->scene->cameras[v->camera];
  const float *w = v->scene->nodes[camera_node].world;
  float len = sqrtf(w[8] * w[8] + w[9] * w[9] + w[10] * w[10]);
  if (!(len > 0)) len = 1;
  const char *written[3] = {cams, job_path, line};
  FILE *f[3] = {NULL, NULL, NULL};
  bool ok = true;
  for (int i = 0; i < 3 && ok; i++) {
    snprintf(tmp, sizeof tmp, "%s.tmp", written[i]);
    ok = (f[i] = fopen(tmp, "w")) != NULL;
  }
  if (ok) {
    fprintf(f[0], "# The view limn view showed (written with %s).\n", strrchr(job_path, '/') + 1);
    fprintf(f[0], "view %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", w[12], w[13], w[14], w[12] - w[8] / len,
            w[13] - w[9] / len, w[14] - w[10] / len, c->fov_y * 180.0 / M_PI, c->znear, c->zfar);
    fprintf(f[1], "-- Written by limn view: its technique, view and the options changed from the script's defaults.\n"
                  "return {\n  script = ");
    lua_quoted(f[1], script);
    fprintf(f[1], ",\n  scenes = { { scene = ");
    lua_quoted(f[1], scene);
    fprintf(f[1], ", cameras = ");
    lua_quoted(f[1], cams_name); /* beside the job */
    fprintf(f[1], " } },\n  techniques = { ");
    lua_quoted(f[1], lm_pipeline_technique(v->pipeline));
    fprintf(f[1], " },\n  sizes = { \"%dx%d\" },\n  set = {", v->width, v->height);
    for (int i = 0; i < set_count; i++) {
      char *eq = strchr(sets[i], '=');
      *eq = '\0';
      fprintf(f[1], "%s\n    [", i ? "," : "");
      lua_quoted(f[1], sets[i]);
      fprintf(f[1], "] = ");
      lua_quoted(f[1], eq + 1); /* text, as --set takes it: the script's type decides */
      *eq = '=';
    }
    fprintf(f[1], "%s},\n", set_count ? "\n  " : " ");
    if (lm_scene_animated(v->scene)) {
      fprintf(f[1], "  time = %.9g,\n  animation = ", v->time);
      lua_quoted(f[1], v->args->animation);
      fprintf(f[1], ",\n");
    }
    fprintf(f[1], "  output = ");
    lua_quoted(f[1], image);
    fprintf(f[1], ",\n}\n");
    /* The command line: the scene's camera (a flag cannot carry a moved view: the job can). */
    fprintf(f[2], "# Written by limn view with %s%s\nlimn capture --scene ", strrchr(job_path, '/') + 1,
            v->camera_user ? "; the camera was moved, which only the job keeps: this renders the scene's camera" : "");
    shell_word(f[2], scene);
    fprintf(f[2], " --script ");
    shell_word(f[2], script);
    fprintf(f[2], " --tech ");
    shell_word(f[2], lm_pipeline_technique(v->pipeline));
    fprintf(f[2], " --size %dx%d --camera %d", v->width, v->height, v->camera);
    if (lm_scene_animated(v->scene)) {
      fprintf(f[2], " --time %.9g --animation ", v->time);
      shell_word(f[2], v->args->animation);
    }
    for (int i = 0; i < set_count; i++) {
      fprintf(f[2], " --set ");
      shell_word(f[2], sets[i]);
    }
    fprintf(f[2], " --output ");
    shell_word(f[2], image);
    fprintf(f[2], "\n");
  }
  for (int i = 0; i < 3; i++) {
    snprintf(tmp, sizeof tmp, "%s.tmp", written[i]);
    if (f[i] && fclose(f[i]) != 0) ok = false;
    if (ok && rename(tmp, written[i]) != 0) ok = false;
    if (!ok) remove(tmp);
  }
  free(sets);
  if (!ok) {
    lm_error_set(err, "cannot write %s (and its .cams, .sh) in %s", job_path, v->args->capture_dir);
    return false;
  }
  lm_info("wrote %s, %s and %s", job_path, cams, line);
  return true;
}

bool load_view_job(view_args *a) {
  job *j = calloc(1, sizeof *j);
  job_view *views = NULL;
  int count = 0;
  lm_error err;
  bool ok = j && job_read(j, a->job, &err) && job_views(j, true, &views, &count, &err);
  if (ok && a->job_view >= count) {
    lm_error_set(&err, "--view %d: job %s has %d view(s), 0..%d", a->job_view, a->job, count, count - 1);
    ok = false;
  } else if (ok && a->fps_given && j->fps > 0 && a->fps != j->fps) { /* two frame rates: one of them is a mistake */
    lm_error_set(&err, "--fps %g: the job's time.fps is %g (leave --fps out: the job's counts the frames)", a->fps,
                 j->fps);
    ok = false;
  }
  if (ok) {
    const job_view *jv = &views[a->job_view];
    const job_scene *s = &j->scenes[jv->scene];
    job_pose(j, jv); /* a path's camera where the view has it */
    snprintf(a->job_script, sizeof a->job_script, "%s", j->script);
    snprintf(a->job_scene, sizeof a->job_scene, "%s", s->path);
    a->common.script = a->job_script, a->common.scene = a->job_scene;
    if (j->technique_count) {
      snprintf(a->job_tech, sizeof a->job_tech, "%s", j->techniques[jv->technique]);
      a->common.tech = a->job_tech;
    }
    a->common.width = j->sizes[jv->size][0], a->common.height = j->sizes[jv->size][1];
    a->common.camera = jv->camera;
    if (j->timed) a->time = jv->time, a->time_given = true;
    if (j->fps > 0) a->fps = j->fps, a->frame_zero = j->time_start; /* its frames numbered as the job's */
    if (j->animation[0]) snprintf(a->job_animation, sizeof a->job_animation, "%s", j->animation), a->animation = a->job_animation;
    /* The job's options first: --set flags given with --job come after and win. */
    int given = a->set_count;
    if (given + j->set_count > MAX_SETS) j->set_count = MAX_SETS - given;
    memmove(a->sets + j->set_count, a->sets, sizeof *a->sets * (size_t)given);
    for (int i = 0; i < j->set_count; i++) {
      a->sets[i] = lm_alloc(strlen(j->set_names[i]) + strlen(j->set_values[i]) + 2);
      sprintf(a->sets[i], "%s=%s", j->set_names[i], j->set_values[i]);
    }
    a->set_count += j->set_count;
    /* Its views with a cached reference: the error against it while the camera is at one. */
    find_places(a, j, views, count, jv->scene);
    job_pose(j, jv);
    /* The scene as the job loaded it: its camera list's views are cameras of it. */
    a->job_loaded = j->scenes[jv->scene].scene;
    j->scenes[jv->scene].scene = NULL;
    lm_info("job %s, view %d: %s, camera %d, %s, %dx%d", a->job, a->job_view, a->common.scene, a->common.camera,
            a->common.tech ? a->common.tech : "(the script's first technique)", a->common.width, a->common.height);
  } else {
    lm_log(LM_LOG_ERROR, "--job %s: %s", a->job, err.msg);
  }
  if (j) job_free_scenes(j);
  free(views);
  free(j);
  return ok;
}
