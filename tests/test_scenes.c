/* Every scene of data/scenes through a capture job (the limn command, every
 * view at 96x72), then each written image checked for content: not blank,
 * lit (bright and shaded parts), and for scenes with textures, texture detail
 * that the same view without its textures lacks. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image/image.h"
#include "render/render.h"
#include "scene/gltf.h"

enum { W = 96, H = 72 };

static const char *limn;
static char tmp[256];

/* Mean |difference| of horizontal neighbours (0..255 scale): high-frequency energy. */
static double detail(const float *px, int channels) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x + 1 < W; x++)
      for (int c = 0; c < 3; c++, n++)
        sum += fabs(px[(y * W + x) * channels + c] - px[(y * W + x + 1) * channels + c]) * 255.0;
  return sum / n;
}

/* Texture detail: the high-frequency energy of (image - flat render). The
 * geometry is the same in both, so its edges cancel; what is left is the
 * texture's variation about its mean. */
static double texture_detail(const float *px, int channels, const unsigned char *flat) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y + 1 < H; y++)
    for (int x = 0; x + 1 < W; x++)
      for (int c = 0; c < 3; c++, n++) {
        int a = y * W + x, right = a + 1, down = a + W;
        double d = px[a * channels + c] * 255.0 - flat[a * 3 + c];
        double dr = px[right * channels + c] * 255.0 - flat[right * 3 + c];
        double dd = px[down * channels + c] * 255.0 - flat[down * 3 + c];
        sum += 0.5 * (fabs(d - dr) + fabs(d - dd)); /* across and down: stripes either way count */
      }
  return sum / n;
}

/* The same view rendered here with the scene as given (textures taken off by the caller). */
static const unsigned char *flat_render(lm_scene *s, int camera, const char *pp) {
  lm_error err;
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = pp}, &err);
  assert_non_null(p);
  assert_true(lm_pipeline_set_option(p, "ambient", "0.05", &err));
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = s, .pipeline = p, .width = W, .height = H,
                                                          .camera = camera}, &err);
  assert_non_null(r);
  static unsigned char rgb[W * H * 3];
  assert_true(lm_renderer_frame(r, &err) && lm_renderer_read(r, false, rgb, &err));
  lm_renderer_destroy(r);
  lm_pipeline_destroy(p);
  return rgb;
}

static void every_scene_renders_every_view_with_content(void **state) {
  (void)state;
  char scenes_dir[1024], job[512], cmd[2048];
  snprintf(scenes_dir, sizeof scenes_dir, "%s/data/scenes", lm_root_dir());
  /* The job lists every .glb there is, so a new scene is tested without an edit here. */
  DIR *d = opendir(scenes_dir);
  assert_non_null(d);
  char names[32][64];
  int count = 0;
  for (struct dirent *e; (e = readdir(d)) && count < 32;) {
    size_t len = strlen(e->d_name);
    if (len > 4 && !strcmp(e->d_name + len - 4, ".glb")) snprintf(names[count++], 64, "%.*s", (int)len - 4, e->d_name);
  }
  closedir(d);
  assert_true(count >= 5);
  snprintf(job, sizeof job, "%s/all.lua", tmp);
  FILE *f = fopen(job, "w");
  assert_non_null(f);
  fprintf(f, "return {\n  scenes = {");
  for (int i = 0; i < count; i++) fprintf(f, " \"%s/%s.glb\",", scenes_dir, names[i]);
  fprintf(f, " },\n  sizes = { \"96x72\" },\n  techniques = { \"dl\" },\n  set = { ambient = 0.05 },\n"
             "  output = \"%s/out/{scene}/{camera}.png\",\n}\n", tmp);
  fclose(f);
  snprintf(cmd, sizeof cmd, "'%s' capture --job '%s' > %s/log.txt 2>&1", limn, job, tmp);
  int rc = system(cmd);
  if (rc != 0) {
    snprintf(cmd, sizeof cmd, "cat %s/log.txt", tmp);
    (void)system(cmd);
    fail_msg("the job failed (%d)", rc);
  }

  char pp[1024];
  snprintf(pp, sizeof pp, "%s/scripts/pp.lua", lm_root_dir());
  lm_error err;
  assert_true(lm_context_create_headless(&(lm_context_desc){0}, &err));
  int views = 0, textured_scenes = 0;
  for (int i = 0; i < count; i++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.glb", scenes_dir, names[i]);
    lm_scene *s = lm_scene_load_gltf(path, &err);
    assert_non_null(s);
    int first = s->camera_count, n = 0;
    snprintf(path, sizeof path, "%s/%s.cams", scenes_dir, names[i]);
    if (access(path, F_OK) == 0) assert_true(lm_scene_add_camera_list(s, path, &n, &err) >= 0);
    else first = 0, n = s->camera_count; /* no list: the file's own cameras, as jobs take them */
    assert_true(n >= (lm_scene_animated(s) ? 1 : 3)); /* several views per still scene; one that moves
                                                        shows itself over time */
    /* The reference: each textured material's colour times its texture's
     * mean (linear) colour, no texture: the same light, without the detail. */
    bool textured = s->texture_count > 0;
    for (int t = 0; textured && t < s->material_count; t++) {
      lm_material *m = &s->materials[t];
      if (!m->base_color_texture) continue;
      const lm_scene_texture *tex = &s->textures[m->base_color_texture - 1];
      for (int c = 0; c < 3; c++) {
        double sum = 0;
        for (int p = 0; p < tex->width * tex->height; p++) sum += pow(tex->rgba[p * 4 + c] / 255.0, 2.2);
        m->color[c] *= (float)(sum / (tex->width * tex->height));
      }
      m->base_color_texture = 0;
    }
    double best_ratio = 0; /* the most texture detail in a view */
    for (int c = 0; c < n; c++, views++) {
      snprintf(path, sizeof path, "%s/out/%s/%s.png", tmp, names[i], s->cameras[first + c].name);
      lm_image img;
      if (!lm_image_read(path, &img, &err)) fail_msg("%s", err.msg);
      assert_int_equal(img.width, W);
      assert_int_equal(img.height, H);
      double lit = 0, dark = 0, sum = 0, maxl = 0;
      for (int p = 0; p < W * H; p++) {
        const float *q = img.pixels + p * img.channels;
        double l = 0.27 * q[0] + 0.67 * q[1] + 0.06 * q[2];
        sum += l;
        maxl = fmax(maxl, l);
        lit += l > 0.25, dark += l < 0.15;
      }
      double mean = sum / (W * H);
      printf("%-12s %-10s mean %.2f max %.2f lit %4.0f%% detail %5.1f", names[i], s->cameras[first + c].name, mean,
             maxl, 100 * lit / (W * H), detail(img.pixels, img.channels));
      /* Not blank and lit: a fair share of bright pixels, and light that varies (shading, not a flat fill). */
      assert_true(mean > 0.15 && maxl > 0.6);
      assert_true(lit > 0.2 * W * H);
      assert_true(lit + dark < W * H || dark > 0.02 * W * H);
      if (textured) {
        double td = texture_detail(img.pixels, img.channels, flat_render(s, first + c, pp));
        printf(" texture detail %5.1f", td);
        best_ratio = fmax(best_ratio, td);
      }
      printf("\n");
      lm_image_free(&img);
    }
    if (textured) {
      textured_scenes++;
      /* Some view shows its texture as detail a flat colour lacks (0..255 scale). */
      if (!(best_ratio > 3.0)) fail_msg("%s: texture detail %.2f", names[i], best_ratio);
    }
    lm_scene_destroy(s);
  }
  assert_true(textured_scenes >= 2);
  printf("%d views of %d scenes\n", views, count);
  snprintf(cmd, sizeof cmd, "%s/out/manifest.json", tmp);
  size_t len;
  char *manifest = lm_read_file(cmd, &len, &err);
  assert_non_null(manifest);
  int entries = 0;
  for (const char *p = manifest; (p = strstr(p, "{\"file\": ")); p++) entries++;
  assert_int_equal(entries, views);
  free(manifest);
  lm_programs_clear();
  lm_context_destroy();
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: test_scenes LIMN_BINARY\n");
    return 2;
  }
  limn = argv[1];
  snprintf(tmp, sizeof tmp, "/tmp/limn-scenes-XXXXXX");
  if (!mkdtemp(tmp)) return 1;
  lm_log_set_level(LM_LOG_ERROR);
  const struct CMUnitTest tests[] = {cmocka_unit_test(every_scene_renders_every_view_with_content)};
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", tmp);
  if (system(cmd) != 0) rc = 1;
  return rc;
}
