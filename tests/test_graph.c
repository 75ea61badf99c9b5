/* Frame graph validation, culling and texture planning: no GL needed.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <string.h>

#include "graph/graph.h"

static int target(lm_graph *g, const char *name, lm_format f, float scale) {
  lm_error err;
  int t = lm_graph_add_target(g, &(lm_target_desc){.name = name, .format = f, .scale = scale}, &err);
  assert_true(t >= 0);
  return t;
}

/* A full-screen pass reading `in` (or none when < 0) and writing `out`. */
static int fs(lm_graph *g, const char *name, int in, int out) {
  lm_error err;
  lm_pass_input input = {"src", in};
  lm_pass_desc d = {.kind = LM_PASS_FULLSCREEN, .name = name, .where = "test.lua:1",
                    .shader = "x.frag", .inputs = &input, .input_count = in >= 0,
                    .outputs = &out, .output_count = 1, .depth = -1};
  int p = lm_graph_add_pass(g, &d, &err);
  assert_true(p >= 0);
  return p;
}

/* The output stage folds into the last pass only where that pass allows it, writes the image alone,
 * and the image is output-sized and transient and read by nobody; else nothing changes. */
static void output_stage_folds_only_into_a_pass_that_allows_it(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_error err;
  for (int c = 0; c < 5; c++) {
    lm_graph_begin(g, 64, 32);
    int lit = target(g, "lit", LM_FORMAT_RGBA16F, 1);
    int img = target(g, "img", LM_FORMAT_RGBA16F, c == 1 ? 0.5f : 1); /* 1: not output-sized */
    int srgb = target(g, "output.srgb", LM_FORMAT_RGBA8, 1);
    fs(g, "lit", -1, lit);
    lm_pass_input in[2] = {{"src", lit}, {"self", img}};
    lm_pass_desc d = {.kind = LM_PASS_FULLSCREEN, .name = "tonemap", .where = "test.lua:2", .shader = "x.frag",
                      .defines = "BLOOM", .inputs = in, .input_count = c == 3 ? 2 : 1, .outputs = &img,
                      .output_count = 1, .depth = -1, .fold_output = c != 2}; /* 2: not allowed */
    int tonemap = lm_graph_add_pass(g, &d, &err);
    if (c == 4) fs(g, "after", lit, target(g, "other", LM_FORMAT_RGBA8, 1)); /* 4: not the last pass */
    int folded = lm_graph_fold_output(g, img, &srgb, 1, "OUTPUT_STAGE;DISPLAY");
    lm_graph_pass_info p = lm_graph_pass(g, tonemap);
    if (c == 0) {
      assert_int_equal(folded, tonemap);
      assert_int_equal(p.desc->output_count, 1), assert_int_equal(p.desc->outputs[0], srgb);
      assert_string_equal(p.desc->defines, "BLOOM;OUTPUT_STAGE;DISPLAY");
      lm_graph_mark_output(g, srgb);
      assert_true(lm_graph_compile(g, &err)); /* img has no writer now, and nothing reads it */
      assert_false(lm_graph_target(g, img).used);
    } else {
      assert_int_equal(folded, -1);
      assert_int_equal(p.desc->outputs[0], img);
      assert_string_equal(p.desc->defines, "BLOOM");
    }
  }
  lm_graph_destroy(g);
}

static void target_sizes_follow_output_and_never_vanish(void **state) {
  (void)state;
  int w, h;
  lm_target_size(&(lm_target_desc){.scale = 0.5f}, 256, 192, &w, &h);
  assert_int_equal(w, 128), assert_int_equal(h, 96);
  lm_target_size(&(lm_target_desc){.scale = 0}, 256, 192, &w, &h); /* 0 means 1 */
  assert_int_equal(w, 256), assert_int_equal(h, 192);
  lm_target_size(&(lm_target_desc){.scale = 0.25f}, 1, 1, &w, &h);
  assert_int_equal(w, 1), assert_int_equal(h, 1);
  lm_target_size(&(lm_target_desc){.scale = 1e-9f}, 8192, 8192, &w, &h);
  assert_int_equal(w, 1), assert_int_equal(h, 1);
  lm_target_size(&(lm_target_desc){.width = 512, .height = 64, .scale = 0.5f}, 256, 192, &w, &h);
  assert_int_equal(w, 512), assert_int_equal(h, 64);
  lm_target_size(&(lm_target_desc){.scale = 1.0f / 3.0f}, 100, 7, &w, &h);
  assert_int_equal(w, 33), assert_int_equal(h, 2);
  /* The output stage reads an output-sized image texel by texel (lm_graph_target_output_sized). */
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  lm_error err;
  int one = target(g, "one", LM_FORMAT_RGBA16F, 1), half = target(g, "half", LM_FORMAT_RGBA16F, 0.5f),
      same = lm_graph_add_target(g, &(lm_target_desc){.name = "same", .format = LM_FORMAT_RGBA8, .width = 64,
                                                       .height = 48}, &err),
      other = lm_graph_add_target(g, &(lm_target_desc){.name = "other", .format = LM_FORMAT_RGBA8, .width = 64,
                                                        .height = 47}, &err);
  assert_true(lm_graph_target_output_sized(g, one) && lm_graph_target_output_sized(g, same));
  assert_false(lm_graph_target_output_sized(g, half) || lm_graph_target_output_sized(g, other));
  assert_false(lm_graph_target_output_sized(g, -1));
  lm_graph_destroy(g);
}

static void bad_targets_are_refused(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 64);
  lm_error err;
  assert_int_equal(lm_graph_add_target(g, &(lm_target_desc){.name = "a"}, &err), -1);
  assert_non_null(strstr(err.msg, "target 'a': no format"));
  target(g, "a", LM_FORMAT_RGBA8, 1);
  assert_int_equal(lm_graph_add_target(g, &(lm_target_desc){.name = "a", .format = LM_FORMAT_R32F}, &err), -1);
  assert_non_null(strstr(err.msg, "declared twice"));
  assert_int_equal(lm_graph_add_target(g, &(lm_target_desc){.name = "b", .format = LM_FORMAT_R32F,
                                                             .width = 4}, &err), -1);
  assert_non_null(strstr(err.msg, "target 'b'"));
  lm_graph_destroy(g);
}

static void unread_passes_are_left_out(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  int a = target(g, "a", LM_FORMAT_RGBA16F, 1), b = target(g, "b", LM_FORMAT_RGBA16F, 0.5f);
  int unused = target(g, "unused", LM_FORMAT_RGBA16F, 1), out = target(g, "out", LM_FORMAT_RGBA8, 1);
  fs(g, "make_a", -1, a);
  fs(g, "make_unused", a, unused); /* nobody reads it */
  fs(g, "make_b", a, b);
  fs(g, "final", b, out);
  lm_graph_mark_output(g, out);
  lm_error err;
  assert_true(lm_graph_compile(g, &err));
  assert_false(lm_graph_pass(g, 0).culled);
  assert_true(lm_graph_pass(g, 1).culled);
  assert_false(lm_graph_pass(g, 2).culled);
  assert_false(lm_graph_pass(g, 3).culled);
  assert_false(lm_graph_target(g, unused).used);
  assert_int_equal(lm_graph_target(g, b).width, 32);
  assert_int_equal(lm_graph_target(g, b).height, 24);
  lm_graph_destroy(g);
}

/* A CPU pass is culled and ordered by its edges like any pass; it takes no depth target. */
static void cpu_passes_follow_their_edges(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  int rays = target(g, "rays", LM_FORMAT_RGBA32F, 0.5f), hits = target(g, "hits", LM_FORMAT_RGBA32F, 0.5f);
  int spare = target(g, "spare", LM_FORMAT_RGBA32F, 0.5f), out = target(g, "out", LM_FORMAT_RGBA8, 1);
  int depth = target(g, "depth", LM_FORMAT_DEPTH32F, 0.5f);
  fs(g, "make_rays", -1, rays);
  lm_error err;
  lm_pass_input in = {"rays", rays};
  lm_pass_desc d = {.kind = LM_PASS_CPU, .name = "trace", .where = "test.lua:2", .shader = "trace",
                    .inputs = &in, .input_count = 1, .outputs = &hits, .output_count = 1, .depth = -1};
  assert_int_equal(lm_graph_add_pass(g, &d, &err), 1);
  d.name = "unread", d.outputs = &spare;
  assert_int_equal(lm_graph_add_pass(g, &d, &err), 2);
  fs(g, "light_hits", hits, out);
  lm_graph_mark_output(g, out);
  assert_true(lm_graph_compile(g, &err));
  assert_false(lm_graph_pass(g, 1).culled);
  assert_true(lm_graph_pass(g, 2).culled);
  d.shader = "";
  assert_int_equal(lm_graph_add_pass(g, &d, &err), -1);
  assert_non_null(strstr(err.msg, "pass 'unread': no function"));
  lm_graph_destroy(g);

  g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  rays = target(g, "rays", LM_FORMAT_RGBA32F, 0.5f), hits = target(g, "hits", LM_FORMAT_RGBA32F, 0.5f);
  depth = target(g, "depth", LM_FORMAT_DEPTH32F, 0.5f);
  fs(g, "make_rays", -1, rays);
  d = (lm_pass_desc){.kind = LM_PASS_CPU, .name = "trace", .where = "test.lua:2", .shader = "trace",
                     .inputs = &in, .input_count = 1, .outputs = &hits, .output_count = 1, .depth = depth};
  in.target = rays;
  lm_graph_add_pass(g, &d, &err);
  lm_graph_mark_output(g, hits);
  assert_false(lm_graph_compile(g, &err));
  assert_non_null(strstr(err.msg, "test.lua:2: pass 'trace': CPU passes take no depth target"));
  lm_graph_destroy(g);
}

/* A points pass needs a vertex shader and a count in range, takes no depth
 * target, and is culled by its edges like any pass. */
static void points_passes_are_checked_and_culled(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  int volume = target(g, "volume", LM_FORMAT_RGBA32F, 0.5f), spare = target(g, "spare", LM_FORMAT_RGBA32F, 0.5f);
  int out = target(g, "out", LM_FORMAT_RGBA8, 1), depth = target(g, "depth", LM_FORMAT_DEPTH32F, 0.5f);
  lm_error err;
  lm_pass_desc d = {.kind = LM_PASS_POINTS, .name = "inject", .where = "test.lua:4", .shader = "x.frag",
                    .vertex = "x.vert", .count = 100, .outputs = &volume, .output_count = 1, .depth = -1};
  assert_int_equal(lm_graph_add_pass(g, &d, &err), 0);
  d.name = "unread", d.outputs = &spare;
  assert_int_equal(lm_graph_add_pass(g, &d, &err), 1);
  fs(g, "lookup", volume, out);
  lm_graph_mark_output(g, out);
  assert_true(lm_graph_compile(g, &err));
  assert_false(lm_graph_pass(g, 0).culled);
  assert_true(lm_graph_pass(g, 1).culled);
  assert_string_equal(lm_pass_kind_name(lm_graph_pass(g, 0).kind), "points");
  d.vertex = NULL;
  assert_int_equal(lm_graph_add_pass(g, &d, &err), -1);
  assert_string_equal(err.msg, "test.lua:4: pass 'unread': no vertex shader");
  d.vertex = "x.vert", d.count = -1;
  assert_int_equal(lm_graph_add_pass(g, &d, &err), -1);
  assert_non_null(strstr(err.msg, "pass 'unread': count must be a whole number in 0 .. 67108864 (got -1)"));
  d.count = LM_MAX_POINTS + 1;
  assert_int_equal(lm_graph_add_pass(g, &d, &err), -1);
  d.count = 0, d.depth = depth;
  assert_true(lm_graph_add_pass(g, &d, &err) >= 0);
  lm_graph_mark_output(g, spare);
  assert_false(lm_graph_compile(g, &err));
  assert_non_null(strstr(err.msg, "test.lua:4: pass 'unread': points passes take no depth target"));
  lm_graph_destroy(g);
}

static void reading_an_unwritten_target_names_the_pass(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  int a = target(g, "never_written", LM_FORMAT_RGBA8, 1), out = target(g, "out", LM_FORMAT_RGBA8, 1);
  fs(g, "light", a, out);
  lm_graph_mark_output(g, out);
  lm_error err;
  assert_false(lm_graph_compile(g, &err));
  assert_string_equal(err.msg, "test.lua:1: pass 'light' reads target 'never_written' that no pass writes before it");
  lm_graph_destroy(g);
}

static void feedback_loops_are_refused(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  int a = target(g, "a", LM_FORMAT_RGBA8, 1);
  fs(g, "first", -1, a);
  fs(g, "loop", a, a);
  lm_graph_mark_output(g, a);
  lm_error err;
  assert_false(lm_graph_compile(g, &err));
  assert_non_null(strstr(err.msg, "pass 'loop' reads and writes target 'a'"));
  lm_graph_destroy(g);
}

static void formats_and_sizes_are_checked(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  int depth = target(g, "depth", LM_FORMAT_DEPTH32F, 1);
  fs(g, "depth_as_colour", -1, depth);
  lm_graph_mark_output(g, depth);
  lm_error err;
  assert_false(lm_graph_compile(g, &err));
  assert_non_null(strstr(err.msg, "target 'depth' (depth32f) cannot be a colour output"));

  lm_graph_begin(g, 64, 48);
  int full = target(g, "full", LM_FORMAT_RGBA8, 1), half = target(g, "half", LM_FORMAT_RGBA8, 0.5f);
  int outs[2] = {full, half};
  lm_pass_desc d = {.kind = LM_PASS_SCENE, .name = "mrt", .where = "t.lua:3", .shader = "std",
                    .outputs = outs, .output_count = 2, .depth = -1, .clear = true};
  assert_true(lm_graph_add_pass(g, &d, &err) >= 0);
  lm_graph_mark_output(g, full);
  assert_false(lm_graph_compile(g, &err));
  assert_non_null(strstr(err.msg, "its outputs differ in size"));

  lm_graph_begin(g, 64, 48);
  assert_false(lm_graph_compile(g, &err));
  assert_non_null(strstr(err.msg, "presents nothing"));
  lm_graph_destroy(g);
}

static void scene_passes_without_clear_keep_the_earlier_writer(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 32, 32);
  int c = target(g, "c", LM_FORMAT_RGBA8, 1);
  lm_error err;
  lm_pass_desc d = {.kind = LM_PASS_SCENE, .name = "opaque", .where = "t.lua:1", .shader = "std",
                    .outputs = &c, .output_count = 1, .depth = -1, .clear = true};
  assert_int_equal(lm_graph_add_pass(g, &d, &err), 0);
  d.name = "overlay";
  d.clear = false;
  assert_int_equal(lm_graph_add_pass(g, &d, &err), 1);
  lm_graph_mark_output(g, c);
  assert_true(lm_graph_compile(g, &err));
  assert_false(lm_graph_pass(g, 0).culled);
  assert_false(lm_graph_pass(g, 1).culled);
  /* Clearing makes the earlier pass dead. */
  lm_graph_begin(g, 32, 32);
  c = target(g, "c", LM_FORMAT_RGBA8, 1);
  d.outputs = &c;
  d.clear = true;
  d.name = "opaque";
  lm_graph_add_pass(g, &d, &err);
  d.name = "redraw";
  lm_graph_add_pass(g, &d, &err);
  lm_graph_mark_output(g, c);
  assert_true(lm_graph_compile(g, &err));
  assert_true(lm_graph_pass(g, 0).culled);
  assert_false(lm_graph_pass(g, 1).culled);
  lm_graph_destroy(g);
}

static void disjoint_lifetimes_share_a_texture(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  /* a -> b -> c -> out, all alike: a is dead once b is made, so c can reuse a's texture. */
  int a = target(g, "a", LM_FORMAT_RGBA16F, 1), b = target(g, "b", LM_FORMAT_RGBA16F, 1);
  int c = target(g, "c", LM_FORMAT_RGBA16F, 1), out = target(g, "out", LM_FORMAT_RGBA16F, 1);
  fs(g, "pa", -1, a);
  fs(g, "pb", a, b);
  fs(g, "pc", b, c);
  fs(g, "pout", c, out);
  lm_graph_mark_output(g, out);
  lm_error err;
  assert_true(lm_graph_compile(g, &err));
  assert_int_equal(lm_graph_slot_count(g), 2);
  assert_int_equal(lm_graph_target(g, a).slot, lm_graph_target(g, c).slot);
  assert_int_not_equal(lm_graph_target(g, a).slot, lm_graph_target(g, b).slot);
  assert_int_not_equal(lm_graph_target(g, c).slot, lm_graph_target(g, out).slot);
  lm_graph_destroy(g);
}

/* A scene pass with views (shadow tiles, the RSM's) keeps its tiles in its
 * textures across frames (render.c's tile cache): its targets get slots of
 * their own. Here "before" dies before the tiles are drawn and "late" is
 * first written after the last read of them, all alike: shared, either
 * would overwrite the tiles (before the fix "late" took their texture). */
static void tile_targets_share_no_texture(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  lm_error err;
  int before = target(g, "before", LM_FORMAT_RGBA16F, 0.5f), mid = target(g, "mid", LM_FORMAT_RGBA16F, 0.5f);
  int tiles = target(g, "tiles", LM_FORMAT_RGBA16F, 0.5f), zbuf = target(g, "zbuf", LM_FORMAT_DEPTH32F, 0.5f);
  int read = target(g, "read", LM_FORMAT_RGBA16F, 0.5f), late = target(g, "late", LM_FORMAT_RGBA16F, 0.5f);
  int out = target(g, "out", LM_FORMAT_RGBA16F, 1);
  fs(g, "p_before", -1, before);
  fs(g, "p_mid", before, mid);
  lm_pass_view view = {.width = 32, .height = 24};
  lm_pass_desc d = {.kind = LM_PASS_SCENE, .name = "shadow.rsm", .where = "t.lua:1", .shader = "shadow",
                    .outputs = &tiles, .output_count = 1, .depth = zbuf, .clear = true, .views = &view,
                    .view_count = 1};
  assert_true(lm_graph_add_pass(g, &d, &err) >= 0);
  lm_pass_input both[] = {{"tiles", tiles}, {"mid", mid}}; /* mid lives past the tiles' pass */
  lm_pass_desc r = {.kind = LM_PASS_FULLSCREEN, .name = "p_read", .where = "t.lua:2", .shader = "x.frag",
                    .inputs = both, .input_count = 2, .outputs = &read, .output_count = 1, .depth = -1};
  assert_true(lm_graph_add_pass(g, &r, &err) >= 0);
  fs(g, "p_late", read, late);
  fs(g, "p_out", late, out);
  lm_graph_mark_output(g, out);
  assert_true(lm_graph_compile(g, &err));
  lm_graph_target_info t = lm_graph_target(g, tiles);
  assert_true(t.alone && lm_graph_target(g, zbuf).alone);
  int others[] = {before, mid, read, late};
  for (int i = 0; i < 4; i++) assert_int_not_equal(lm_graph_target(g, others[i]).slot, t.slot);
  /* The targets around them still share among themselves. */
  assert_int_equal(lm_graph_target(g, before).slot, lm_graph_target(g, read).slot);
  assert_int_equal(lm_graph_target(g, mid).slot, lm_graph_target(g, late).slot);
  lm_graph_destroy(g);
}

static void persistent_targets_outlive_frames(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_graph_begin(g, 64, 48);
  lm_error err;
  int hist = lm_graph_add_target(g, &(lm_target_desc){.name = "history", .format = LM_FORMAT_R32F,
                                                      .width = 1, .height = 1, .persistent = true}, &err);
  assert_int_equal(hist, 0);
  int out = target(g, "out", LM_FORMAT_RGBA8, 1);
  fs(g, "use_history", hist, out); /* reading last frame's contents is allowed */
  lm_graph_mark_output(g, out);
  assert_true(lm_graph_compile(g, &err));
  lm_graph_begin(g, 64, 48);
  assert_int_equal(lm_graph_find_target(g, "history"), 0);
  assert_int_equal(lm_graph_find_target(g, "out"), -1);
  assert_int_equal(lm_graph_add_target(g, &(lm_target_desc){.name = "late", .format = LM_FORMAT_R32F,
                                                            .persistent = true}, &err), 1);
  target(g, "x", LM_FORMAT_R32F, 1);
  assert_int_equal(lm_graph_add_target(g, &(lm_target_desc){.name = "later", .format = LM_FORMAT_R32F,
                                                            .persistent = true}, &err), -1);
  assert_non_null(strstr(err.msg, "in OnCreate"));
  lm_graph_destroy(g);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(target_sizes_follow_output_and_never_vanish),
      cmocka_unit_test(output_stage_folds_only_into_a_pass_that_allows_it),
      cmocka_unit_test(bad_targets_are_refused),
      cmocka_unit_test(unread_passes_are_left_out),
      cmocka_unit_test(cpu_passes_follow_their_edges),
      cmocka_unit_test(points_passes_are_checked_and_culled),
      cmocka_unit_test(reading_an_unwritten_target_names_the_pass),
      cmocka_unit_test(feedback_loops_are_refused),
      cmocka_unit_test(formats_and_sizes_are_checked),
      cmocka_unit_test(scene_passes_without_clear_keep_the_earlier_writer),
      cmocka_unit_test(disjoint_lifetimes_share_a_texture),
      cmocka_unit_test(tile_targets_share_no_texture),
      cmocka_unit_test(persistent_targets_outlive_frames),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
