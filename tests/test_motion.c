/* Motion the passes see (docs/motion.md): the G-buffer's velocity target
 * against the motion of a known camera translation, a moving node and a
 * deformed mesh, to a thousandth of a pixel; none on a first frame, a cut or
 * a still scene; motion blur that smears a moving object along its motion
 * and leaves a still frame as it is; temporal reuse that reprojects a moving
 * object along its motion and so leaves no ghost behind it; nothing
 * non-finite from extreme motion. On the built-in Cornell box, moved by hand
 * between frames. Needs GL (llvmpipe will do).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"
#include "scene/gltf.h"

enum { W = 256, H = 192 };

static gl_result start(const char *tech, const char *const *sets, int width, int height) {
  gl_result r = gl_render(&(gl_run){.tech = tech, .sets = sets, .width = width, .height = height, .keep_targets = true});
  if (!r.ok) fail_msg("%s", r.err.msg);
  return r;
}

static void frame(gl_result *r) {
  if (!gl_render_again(r)) fail_msg("%s", r->err.msg);
}

/* Moves node `name` of the Cornell box by dx along x (its local transform, a root's). */
static void move(const char *name, float dx) {
  lm_scene *s = gl_cornell();
  int n = lm_scene_find_node(s, name);
  assert_true(n >= 0);
  s->nodes[n].local[12] += dx;
  lm_scene_update(s);
}

/* The last frame's velocity target (W x H x 4, rows top first). */
static float *velocity(gl_result *r) {
  int w, h;
  float *v = gl_read_target(r, "gbuffer.vel", &w, &h);
  if (!v) fail_msg("the frame has no gbuffer.vel");
  assert_int_equal(w, r->width);
  assert_int_equal(h, r->height);
  return v;
}

/* The screen motion along x, in pixels, of a point at view depth z when it
 * moves by dx along the view's x axis (the box's camera looks down -z). */
static double expected_motion(const gl_result *r, double z, double dx) {
  lm_frame_data f;
  lm_scene_frame_data(gl_cornell(), 0, r->width, r->height, &f);
  return dx * r->height / (2.0 * z * f.clip[3]);
}

/* Checks every covered pixel's motion against expected_motion(dx_of(a)), where
 * a is the pixel's velocity coverage (1 still, 2 moved on its own); returns
 * the largest error in pixels and counts the pixels of each coverage. */
static double motion_error(gl_result *r, double dx_still, double dx_moved, int count[3]) {
  float *v = velocity(r);
  int w, h;
  float *d = gl_read_target(r, "gbuffer.dpt", &w, &h);
  assert_non_null(d);
  lm_frame_data f;
  lm_scene_frame_data(gl_cornell(), 0, r->width, r->height, &f);
  double worst = 0;
  count[0] = count[1] = count[2] = 0;
  for (int i = 0; i < w * h; i++) {
    const float *p = v + (size_t)i * 4;
    int a = (int)lroundf(p[3]);
    assert_true(a >= 0 && a <= 2);
    count[a]++;
    if (a == 0) {
      assert_true(p[0] == 0 && p[1] == 0);
      continue;
    }
    double z = d[(size_t)i * 4] * f.clip[1];
    double want = expected_motion(r, z, a == 2 ? dx_moved : dx_still);
    worst = fmax(worst, fmax(fabs(p[0] - want), fabs(p[1])));
    /* The depth then: the same, as both motions keep z. */
    assert_true(fabs(p[2] - z) <= 2e-3 * z);
  }
  free(d);
  free(v);
  return worst;
}

/* A camera moving 0.01 to the right moves every point 0.01 to the left in
 * view: each pixel's motion is -0.01 h / (2 z tan(fov / 2)), about 0.5 to 1
 * pixels here, and the target holds it to 1e-3 pixels. */
static void velocity_of_a_camera_translation(void **state) {
  (void)state;
  const char *sets[] = {"motion_blur=true", NULL};
  gl_result r = start("dl", sets, W, H);
  move("camera", 0.01f);
  frame(&r);
  int count[3];
  double err = motion_error(&r, -0.01, -0.01, count);
  move("camera", -0.01f);
  print_message("camera translation: worst velocity error %.2e px over %d pixels\n", err, count[1]);
  assert_true(err < 1e-3);
  assert_int_equal(count[2], 0); /* no node moved */
  assert_true(count[1] > W * H / 2);
  gl_result_free(&r);
}

/* The tall box moving 0.012 to the right under a still camera: its pixels
 * move by +0.012 h / (2 z tan), marked as moving on their own; every other
 * pixel stays where it was, exactly. With either material technique (pbr's
 * G-buffer has its emitted light before the velocity). */
static void velocity_of_a_moving_node(void **state) {
  (void)state;
  const char *sets[2][3] = {{"motion_blur=true", NULL}, {"motion_blur=true", "materials=pbr", NULL}};
  for (int k = 0; k < 2; k++) {
    gl_result r = start("dl", sets[k], W, H);
    move("tall_box", 0.012f);
    frame(&r);
    int count[3];
    double err = motion_error(&r, 0, 0.012, count);
    move("tall_box", -0.012f);
    print_message("moving node (%s): worst velocity error %.2e px; %d pixels moved, %d still\n",
                  k ? "pbr" : "phong", err, count[2], count[1]);
    assert_true(err < 1e-3);
    assert_true(count[2] > 500);
    assert_true(count[1] > W * H / 2);
    gl_result_free(&r);
  }
}

/* Moves every node drawing mesh `mesh` by its model matrix times d (the
 * world motion of its vertices moved by d), times `sign`. */
static void move_mesh_nodes(int mesh, const float d[3], float sign) {
  lm_scene *s = gl_cornell();
  for (int n = 0; n < s->node_count; n++) {
    if (s->nodes[n].mesh != mesh) continue;
    for (int r = 0; r < 3; r++)
      for (int k = 0; k < 3; k++) s->nodes[n].local[12 + r] += sign * s->nodes[n].local[4 * k + r] * d[k];
  }
  lm_scene_update(s);
}

/* A deformed mesh (its vertices now, prev_positions then, marked dirty, as
 * the animation leaves it) moves as its nodes would have moved had the
 * vertices stayed and the nodes carried them: the two velocity targets agree
 * to 1e-3 pixels. The frame after (no new deformation) has no motion. */
static void velocity_of_a_deformed_mesh(void **state) {
  (void)state;
  lm_scene *s = gl_cornell();
  int mesh = s->nodes[lm_scene_find_node(s, "tall_box")].mesh; /* the cube both boxes draw */
  lm_scene_mesh *m = &s->meshes[mesh];
  const float d[3] = {0.02f, 0.0f, -0.015f}; /* in the mesh's space */
  const char *sets[] = {"motion_blur=true", NULL};
  /* The nodes carry the vertices. */
  move_mesh_nodes(mesh, d, -1);
  gl_result r = start("dl", sets, W, H);
  move_mesh_nodes(mesh, d, 1);
  frame(&r);
  float *by_nodes = velocity(&r);
  gl_result_free(&r);
  /* The vertices move alone. */
  r = start("dl", sets, W, H);
  m->prev_positions = malloc(sizeof(float) * 3 * (size_t)m->vertex_count);
  for (int i = 0; i < m->vertex_count; i++)
    for (int k = 0; k < 3; k++) m->prev_positions[3 * i + k] = m->vertices[(size_t)i * 8 + k] - d[k];
  m->dirty = true;
  frame(&r);
  float *by_vertices = velocity(&r);
  double worst = 0;
  int moved = 0;
  for (int i = 0; i < W * H; i++) {
    const float *a = by_nodes + (size_t)i * 4, *b = by_vertices + (size_t)i * 4;
    assert_true(a[3] == b[3]);
    moved += b[3] == 2;
    worst = fmax(worst, fmax(fabs(a[0] - b[0]), fabs(a[1] - b[1])));
  }
  frame(&r);
  int w, h;
  float *after = gl_read_target(&r, "gbuffer.vel", &w, &h); /* nothing moved: motion blur reads none */
  free(m->prev_positions);
  m->prev_positions = NULL;
  free(by_nodes);
  free(by_vertices);
  print_message("deformed mesh: %d pixels moved, worst difference from the same motion of its nodes %.2e px\n",
                moved, worst);
  assert_true(moved > 1000);
  assert_true(worst < 1e-3);
  assert_null(after);
  gl_result_free(&r);
}

/* No motion on a first frame, on a still scene's next frames (where motion
 * blur reads none and pp.lua declares none; a script that declares it anyway
 * finds it zero), or on the first frame after a cut (lm_renderer_set_view)
 * however far the camera jumped. */
static void no_velocity_without_motion(void **state) {
  (void)state;
  const char *sets[] = {"motion_blur=true", NULL};
  gl_result r = start("dl", sets, W, H);
  int count[3], w, h;
  assert_true(motion_error(&r, 0, 0, count) == 0);
  frame(&r);
  assert_null(gl_read_target(&r, "gbuffer.vel", &w, &h));
  /* A script that always declares the target and presents a copy of it. */
  assert_true(gl_write_file("shaders/test_copy.frag", "#include \"common.glsl\"\nuniform sampler2D src;\nout vec4 o;\n"
                            "void main() { o = texelFetch(src, ivec2(gl_FragCoord.xy), 0); }\n"));
  assert_true(gl_write_file("vel.lua", "local gbuffer = require 'gbuffer'\nTechniques = { 'vel' }\nOptions = {}\n"
                            "function OnRender()\n  local G = gbuffer.render(gbuffer.targets(1, 'std', true), 'std')\n"
                            "  present(pass{ 'copy', shader = 'test_copy.frag', inputs = { src = G.vel },\n"
                            "                out = target{ 'vel.copy', format = 'rgba32f' } })\nend\n"));
  gl_result t = gl_render(&(gl_run){.script = "vel.lua", .width = W, .height = H, .frames = 3});
  if (!t.ok) fail_msg("%s", t.err.msg);
  float *v = gl_read_target(&t, "vel.copy", &w, &h);
  assert_non_null(v);
  for (int i = 0; i < W * H; i++)
    assert_true(v[(size_t)i * 4] == 0 && v[(size_t)i * 4 + 1] == 0 && v[(size_t)i * 4 + 3] < 1.5f);
  free(v);
  gl_result_free(&t);
  move("camera", 0.5f);
  move("tall_box", 0.2f);
  lm_renderer_set_view(r.renderer, 0, W, H);
  frame(&r);
  move("camera", -0.5f);
  move("tall_box", -0.2f);
  assert_true(motion_error(&r, 0, 0, count) == 0);
  assert_int_equal(count[2], 0);
  gl_result_free(&r);
}

/* A frame that reads no velocity declares none: dl without motion blur or
 * temporal reuse, isr with temporal.velocity off, and isr's temporal reuse
 * in a frame whose scene did not change (no node moved: every pixel
 * reprojects through the camera alone), whatever the camera does. */
static void no_velocity_target_unless_read(void **state) {
  (void)state;
  const char *none[] = {NULL}, *novel[] = {"isr.temporal=true", "isr.temporal.velocity=false", NULL},
             *isr[] = {"isr.temporal=true", NULL};
  gl_result r = start("dl", none, 64, 48);
  int w, h;
  assert_null(gl_read_target(&r, "gbuffer.vel", &w, &h));
  gl_result_free(&r);
  r = start("isr", novel, 64, 48);
  assert_null(gl_read_target(&r, "gbuffer.vel", &w, &h));
  gl_result_free(&r);
  r = start("isr", isr, 64, 48);
  float *v = gl_read_target(&r, "gbuffer.vel", &w, &h);
  assert_non_null(v);
  free(v);
  move("camera", 0.01f);
  frame(&r);
  move("camera", -0.01f);
  assert_null(gl_read_target(&r, "gbuffer.vel", &w, &h));
  move("tall_box", 0.01f);
  frame(&r);
  move("tall_box", -0.01f);
  v = gl_read_target(&r, "gbuffer.vel", &w, &h); /* the box moved on its own */
  assert_non_null(v);
  free(v);
  gl_result_free(&r);
  const gl_bad_option cases[] = {
      {"isr", "isr.temporal.velocity=3", "is not a boolean"},
  };
  gl_assert_bad_options(cases, sizeof cases / sizeof *cases, "isr.temporal.velocity");
}

/* Pixel (x, y) of a W x H linear RGB image, rows from the top. */
static const float *px(const float *img, int x, int y) { return img + ((size_t)y * W + x) * 3; }

/* Horizontal and vertical gradient energy of the green channel (clamped to 1)
 * over x0..x1, y0..y1. */
static void gradients(const float *img, int x0, int y0, int x1, int y1, double *gx, double *gy) {
  *gx = *gy = 0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      double l = fmin(px(img, x, y)[1], 1), dx = fmin(px(img, x + 1, y)[1], 1) - l,
             dy = fmin(px(img, x, y + 1)[1], 1) - l;
      *gx += dx * dx, *gy += dy * dy;
    }
}

/* Node `name`'s screen rectangle in the box's view (rows from the top), grown by `margin`. */
static void box_rect(const char *name, int margin, int rect[4]) {
  lm_scene *s = gl_cornell();
  float lo[3], hi[3];
  assert_true(lm_scene_node_bounds(s, lm_scene_find_node(s, name), lo, hi));
  rect[0] = W, rect[1] = H, rect[2] = 0, rect[3] = 0;
  for (int c = 0; c < 8; c++) {
    int col, row;
    gl_project(W, H, c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2], &col, &row);
    rect[0] = col < rect[0] ? col : rect[0], rect[1] = row < rect[1] ? row : rect[1];
    rect[2] = col > rect[2] ? col : rect[2], rect[3] = row > rect[3] ? row : rect[3];
  }
  rect[0] = rect[0] - margin > 0 ? rect[0] - margin : 0, rect[1] = rect[1] - margin > 0 ? rect[1] - margin : 0;
  rect[2] = rect[2] + margin < W - 1 ? rect[2] + margin : W - 2;
  rect[3] = rect[3] + margin < H - 1 ? rect[3] + margin : H - 2;
}

/* Still, motion blur changes no pixel (1e-6); with the tall box moving 0.2
 * to the right (about 8 pixels) under a still camera, it smears the box
 * along x: around the box the horizontal gradient energy drops by half and
 * more than the vertical, and the pixels far from the box stay as they were. */
static void motion_blur_smears_a_moving_object(void **state) {
  (void)state;
  const char *off[] = {NULL}, *on[] = {"motion_blur=true", "motion_blur.strength=1", NULL};
  float *img[2];
  for (int k = 0; k < 2; k++) {
    gl_result r = start("dl", k ? on : off, W, H);
    frame(&r);
    double worst = 0;
    for (int i = 0; k && i < W * H * 3; i++) worst = fmax(worst, fabs(img[0][i] - r.rgb[i]));
    if (k) print_message("still frame, motion blur on against off: worst difference %.2e\n", worst);
    if (k) assert_true(worst < 1e-6);
    if (!k) img[0] = r.rgb, r.rgb = NULL;
    gl_result_free(&r);
  }
  free(img[0]);
  for (int k = 0; k < 2; k++) {
    gl_result r = start("dl", k ? on : off, W, H);
    move("tall_box", 0.2f);
    frame(&r);
    img[k] = r.rgb, r.rgb = NULL;
    gl_result_free(&r);
    if (k) break;
    move("tall_box", -0.2f);
  }
  int rect[4];
  box_rect("tall_box", 4, rect);
  move("tall_box", -0.2f);
  double gx[2], gy[2];
  for (int k = 0; k < 2; k++) gradients(img[k], rect[0], rect[1], rect[2], rect[3], &gx[k], &gy[k]);
  print_message("motion blur of a moving box: horizontal gradient energy %.3f -> %.3f, vertical %.3f -> %.3f\n",
                gx[0], gx[1], gy[0], gy[1]);
  assert_true(gx[1] < 0.5 * gx[0]);
  assert_true(gx[1] / gx[0] < 0.75 * (gy[1] / gy[0]));
  /* Far from the box (the left wall's half of the image, left of it by more
   * than max_length): nothing moved there, nothing changed. */
  double far = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < rect[0] - 40 && x < W / 2; x++)
      for (int c = 0; c < 3; c++) far = fmax(far, fabs(px(img[0], x, y)[c] - px(img[1], x, y)[c]));
  assert_true(rect[0] - 40 > 16);
  assert_true(far < 1e-6);
  free(img[0]);
  free(img[1]);
}

/* Mean |a - b| over the W x H pixels where mask is set. */
static double masked_error(const float *a, const float *b, const bool *mask) {
  double sum = 0;
  int n = 0;
  for (int i = 0; i < W * H; i++)
    if (mask[i]) {
      for (int c = 0; c < 3; c++) sum += fabs(a[(size_t)i * 3 + c] - b[(size_t)i * 3 + c]);
      n++;
    }
  return n ? sum / (3.0 * n) : 0;
}

/* Temporal reuse under a still camera while the tall box slides 0.15 a
 * frame to the right for 4 frames after 10 still ones. In the band it
 * uncovered (the pixels whose depth changed by more than the disocclusion
 * test's share, but for where the box is now) its history must be gone:
 * the error against a still render of the box where it stopped (the same
 * settings, its history converged over 40 frames and unclamped: a
 * reference that a fresh frame's pattern is not a large part of; one of 14
 * frames at 4 held 1/4 of it, and flattered the fresh frame by a third; a
 * clamped one follows each frame's neighbourhood) within a bound of a
 * frame without reuse there, and no more than reprojecting through the
 * camera alone (which drops it too: the depth test sees the box's depth in
 * that band's history). On the box itself the velocity carries the history
 * along; the test prints that error. Each technique with temporal reuse:
 * ISR (isr.temporal.turn = always: with the default a still camera's frames
 * are reuse off's, history or not), the combined technique and RSM at
 * their defaults (their RSM turns every frame, so their histories
 * average). Measured, band error with velocity / a frame without reuse / a
 * whole ghost: isr 0.0517 / 0.0492 / 0.269, isr+rsm+esm 0.0537 / 0.0463 /
 * 0.274, rsm+esm 0.0214 / 0.0173 / 0.302 (its fresh frame 0.0368 while
 * every tile of the RSM gather took one pattern, whose bias reuse averaged
 * away: now its lag shows as isr+rsm+esm's). isr+rsm+esm's excess over the
 * fresh frame is lag, not a ghost: the box changes the RSM, so every
 * pixel's light changes while it moves, and a history (the band was
 * uncovered over 4 frames; its pixels' histories since, and their
 * neighbours' through the blur) holds the light of the box's earlier
 * places, as much as temporal.moving lets it: the band at moving 1 / 1.5 /
 * 2.5 (the default) / 4 is 1.16 / 1.19 / 1.23 / 1.26 times the fresh
 * frame's error, with the velocity target or without, while on the box
 * itself longer histories win (0.0479 / 0.0423 / 0.0366 / 0.0334: noise).
 * ISR alone sees the box only on screen, and its noise hides the lag. */
static void moving_object_leaves_no_ghost(void **state) {
  (void)state;
  static const struct {
    const char *tech, *with[4], *without[5];
    double fresh; /* bound of the band's error over a frame's without reuse */
    const char *converged[2]; /* the still render's history: long enough to converge, unclamped */
  } cases[] = {
      {"isr", {"isr.temporal=true", "isr.temporal.frames=8", "isr.temporal.turn=always", NULL},
       {"isr.temporal=true", "isr.temporal.frames=8", "isr.temporal.turn=always", "isr.temporal.velocity=false", NULL},
       1.15, {"isr.temporal.frames=64", "isr.temporal.clamp=0"}},
      {"isr+rsm+esm", {"isr.temporal=true", NULL}, {"isr.temporal=true", "isr.temporal.velocity=false", NULL}, 1.3,
       {"isr.temporal.frames=64", "isr.temporal.clamp=0"}},
      {"isr+rsm+esm", {"isr.temporal=true", "isr.temporal.moving=1", NULL},
       {"isr.temporal=true", "isr.temporal.moving=1", "isr.temporal.velocity=false", NULL}, 1.2,
       {"isr.temporal.frames=64", "isr.temporal.clamp=0"}},
      {"rsm+esm", {"rsm.temporal=true", NULL}, {"rsm.temporal=true", "rsm.temporal.velocity=false", NULL}, 1.3,
       {"rsm.temporal.frames=64", "rsm.temporal.clamp=0"}},
  };
  enum { STILL = 10, MOVING = 4 };
  const float step = 0.15f;
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    const char *tech = cases[c].tech;
    move("tall_box", step * MOVING);
    const char *still[7] = {0};
    int n = 0;
    while (cases[c].with[n]) still[n] = cases[c].with[n], n++;
    still[n] = cases[c].converged[0], still[n + 1] = cases[c].converged[1];
    gl_result ref = start(tech, still, W, H);
    for (int f = 1; f < 40; f++) frame(&ref);
    gl_result one = start(tech, NULL, W, H);
    move("tall_box", -step * MOVING);
    bool *band = calloc((size_t)W * H, sizeof *band), *box = calloc((size_t)W * H, sizeof *box);
    float *img[2], *first = NULL;
    for (int k = 0; k < 2; k++) {
      gl_result r = start(tech, k ? cases[c].without : cases[c].with, W, H);
      int w, h;
      float *before = gl_read_target(&r, "gbuffer.dpt", &w, &h);
      assert_non_null(before);
      if (!k) first = memcpy(malloc(sizeof(float) * 3 * W * H), r.rgb, sizeof(float) * 3 * W * H); /* a whole ghost */
      for (int f = 1; f < STILL; f++) frame(&r);
      for (int f = 0; f < MOVING; f++) {
        move("tall_box", step);
        frame(&r);
      }
      move("tall_box", -step * MOVING);
      float *after = gl_read_target(&r, "gbuffer.dpt", &w, &h);
      for (int i = 0; !k && i < W * H; i++) {
        float d0 = before[(size_t)i * 4], d1 = after[(size_t)i * 4];
        band[i] = fabsf(d0 - d1) > 0.01f * d1;
      }
      free(before), free(after);
      assert_true(gl_all_finite(&r));
      img[k] = r.rgb, r.rgb = NULL;
      gl_result_free(&r);
    }
    /* The box where it stopped: the pixels that moved on their own in the last
     * frame of the same motion (read where the velocity target lives to the
     * end of the frame: motion blur reads it last). */
    const char *blur[] = {"motion_blur=true", NULL};
    gl_result r = start("dl", blur, W, H);
    for (int f = 0; f < MOVING; f++) {
      move("tall_box", step);
      frame(&r);
    }
    move("tall_box", -step * MOVING);
    float *v = velocity(&r);
    for (int i = 0; i < W * H; i++) {
      box[i] = v[(size_t)i * 4 + 3] > 1.5f;
      band[i] = band[i] && !box[i];
    }
    free(v);
    gl_result_free(&r);
    int n_band = 0, n_box = 0;
    for (int i = 0; i < W * H; i++) n_band += band[i], n_box += box[i];
    double e_band[2] = {masked_error(img[0], ref.rgb, band), masked_error(img[1], ref.rgb, band)},
           e_box[2] = {masked_error(img[0], ref.rgb, box), masked_error(img[1], ref.rgb, box)},
           one_band = masked_error(one.rgb, ref.rgb, band), one_box = masked_error(one.rgb, ref.rgb, box),
           ghost = masked_error(first, ref.rgb, band);
    print_message("moving box under %s with temporal reuse, error against the still render: in the band it "
                  "uncovered (%d pixels) %.4f with velocity, %.4f without, %.4f a frame without reuse, %.4f the "
                  "box itself (a whole ghost); on the box (%d pixels) %.4f, %.4f, %.4f\n", tech, n_band, e_band[0],
                  e_band[1], one_band, ghost, n_box, e_box[0], e_box[1], one_box);
    assert_true(n_band > 300 && n_box > 300);
    assert_true(e_band[0] < 0.25 * ghost);
    assert_true(e_band[0] < cases[c].fresh * one_band);
    assert_true(fabs(e_band[0] - e_band[1]) < 0.05 * e_band[1]);
    free(img[0]), free(img[1]), free(first), free(band), free(box);
    gl_result_free(&one);
    gl_result_free(&ref);
  }
}

/* A glTF animation moving a caster (the door scene's door opening from 0.5
 * s): the tile cache makes its static layers on the first frame (render.c
 * casters_animated) and every frame equals drawing every tile; from the
 * door's second moving frame on, its tiles are drawn over their layers. */
static void an_animated_caster_draws_over_static_layers(void **state) {
  (void)state;
  char path[4096];
  snprintf(path, sizeof path, "%s/data/scenes/door.glb", LIMN_SOURCE_ROOT);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  const char *off[] = {"shadow.cache=false", NULL};
  lm_scene_set_time(s, LM_ANIM_ALL, 0.4);
  gl_result c = gl_render(&(gl_run){.scene = s, .tech = "rsm+esm", .width = 64, .height = 48}),
            u = gl_render(&(gl_run){.scene = s, .tech = "rsm+esm", .sets = off, .width = 64, .height = 48});
  if (!c.ok || !u.ok) fail_msg("%s", c.ok ? u.err.msg : c.err.msg);
  int layered = 0;
  for (int f = 0; f < 4; f++) {
    lm_scene_set_time(s, LM_ANIM_ALL, 0.5 + 0.05 * f);
    frame(&c);
    frame(&u);
    lm_scene_draw_stats kept = lm_renderer_shadow_draw_stats(c.renderer);
    double worst = 0;
    for (int i = 0; i < c.width * c.height * 3; i++) worst = fmax(worst, fabs(c.rgb[i] - u.rgb[i]));
    print_message("door at %.2f s: %d of %d tiles kept, %d drawn over their static layer; worst difference from "
                  "drawing them all %.2e\n", 0.5 + 0.05 * f, kept.kept, lm_renderer_shadows(c.renderer)->view_count,
                  kept.layered, worst);
    assert_true(worst == 0);
    if (f > 0) layered += kept.layered;
  }
  assert_true(layered > 0);
  gl_result_free(&c);
  gl_result_free(&u);
  lm_scene_destroy(s);
}

/* Shadow tiles, the RSM and the LPV follow a moving caster: a renderer that
 * keeps its tiles (shadow.cache) and one that draws them all run the same
 * frames, the tall box moving twice, then the cube both boxes draw deforming
 * (its vertices shifted, marked dirty); each frame is the same in both, and
 * the cached one draws again only some of its tiles; the second move draws
 * them over their kept static layers: only the box, once a tile at most. */
static void shadows_follow_moving_casters(void **state) {
  (void)state;
  static const char *const techs[] = {"rsm+esm", "lpv+esm"};
  const char *off[] = {"shadow.cache=false", NULL};
  lm_scene *s = gl_cornell();
  lm_scene_mesh *m = &s->meshes[s->nodes[lm_scene_find_node(s, "tall_box")].mesh];
  for (size_t t = 0; t < sizeof techs / sizeof *techs; t++) {
    gl_result c = start(techs[t], NULL, 128, 96), u = start(techs[t], off, 128, 96);
    for (int step = 0; step < 5; step++) {
      if (step == 1 || step == 2) move("tall_box", 0.05f);
      if (step == 3 || step == 4) { /* deform, then take it back */
        for (int i = 0; i < m->vertex_count; i++) m->vertices[(size_t)i * 8] += step == 3 ? 0.05f : -0.05f;
        m->dirty = true;
      }
      frame(&c);
      frame(&u);
      lm_scene_draw_stats kept = lm_renderer_shadow_draw_stats(c.renderer);
      int views = lm_renderer_shadows(c.renderer)->view_count + lm_renderer_shadows(c.renderer)->rsm_view_count;
      double worst = 0;
      for (int i = 0; i < c.width * c.height * 3; i++) worst = fmax(worst, fabs(c.rgb[i] - u.rgb[i]));
      print_message("%s, %s: %d of %d tiles kept, %d drawn over their static layer, %d nodes drawn; worst "
                    "difference from drawing them all %.2e\n", techs[t],
                    (const char *[]){"still", "box moved", "box moved again", "cube deformed", "cube back"}[step],
                    kept.kept, views, kept.layered, kept.drawn, worst);
      assert_true(worst == 0);
      assert_true(views > 1);
      if (step == 0) assert_int_equal(kept.kept, views);
      else assert_true(kept.kept < views);
      if (step == 2) assert_true(kept.layered == views - kept.kept && kept.drawn <= views - kept.kept);
    }
    move("tall_box", -0.1f);
    gl_result_free(&c);
    gl_result_free(&u);
  }
}

/* Extreme motion: the box flung 1e4 away and the camera turned about between
 * frames, with motion blur and ISR's temporal reuse on: every velocity finite
 * and within the half float's clamp, every pixel finite. */
static void extreme_motion_stays_finite(void **state) {
  (void)state;
  const char *sets[] = {"motion_blur=true", "isr.temporal=true", NULL};
  gl_result r = start("isr", sets, 64, 48);
  lm_scene *s = gl_cornell();
  int cam = s->cameras[0].node;
  float saved[16];
  memcpy(saved, s->nodes[cam].local, sizeof saved);
  for (int step = 0; step < 3; step++) {
    if (step == 0) move("short_box", 1e4f);
    if (step == 1) move("short_box", -1e4f - 0.5f);
    if (step == 2) { /* half a turn about y, and 3 back: everything behind the previous eye */
      float turn[16] = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, saved[12], saved[13], saved[14] - 3, 1};
      lm_scene_node_set_world(s, cam, turn);
    }
    frame(&r);
    int w, h;
    float *v = gl_read_target(&r, "gbuffer.vel", &w, &h);
    assert_non_null(v);
    for (int i = 0; i < w * h * 4; i++) {
      assert_true(isfinite(v[i]));
      assert_true(fabsf(v[i]) <= 65000);
    }
    free(v);
    assert_true(gl_all_finite(&r));
  }
  move("short_box", 0.5f);
  memcpy(s->nodes[cam].local, saved, sizeof saved);
  lm_scene_update(s);
  gl_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(velocity_of_a_camera_translation),
      cmocka_unit_test(velocity_of_a_moving_node),
      cmocka_unit_test(velocity_of_a_deformed_mesh),
      cmocka_unit_test(no_velocity_without_motion),
      cmocka_unit_test(no_velocity_target_unless_read),
      cmocka_unit_test(motion_blur_smears_a_moving_object),
      cmocka_unit_test(moving_object_leaves_no_ghost),
      cmocka_unit_test(shadows_follow_moving_casters),
      cmocka_unit_test(an_animated_caster_draws_over_static_layers),
      cmocka_unit_test(extreme_motion_stays_finite),
  };
  return cmocka_run_group_tests(tests, gl_test_setup, gl_test_teardown);
}
