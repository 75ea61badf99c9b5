/* limn view under Xvfb (ctest runs this binary through xvfb-run): the
 * window's content, keys, live reload of shaders and scripts with errors,
 * resizing to 1x1, the inspector's files and a 1000-edit reload loop counted
 * for leaks. Each case starts the real `limn view` on a scratch engine root
 * (copies of shaders/ and scripts/, so edits never touch the source tree).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "image/image.h"
#include "image/metrics.h"
#include "scene/gltf.h"

static char root[256];
static pid_t running; /* the viewer a failed case left behind */

static void sleep_ms(int ms) {
  struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
  nanosleep(&ts, NULL);
}

static void path_in_root(char *out, size_t cap, const char *rel) { snprintf(out, cap, "%s/%s", root, rel); }

/* Written under a temporary name and renamed, as editors save. */
static void write_file(const char *rel, const char *text) {
  char path[512], tmp[520];
  path_in_root(path, sizeof path, rel);
  snprintf(tmp, sizeof tmp, "%s.tmp~", path);
  FILE *f = fopen(tmp, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
  assert_int_equal(rename(tmp, path), 0);
}

static char *read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return calloc(1, 1);
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *s = calloc(1, (size_t)n + 1);
  if (fread(s, 1, (size_t)n, f) != (size_t)n) s[0] = '\0';
  fclose(f);
  return s;
}

static bool file_has(const char *path, const char *needle) {
  char *s = read_text(path);
  bool found = strstr(s, needle) != NULL;
  free(s);
  return found;
}

static bool wait_for(const char *path, const char *needle, int timeout_ms) {
  for (int t = 0; t < timeout_ms; t += 50) {
    if (file_has(path, needle)) return true;
    sleep_ms(50);
  }
  return false;
}

/* Starts `limn view ARGS...` with stdout and stderr into log (NULL-terminated
 * args); the panel off unless ARGS turn it on (screenshots see the frame). */
static pid_t spawn_view(const char *log, ...) {
  const char *argv[64] = {LIMN_EXE, "view", "--panel", "off"};
  int n = 4;
  va_list ap;
  va_start(ap, log);
  for (const char *a; (a = va_arg(ap, const char *)) && n < 63;) argv[n++] = a;
  va_end(ap);
  argv[n] = NULL;
  FILE *f = fopen(log, "w"); /* empty now: a wait_for must not see the last run's lines */
  if (f) fclose(f);
  pid_t pid = fork();
  running = pid;
  if (pid == 0) {
    FILE *f = freopen(log, "w", stdout);
    if (!f || dup2(fileno(stdout), 2) < 0) _exit(127);
    execv(LIMN_EXE, (char *const *)argv);
    _exit(127);
  }
  return pid;
}

/* The exit code, or -1 after killing a run that took over timeout_ms,
 * times three: the limits only catch a hung viewer, and one core under a
 * load of ten (a busy shared machine) ran 14 frames in over 20 s. */
static int wait_exit(pid_t pid, int timeout_ms) {
  for (int t = 0; t < 3 * timeout_ms; t += 20) {
    int status;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      running = 0;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    sleep_ms(20);
  }
  kill(pid, SIGKILL);
  waitpid(pid, NULL, 0);
  running = 0;
  return -1;
}

/* The source tree's shaders and scripts, fresh under root (edits undone). */
static int copy_sources(void) {
  char cmd[1024];
  snprintf(cmd, sizeof cmd, "rm -rf %s/shaders %s/scripts && cp -r %s/shaders %s/scripts %s/", root, root,
           LIMN_SOURCE_ROOT, LIMN_SOURCE_ROOT, root);
  return system(cmd) == 0 ? 0 : -1;
}

/* After each case: a viewer still running (its case failed) is stopped, and
 * the sources it edited are restored, so that one failure does not fail the
 * cases after it. */
static int stop_leftover(void **state) {
  (void)state;
  if (running > 0) wait_exit(running, 0);
  return copy_sources();
}

static bool alive(pid_t pid) {
  int status;
  return waitpid(pid, &status, WNOHANG) == 0;
}

static void print_log(const char *log) {
  char *s = read_text(log);
  fprintf(stderr, "---- %s\n%s----\n", log, s);
  free(s);
}

/* Mean RGB over a box given in fractions of the image. */
static void box_mean(const lm_image *img, double x0, double y0, double x1, double y1, double rgb[3]) {
  int n = 0;
  rgb[0] = rgb[1] = rgb[2] = 0;
  for (int y = (int)(y0 * img->height); y < (int)(y1 * img->height); y++)
    for (int x = (int)(x0 * img->width); x < (int)(x1 * img->width); x++, n++)
      for (int c = 0; c < 3; c++) rgb[c] += img->pixels[((size_t)y * img->width + x) * img->channels + c];
  for (int c = 0; c < 3; c++) rgb[c] /= n > 0 ? n : 1;
}

/* The lower half: messages (up to three lines) show at the top. */
static double image_mean(const lm_image *img) {
  double m[3];
  box_mean(img, 0, 0.5, 1, 1, m);
  fprintf(stderr, "mean %.4f %.4f %.4f\n", m[0], m[1], m[2]);
  return (m[0] + m[1] + m[2]) / 3;
}

/* Mean absolute difference per value, over the lower half. */
static double image_diff(const lm_image *a, const lm_image *b) {
  assert_int_equal(a->width, b->width);
  assert_int_equal(a->height, b->height);
  double sum = 0;
  int n = 0;
  for (int y = a->height / 2; y < a->height; y++)
    for (int x = 0; x < a->width; x++)
      for (int c = 0; c < 3; c++, n++)
        sum += fabs(a->pixels[((size_t)y * a->width + x) * a->channels + c] -
                    b->pixels[((size_t)y * b->width + x) * b->channels + c]);
  fprintf(stderr, "diff %.4f\n", sum / n);
  return sum / n;
}

static void load(const char *rel, lm_image *img) {
  char path[512];
  path_in_root(path, sizeof path, rel);
  lm_error err;
  if (!lm_image_read(path, img, &err)) fail_msg("%s", err.msg);
}

/* The Cornell box's red left wall and green right wall. */
static void assert_walls(const lm_image *img) {
  double left[3], right[3];
  box_mean(img, 0.18, 0.42, 0.25, 0.57, left); /* as in test_render.c */
  box_mean(img, 0.75, 0.42, 0.82, 0.57, right);
  fprintf(stderr, "walls: left %.3f %.3f %.3f, right %.3f %.3f %.3f (%dx%d, %d channels)\n", left[0], left[1],
          left[2], right[0], right[1], right[2], img->width, img->height, img->channels);
  /* sRGB-encoded: the linear ratios (3x, 2x in test_render.c) shrink. The
   * inverse-square ceiling light leaves the walls' middle near 0.5 from
   * inside the box. */
  assert_true(left[0] > 0.4 && left[0] > 2 * left[1] && left[0] > 2 * left[2]);
  assert_true(right[1] > 0.4 && right[1] > 1.4 * right[0] && right[1] > 1.4 * right[2]);
}

static int setup(void **state) {
  (void)state;
  snprintf(root, sizeof root, "/tmp/limn-view-XXXXXX");
  if (!mkdtemp(root) || copy_sources() != 0) return -1;
  setenv("LIMN_ROOT", root, 1);
  if (!getenv("DISPLAY")) {
    fprintf(stderr, "test_view: no DISPLAY; run it through xvfb-run (ctest does)\n");
    return -1;
  }
  return 0;
}

static int teardown(void **state) {
  (void)state;
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", root);
  return system(cmd);
}

static void log_path(char *out, const char *name) { snprintf(out, 512, "%s/%s.log", root, name); }
static void shot_path(char *out, const char *name) { snprintf(out, 512, "%s/%s", root, name); }

/* The window shows the box; the overlay draws text over its top only, and
 * turned off (F1) leaves none behind (its image is redrawn only when its
 * lines change). */
static void window_shows_the_box(void **state) {
  (void)state;
  char log[512], plain[512], text[512], off[512];
  log_path(log, "plain");
  shot_path(plain, "plain.png");
  shot_path(text, "overlay.png");
  shot_path(off, "overlay_off.png");
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "256x192", "--overlay", "off", "--exit-after", "5",
                         "--screenshot", plain, NULL);
  int rc = wait_exit(pid, 20000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  pid = spawn_view(log, "--tech", "dl", "--size", "256x192", "--exit-after", "5", "--screenshot", text, NULL);
  assert_int_equal(wait_exit(pid, 20000), 0);
  pid = spawn_view(log, "--tech", "dl", "--size", "256x192", "--exit-after", "5", "--script-keys", "2:F1",
                   "--screenshot", off, NULL);
  assert_int_equal(wait_exit(pid, 20000), 0);
  lm_image a, b, c;
  load("plain.png", &a);
  load("overlay.png", &b);
  load("overlay_off.png", &c);
  assert_int_equal(a.width, 256);
  assert_int_equal(a.height, 192);
  assert_walls(&a);
  /* Text and its dark band change the top rows; the floor is left alone. */
  double top_a[3], top_b[3], top_c[3], low_a[3], low_b[3];
  box_mean(&a, 0, 0, 1, 0.1, top_a);
  box_mean(&b, 0, 0, 1, 0.1, top_b);
  box_mean(&c, 0, 0, 1, 0.1, top_c);
  box_mean(&a, 0.3, 0.95, 0.7, 1, low_a);
  box_mean(&b, 0.3, 0.95, 0.7, 1, low_b);
  double dtop = 0, dlow = 0, doff = 0;
  for (int k = 0; k < 3; k++)
    dtop += fabs(top_a[k] - top_b[k]), dlow += fabs(low_a[k] - low_b[k]), doff += fabs(top_a[k] - top_c[k]);
  assert_true(dtop > 0.05);
  assert_true(dlow < 0.01);
  assert_true(doff < 0.01);
  lm_image_free(&a);
  lm_image_free(&b);
  lm_image_free(&c);
}

/* A scratch pipeline: the isr technique adds 0.25 to the ambient light,
 * option bloom (a boolean) 0.5, dof.enabled 1; no OnCreate targets. */
static void write_toggles(void) {
  write_file("scripts/toggles.lua",
             "local gbuffer = require \"gbuffer\"\n"
             "Techniques = { \"dl\", \"isr\" }\n"
             "Options = { bloom = false, dof = { enabled = false, focus = 1 } }\n"
             "function OnRender(tech)\n"
             "  local G = gbuffer.render(gbuffer.targets())\n"
             "  local a = (tech.bloom and 0.5 or 0) + (tech.dof.enabled and 1 or 0)\n"
             "  if tech.name == \"isr\" then a = a + 0.25 end\n"
             "  local lit = target{ \"lit\", format = \"rgba16f\" }\n"
             "  present(pass{ \"direct\", shader = \"direct.frag\", inputs = gbuffer.inputs(G),\n"
             "                params = { ambient = { a, a, a } }, out = lit })\n"
             "end\n");
}

/* F3 switches to isr (more light: a bounce), F2 names a technique the script
 * lacks and the viewer goes on; F6 toggles a boolean option and F7 a table's
 * `enabled`, F8 one the script does not declare. */
static void keys_switch_techniques_and_options(void **state) {
  (void)state;
  write_toggles();
  char log[512], dl[512], isr[512], bloom[512], base[512];
  log_path(log, "keys");
  shot_path(dl, "dl.png");
  shot_path(isr, "isr.png");
  shot_path(bloom, "bloom.png");
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "128x96", "--overlay", "off", "--exit-after", "3",
                         "--screenshot", dl, NULL);
  assert_int_equal(wait_exit(pid, 20000), 0);
  pid = spawn_view(log, "--tech", "dl", "--size", "128x96", "--overlay", "off", "--exit-after", "6", "--script-keys",
                   "2:F3", "--screenshot", isr, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  assert_true(file_has(log, "technique isr"));
  lm_image a, b;
  load("dl.png", &a);
  load("isr.png", &b);
  assert_walls(&b);
  assert_true(image_diff(&a, &b) > 0.004); /* ISR's bounce is subtle at this size */
  lm_image_free(&b);
  /* F6 turns pp.lua's bloom (a table with `enabled`) on: the image changes
   * (bloom's threshold lowered so that the lower half, which image_diff
   * compares, has light over it: the box's light is brightest at the top). */
  pid = spawn_view(log, "--tech", "dl", "--size", "128x96", "--overlay", "off", "--exit-after", "4", "--script-keys",
                   "1:F6", "--set", "bloom.threshold=0.3", "--screenshot", bloom, NULL);
  rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  assert_true(file_has(log, "bloom.enabled = true"));
  load("bloom.png", &b);
  assert_true(image_diff(&a, &b) > 0.002);
  lm_image_free(&a);
  lm_image_free(&b);

  /* The scratch script: the isr technique adds 0.25 to the ambient light,
   * bloom 0.5, dof.enabled 1; F8 (glass) it does not declare. */
  char script[512];
  path_in_root(script, sizeof script, "scripts/toggles.lua");
  const char *runs[3] = {"1:F5", "1:F3", "1:F6,2:F7,3:F8,4:F3,5:F2"};
  double means[3];
  for (int i = 0; i < 3; i++) {
    char name[32];
    snprintf(name, sizeof name, "toggles%d.png", i);
    shot_path(base, name);
    pid = spawn_view(log, "--script", script, "--size", "128x96", "--overlay", "off", "--exit-after", "6",
                     "--script-keys", runs[i], "--screenshot", base, NULL);
    rc = wait_exit(pid, 20000);
    if (rc) print_log(log);
    assert_int_equal(rc, 0);
    load(name, &a);
    means[i] = image_mean(&a);
    lm_image_free(&a);
  }
  assert_true(file_has(log, "bloom = true"));
  assert_true(file_has(log, "dof.enabled = true"));
  assert_true(file_has(log, "declares no option 'glass'"));
  assert_true(file_has(log, "unknown technique 'isr+esm'")); /* F2: not in this script */
  assert_true(means[1] > means[0] + 0.05);
  assert_true(means[2] > means[1] + 0.08);
}

/* A broken shader and a broken script while it runs: the viewer goes on,
 * names file:line, and takes the fixed files. The fix swaps red and blue,
 * so the left wall turns blue in the window. */
static void live_reload_survives_errors(void **state) {
  (void)state;
  char log[512], shot[512];
  log_path(log, "reload");
  shot_path(shot, "reload.png");
  char *direct = read_text(LIMN_SOURCE_ROOT "/shaders/direct.frag");
  char *pp = read_text(LIMN_SOURCE_ROOT "/scripts/pp.lua");
  assert_non_null(strstr(direct, "lit = vec4("));
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "128x96", "--overlay", "off", "--exit-after", "1000000",
                         "--screenshot", shot, NULL);
  if (!wait_for(log, "limn: renderer:", 20000)) print_log(log);
  assert_true(alive(pid));
  sleep_ms(200);

  /* The line that writes `lit` gets a syntax error. */
  char *broken = lm_strdup(direct), *at = strstr(broken, "lit = vec4("), where[64];
  memcpy(at, "lit = vec4{", 11);
  int line = 1;
  for (const char *c = broken; c < at; c++) line += *c == '\n';
  snprintf(where, sizeof where, "shaders/direct.frag:%d:", line);
  write_file("shaders/direct.frag", broken);
  bool reported = wait_for(log, where, 10000);
  if (!reported) print_log(log);
  assert_true(reported);
  assert_true(alive(pid));

  char *swapped = lm_alloc(strlen(direct) + 64);
  at = strrchr(direct, '}');
  sprintf(swapped, "%.*s  lit.rgb = lit.bgr;\n}\n", (int)(at - direct), direct);
  write_file("shaders/direct.frag", swapped);
  assert_true(wait_for(log, "shaders rebuilt: error cleared", 10000));
  assert_true(alive(pid));

  /* A script error at line 2, then the script again. */
  lm_buf b = {0};
  lm_buf_printf(&b, "-- edited\nlocal x = = 1\n%s", pp);
  write_file("scripts/pp.lua", b.data);
  reported = wait_for(log, "scripts/pp.lua:2:", 10000);
  if (!reported) print_log(log);
  assert_true(reported);
  assert_true(alive(pid));
  write_file("scripts/pp.lua", pp);
  assert_true(wait_for(log, "script reloaded: error cleared", 10000));
  sleep_ms(300);
  assert_true(alive(pid));
  kill(pid, SIGTERM);
  int rc = wait_exit(pid, 10000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);

  lm_image img;
  load("reload.png", &img);
  double left[3], right[3];
  box_mean(&img, 0.18, 0.42, 0.25, 0.57, left);
  box_mean(&img, 0.75, 0.42, 0.82, 0.57, right);
  assert_true(left[2] > 0.5 && left[2] > 2 * left[0]); /* red became blue */
  assert_true(right[1] > 0.5 && right[1] > 1.4 * right[0]);
  lm_image_free(&img);
  write_file("shaders/direct.frag", direct);
  lm_buf_free(&b);
  free(broken);
  free(swapped);
  free(direct);
  free(pp);
}

/* Down to 1x1 (no 0x0 target, no crash) and back; the last frame is whole. */
static void resize_to_1x1_and_back(void **state) {
  (void)state;
  char log[512], shot[512];
  log_path(log, "resize");
  shot_path(shot, "resize.png");
  pid_t pid = spawn_view(log, "--size", "96x72", "--overlay", "off", "--exit-after", "14", "--script-keys",
                         "3:resize=1x1,8:resize=128x96", "--screenshot", shot, NULL);
  int rc = wait_exit(pid, 20000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  assert_true(file_has(log, "window 1x1"));
  assert_true(file_has(log, "window 128x96"));
  assert_false(file_has(log, "error"));
  lm_image img;
  load("resize.png", &img);
  assert_int_equal(img.width, 128);
  assert_int_equal(img.height, 96);
  assert_walls(&img);
  lm_image_free(&img);
}

/* PageDown steps to the first target, P writes it (EXR) and the frame (PNG);
 * V shows it in false colour. */
static void inspector_writes_target_and_frame(void **state) {
  (void)state;
  char log[512], shot[512];
  log_path(log, "inspect");
  shot_path(shot, "inspect.png");
  write_toggles();
  char script[512];
  path_in_root(script, sizeof script, "scripts/toggles.lua"); /* its first target: gbuffer.clr */
  pid_t pid = spawn_view(log, "--script", script, "--size", "96x72", "--overlay", "off", "--exit-after", "6",
                         "--capture-dir", root, "--script-keys", "2:PageDown,3:P,4:V", "--screenshot", shot, NULL);
  int rc = wait_exit(pid, 20000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  char *s = read_text(log), *exr = strstr(s, "wrote "), path[512];
  assert_non_null(exr);
  assert_int_equal(sscanf(exr, "wrote %511s", path), 1);
  assert_non_null(strstr(path, ".exr"));
  lm_error err;
  lm_image img;
  assert_true(lm_image_read(path, &img, &err));
  assert_true(img.width >= 1 && img.height >= 1 && img.channels == 4);
  for (size_t i = 0; i < (size_t)img.width * img.height * 4; i++) assert_true(isfinite(img.pixels[i]));
  lm_image_free(&img);
  snprintf(path, sizeof path, "%s/limn-frame-0001.png", root);
  assert_true(lm_image_read(path, &img, &err));
  assert_int_equal(img.width, 96);
  assert_walls(&img);
  lm_image_free(&img);
  free(s);
  /* False colour spans blue (low) to red (high): the screen has both. */
  load("inspect.png", &img);
  bool blue = false, red = false;
  for (size_t i = 0; i < (size_t)img.width * img.height; i++) {
    const float *p = img.pixels + i * 3;
    blue |= p[2] > 0.6f && p[0] < 0.3f;
    red |= p[0] > 0.6f && p[2] < 0.3f;
  }
  assert_true(blue && red);
  lm_image_free(&img);
}

/* Black pixels (outside the box) and the mean x of red-wall pixels. */
static void look(const lm_image *img, int *black, double *red_x) {
  int reds = 0;
  double sum = 0;
  *black = 0;
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++) {
      const float *p = img->pixels + ((size_t)y * img->width + x) * img->channels;
      *black += p[0] + p[1] + p[2] < 0.02f;
      if (p[0] > 0.4f && p[0] > 2 * p[1] && p[0] > 2 * p[2]) reds++, sum += x;
    }
  *red_x = reds ? sum / reds / img->width : 0;
}

/* W held for 30 frames walks into the box (the black outside leaves the
 * view, the walls keep their sides); dragging left turns left (the red wall
 * moves toward the middle). Scripted runs step 1/60 s a frame. */
static void camera_moves_and_turns(void **state) {
  (void)state;
  char log[512], base[512], fwd[512], turn[512];
  log_path(log, "camera");
  shot_path(base, "cam0.png");
  shot_path(fwd, "cam1.png");
  shot_path(turn, "cam2.png");
  const char *shots[3] = {base, fwd, turn};
  const char *keys[3] = {"1:F5", "2:hold=W,32:release=W", "2:drag=-60;0"};
  for (int i = 0; i < 3; i++) {
    pid_t pid = spawn_view(log, "--tech", "dl", "--size", "128x96", "--overlay", "off", "--exit-after", "34",
                           "--script-keys", keys[i], "--screenshot", shots[i], NULL);
    int rc = wait_exit(pid, 30000);
    if (rc) print_log(log);
    assert_int_equal(rc, 0);
  }
  lm_image a, b, c;
  load("cam0.png", &a);
  load("cam1.png", &b);
  load("cam2.png", &c);
  int black[3];
  double red_x[3];
  look(&a, &black[0], &red_x[0]);
  look(&b, &black[1], &red_x[1]);
  look(&c, &black[2], &red_x[2]);
  print_message("black pixels %d, %d, %d; red wall at x %.3f, %.3f, %.3f\n", black[0], black[1], black[2],
                red_x[0], red_x[1], red_x[2]);
  assert_true(black[0] > 200);               /* the box seen from outside */
  assert_true(black[1] < black[0] / 10);     /* walked in: the box fills the view */
  assert_walls(&b);
  assert_true(red_x[2] > red_x[0] + 0.15);   /* turned left: the red wall comes to the middle */
  lm_image_free(&a);
  lm_image_free(&b);
  lm_image_free(&c);
}

/* Usage errors exit 2 naming the flag; a missing script or window exits 1 naming why. */
static void command_line_errors(void **state) {
  (void)state;
  char log[512];
  log_path(log, "usage");
  static const struct {
    const char *args[3], *says;
    int rc;
  } cases[] = {
      {{"--bogus"}, "unknown flag '--bogus'", 2},
      {{"--size", "0x5"}, "--size wants WxH", 2},
      {{"--script-keys", "x:F5"}, "--script-keys wants FRAME:KEY", 2},
      {{"--screenshot", "out.jpg"}, "give a .png file", 2},
      {{"--tech", "nope"}, "unknown technique 'nope'", 2},
      {{"--script", "nope.lua"}, "nope.lua: cannot open", 1},
      {{"--scene", "nope"}, "nope", 2},
      {{"--animation", "nope"}, "has no animation 'nope'", 2},
      {{"--time", "soon"}, "--time wants seconds", 2},
      {{"--fps", "0"}, "--fps wants frames a second in (0, 1000]", 2},
      {{"--fps", "1001"}, "--fps wants frames a second in (0, 1000]", 2},
      {{"--script-keys", "4:time=later"}, "--script-keys wants FRAME:KEY", 2},
      {{"--panel", "maybe"}, "--panel wants on or off", 2},
      {{"--view", "2"}, "--view N needs --job FILE", 2},
      {{"--job", "nope.lua"}, "--job nope.lua", 2},
      {{"--script-keys", "3:mouse=10"}, "--script-keys wants FRAME:KEY", 2},
      {{"--help"}, "F2 isr+esm", 0},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    pid_t pid = spawn_view(log, cases[i].args[0], cases[i].args[1], cases[i].args[2], NULL);
    int rc = wait_exit(pid, 10000);
    if (rc != cases[i].rc || !file_has(log, cases[i].says)) {
      print_log(log);
      fail_msg("case %zu (%s): exit %d", i, cases[i].args[0], rc);
    }
  }
  /* No X server: a message, not a crash. */
  char *display = lm_strdup(getenv("DISPLAY"));
  unsetenv("DISPLAY");
  pid_t pid = spawn_view(log, "--exit-after", "1", NULL);
  int rc = wait_exit(pid, 10000);
  setenv("DISPLAY", display, 1);
  free(display);
  if (rc != 1 || !file_has(log, "no window system")) print_log(log);
  assert_int_equal(rc, 1);
  assert_true(file_has(log, "no window system"));
}

/* ---- a glTF scene: one quad, a sun, two cameras (the second looks away) */
static char *base64(const unsigned char *p, size_t n) {
  static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  char *out = malloc(4 * ((n + 2) / 3) + 1), *o = out;
  for (size_t i = 0; i < n; i += 3) {
    uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
    *o++ = tab[v >> 18 & 63];
    *o++ = tab[v >> 12 & 63];
    *o++ = i + 1 < n ? tab[v >> 6 & 63] : '=';
    *o++ = i + 2 < n ? tab[v & 63] : '=';
  }
  *o = '\0';
  return out;
}

static void write_quad_scene(const char *rel, const char *color) {
  static const float pos[12] = {-5, -5, 0, 5, -5, 0, 5, 5, 0, -5, 5, 0};
  static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  unsigned char bytes[sizeof pos + sizeof idx];
  memcpy(bytes, pos, sizeof pos);
  memcpy(bytes + sizeof pos, idx, sizeof idx);
  char *b64 = base64(bytes, sizeof bytes), json[4096];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
           "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"directional\",\"intensity\":4291}]}},"
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3]}],"
           "\"nodes\":[{\"name\":\"quad\",\"mesh\":0},"
           "{\"name\":\"sun\",\"translation\":[0,0,4],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
           "{\"name\":\"front\",\"translation\":[0,0,3],\"camera\":0},"
           "{\"name\":\"back\",\"translation\":[0,0,3],\"rotation\":[0,1,0,0],\"camera\":0}],"
           "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1,\"zfar\":20}}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
           "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[%s,1],\"metallicFactor\":0}}],"
           "\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\",\"byteLength\":%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":24}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
           "\"min\":[-5,-5,0],\"max\":[5,5,0]},"
           "{\"bufferView\":1,\"componentType\":5125,\"count\":6,\"type\":\"SCALAR\"}]}",
           color, b64, sizeof bytes);
  free(b64);
  write_file(rel, json);
}

/* Number keys pick the scene's cameras; saving the scene file with another
 * material colour shows at once. */
static void cameras_and_scene_reload(void **state) {
  (void)state;
  char log[512], scene[512], front[512], back[512], edited[512];
  log_path(log, "scene");
  write_quad_scene("quad.gltf", "1,0,0");
  path_in_root(scene, sizeof scene, "quad.gltf");
  shot_path(front, "front.png");
  shot_path(back, "back.png");
  shot_path(edited, "edited.png");
  pid_t pid = spawn_view(log, "--scene", scene, "--size", "128x96", "--overlay", "off", "--exit-after", "4",
                         "--screenshot", front, NULL);
  int rc = wait_exit(pid, 20000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  pid = spawn_view(log, "--scene", scene, "--size", "128x96", "--overlay", "off", "--exit-after", "6",
                   "--script-keys", "1:3,2:2", "--screenshot", back, NULL);
  assert_int_equal(wait_exit(pid, 20000), 0);
  assert_true(file_has(log, "has 2 camera(s)"));
  assert_true(file_has(log, "camera 2"));
  lm_image a, b;
  load("front.png", &a);
  load("back.png", &b);
  double fa[3], fb[3];
  box_mean(&a, 0.2, 0.5, 0.8, 1, fa); /* below any message */
  box_mean(&b, 0.2, 0.5, 0.8, 1, fb);
  assert_true(fa[0] > 0.3 && fa[0] > 3 * fa[1]); /* the red quad, lit */
  assert_true(fb[0] < 0.02 && fb[1] < 0.02);     /* nothing behind */
  lm_image_free(&a);
  lm_image_free(&b);

  pid = spawn_view(log, "--scene", scene, "--size", "128x96", "--overlay", "off", "--exit-after", "1000000",
                   "--screenshot", edited, NULL);
  assert_true(wait_for(log, "limn: renderer:", 20000));
  sleep_ms(200);
  write_quad_scene("quad.gltf", "0,1,0");
  bool reloaded = wait_for(log, "reloaded scene", 10000);
  if (!reloaded) print_log(log);
  assert_true(reloaded);
  sleep_ms(300);
  kill(pid, SIGTERM);
  assert_int_equal(wait_exit(pid, 10000), 0);
  load("edited.png", &a);
  box_mean(&a, 0.2, 0.5, 0.8, 1, fa); /* below any message */
  assert_true(fa[1] > 0.3 && fa[1] > 3 * fa[0]); /* now green */
  lm_image_free(&a);
}

/* ---- time: the animated test scenes of data/scenes ---------------------- */
#define SCENE(name) LIMN_SOURCE_ROOT "/data/scenes/" name ".glb"

typedef struct time_line {
  double time;
  long frame;
  bool paused;
  char why[32];
} time_line;

/* The viewer's "time T s, frame F, animation 'A'[, paused] (why)" lines, in order. */
static int time_lines(const char *log, time_line *out, int max) {
  char *s = read_text(log);
  int n = 0;
  for (char *p = s; (p = strstr(p, "limn: time ")) && n < max; p++) {
    time_line *t = &out[n];
    char *why = strchr(p, '(');
    if (sscanf(p, "limn: time %lf s, frame %ld", &t->time, &t->frame) != 2 || !why) continue;
    char *eol = strchr(p, '\n');
    t->paused = strstr(p, ", paused (") && strstr(p, ", paused (") < (eol ? eol : p + strlen(p));
    sscanf(why, "(%31[^)])", t->why);
    n++;
  }
  free(s);
  return n;
}

static void assert_time(const time_line *t, const char *why, double time, long frame, bool paused) {
  if (strcmp(t->why, why) || fabs(t->time - time) > 2e-6 || t->frame != frame || t->paused != paused)
    fail_msg("wanted time %.6f frame %ld%s (%s), the viewer said %.6f frame %ld%s (%s)", time, frame,
             paused ? " paused" : "", why, t->time, t->frame, t->paused ? " paused" : "", t->why);
}

static void run_view_ok(const char *log, const char *scene, const char *size, const char *time, const char *keys,
                        const char *frames, const char *shot) {
  pid_t pid = spawn_view(log, "--scene", scene, "--tech", "dl", "--size", size, "--overlay", "off", "--time", time,
                         "--exit-after", frames, "--script-keys", keys, "--screenshot", shot, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
}

/* The largest difference of one value between two images. */
static double image_max_diff(const lm_image *a, const lm_image *b) {
  assert_int_equal(a->width, b->width);
  assert_int_equal(a->height, b->height);
  double m = 0;
  for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++) m = fmax(m, fabs(a->pixels[i] - b->pixels[i]));
  return m;
}

/* Space pauses, Left/Right step 1/24 s, time= scrubs; scripted runs play
 * 1/60 s a frame from the first. Paused, later frames are the same image. */
static void time_pauses_steps_and_scrubs(void **state) {
  (void)state;
  char log[512], a[512], b[512];
  log_path(log, "time");
  shot_path(a, "time_a.png");
  shot_path(b, "time_b.png");
  const char *keys = "3:Space,5:Right,6:Right,7:Left,8:Right,9:time=1.25,10:Right";
  run_view_ok(log, SCENE("moving_light"), "96x72", "0", keys, "12", a);
  time_line t[16];
  int n = time_lines(log, t, 16);
  if (n != 8) print_log(log);
  assert_int_equal(n, 8);
  double paused = 2.0 / 60, frame = 1.0 / 24; /* frames 1 and 2 played; Space came before frame 3's step */
  assert_time(&t[0], "Space", paused, 0, true);
  assert_time(&t[1], "Right", paused + frame, 1, true);
  assert_time(&t[2], "Right", paused + 2 * frame, 2, true);
  assert_time(&t[3], "Left", paused + frame, 1, true);
  assert_time(&t[4], "Right", paused + 2 * frame, 2, true);
  assert_time(&t[5], "scrubbed", 1.25, 30, true);
  assert_time(&t[6], "Right", 1.25 + frame, 31, true);
  assert_time(&t[7], "at exit", 1.25 + frame, 31, true);
  /* Twice the frames, paused all the same: the same time and the same pixels. */
  run_view_ok(log, SCENE("moving_light"), "96x72", "0", keys, "24", b);
  n = time_lines(log, t, 16);
  assert_int_equal(n, 8);
  assert_time(&t[7], "at exit", 1.25 + frame, 31, true);
  lm_image ia, ib;
  load("time_a.png", &ia);
  load("time_b.png", &ib);
  assert_true(image_max_diff(&ia, &ib) == 0);
  lm_image_free(&ia);
  lm_image_free(&ib);
  /* Playing from 0.9 s: 1/60 s at frames 1 to 11, Right pauses a frame
   * later (1.125 s, frame 27), Space plays on at frames 13 to 15. */
  run_view_ok(log, SCENE("moving_light"), "96x72", "0.9", "1:F5,12:Right,13:Space", "16", b);
  n = time_lines(log, t, 16);
  assert_int_equal(n, 3);
  assert_time(&t[0], "Right", 0.9 + 11.0 / 60 + frame, 27, true);
  assert_time(&t[1], "Space", 0.9 + 11.0 / 60 + frame, 27, false);
  assert_time(&t[2], "at exit", 0.9 + 14.0 / 60 + frame, 28, false);
}

/* Times as far out as 1e300 s (--time, time=) pose the animation's ends and
 * count a frame number held at +-1e15, with the overlay and the panel on
 * (they show it: the panel's slider keeps its knob within the keys). The
 * number was a conversion past a long's range, undefined, and the time was
 * printed with its 300 digits (now %g-like: limn_time_text). */
static void a_time_far_out_has_a_frame_number(void **state) {
  (void)state;
  char log[512], shot[512];
  log_path(log, "time_far");
  shot_path(shot, "time_far.png");
  pid_t pid = spawn_view(log, "--scene", SCENE("moving_light"), "--tech", "dl", "--size", "96x72", "--time", "1e300",
                         "--panel", "on", "--exit-after", "4", "--script-keys", "1:Space,2:time=-1e300", "--screenshot",
                         shot, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  time_line t[4];
  int n = time_lines(log, t, 4);
  if (n != 3) print_log(log);
  assert_int_equal(n, 3);
  assert_time(&t[0], "Space", 1e300, 1000000000000000L, true);
  assert_time(&t[1], "scrubbed", -1e300, -1000000000000000L, true);
  assert_time(&t[2], "at exit", -1e300, -1000000000000000L, true);
  assert_true(file_has(log, "limn: time 1e+300 s, frame "));
  assert_true(file_has(log, "limn: time -1e+300 s, frame "));
}

/* A sequence job's view (time = { 1, 2, 12.5 }: frame 3 at 1.24 s) counts the
 * job's frames: frame 3, not the viewer's default 24 fps from 0 (frame 29);
 * a --fps of another rate is refused naming both, the same one taken (a
 * rate of 12.5, as capture takes it: --fps wanted a whole number). */
static void a_sequence_job_counts_its_own_frames(void **state) {
  (void)state;
  char log[512], job[1200];
  log_path(log, "job_fps");
  snprintf(job, sizeof job,
           "return { scenes = { \"%s\" }, sizes = { \"48x36\" }, techniques = { \"dl\" },\n"
           "  time = { 1, 2, 12.5 }, output = \"seq/{camera}-{frame}.png\" }\n", SCENE("moving_light"));
  write_file("fps_job.lua", job);
  path_in_root(job, sizeof job, "fps_job.lua");
  for (int fps = 0; fps < 3; fps++) { /* without --fps, with the job's, with another */
    const char *rate = fps == 1 ? "12.5" : "24";
    pid_t pid = fps ? spawn_view(log, "--job", job, "--view", "3", "--fps", rate, "--exit-after", "2",
                                 "--script-keys", "1:Space", NULL)
                    : spawn_view(log, "--job", job, "--view", "3", "--exit-after", "2", "--script-keys", "1:Space",
                                 NULL);
    int rc = wait_exit(pid, 30000);
    if (rc != (fps == 2 ? 2 : 0)) print_log(log);
    if (fps == 2) {
      assert_int_equal(rc, 2);
      assert_true(file_has(log, "--fps 24: the job's time.fps is 12.5"));
      continue;
    }
    assert_int_equal(rc, 0);
    time_line t[4];
    int n = time_lines(log, t, 4);
    if (n != 2) print_log(log);
    assert_int_equal(n, 2);
    assert_time(&t[0], "Space", 1.24, 3, true);
    assert_time(&t[1], "at exit", 1.24, 3, true);
  }
}

/* A script and a scene file saved while paused at 1.25 s: the time and the
 * pause stay. */
static void time_survives_reload(void **state) {
  (void)state;
  char log[512], scene[512], cmd[1200];
  log_path(log, "time_reload");
  path_in_root(scene, sizeof scene, "motion.glb");
  snprintf(cmd, sizeof cmd, "cp %s %s", SCENE("moving_light"), scene);
  assert_int_equal(system(cmd), 0);
  pid_t pid = spawn_view(log, "--scene", scene, "--tech", "dl", "--size", "64x48", "--overlay", "off", "--time",
                         "1.25", "--script-keys", "1:Space", "--exit-after", "1000000", NULL);
  bool paused = wait_for(log, "(Space)", 20000);
  if (!paused) print_log(log);
  assert_true(paused);
  char *pp = read_text(LIMN_SOURCE_ROOT "/scripts/pp.lua");
  lm_buf b = {0};
  lm_buf_printf(&b, "%s\n-- edited\n", pp);
  write_file("scripts/pp.lua", b.data);
  bool reloaded = wait_for(log, "(script reloaded)", 10000);
  if (!reloaded) print_log(log);
  assert_true(reloaded);
  snprintf(cmd, sizeof cmd, "cp %s %s.tmp~ && mv %s.tmp~ %s", SCENE("moving_light"), scene, scene, scene);
  assert_int_equal(system(cmd), 0);
  reloaded = wait_for(log, "(scene reloaded)", 10000);
  if (!reloaded) print_log(log);
  assert_true(reloaded);
  sleep_ms(200);
  kill(pid, SIGTERM);
  assert_int_equal(wait_exit(pid, 10000), 0);
  time_line t[8];
  int n = time_lines(log, t, 8);
  assert_int_equal(n, 4);
  assert_time(&t[0], "Space", 1.25, 30, true);
  assert_time(&t[1], "script reloaded", 1.25, 30, true);
  assert_time(&t[2], "scene reloaded", 1.25, 30, true);
  assert_time(&t[3], "at exit", 1.25, 30, true);
  write_file("scripts/pp.lua", pp);
  lm_buf_free(&b);
  free(pp);
}

/* World position of node `name` of `path` at `seconds` (all animations). */
static void node_at(lm_scene *s, const char *name, double seconds, float pos[3]) {
  int node = lm_scene_find_node(s, name);
  assert_true(node >= 0);
  lm_scene_set_time(s, LM_ANIM_ALL, seconds);
  memcpy(pos, s->nodes[node].world + 12, 3 * sizeof *pos);
}

/* Are the scene's animations read and evaluated? The lamp of moving_light
 * crosses the room (x from -1.5 to 1.5 in 3 s) once they are. */
static const char *animation_missing(void) {
  lm_error err;
  lm_scene *s = lm_scene_load(SCENE("moving_light"), &err);
  if (!s) fail_msg("%s", err.msg);
  bool animated = lm_scene_animated(s);
  float a[3] = {0}, b[3] = {0};
  if (animated) {
    node_at(s, "lamp", 0, a);
    node_at(s, "lamp", 3, b);
  }
  lm_scene_destroy(s);
  if (!animated) return "the glTF loader reads no animations yet";
  if (fabsf(b[0] - a[0]) < 1e-3f) return "lm_scene_set_time is still a stub";
  if (fabsf(a[0] + 1.5f) > 1e-4f || fabsf(b[0] - 1.5f) > 1e-4f)
    fail_msg("the lamp goes from x %g to %g, not -1.5 to 1.5", a[0], b[0]);
  return NULL;
}

/* The moving light lights the left of the room at 0.25 s and its right at
 * 2.75 s; the turntable's camera, a quarter turn round at 1 s and whole
 * again at 4 s, is the user's once dragged (a scrub leaves it) until 0. */
static void animation_moves_light_and_camera(void **state) {
  (void)state;
  const char *missing = animation_missing();
  if (missing) {
    print_message("skipped: %s (the viewer's time is tested above)\n", missing);
    skip();
  }
  char log[512], path[512];
  log_path(log, "animated");
  const char *times[2] = {"0.25", "2.75"};
  double left[2][3], right[2][3];
  for (int i = 0; i < 2; i++) {
    char name[32];
    snprintf(name, sizeof name, "light%d.png", i);
    shot_path(path, name);
    run_view_ok(log, SCENE("moving_light"), "96x72", times[i], "1:Space", "3", path);
    lm_image img;
    load(name, &img);
    box_mean(&img, 0, 0.5, 0.33, 1, left[i]);
    box_mean(&img, 0.67, 0.5, 1, 1, right[i]);
    lm_image_free(&img);
    print_message("light at %s s: left %.3f, right %.3f (red)\n", times[i], left[i][0], right[i][0]);
  }
  assert_true(left[0][0] > 1.3 * right[0][0]);
  assert_true(right[1][0] > 1.3 * left[1][0]);

  /* 128x96: the lower half that image_diff compares stays clear of the
   * message a drag shows (three lines at the top). */
  static const struct { const char *time, *keys, *name; } runs[] = {
      {"0", "1:Space", "turn0.png"},       {"1", "1:Space", "turn1.png"},
      {"4", "1:Space", "turn4.png"},       {"1", "1:Space,2:drag=1;0,3:time=0", "dragged.png"},
      {"1", "1:Space,2:drag=1;0,3:time=0,4:0", "given_back.png"}};
  lm_image img[5];
  for (int i = 0; i < 5; i++) {
    shot_path(path, runs[i].name);
    run_view_ok(log, SCENE("turntable"), "128x96", runs[i].time, runs[i].keys, "7", path);
    load(runs[i].name, &img[i]);
  }
  assert_true(file_has(log, "camera 1 follows the animation"));
  assert_walls(&img[0]);
  assert_true(image_diff(&img[0], &img[1]) > 0.05);  /* a quarter turn round */
  assert_true(image_diff(&img[0], &img[2]) < 0.01);  /* whole round */
  assert_true(image_diff(&img[3], &img[1]) < 0.02);  /* the user's view stays at 1 s's */
  assert_true(image_diff(&img[3], &img[0]) > 0.05);
  assert_true(image_diff(&img[4], &img[0]) < 0.01);  /* 0 gives the camera back: 0 s's view */
  for (int i = 0; i < 5; i++) lm_image_free(&img[i]);
}

/* 1000 script edits through the real file watch (every tenth broken, every
 * hundredth rebuilding all shaders) leave the GL object and heap counts where
 * they were after the warm-up. */
static void reload_loop_leaks_nothing(void **state) {
  (void)state;
  char log[512];
  log_path(log, "loop");
  /* Mesa's shader disk cache keeps an in-memory index that grows by a few
   * bytes per compile (measured: with it off, 500 and 2000 edits end at the
   * same heap size); it is not ours to count. */
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "48x36", "--overlay", "off", "--quiet", "--reload-test",
                         "1000", NULL);
  unsetenv("MESA_SHADER_CACHE_DISABLE");
  int rc = wait_exit(pid, 50000);
  print_log(log);
  assert_int_equal(rc, 0);
  char *s = read_text(log), *line = strstr(s, "GL textures");
  assert_non_null(line);
  int t0, t1, f0, f1, p0, p1;
  assert_int_equal(sscanf(line, "GL textures %d -> %d, framebuffers %d -> %d, programs %d -> %d", &t0, &t1, &f0,
                          &f1, &p0, &p1), 6);
  assert_true(t0 > 0 && p0 > 0);
  assert_int_equal(t1, t0);
  assert_true(f1 <= f0);
  assert_int_equal(p1, p0);
  assert_non_null(strstr(s, "1000 edits, 0 reloads that went the wrong way"));
  free(s);
}


/* ---- the panel ----------------------------------------------------------- */
typedef struct widget_line {
  char name[128], kind[32], group[64];
  double x, y, w, h;
} widget_line;

/* The "panel widget ..." lines of a log (the script key `widgets`). */
static int read_widgets(const char *log, widget_line *out, int cap) {
  char *s = read_text(log);
  int n = 0;
  for (char *p = s; (p = strstr(p, "panel widget ")) && n < cap; p++) {
    widget_line *w = &out[n];
    if (sscanf(p, "panel widget %127s %31s %63s %lf %lf %lf %lf", w->name, w->kind, w->group, &w->x, &w->y, &w->w,
               &w->h) == 7)
      n++;
  }
  free(s);
  return n;
}

static const widget_line *find_widget(const widget_line *w, int n, const char *name) {
  for (int i = 0; i < n; i++)
    if (!strcmp(w[i].name, name)) return &w[i];
  fail_msg("the panel has no widget for option %s", name);
  return NULL;
}

/* Every option `limn capture --list-options` names has a widget, chosen by
 * its rule: a slider with the rule's range, a checkbox, a drop-down for
 * one_of, a colour for a colour; the pipeline's own group is open. */
static void panel_has_every_option(void **state) {
  (void)state;
  char log[512], list[512], cmd[2048];
  log_path(log, "panel_widgets");
  log_path(list, "list_options");
  snprintf(cmd, sizeof cmd, "%s capture --script %s/scripts/pp.lua --list-options > %s 2>&1", LIMN_EXE, root, list);
  assert_int_equal(system(cmd), 0);
  pid_t pid = spawn_view(log, "--panel", "on", "--tech", "dl", "--size", "384x288", "--exit-after", "4",
                         "--script-keys", "3:widgets", NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  static widget_line w[1024];
  int n = read_widgets(log, w, 1024), listed = 0;
  char *text = read_text(list);
  /* "options: a=1, b.c=x, sky.zenith=0.1,0.15,0.3, ..." after the techniques line */
  char *opts = strstr(text, "options:");
  assert_non_null(opts);
  for (char *p = opts + 8; p && *p; p = strstr(p, ", ")) {
    p += strspn(p, " ,\n");
    size_t len = strcspn(p, "=\n");
    if (p[len] != '=') break;
    char name[128];
    snprintf(name, sizeof name, "%.*s", (int)len, p);
    find_widget(w, n, name);
    listed++;
  }
  free(text);
  fprintf(stderr, "%d options listed, %d widgets\n", listed, n);
  assert_true(listed > 50 && n >= listed);
  static const struct { const char *name, *kind; } kinds[] = {
      {"ambient", "slider"},          {"light_cull", "checkbox"}, {"materials", "combo"},
      {"light_variants", "slider-int"}, {"sky.zenith", "colour"}, {"bloom.enabled", "checkbox"},
      {"dof.mode", "combo"},          {"isr.temporal.frames", "slider"}, {"sky.map", "text"},
      {"isr.seed.radius", "drag"}};
  for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++)
    assert_string_equal(find_widget(w, n, kinds[i].name)->kind, kinds[i].kind);
  const widget_line *ambient = find_widget(w, n, "ambient");
  assert_true(ambient->w > 20 && ambient->h > 5 && ambient->x > 384 / 2); /* shown, on the right */
  assert_true(find_widget(w, n, "bloom.strength")->w == 0);             /* its group closed */
}

/* Dragging the ambient slider to its right end sets ambient as --set would
 * (the log says so) and brightens the next frames. */
static void panel_slider_changes_option_and_image(void **state) {
  (void)state;
  char log[512], keys[256], dragged[512];
  log_path(log, "panel_drag");
  snprintf(dragged, sizeof dragged, "%s/dragged", root);
  mkdir(dragged, 0755);
  pid_t pid = spawn_view(log, "--panel", "on", "--tech", "dl", "--size", "384x288", "--exit-after", "6",
                         "--script-keys", "5:widgets", "--capture-dir", root, "--script-keys", "4:P", NULL);
  assert_int_equal(wait_exit(pid, 30000), 0);
  static widget_line w[1024];
  int n = read_widgets(log, w, 1024);
  const widget_line *a = find_widget(w, n, "ambient");
  int y = (int)(a->y + a->h / 2), x0 = (int)(a->x + 2), x1 = (int)(a->x + a->w + 40);
  snprintf(keys, sizeof keys, "3:mouse=%d;%d,4:button=down,5:mouse=%d;%d,6:button=up,9:P", x0, y, x1, y);
  pid = spawn_view(log, "--panel", "on", "--tech", "dl", "--size", "384x288", "--exit-after", "10",
                   "--capture-dir", dragged, "--script-keys", keys, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  char *s = read_text(log), *set = strstr(s, "ambient = ");
  if (!set) print_log(log);
  assert_non_null(set);
  double value = 0;
  for (char *p = set; p; p = strstr(p + 1, "ambient = ")) sscanf(p, "ambient = %lf", &value); /* the last */
  free(s);
  fprintf(stderr, "ambient dragged to %g\n", value);
  assert_true(value > 1000); /* the right end of 0..1e6 */
  lm_image before, after;
  load("limn-frame-0001.png", &before);
  load("dragged/limn-frame-0001.png", &after);
  assert_true(image_mean(&after) > image_mean(&before) + 0.2);
  lm_image_free(&before);
  lm_image_free(&after);
}

/* An option of a type the panel cannot set (a list) shows read-only, not a crash. */
static void panel_shows_unsupported_option_read_only(void **state) {
  (void)state;
  char log[512], script[512];
  log_path(log, "panel_list");
  write_file("scripts/listed.lua",
             "local gbuffer = require \"gbuffer\"\n"
             "Techniques = { \"plain\" }\n"
             "Options = { weights = { 1, 2, 3, 4 }, gain = 0.5 }\n"
             "function OnRender(tech)\n"
             "  local G = gbuffer.render(gbuffer.targets())\n"
             "  local lit = target{ \"lit\", format = \"rgba16f\" }\n"
             "  present(pass{ \"direct\", shader = \"direct.frag\", inputs = gbuffer.inputs(G),\n"
             "                params = { ambient = { tech.gain, tech.gain, tech.gain } }, out = lit })\n"
             "end\n");
  path_in_root(script, sizeof script, "scripts/listed.lua");
  pid_t pid = spawn_view(log, "--panel", "on", "--script", script, "--size", "256x192", "--exit-after", "4",
                         "--script-keys", "3:widgets", NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  static widget_line w[16];
  int n = read_widgets(log, w, 16);
  assert_string_equal(find_widget(w, n, "weights")->kind, "read-only");
  assert_string_equal(find_widget(w, n, "gain")->kind, "drag"); /* no rule: any number */
}

/* J writes the technique, the changed options and the view as a capture job
 * and a command line; `limn capture` renders from each the frame the viewer
 * showed, and --job FILE --view 0 opens the viewer on it again. */
static void job_leaves_and_comes_back(void **state) {
  (void)state;
  char log[512], scene[512], job[512], cmd[2048], dir2[512];
  log_path(log, "job");
  snprintf(scene, sizeof scene, "%s/data/scenes/cornell.glb", LIMN_SOURCE_ROOT);
  pid_t pid = spawn_view(log, "--scene", scene, "--tech", "dl", "--set", "ambient=0.3", "--size", "128x96",
                         "--exit-after", "6", "--capture-dir", root, "--script-keys", "3:J,4:P", NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  snprintf(job, sizeof job, "%s/limn-view-0001.lua", root);
  assert_true(file_has(job, "[\"ambient\"] = \"0.3\""));
  assert_true(file_has(job, "\"dl\""));
  snprintf(cmd, sizeof cmd, "%s capture --job %s --quiet", LIMN_EXE, job);
  assert_int_equal(system(cmd), 0);
  lm_image frame, rendered;
  load("limn-frame-0001.png", &frame);
  load("limn-view-0001.png", &rendered);
  assert_true(image_diff(&frame, &rendered) < 0.004);
  lm_image_free(&rendered);
  /* The command line: the scene's camera, which the viewer did not move. */
  snprintf(cmd, sizeof cmd, "cd %s && PATH=%.*s:$PATH sh limn-view-0001.sh >/dev/null 2>&1", root,
           (int)(strrchr(LIMN_EXE, '/') - LIMN_EXE), LIMN_EXE);
  assert_int_equal(system(cmd), 0);
  load("limn-view-0001.png", &rendered);
  assert_true(image_diff(&frame, &rendered) < 0.004);
  lm_image_free(&rendered);
  /* Back into the viewer: the job's scene, camera list, size, technique and options. */
  snprintf(dir2, sizeof dir2, "%s/back", root);
  mkdir(dir2, 0755);
  pid = spawn_view(log, "--job", job, "--view", "0", "--exit-after", "4", "--capture-dir", dir2, "--script-keys",
                   "3:P", NULL);
  rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  load("back/limn-frame-0001.png", &rendered);
  assert_int_equal(rendered.width, 128);
  assert_true(image_diff(&frame, &rendered) < 0.004);
  lm_image_free(&rendered);
  lm_image_free(&frame);
  pid = spawn_view(log, "--job", job, "--view", "1", "--exit-after", "2", NULL);
  assert_int_equal(wait_exit(pid, 30000), 2); /* one view: 0 */
  assert_true(file_has(log, "--view 1: job"));
}

/* The inspector starts on the frame's output, lists the targets the frame
 * did not write last, and shows a depth target grey with its range. */
static void inspector_order_and_grey_depth(void **state) {
  (void)state;
  char log[512], shot[512];
  log_path(log, "inspect_order");
  shot_path(shot, "depth.png");
  /* Through every target (more PageDowns than targets), then to the G-buffer's depth. */
  char keys[1024] = "2:PageDown";
  for (int i = 3; i < 40; i++) snprintf(keys + strlen(keys), sizeof keys - strlen(keys), ",%d:PageDown", i);
  snprintf(keys + strlen(keys), sizeof keys - strlen(keys), ",41:inspect=gbuffer.dpt");
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "96x72", "--overlay", "off", "--exit-after", "44",
                         "--script-keys", keys, "--screenshot", shot, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  char *s = read_text(log), *first = strstr(s, "inspecting '");
  assert_non_null(first);
  assert_true(!strncmp(first, "inspecting 'output.srgb'", 24));
  /* After the first target not written this frame, only such targets until the cycle starts again. */
  bool unwritten = false;
  for (char *p = first; (p = strstr(p, "inspecting '")); p++) {
    char line[256];
    snprintf(line, sizeof line, "%.*s", (int)strcspn(p, "\n"), p);
    bool marked = strstr(line, "not written") != NULL;
    if (!strncmp(p, "inspecting 'output.srgb'", 24) || !strncmp(p, "inspecting 'gbuffer.dpt'", 24)) {
      unwritten = false;
      continue;
    }
    assert_true(marked || !unwritten);
    unwritten |= marked;
  }
  char *dpt = strstr(s, "inspecting 'gbuffer.dpt' r32f 96x72 grey, range ");
  assert_non_null(dpt);
  double lo, hi;
  assert_int_equal(sscanf(dpt, "inspecting 'gbuffer.dpt' r32f 96x72 grey, range %lf .. %lf", &lo, &hi), 2);
  assert_true(lo >= 0 && hi > lo && hi <= 1);
  free(s);
  lm_image img;
  load("depth.png", &img);
  int greys = 0, n = img.width * img.height, levels = 0;
  float seen_lo = 1, seen_hi = 0;
  for (int i = 0; i < n; i++) {
    const float *p = img.pixels + (size_t)i * 3;
    greys += fabsf(p[0] - p[1]) < 0.01f && fabsf(p[1] - p[2]) < 0.01f;
    seen_lo = fminf(seen_lo, p[0]), seen_hi = fmaxf(seen_hi, p[0]);
  }
  levels = seen_hi - seen_lo > 0.5f;
  assert_int_equal(greys, n);  /* grey, not red */
  assert_int_equal(levels, 1); /* over its range: near and far apart */
  lm_image_free(&img);
}

/* A "panel control NAME X Y W H" line's rectangle. */
static void find_control(const char *log, const char *name, double rect[4]) {
  char *s = read_text(log), key[64];
  snprintf(key, sizeof key, "panel control %s ", name);
  char *line = strstr(s, key);
  if (!line) print_log(log);
  assert_non_null(line);
  assert_int_equal(sscanf(line + strlen(key), "%lf %lf %lf %lf", &rect[0], &rect[1], &rect[2], &rect[3]), 4);
  free(s);
}

/* A 384x288 dl run with the panel on, `frames` frames long, pressing keys. */
static void panel_run(const char *log, const char *frames, const char *keys) {
  pid_t pid = spawn_view(log, "--panel", "on", "--tech", "dl", "--size", "384x288", "--exit-after", frames,
                         "--script-keys", keys, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
}

/* Appends the keys that click the middle of rect: move at `frame`, press and release on the next two. */
static void click_keys(char *keys, size_t cap, int frame, const double rect[4]) {
  size_t n = strlen(keys);
  snprintf(keys + n, cap - n, "%s%d:mouse=%d;%d,%d:button=down,%d:button=up", n ? "," : "", frame,
           (int)(rect[0] + rect[2] / 2), (int)(rect[1] + rect[3] / 2), frame + 1, frame + 2);
}

/* Opens the panel's section `header` (a control) at frame 6; keys gets the
 * click and a widgets listing at frame 11, whose lines the run leaves in log. */
static void open_section(const char *log, const char *header, char *keys, size_t cap) {
  double rect[4];
  panel_run(log, "6", "5:widgets");
  find_control(log, header, rect);
  keys[0] = '\0';
  click_keys(keys, cap, 6, rect);
  strncat(keys, ",11:widgets", cap - strlen(keys) - 1);
  panel_run(log, "12", keys);
}

/* The panel's time controls: its button pauses an animation that plays, and
 * dragging its slider to the left end scrubs to the animation's first key. */
static void panel_plays_pauses_and_scrubs(void **state) {
  (void)state;
  char log[512], scene[512], keys[512];
  log_path(log, "panel_time");
  snprintf(scene, sizeof scene, "%s/data/scenes/door.glb", LIMN_SOURCE_ROOT);
  pid_t pid = spawn_view(log, "--panel", "on", "--scene", scene, "--tech", "dl", "--size", "384x288",
                         "--exit-after", "6", "--script-keys", "5:widgets", NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  double play[4], slider[4], lo, hi;
  find_control(log, "play", play);
  find_control(log, "time", slider);
  char *s = read_text(log), *keys_line = strstr(s, "': keys ");
  assert_non_null(keys_line);
  assert_int_equal(sscanf(keys_line, "': keys %lf..%lf s", &lo, &hi), 2);
  free(s);
  int px = (int)(play[0] + play[2] / 2), py = (int)(play[1] + play[3] / 2);
  int sy = (int)(slider[1] + slider[3] / 2), sx = (int)(slider[0] + slider[2] / 3);
  snprintf(keys, sizeof keys, "3:mouse=%d;%d,4:button=down,5:button=up,8:mouse=%d;%d,9:button=down,10:mouse=%d;%d,"
           "11:button=up", px, py, sx, sy, (int)slider[0] - 60, sy);
  pid = spawn_view(log, "--panel", "on", "--scene", scene, "--tech", "dl", "--size", "384x288", "--exit-after", "14",
                   "--script-keys", keys, NULL);
  rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  s = read_text(log);
  assert_non_null(strstr(s, ", paused (play button)"));
  double t = -1;
  for (char *line = s; line && *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL) {
    char *time = strstr(line, "limn: time "), *eol = strchr(line, '\n');
    char *scrubbed = strstr(line, ", paused (scrubbed)");
    if (time == line && scrubbed && (!eol || scrubbed < eol)) sscanf(time, "limn: time %lf", &t); /* the last */
  }
  free(s);
  if (t < 0) print_log(log);
  fprintf(stderr, "scrubbed to %g (keys %g..%g)\n", t, lo, hi);
  assert_true(fabs(t - lo) < 1e-4); /* the slider's left end: the first key */
}

/* The frame graph in the panel: opening it lists each pass's targets as
 * buttons, and clicking one shows that target in the inspector. */
static void panel_graph_button_inspects_target(void **state) {
  (void)state;
  char log[512], keys[512];
  log_path(log, "panel_graph");
  open_section(log, "graph", keys, sizeof keys);
  double button[4];
  char *s = read_text(log), *line = strstr(s, "panel target gbuffer.clr ");
  if (!line) print_log(log);
  assert_non_null(line);
  assert_int_equal(sscanf(line, "panel target gbuffer.clr %lf %lf %lf %lf", &button[0], &button[1], &button[2],
                          &button[3]), 4);
  free(s);
  click_keys(keys, sizeof keys, 12, button);
  panel_run(log, "17", keys);
  assert_true(file_has(log, "inspecting 'gbuffer.clr' rgba8"));
}

/* The panel's "Write job (J)" button writes one job, as J does: the
 * technique and the options changed. */
static void panel_button_writes_job(void **state) {
  (void)state;
  char log[512], keys[256], dir[512], job[600], scene[512];
  double rect[4];
  log_path(log, "panel_job");
  snprintf(dir, sizeof dir, "%s/button", root);
  mkdir(dir, 0755);
  snprintf(scene, sizeof scene, "%s/data/scenes/cornell.glb", LIMN_SOURCE_ROOT); /* a job names a file */
  strcpy(keys, "5:widgets");
  int rc = 0;
  for (int run = 0; run < 2 && !rc; run++) { /* where the button is, then a click on it */
    pid_t pid = spawn_view(log, "--panel", "on", "--scene", scene, "--tech", "dl", "--set", "ambient=0.25", "--size",
                           "384x288", "--exit-after", run ? "12" : "6", "--capture-dir", dir, "--script-keys", keys,
                           NULL);
    rc = wait_exit(pid, 30000);
    if (run) break;
    find_control(log, "job", rect);
    keys[0] = '\0';
    click_keys(keys, sizeof keys, 6, rect);
  }
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  snprintf(job, sizeof job, "%s/limn-view-0001.lua", dir);
  assert_true(file_has(job, "\"dl\""));
  assert_true(file_has(job, "[\"ambient\"] = \"0.25\""));
  snprintf(job, sizeof job, "%s/limn-view-0002.lua", dir);
  assert_false(lm_file_exists(job)); /* one click, one job */
}

/* The inspector gives the raw value of the texel under the cursor: the
 * depth target's there equals what P writes of it (EXR, raw values), at a
 * texel (on the short block) whose depth differs from its mirror's across
 * either axis, so that a flipped cursor would not pass. */
static void inspector_value_under_cursor(void **state) {
  (void)state;
  enum { X = 62, Y = 50, W = 96, H = 72 };
  char log[512], dir[512], keys[128];
  log_path(log, "inspect_cursor");
  snprintf(dir, sizeof dir, "%s/cursor", root);
  mkdir(dir, 0755);
  snprintf(keys, sizeof keys, "2:inspect=gbuffer.dpt,3:mouse=%d;%d,4:P", X, Y);
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "96x72", "--verbose", "--exit-after", "6", "--capture-dir",
                         dir, "--script-keys", keys, NULL);
  int rc = wait_exit(pid, 30000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  char *s = read_text(log), *line = strstr(s, "of the inspected target: "), path[600];
  if (!line) print_log(log);
  assert_non_null(line);
  int at[2];
  float shown[4];
  while (line > s && line[-1] != '\n') line--;
  line = strstr(line, "texel ");
  assert_int_equal(sscanf(line, "texel %d,%d of the inspected target: %f %f %f %f", &at[0], &at[1], &shown[0],
                          &shown[1], &shown[2], &shown[3]), 6);
  free(s);
  assert_int_equal(at[0], X);
  assert_int_equal(at[1], Y);
  snprintf(path, sizeof path, "%s/limn-gbuffer.dpt-0001.exr", dir);
  lm_image img;
  lm_error err;
  assert_true(lm_image_read(path, &img, &err));
  assert_int_equal(img.width, W);
#define DEPTH(x, y) img.pixels[((size_t)(y) * img.width + (x)) * img.channels]
  float raw = DEPTH(X, Y), across_x = DEPTH(W - 1 - X, Y), across_y = DEPTH(X, H - 1 - Y);
#undef DEPTH
  fprintf(stderr, "depth under the cursor: shown %.9g, written %.9g (mirrored %.9g, %.9g)\n", shown[0], raw, across_x,
          across_y);
  assert_true(fabsf(raw - across_x) > 1e-3f && fabsf(raw - across_y) > 1e-3f);
  assert_true(fabsf(shown[0] - raw) <= 1e-6f * fabsf(raw));
  lm_image_free(&img);
}

/* Mean absolute difference per value over columns x0..x1-1 of the lower half
 * (a message may show at the top). */
static double band_diff(const lm_image *a, const lm_image *b, int x0, int x1) {
  assert_int_equal(a->width, b->width);
  assert_int_equal(a->height, b->height);
  double sum = 0;
  int n = 0;
  for (int y = a->height / 2; y < a->height; y++)
    for (int x = x0; x < x1; x++)
      for (int c = 0; c < 3; c++, n++)
        sum += fabs(a->pixels[((size_t)y * a->width + x) * a->channels + c] -
                    b->pixels[((size_t)y * b->width + x) * b->channels + c]);
  return sum / (n > 0 ? n : 1);
}

/* A 128x96 dl run's screenshot as name.png, with up to two more flag pairs
 * (NULL ends them early). */
static void run_shot(const char *name, const char *keys, const char *flag1, const char *value1, const char *flag2,
                     const char *value2) {
  char log[512], shot[512];
  log_path(log, name);
  snprintf(shot, sizeof shot, "%s/%s.png", root, name);
  pid_t pid = spawn_view(log, "--tech", "dl", "--size", "128x96", "--overlay", "off", "--exit-after", "8",
                         "--screenshot", shot, "--script-keys", keys, flag1, value1, flag2, value2, NULL);
  int rc = wait_exit(pid, 60000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
}

/* --compare: dl left of the split, dl with a bright ambient right of it; a
 * drag on the line moves it, B turns the wipe off. Each side matches the
 * viewer run with that setting alone. */
static void compare_wipe_shows_both_sides(void **state) {
  (void)state;
  run_shot("ab_left", "1:F5", NULL, NULL, NULL, NULL);
  run_shot("ab_right", "1:F5", "--set", "ambient=5", NULL, NULL);
  run_shot("ab_wipe", "1:F5", "--compare", "dl", "--compare-set", "ambient=5");
  run_shot("ab_drag", "2:mouse=64;60,3:button=down,4:mouse=96;60,5:button=up", "--compare", "dl", "--compare-set",
           "ambient=5");
  run_shot("ab_off", "2:B", "--compare", "dl", "--compare-set", "ambient=5");
  lm_image left, right, wipe, drag, off;
  load("ab_left.png", &left);
  load("ab_right.png", &right);
  load("ab_wipe.png", &wipe);
  load("ab_drag.png", &drag);
  load("ab_off.png", &off);
  double apart = band_diff(&left, &right, 0, 128), wl = band_diff(&wipe, &left, 0, 60),
         wr = band_diff(&wipe, &right, 68, 128), dl = band_diff(&drag, &left, 0, 92),
         dr = band_diff(&drag, &right, 100, 128), ol = band_diff(&off, &left, 0, 128);
  fprintf(stderr, "A/B: sides apart %.4f; wipe left %.4f right %.4f; dragged left %.4f right %.4f; off %.4f\n",
          apart, wl, wr, dl, dr, ol);
  assert_true(apart > 0.1); /* the two settings differ visibly */
  assert_true(wl < 0.01 && wr < 0.01);
  assert_true(dl < 0.01 && dr < 0.01);
  assert_true(ol < 0.01);
  double line[3];
  box_mean(&wipe, 64.0 / 128, 0.5, 65.0 / 128, 1, line); /* the split's white line */
  assert_true(line[0] > 0.99 && line[1] > 0.99 && line[2] > 0.99);
  lm_image_free(&left);
  lm_image_free(&right);
  lm_image_free(&wipe);
  lm_image_free(&drag);
  lm_image_free(&off);
  char log[512];
  log_path(log, "ab_bad");
  assert_int_equal(wait_exit(spawn_view(log, "--compare", "nosuch", "--exit-after", "2", NULL), 30000), 2);
  assert_true(file_has(log, "--compare nosuch"));
  assert_int_equal(wait_exit(spawn_view(log, "--compare-set", "ambient=1", NULL), 30000), 2);
  assert_true(file_has(log, "--compare-set needs --compare"));
}

/* sRGB-encoded as the output stage writes 8-bit images (saturated first). */
static double srgb(double c) {
  c = c < 0 ? 0 : c > 1 ? 1 : c;
  return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1 / 2.4) - 0.055;
}

/* Mean |shot - expected| per value over columns x0..x1-1 of the lower half
 * (messages show at the top); expected holds linear values (encoded to sRGB
 * first) or, without linear, 8-bit values. */
static double band_vs(const lm_image *shot, const float *expected, int channels, bool linear, int x0, int x1) {
  double sum = 0;
  int n = 0;
  for (int y = shot->height / 2; y < shot->height; y++)
    for (int x = x0; x < x1; x++)
      for (int c = 0; c < 3; c++, n++) {
        double e = expected[((size_t)y * shot->width + x) * channels + c];
        sum += fabs(shot->pixels[((size_t)y * shot->width + x) * shot->channels + c] - (linear ? srgb(e) : e / 255));
      }
  return sum / (n > 0 ? n : 1);
}

/* The file whose name `limn report` gives setting s's image of the job's one view. */
static void report_image(int s, lm_image *img) {
  char cmd[600], path[512] = "";
  snprintf(cmd, sizeof cmd, "ls %s/rep/images/*_%d.exr", root, s);
  FILE *p = popen(cmd, "r");
  assert_non_null(p);
  if (!fgets(path, sizeof path, p)) path[0] = '\0';
  pclose(p);
  path[strcspn(path, "\n")] = '\0';
  lm_error err;
  if (!lm_image_read(path, img, &err)) fail_msg("%s", err.msg);
}

/* The last "reference error: view N, mean M, pearson P, indirect removed R" line. */
static bool reference_line(const char *log, double *mean, double *pearson, double *removed) {
  char *text = read_text(log), *at = NULL;
  for (char *p = text; (p = strstr(p, "reference error: view ")); p++) at = p;
  int view;
  bool ok = at && sscanf(at, "reference error: view %d, mean %lf, pearson %lf, indirect removed %lf", &view, mean,
                         pearson, removed) == 4;
  free(text);
  return ok;
}

/* At a view of a job whose POV-Ray references are cached, E shows the
 * frame's error against the reference: the figures limn report gives for
 * that view, a wipe with the reference on its right (pixels) and one with
 * the error heat map; the camera moved away, none. */
static void reference_error_and_wipe(void **state) {
  (void)state;
  if (system("command -v povray >/dev/null 2>&1") != 0) skip(); /* Debian's povray */
  char job[512], cams[600], cmd[2048], log[512], shot[512], refs[512];
  snprintf(cams, sizeof cams, "%s/one.cams", root);
  write_file("one.cams", "front 0 1 3.4 0 1 0 45\n");
  snprintf(job, sizeof job, "%s/refjob.lua", root);
  snprintf(cmd, sizeof cmd,
           "return { scenes = { { scene = \"%s/data/scenes/cornell.glb\", cameras = \"%s\" } },\n"
           "  techniques = { \"dl\" }, sizes = { \"128x96\" }, set = { ambient = 0 },\n"
           "  output = \"%s/refjob/{camera}_{technique}.png\" }\n", LIMN_SOURCE_ROOT, cams, root);
  write_file("refjob.lua", cmd);
  snprintf(refs, sizeof refs, "%s/refs", root);
  snprintf(cmd, sizeof cmd, "%s report --job %s --sweep dl --baseline dl+esm --out %s/rep --refs %s --quiet", LIMN_EXE,
           job, root, refs);
  assert_int_equal(system(cmd), 0);
  /* report.csv's dl row: mean_error (8th field), pearson (11th), indirect_removed (17th). */
  char path[512], *csv;
  snprintf(path, sizeof path, "%s/rep/report.csv", root);
  csv = read_text(path);
  char *row = strstr(csv, "\n\"dl\",");
  assert_non_null(row);
  double want[3] = {0};
  int field = 0;
  for (char *p = row + 1; *p && *p != '\n' && field < 17; p++) {
    if (*p == '"') p = strchr(p + 1, '"'); /* passes_ms: quoted */
    if (*p != ',') continue;
    field++;
    if (field == 7 || field == 10 || field == 16) want[field == 7 ? 0 : field == 10 ? 1 : 2] = atof(p + 1);
  }
  free(csv);
  fprintf(stderr, "report: mean %.6f pearson %.6f removed %.3f%%\n", want[0], want[1], want[2]);
  assert_true(want[0] > 0 && want[1] > 0);
  /* The wipe with the reference, then with the heat map, then moved away. */
  log_path(log, "ref_wipe");
  shot_path(shot, "ref_wipe.png");
  pid_t pid = spawn_view(log, "--job", job, "--view", "0", "--refs", refs, "--overlay", "off", "--exit-after", "8",
                         "--screenshot", shot, "--script-keys", "2:E", NULL);
  int rc = wait_exit(pid, 60000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  double got[3];
  assert_true(reference_line(log, &got[0], &got[1], &got[2]));
  fprintf(stderr, "viewer: mean %.6f pearson %.6f removed %.3f%%\n", got[0], got[1], got[2]);
  assert_true(fabs(got[0] - want[0]) <= 1e-3 * want[0]);
  assert_true(fabs(got[1] - want[1]) <= 1e-4);
  assert_true(fabs(got[2] - want[2]) <= 0.1);
  lm_image wipe, limn, base, ref;
  load("ref_wipe.png", &wipe);
  report_image(1, &limn);
  report_image(0, &base);
  char *text = read_text(log), *at = strstr(text, ": reference ");
  assert_non_null(at);
  char ref_path[512];
  assert_int_equal(sscanf(at, ": reference %511[^,]", ref_path), 1);
  free(text);
  lm_error err;
  if (!lm_image_read(ref_path, &ref, &err)) fail_msg("%s", err.msg);
  assert_int_equal(wipe.width, 128);
  double left = band_vs(&wipe, limn.pixels, limn.channels, true, 0, 60),
         right = band_vs(&wipe, ref.pixels, ref.channels, true, 68, 128),
         apart = band_vs(&wipe, limn.pixels, limn.channels, true, 68, 128);
  fprintf(stderr, "wipe: left vs Limn %.4f, right vs the reference %.4f (vs Limn %.4f)\n", left, right, apart);
  assert_true(left < 0.01 && right < 0.01 && apart > 0.03);
  lm_image_free(&wipe);
  /* The heat map: the frame's error against the reference, white at the baseline's largest pixel error. */
  shot_path(shot, "ref_heat.png");
  pid = spawn_view(log, "--job", job, "--view", "0", "--refs", refs, "--overlay", "off", "--exit-after", "8",
                   "--screenshot", shot, "--script-keys", "2:E,3:E", NULL);
  assert_int_equal(wait_exit(pid, 60000), 0);
  lm_image heat;
  load("ref_heat.png", &heat);
  unsigned char *rgb = malloc((size_t)128 * 96 * 3);
  lm_metrics_heatmap(&limn, &ref, lm_metrics_max_pixel_error(&base, &ref), rgb);
  float *bytes = malloc(sizeof(float) * 128 * 96 * 3);
  for (int i = 0; i < 128 * 96 * 3; i++) bytes[i] = rgb[i];
  double hot = band_vs(&heat, bytes, 3, false, 68, 128);
  fprintf(stderr, "heat map: right vs lm_metrics_heatmap %.4f\n", hot);
  assert_true(hot < 0.01);
  free(rgb);
  free(bytes);
  lm_image_free(&heat);
  lm_image_free(&limn);
  lm_image_free(&base);
  lm_image_free(&ref);
  /* A drag turns the camera: no reference there. */
  pid = spawn_view(log, "--job", job, "--view", "0", "--refs", refs, "--overlay", "off", "--exit-after", "8",
                   "--script-keys", "2:E,4:drag=40;0", NULL);
  assert_int_equal(wait_exit(pid, 60000), 0);
  assert_true(file_has(log, "no reference here"));
}

/* The panel's A/B: opening it and picking dl+esm in its list starts the
 * wipe's right side live; with the panel then closed (M) the left half is
 * dl's frame and the right half dl+esm's. */
static void panel_picks_compare_technique(void **state) {
  (void)state;
  /* Taller than panel_run's window (its control places hold, the panel
   * being anchored at the top): the list's later rows lie below 288. */
  const char *size = "384x352";
  char log[512], keys[512], shot[512];
  log_path(log, "panel_ab");
  open_section(log, "ab", keys, sizeof keys);
  double item[4];
  find_control(log, "ab=dl+esm", item);
  click_keys(keys, sizeof keys, 12, item);
  strcat(keys, ",16:M");
  shot_path(shot, "panel_ab.png");
  pid_t pid = spawn_view(log, "--panel", "on", "--tech", "dl", "--size", size, "--overlay", "off", "--exit-after",
                         "20", "--screenshot", shot, "--script-keys", keys, NULL);
  int rc = wait_exit(pid, 60000);
  if (rc) print_log(log);
  assert_int_equal(rc, 0);
  assert_true(file_has(log, "A/B: dl+esm on the right"));
  char left_shot[512], right_shot[512];
  shot_path(left_shot, "ab_dl.png");
  shot_path(right_shot, "ab_dlesm.png");
  assert_int_equal(wait_exit(spawn_view(log, "--tech", "dl", "--size", size, "--overlay", "off", "--exit-after",
                                        "8", "--screenshot", left_shot, NULL), 60000), 0);
  assert_int_equal(wait_exit(spawn_view(log, "--tech", "dl+esm", "--size", size, "--overlay", "off",
                                        "--exit-after", "8", "--screenshot", right_shot, NULL), 60000), 0);
  lm_image wipe, left, right;
  load("panel_ab.png", &wipe);
  load("ab_dl.png", &left);
  load("ab_dlesm.png", &right);
  double apart = band_diff(&left, &right, 200, 384), wl = band_diff(&wipe, &left, 0, 184),
         wr = band_diff(&wipe, &right, 200, 384);
  fprintf(stderr, "panel A/B: dl and dl+esm apart %.4f right of the line; wipe left %.4f, right %.4f\n", apart, wl, wr);
  assert_true(apart > 0.005);
  assert_true(wl < 0.002 && wr < 0.002);
  lm_image_free(&wipe);
  lm_image_free(&left);
  lm_image_free(&right);
}

/* An argument runs only the cases it matches (cmocka's filter: "reference_*"). */
int main(int argc, char **argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_teardown(command_line_errors, stop_leftover),
      cmocka_unit_test_teardown(window_shows_the_box, stop_leftover),
      cmocka_unit_test_teardown(keys_switch_techniques_and_options, stop_leftover),
      cmocka_unit_test_teardown(live_reload_survives_errors, stop_leftover),
      cmocka_unit_test_teardown(resize_to_1x1_and_back, stop_leftover),
      cmocka_unit_test_teardown(inspector_writes_target_and_frame, stop_leftover),
      cmocka_unit_test_teardown(cameras_and_scene_reload, stop_leftover),
      cmocka_unit_test_teardown(camera_moves_and_turns, stop_leftover),
      cmocka_unit_test_teardown(time_pauses_steps_and_scrubs, stop_leftover),
      cmocka_unit_test_teardown(a_time_far_out_has_a_frame_number, stop_leftover),
      cmocka_unit_test_teardown(a_sequence_job_counts_its_own_frames, stop_leftover),
      cmocka_unit_test_teardown(time_survives_reload, stop_leftover),
      cmocka_unit_test_teardown(animation_moves_light_and_camera, stop_leftover),
      cmocka_unit_test_teardown(reload_loop_leaks_nothing, stop_leftover),
      cmocka_unit_test_teardown(panel_has_every_option, stop_leftover),
      cmocka_unit_test_teardown(panel_slider_changes_option_and_image, stop_leftover),
      cmocka_unit_test_teardown(panel_shows_unsupported_option_read_only, stop_leftover),
      cmocka_unit_test_teardown(job_leaves_and_comes_back, stop_leftover),
      cmocka_unit_test_teardown(inspector_order_and_grey_depth, stop_leftover),
      cmocka_unit_test_teardown(panel_plays_pauses_and_scrubs, stop_leftover),
      cmocka_unit_test_teardown(panel_graph_button_inspects_target, stop_leftover),
      cmocka_unit_test_teardown(panel_button_writes_job, stop_leftover),
      cmocka_unit_test_teardown(inspector_value_under_cursor, stop_leftover),
      cmocka_unit_test_teardown(compare_wipe_shows_both_sides, stop_leftover),
      cmocka_unit_test_teardown(reference_error_and_wipe, stop_leftover),
      cmocka_unit_test_teardown(panel_picks_compare_technique, stop_leftover),
  };
  if (argc > 1) cmocka_set_test_filter(argv[1]);
  return cmocka_run_group_tests(tests, setup, teardown);
}
