/* Reloading without a window (what `limn view` does on a save): a new
 * pipeline swapped into a running renderer keeps persistent targets that
 * match by name, format and size rule, a failing one leaves the old one
 * running, and a broken shader rebuild keeps the last good program.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gl_test.h"

enum { W = 32, H = 24 };

static void write_file(const char *rel, const char *text) { assert_true(gl_write_file(rel, text)); }

static const char fill_frag[] = "uniform vec4 c = vec4(0.0);\nout vec4 o;\nvoid main() { o = c; }\n";
static const char copy_frag[] =
    "in vec2 uv;\nuniform sampler2D src;\nuniform float gain = 1.0;\nout vec4 o;\n"
    "void main() { o = texture(src, uv) * gain; }\n";

/* Writes History red in its first frame only: later frames show it again. */
static const char writer_lua[] =
    "Techniques = { \"a\" }\n"
    "function OnCreate() History = target{ \"history\", format = \"rgba16f\", size = { 4, 4 } } end\n"
    "local first = true\n"
    "function OnRender(tech)\n"
    "  if first then pass{ \"fill\", shader = \"fill.frag\", params = { c = { 1, 0, 0, 1 } }, out = History } end\n"
    "  first = false\n"
    "  present(pass{ \"show\", shader = \"copy.frag\", inputs = { src = History },\n"
    "                out = target{ \"shown\", format = \"rgba16f\" } })\n"
    "end\n";

/* Only reads History: what it shows is what a swap kept. FORMAT is replaced. */
static const char reader_lua[] =
    "Techniques = { \"b\" }\n"
    "function OnCreate() History = target{ \"history\", format = \"FORMAT\", size = { 4, 4 } } end\n"
    "function OnRender(tech)\n"
    "  present(pass{ \"show\", shader = \"copy.frag\", inputs = { src = History },\n"
    "                out = target{ \"shown\", format = \"rgba16f\" } })\n"
    "end\n";


static lm_pipeline *load(const char *rel, const char *text) {
  write_file(rel, text);
  char path[512];
  snprintf(path, sizeof path, "%s/%s", gl_root(), rel);
  lm_error err;
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = path}, &err);
  if (!p) fail_msg("%s", err.msg);
  return p;
}

static lm_pipeline *reader(const char *format) {
  char text[1024], *at;
  snprintf(text, sizeof text, "%s", reader_lua);
  at = strstr(text, "FORMAT");
  char rest[1024];
  snprintf(rest, sizeof rest, "%s", at + 6);
  size_t head = (size_t)(at - text);
  int n = snprintf(at, sizeof text - head, "%s%s", format, rest);
  assert_true(n >= 0 && (size_t)n < sizeof text - head);
  return load("reader.lua", text);
}

/* The middle pixel of the last frame's output (sRGB bytes). */
static void middle(lm_renderer *r, unsigned char rgb[3]) {
  unsigned char img[W * H * 3];
  lm_error err;
  assert_true(lm_renderer_read(r, false, img, &err));
  memcpy(rgb, img + ((H / 2) * W + W / 2) * 3, 3);
}

static void swaps_keep_matching_history(void **state) {
  (void)state;
  write_file("shaders/fill.frag", fill_frag);
  write_file("shaders/copy.frag", copy_frag);
  lm_gfx_counts at_start = lm_gfx_stats();
  lm_error err;
  lm_scene *scene = lm_scene_builtin("cornell", &err);
  lm_pipeline *a = load("writer.lua", writer_lua);
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = a, .width = W, .height = H},
                                      &err);
  assert_non_null(r);
  unsigned char px[3];
  for (int i = 0; i < 2; i++) assert_true(lm_renderer_frame(r, &err));
  middle(r, px);
  assert_true(px[0] == 255 && px[1] == 0 && px[2] == 0); /* written in frame 1, shown in frame 2 */

  /* Same name, format and size: the texture and its red move over. */
  lm_pipeline *b = reader("rgba16f");
  assert_true(lm_renderer_swap_pipeline(r, b, &err));
  lm_pipeline_destroy(a);
  middle(r, px);
  assert_int_equal(px[0], 255);

  /* A script whose first frame fails leaves b running, history and all. */
  lm_pipeline *bad = load("bad.lua", "Techniques = { \"x\" }\n"
                                             "function OnRender(tech)\n"
                                             "  error(\"broken on purpose\")\n"
                                             "end\n");
  assert_false(lm_renderer_swap_pipeline(r, bad, &err));
  assert_non_null(strstr(err.msg, "bad.lua:3: broken on purpose"));
  lm_pipeline_destroy(bad);
  /* One that records fine but whose shader does not compile fails at execution. */
  write_file("shaders/nope.frag", "out vec4 o;\nvoid main() { o = vec4(1.0) }\n");
  bad = load("bad2.lua", "Techniques = { \"x\" }\n"
                                 "function OnRender(tech)\n"
                                 "  present(pass{ \"p\", shader = \"nope.frag\", out = target{ \"t\", format = \"rgba8\" } })\n"
                                 "end\n");
  assert_false(lm_renderer_swap_pipeline(r, bad, &err));
  assert_non_null(strstr(err.msg, "nope.frag:2"));
  lm_pipeline_destroy(bad);
  assert_true(lm_renderer_frame(r, &err));
  middle(r, px);
  assert_int_equal(px[0], 255);

  /* Another format is another target: it starts clear. */
  lm_pipeline *c = reader("rgba32f");
  assert_true(lm_renderer_swap_pipeline(r, c, &err));
  lm_pipeline_destroy(b);
  middle(r, px);
  assert_int_equal(px[0], 0);

  /* A broken shader rebuild keeps the last good program and says where. */
  lm_programs_invalidate();
  write_file("shaders/copy.frag", "in vec2 uv;\nuniform sampler2D src;\nout vec4 o;\nvoid main() { o = ; }\n");
  assert_true(lm_renderer_frame(r, &err));
  assert_non_null(lm_programs_error());
  assert_non_null(strstr(lm_programs_error(), "copy.frag:4"));
  lm_programs_invalidate();
  write_file("shaders/copy.frag", copy_frag);
  assert_true(lm_renderer_frame(r, &err));
  assert_null(lm_programs_error());

  lm_renderer_destroy(r);
  lm_programs_clear();
  lm_pipeline_destroy(c);
  lm_scene_destroy(scene);
  lm_gfx_counts at_end = lm_gfx_stats();
  assert_int_equal(at_end.textures, at_start.textures);
  assert_int_equal(at_end.framebuffers, at_start.framebuffers);
  assert_int_equal(at_end.programs, 0);
}

/* Growing and shrinking the output resizes targets that follow it, never to 0x0. */
static void resize_follows_the_output(void **state) {
  (void)state;
  lm_error err;
  lm_scene *scene = lm_scene_builtin("cornell", &err);
  lm_pipeline *p = load("resize.lua", "Techniques = { \"x\" }\n"
                                              "function OnRender(tech)\n"
                                              "  present(pass{ \"p\", shader = \"fill.frag\", params = { c = { 0, 1, 0, 1 } },\n"
                                              "                out = target{ \"half\", format = \"rgba8\", scale = 0.5 } })\n"
                                              "end\n");
  write_file("shaders/fill.frag", fill_frag);
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = p, .width = W, .height = H},
                                      &err);
  static const int sizes[][2] = {{W, H}, {1, 1}, {0, 0}, {-3, 5}, {W * 2, H}};
  static const int want[][2] = {{W / 2, H / 2}, {1, 1}, {1, 1}, {1, 2}, {W, H / 2}};
  for (int i = 0; i < 5; i++) {
    lm_renderer_resize(r, sizes[i][0], sizes[i][1]);
    assert_true(lm_renderer_frame(r, &err));
    lm_graph *g = lm_renderer_graph(r);
    lm_graph_target_info t = lm_graph_target(g, lm_graph_find_target(g, "half"));
    assert_int_equal(t.width, want[i][0]);
    assert_int_equal(t.height, want[i][1]);
    lm_texture tex;
    int w, h;
    assert_true(lm_renderer_output(r, &tex, &w, &h));
    assert_true(w >= 1 && h >= 1);
  }
  lm_renderer_destroy(r);
  lm_pipeline_destroy(p);
  lm_scene_destroy(scene);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(swaps_keep_matching_history),
      cmocka_unit_test(resize_follows_the_output),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
