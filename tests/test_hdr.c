/* The post effects (scripts/post.lua and its modules): tone mapping of a
 * known HDR image to the key, extremes, eye adaptation over frames, bloom
 * from one bright pixel, depth of field by gradient energy, motion blur from
 * a moving camera, no NaN or Inf anywhere in any effect's chain on the
 * Cornell box with dl and isr, and that an effect turned off records no
 * pass. The synthetic images come from a test shader written into a scratch
 * root (the real shaders and scripts linked in). Needs GL (llvmpipe will do).
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

enum { W = 256, H = 192 };

/* Scripts, relative to the scratch root. */
static const char image_lua[] = "image.lua", pp_lua[] = "scripts/pp.lua", unfolded_lua[] = "unfolded.lua";

/* pp.lua with each effect's passes as the modules one by one record them:
 * depth of field's composite written (post.fold). */
static const char *unfolded_script = "require('post').fold = false\nrequire 'pp'\n";

/* A grey test image: PATTERN 0 is three bands of rows (bottom lo, middle
 * mid, top hi, 64 rows each at 256x192), PATTERN 1 is `fill` everywhere;
 * then one `peak` pixel and one `dim` pixel; everything times gain, as
 * radiance (pre-exposed, as a lighting pass writes it: exposed()). */
static const char *image_frag =
    "#include \"common.glsl\"\n"
    "uniform int pattern = 0;\n"
    "uniform vec3 bands = vec3(0.25, 1.0, 4.0);\n"
    "uniform float gain = 1.0, fill = 0.0, peak = 0.0, dim = 0.0;\n"
    "uniform vec2 peak_at = vec2(-1.0), dim_at = vec2(-1.0);\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "  int h = int(frame.output_size.y);\n"
    "  float v = pattern == 0 ? (p.y < h / 3 ? bands.x : p.y < 2 * h / 3 ? bands.y : bands.z) : fill;\n"
    "  if (p == ivec2(peak_at)) v = peak;\n"
    "  if (p == ivec2(dim_at)) v = dim;\n"
    "  o = vec4(exposed(vec3(v * gain)), 1.0);\n"
    "}\n";

static const char *image_script =
    "local post, bloom, hdr = require 'post', require 'bloom', require 'hdr'\n"
    "Techniques = { 'image' }\n"
    "Options = post.defaults()\n"
    "Options.image = { pattern = 0, lo = 0.25, mid = 1.0, hi = 4.0, gain = 1.0, fill = 0.0,\n"
    "                  peak = 0.0, peak_x = -1, peak_y = -1, dim = 0.0, dim_x = -1, dim_y = -1,\n"
    "                  separate = false }\n"
    "function OnCreate() post.create() end\n"
    "function OnRender(tech)\n"
    "  local i = tech.image\n"
    "  local img = pass{ 'image', shader = 'test_image.frag', out = target{ 'image', format = 'rgba32f' },\n"
    "    params = { pattern = i.pattern, bands = { i.lo, i.mid, i.hi }, gain = i.gain, fill = i.fill,\n"
    "               peak = i.peak, peak_at = { i.peak_x, i.peak_y }, dim = i.dim, dim_at = { i.dim_x, i.dim_y } } }\n"
    "  if i.separate then -- bloom's sum written, then tone mapped: the modules one by one\n"
    "    present(hdr.render(bloom.render(img, tech.bloom), tech.hdr), 'display')\n"
    "  else\n"
    "    present(post.render(img, tech))\n"
    "  end\n"
    "end\n";

static int setup(void **state) {
  if (gl_test_setup(state) != 0) return -1;
  return gl_write_file("shaders/test_image.frag", image_frag) && gl_write_file("image.lua", image_script) &&
                 gl_write_file(unfolded_lua, unfolded_script)
             ? 0
             : -1;
}

/* ---- running a pipeline ------------------------------------------------ */
/* The first frame of `script` with technique `tech` (NULL: the default) and
 * "name=value" options; the test fails when it does not render. */
static gl_result start(const char *script, const char *tech, const char *const *sets) {
  gl_result r = gl_render(&(gl_run){.script = script, .tech = tech, .sets = sets, .width = W, .height = H});
  if (!r.ok) fail_msg("%s", r.err.msg);
  return r;
}

static void set(gl_result *r, const char *assignment) {
  if (!gl_set(r, assignment)) fail_msg("%s", r->err.msg);
}

static void frame(gl_result *r) {
  if (!gl_render_again(r)) fail_msg("%s", r->err.msg);
}

/* One frame; returns the linear output, W*H*3 top row first (the caller frees it). */
static float *render_once(const char *script, const char *tech, const char *const *sets) {
  gl_result r = start(script, tech, sets);
  float *out = r.rgb;
  r.rgb = NULL;
  gl_result_free(&r);
  return out;
}

/* Output pixel (x, y), y counted from the bottom as gl_FragCoord does. */
static const float *at(const float *img, int x, int y) { return img + ((size_t)(H - 1 - y) * W + x) * 3; }

/* Seed 001 eq 2.1 for the band image: 64 rows of each value. */
static double log_average(const double v[3], double delta) {
  double s = 0;
  for (int i = 0; i < 3; i++) s += log(delta + v[i]);
  return exp(s / 3);
}

/* ---- tone mapping ------------------------------------------------------ */
/* With white far away, eq 2.4 is L / (1 + L); the scaled luminance is
 * recovered as L = L_d / (1 - L_d) and must be a * L_w / L_avg within 1% in
 * each band, so the log-average itself maps to the key. Scaling the whole
 * image by 1e-3 or 1e3 changes nothing but delta's small share. */
static void tone_mapping_maps_the_log_average_to_the_key(void **state) {
  (void)state;
  static const char *const gains[] = {"image.gain=1", "image.gain=1000", "image.gain=0.001"};
  static const double gain_value[] = {1, 1000, 0.001};
  for (int g = 0; g < 3; g++) {
    const char *sets[] = {"hdr=true", "hdr.white=1e6", "hdr.key=0.18", gains[g], NULL};
    float *out = render_once(image_lua, NULL, sets);
    double v[3] = {0.25 * gain_value[g], 1.0 * gain_value[g], 4.0 * gain_value[g]};
    double avg = log_average(v, 1e-4);
    for (int b = 0; b < 3; b++) {
      float ld = at(out, 128, 32 + 64 * b)[0];
      double l = ld / (1.0 - ld), want = 0.18 * v[b] / avg;
      print_message("gain %g band %d: L_d %.5f, L %.5f, expected %.5f\n", gain_value[g], b, ld, l, want);
      assert_true(fabs(l / want - 1) < 0.01);
      assert_true(fabsf(at(out, 128, 32 + 64 * b)[1] - ld) < 1e-6f); /* grey stays grey */
    }
    /* Without the white point the mid band (the log-average at gain 1) is the key. */
    if (g == 0) {
      float ld = at(out, 128, 96)[0];
      assert_true(fabs(ld / (1.0 - ld) / 0.18 - 1) < 0.01);
    }
    free(out);
  }
  /* The default white point: eq 2.4 itself. */
  const char *sets[] = {"hdr=true", "hdr.white=2", "hdr.exposure=1", NULL};
  float *out = render_once(image_lua, NULL, sets);
  double v[3] = {0.25, 1, 4}, avg = log_average(v, 1e-4);
  for (int b = 0; b < 3; b++) {
    double l = 2 * 0.18 * v[b] / avg, want = l * (1 + l / 4) / (1 + l);
    float ld = at(out, 128, 32 + 64 * b)[0];
    print_message("white 2, exposure +1, band %d: L_d %.5f expected %.5f\n", b, ld, want);
    assert_true(fabs(ld / fmin(want, 1.0) - 1) < 0.01);
  }
  free(out);
}

/* Values from 1e-8 to 1e6 in one image: every output finite, in [0, 1];
 * the 1e6 pixel white. An all-black image stays black. */
static void extremes_stay_finite_white_and_black(void **state) {
  (void)state;
  static const char *const cases[][8] = {
      {"hdr=true", "image.pattern=1", "image.fill=1e-8", "image.peak=1e6", "image.peak_x=100", "image.peak_y=50", NULL},
      {"hdr=true", "hdr.auto_key=true", "image.pattern=1", "image.fill=1e-8", "image.peak=1e6", "image.peak_x=100",
       "image.peak_y=50", NULL},
      {"hdr=true", "bloom=true", "image.pattern=1", "image.fill=1e-8", "image.peak=1e6", "image.peak_x=100",
       "image.peak_y=50", NULL},
  };
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    float *out = render_once(image_lua, NULL, cases[c]);
    for (int i = 0; i < W * H * 3; i++)
      if (!isfinite(out[i]) || out[i] < 0 || out[i] > 1) fail_msg("case %zu: value %g at %d", c, out[i], i / 3);
    for (int k = 0; k < 3; k++) assert_true(at(out, 100, 50)[k] > 0.999f);
    free(out);
  }
  const char *black[] = {"hdr=true", "image.pattern=1", "image.fill=0", NULL};
  float *out = render_once(image_lua, NULL, black);
  for (int i = 0; i < W * H * 3; i++) assert_true(out[i] == 0.0f);
  free(out);
  /* fp16 overflow in bloom without tone mapping: the sum stays finite (under
   * half floats' ceiling in the pre-exposed image; the linear output is that
   * over the pre-exposure, which the metered 1e6 peak brings below 1). */
  const char *bloom[] = {"bloom=true", "bloom.strength=1000", "image.pattern=1", "image.peak=1e6",
                         "image.peak_x=100", "image.peak_y=50", NULL};
  out = render_once(image_lua, NULL, bloom);
  for (int i = 0; i < W * H * 3; i++)
    if (!isfinite(out[i]) || out[i] < 0) fail_msg("bloom: value %g at %d", out[i], i / 3);
  assert_true(at(out, 100, 50)[0] > 6e4f);
  free(out);
}

/* Seed 003: after a jump in brightness (gain 1 -> 8) the adapted luminance
 * closes the fraction `rate` of the gap each frame, so the mid band, scaled
 * by a / A_n, follows A_n = A_n-1 + (L_avg - A_n-1) rate, and the band
 * that is now the log-average converges to the key. */
static void adaptation_converges_to_the_key_at_its_rate(void **state) {
  (void)state;
  const double rate = 0.25;
  const char *sets[] = {"hdr=true", "hdr.white=1e6", "hdr.rate=0.25", NULL};
  gl_result r = start(image_lua, NULL, sets);
  double v[3] = {0.25, 1, 4};
  double a = log_average(v, 1e-4); /* the first frame takes its average as is */
  float ld = at(r.rgb, 128, 96)[0];
  assert_true(fabs(ld / (1 - ld) / (0.18 * 1 / a) - 1) < 0.01);
  set(&r, "image.gain=8");
  for (int i = 0; i < 3; i++) v[i] *= 8;
  double target = log_average(v, 1e-4), last_gap = INFINITY;
  for (int n = 1; n <= 16; n++) {
    a += (target - a) * rate;
    frame(&r);
    ld = at(r.rgb, 128, 96)[0];
    double l = ld / (1 - ld), want = 0.18 * 8 / a, gap = fabs(l - 0.18);
    if (n <= 4 || n == 16) print_message("frame %d: L %.5f expected %.5f (key 0.18)\n", n + 1, l, want);
    assert_true(fabs(l / want - 1) < 0.01);
    assert_true(gap < last_gap);
    last_gap = gap;
  }
  assert_true(last_gap < 0.01 * 0.18 * 2); /* 0.75^16 of the first gap */
  gl_result_free(&r);
}

/* ---- bloom ------------------------------------------------------------- */
/* One pixel of 100 on black (and one of 0.9, under the threshold): light
 * spreads around the bright pixel only, within the blur's reach, and the
 * light added is what the bright pass kept: 4 x (100/4 - 1) at downsample 2. */
static void bloom_spreads_one_bright_pixel_and_nothing_else(void **state) {
  (void)state;
  const char *sets[] = {"bloom=true", "bloom.threshold=1", "bloom.knee=0", "bloom.radius=4", "bloom.strength=1",
                        "bloom.downsample=2", "image.pattern=1", "image.peak=100", "image.peak_x=100",
                        "image.peak_y=100", "image.dim=0.9", "image.dim_x=30", "image.dim_y=30", NULL};
  float *out = render_once(image_lua, NULL, sets);
  const int reach = 2 * (4 + 1) + 1; /* blur taps and the bilinear enlargement, in full-size pixels */
  double added = 0;
  int lit_near = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      float v = at(out, x, y)[0];
      bool peak = x == 100 && y == 100, dim = x == 30 && y == 30;
      if (dim) {
        assert_true(fabsf(v - 0.9f) < 1e-3f);
        continue;
      }
      added += v - (peak ? 100 : 0);
      if (abs(x - 100) > reach || abs(y - 100) > reach) {
        /* 1e-4, not 0: the output stage's filtered read blends ~1e-5 of a
         * neighbour at texel centres on llvmpipe. */
        if (v > 1e-4f) fail_msg("light at (%d, %d): %g", x, y, v);
      } else if (!peak && abs(x - 100) <= 3 && abs(y - 100) <= 3) {
        lit_near += v > 0.01f;
      }
    }
  print_message("bloom: light added %.2f (bright pass kept 96), %d of 48 pixels around lit\n", added, lit_near);
  assert_int_equal(lit_near, 48);
  assert_true(fabs(added - 96) < 0.05 * 96);
  free(out);
}

/* In the chain (post.render) hdr adds bloom's glow as it reads the image, so
 * no pass writes the sum: the picture is that of bloom.add then hdr one by
 * one, within 0.0005 a channel (the written sum's half-float rounding), over
 * bands and a bright peak whose glow spreads. */
static void bloom_in_the_chain_is_bloom_then_hdr(void **state) {
  (void)state;
  const char *fused[] = {"bloom=true", "hdr=true", "bloom.threshold=2", "image.peak=400", "image.peak_x=100",
                         "image.peak_y=160", NULL};
  const char *separate[] = {"bloom=true", "hdr=true", "bloom.threshold=2", "image.peak=400", "image.peak_x=100",
                            "image.peak_y=160", "image.separate=true", NULL};
  char names[1024];
  gl_result a = start(image_lua, NULL, fused), b = start(image_lua, NULL, separate);
  gl_pass_names(&a, names, sizeof names);
  assert_null(strstr(names, "bloom.add"));
  gl_pass_names(&b, names, sizeof names);
  assert_non_null(strstr(names, "bloom.add"));
  double worst = 0, glow = 0;
  for (int i = 0; i < W * H * 3; i++) worst = fmax(worst, fabsf(a.rgb[i] - b.rgb[i]));
  /* The glow is there: beside the peak, the top band (4, over the threshold) is brighter than far from it. */
  glow = at(a.rgb, 106, 160)[0] - at(a.rgb, 250, 160)[0];
  print_message("bloom in the chain against bloom then hdr: largest difference %.5f; glow near the peak %.4f\n",
                worst, glow);
  assert_true(worst < 0.0005);
  assert_true(glow > 0.01);
  gl_result_free(&a);
  gl_result_free(&b);
}

/* ---- depth of field ---------------------------------------------------- */
/* Pixel of a world point of the box, the row from the bottom as at() counts. */
static void project(float x, float y, float z, int *col, int *row) {
  gl_project(W, H, x, y, z, col, row);
  *row = H - 1 - *row;
}

/* Sum of squared luminance differences between neighbours in a (2r+1)^2
 * square about a world point. */
static double gradient_energy(const float *img, float x, float y, float z, int r) {
  int c, row;
  project(x, y, z, &c, &row);
  double e = 0;
  for (int j = row - r; j < row + r; j++)
    for (int i = c - r; i < c + r; i++) {
      const float *p = at(img, i, j), *px = at(img, i + 1, j), *py = at(img, i, j + 1);
      double l = 0.27 * p[0] + 0.67 * p[1] + 0.06 * p[2];
      double lx = 0.27 * px[0] + 0.67 * px[1] + 0.06 * px[2], ly = 0.27 * py[0] + 0.67 * py[1] + 0.06 * py[2];
      e += (lx - l) * (lx - l) + (ly - l) * (ly - l);
    }
  return e;
}

/* The back wall's corners (where it meets the red wall, and the ceiling and
 * green wall) lie 4.4 from the eye: focused there they stay sharp; focused
 * at 1.5 (range) or through a fast lens at 1.5, they blur. */
static void depth_of_field_keeps_the_focus_plane_sharp(void **state) {
  (void)state;
  static const char *const sharp[] = {"dof=false", NULL};
  static const char *const focused[] = {"dof=true", "dof.focus=4.4", "dof.range=2", "dof.max_radius=6", NULL};
  static const char *const near[] = {"dof=true", "dof.focus=1.5", "dof.range=2", "dof.max_radius=6", NULL};
  /* 50 mm at f/2.8 on a 24 mm sensor: about 3 pixels of blur at 4.4 when focused at 1.5. */
  static const char *const lens_focused[] = {"dof=true", "dof.mode=lens", "dof.focus=4.4", "dof.focal_length=0.05",
                                             "dof.f_number=2.8", "dof.sensor=0.024", "dof.max_radius=6", NULL};
  static const char *const lens_near[] = {"dof=true", "dof.mode=lens", "dof.focus=1.5", "dof.focal_length=0.05",
                                          "dof.f_number=2.8", "dof.sensor=0.024", "dof.max_radius=6", NULL};
  const char *const *cases[] = {sharp, focused, near, lens_focused, lens_near};
  double e[5][2];
  for (int c = 0; c < 5; c++) {
    float *out = render_once(pp_lua, "dl", cases[c]);
    e[c][0] = gradient_energy(out, -1.0f, 1.0f, -1.0f, 6); /* back wall / red wall */
    e[c][1] = gradient_energy(out, 1.0f, 2.0f, -1.0f, 6);  /* back wall / ceiling / green wall */
    free(out);
  }
  for (int k = 0; k < 2; k++) {
    print_message("corner %d gradient energy: sharp %.4f, focused %.4f, focus near %.4f, lens focused %.4f, "
                  "lens near %.4f\n", k, e[0][k], e[1][k], e[2][k], e[3][k], e[4][k]);
    assert_true(e[0][k] > 0.01);
    assert_true(e[1][k] > 0.8 * e[0][k]);
    assert_true(e[3][k] > 0.8 * e[0][k]);
    assert_true(e[2][k] < 0.3 * e[0][k]);
    assert_true(e[4][k] < 0.3 * e[0][k]);
  }
}

/* The tall box's top edge against the back wall (1 behind it), found in the
 * sharp image by scanning up its middle column. Focused on the box, the
 * blurred wall beside the edge keeps its own colour (the sharp box does not
 * bleed onto it) and the box stays sharp; focused on the wall, the blurred
 * box spreads over the sharp wall beside it. */
static void depth_of_field_orders_foreground_and_background(void **state) {
  (void)state;
  static const char *const sharp[] = {NULL};
  static const char *const on_box[] = {"dof=true", "dof.focus=3.46", "dof.range=1", "dof.max_radius=8", NULL};
  static const char *const on_wall[] = {"dof=true", "dof.focus=4.4", "dof.range=1", "dof.max_radius=8", NULL};
  float *s = render_once(pp_lua, "dl", sharp), *b = render_once(pp_lua, "dl", on_box);
  float *w = render_once(pp_lua, "dl", on_wall);
  int col, row;
  project(-0.35f, 0.6f, -0.05f, &col, &row);
  int edge = row; /* the last box row: the next one jumps by over 15% */
  while (edge < H - 1 && fabsf(at(s, col, edge + 1)[1] - at(s, col, edge)[1]) < 0.15f * at(s, col, edge)[1]) edge++;
  assert_true(edge < H - 10);
  float box = at(s, col, edge)[1], wall = at(s, col, edge + 1)[1];
  print_message("edge at row %d: box %.4f wall %.4f | wall by the edge: sharp %.4f, box focused %.4f, wall "
                "focused %.4f | box by the edge: sharp %.4f, box focused %.4f\n", edge, box, wall,
                at(s, col, edge + 3)[1], at(b, col, edge + 3)[1], at(w, col, edge + 3)[1], at(s, col, edge - 2)[1],
                at(b, col, edge - 2)[1]);
  assert_true(fabsf(wall - box) > 0.3f * box);
  float gap = wall - box;
  /* box focused: the wall 3 pixels above the edge moves < 10% of the way to
   * the box (away from it is the wall's own gradient, blurred: the light
   * falls off as 1 / d^2) */
  assert_true((at(s, col, edge + 3)[1] - at(b, col, edge + 3)[1]) * copysignf(1.0f, gap) < 0.1f * fabsf(gap));
  assert_true(fabsf(at(b, col, edge - 2)[1] - at(s, col, edge - 2)[1]) < 0.05f * fabsf(gap));
  /* wall focused: the blurred box reaches 3 pixels over the wall, > 20% of the way */
  assert_true(fabsf(at(w, col, edge + 3)[1] - at(s, col, edge + 3)[1]) > 0.2f * fabsf(gap));
  free(s);
  free(b);
  free(w);
}

/* The half-size gather (dof.downsample 2, the default) against the full-size
 * one: close on average (edges differ most: the blur is built from half-size
 * texels); and where no circle of confusion exceeds a pixel, both leave every
 * pixel as it was (the tile test's shortcut and the composite's (1 - a) L_p). */
static void depth_of_field_at_half_size_follows_the_full_size_one(void **state) {
  (void)state;
  static const char *const sharp[] = {NULL};
  static const char *const full[] = {"dof=true", "dof.focus=4.4", "dof.range=1", "dof.downsample=1", NULL};
  static const char *const half[] = {"dof=true", "dof.focus=4.4", "dof.range=1", "dof.downsample=2", NULL};
  static const char *const still1[] = {"dof=true", "dof.range=1e6", "dof.downsample=1", NULL};
  static const char *const still2[] = {"dof=true", "dof.range=1e6", "dof.downsample=2", NULL};
  float *s = render_once(pp_lua, "dl", sharp), *a = render_once(pp_lua, "dl", full);
  float *b = render_once(pp_lua, "dl", half);
  float *c = render_once(pp_lua, "dl", still1), *d = render_once(pp_lua, "dl", still2);
  double diff = 0, blur = 0;
  for (int i = 0; i < W * H * 3; i++) {
    diff += fabsf(a[i] - b[i]);
    blur += fabsf(a[i] - s[i]);
    if (c[i] != s[i] || d[i] != s[i]) fail_msg("a blur under a pixel changed value %d: %g, %g, %g", i, s[i], c[i], d[i]);
  }
  print_message("dof: half against full size %.5f a channel; full size against sharp %.5f\n", diff / (W * H * 3),
                blur / (W * H * 3));
  assert_true(diff < 0.25 * blur);
  free(s), free(a), free(b), free(c), free(d);
}

/* ---- motion blur ------------------------------------------------------- */
/* A still camera leaves the image as it was; a camera moving sideways blurs
 * along x: the horizontal gradient energy drops to under half, and by more
 * than twice the vertical's share (slanted edges lose some of both). */
static void motion_blur_follows_the_camera(void **state) {
  (void)state;
  const char *off[] = {NULL}, *on[] = {"motion_blur=true", "motion_blur.strength=1", NULL};
  float *still = render_once(pp_lua, "dl", off), *blurred_still = render_once(pp_lua, "dl", on);
  for (int i = 0; i < W * H * 3; i++) assert_true(fabsf(still[i] - blurred_still[i]) < 1e-3f);
  free(blurred_still);
  free(still);
  float *img[2];
  lm_scene *cornell = gl_cornell();
  int cam = cornell->cameras[0].node;
  float x0 = cornell->nodes[cam].local[12];
  for (int k = 0; k < 2; k++) {
    gl_result r = start(pp_lua, "dl", k ? on : off);
    cornell->nodes[cam].local[12] = x0 + 0.1f; /* 0.1 to the right between frames */
    lm_scene_update(cornell);
    frame(&r);
    cornell->nodes[cam].local[12] = x0;
    lm_scene_update(cornell);
    img[k] = r.rgb;
    r.rgb = NULL;
    gl_result_free(&r);
  }
  /* Over the displayed values (clamped to 1): the light's hot spot on the
   * ceiling would otherwise weigh more than every edge together. */
  double gx[2] = {0}, gy[2] = {0};
  for (int k = 0; k < 2; k++)
    for (int y = 0; y < H - 1; y++)
      for (int x = 0; x < W - 1; x++) {
        double l = fmin(at(img[k], x, y)[1], 1), dx = fmin(at(img[k], x + 1, y)[1], 1) - l,
               dy = fmin(at(img[k], x, y + 1)[1], 1) - l;
        gx[k] += dx * dx, gy[k] += dy * dy;
      }
  print_message("motion blur: horizontal gradient energy %.3f -> %.3f, vertical %.3f -> %.3f\n", gx[0], gx[1],
                gy[0], gy[1]);
  assert_true(gx[1] < 0.5 * gx[0]);
  assert_true(gx[1] / gx[0] < 0.5 * (gy[1] / gy[0]));
  free(img[0]);
  free(img[1]);
}

/* ---- every effect, all at once, no NaN or Inf -------------------------- */
static const char *const effects[] = {"motion_blur", "dof", "bloom", "hdr", "radial_blur", "glass", "tiles", "sepia"};
enum { EFFECTS = sizeof effects / sizeof *effects };

/* Targets that may hold negative values: a signed circle of confusion
 * (dof.small's and dof.quarter's alpha too, and the tiles' least),
 * mean logarithms of luminance, the G-buffer's normals and velocities. */
static bool holds_signed(const char *name) {
  static const char *const names[] = {"dof.coc",    "dof.small_coc", "dof.small",  "dof.quarter",
                                      "dof.tiles",  "dof.dilate",    "gbuffer.nrm", "gbuffer.vel"};
  for (size_t i = 0; i < sizeof names / sizeof *names; i++)
    if (!strcmp(name, names[i])) return true;
  return !strncmp(name, "hdr.reduce", 10);
}

/* Every float target the frame used holds finite values (read before the
 * output stage, which would hide a NaN); colour targets are not negative.
 * Targets whose passes never overlap share a texture (the graph's aliasing),
 * which then holds what the last of them wrote: signed if any of them is. */
static void assert_targets_finite(lm_graph *g, const char *what) {
  float *px = malloc(sizeof(float) * 4 * W * H);
  for (int t = 0; t < lm_graph_target_count(g); t++) {
    lm_graph_target_info ti = lm_graph_target(g, t);
    if (!ti.used || lm_format_is_depth(ti.format) || ti.format == LM_FORMAT_RGBA8 || !ti.texture.id) continue;
    lm_texture_read(ti.texture, ti.width, ti.height, true, px);
    bool signed_ok = false;
    for (int u = 0; u < lm_graph_target_count(g); u++) {
      lm_graph_target_info tu = lm_graph_target(g, u);
      signed_ok |= tu.used && tu.texture.id == ti.texture.id && holds_signed(tu.name);
    }
    for (int i = 0; i < ti.width * ti.height * 4; i++)
      if (!isfinite(px[i]) || (!signed_ok && px[i] < 0))
        fail_msg("%s: target '%s' holds %g at %d", what, ti.name, px[i], i / 4);
  }
  free(px);
}

static void every_effect_renders_finite_with_dl_and_isr(void **state) {
  (void)state;
  static const char *const techs[] = {"dl", "isr"};
  for (int t = 0; t < 2; t++) {
    for (int e = 0; e <= EFFECTS; e++) { /* EFFECTS: all at once */
      char on[EFFECTS][48];
      const char *sets[EFFECTS + 4] = {0};
      int n = 0;
      for (int k = 0; k < EFFECTS; k++) {
        snprintf(on[k], sizeof on[k], "%s=true", effects[k]);
        if (k == e || e == EFFECTS) sets[n++] = on[k];
      }
      gl_result r = start(pp_lua, techs[t], sets);
      char what[96];
      snprintf(what, sizeof what, "%s with %s", techs[t], e == EFFECTS ? "every effect" : effects[e]);
      assert_targets_finite(lm_renderer_graph(r.renderer), what);
      double mean = 0;
      for (int i = 0; i < W * H * 3; i++) mean += r.rgb[i];
      if (!(mean / (W * H * 3) > 0.02)) fail_msg("%s: a black image", what);
      gl_result_free(&r);
    }
  }
}

/* Degenerate settings: focus on the near and far planes, zero-size blurs,
 * a lens focused closer than its focal length, huge and tiny values. */
static void degenerate_settings_stay_finite(void **state) {
  (void)state;
  static const char *const cases[][8] = {
      {"dof=true", "dof.focus=0.1", "dof.range=1e-6", NULL},
      {"dof=true", "dof.focus=20", "dof.max_radius=32", "dof.samples=1", NULL},
      {"dof=true", "dof.focus=0", "dof.max_radius=0", NULL},
      {"dof=true", "dof.mode=lens", "dof.focus=0.01", "dof.focal_length=100", "dof.f_number=1e-3", NULL},
      {"dof=true", "dof.mode=lens", "dof.focus=1e6", "dof.sensor=1e-6", NULL},
      {"bloom=true", "bloom.radius=0", "bloom.threshold=0", "bloom.knee=0", "bloom.downsample=4", NULL},
      {"bloom=true", "bloom.knee=1e6", "bloom.strength=1000", "hdr=true", "hdr.rate=1e-9", "hdr.delta=1", NULL},
      {"hdr=true", "hdr.key=0.001", "hdr.white=1e-30", "hdr.exposure=-20", "hdr.delta=1e-30", NULL},
      {"hdr=true", "hdr.key=1", "hdr.white=1e6", "hdr.exposure=20", NULL},
      {"radial_blur=true", "radial_blur.strength=1", "radial_blur.samples=1", "radial_blur.centre_x=10", NULL},
      {"glass=true", "glass.strength=256", "glass.scale=1e-30", "tiles=true", "tiles.size=1", "tiles.grout=1024", NULL},
      {"motion_blur=true", "motion_blur.strength=0", "motion_blur.max_length=0", "sepia=true", "sepia.strength=0", NULL},
  };
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    gl_result r = start(pp_lua, "dl", cases[c]);
    char what[64];
    snprintf(what, sizeof what, "case %zu (%s ...)", c, cases[c][1]);
    assert_targets_finite(lm_renderer_graph(r.renderer), what);
    gl_result_free(&r);
  }
}

/* ---- the frame graph --------------------------------------------------- */
/* Off (the default) records no pass of the effect; on records exactly its
 * passes, and none of them is left out. */
static void an_effect_off_records_no_pass(void **state) {
  (void)state;
  static const char *const passes[EFFECTS] = {
      "motion_blur.tiles4 motion_blur.tiles motion_blur.near motion_blur ", "dof.reduce dof.tiles dof.dilate dof.quarter dof.gather dof.composite ", "bloom.bright bloom.blur_x bloom.blur_y bloom.add ",
      "hdr.reduce1 hdr.reduce2 hdr.adapt hdr.tonemap ", "radial_blur ", "glass ", "tiles ", "sepia "};
  char names[1024], want[1024];
  gl_result r = start(pp_lua, "dl", NULL);
  gl_pass_names(&r, names, sizeof names);
  assert_string_equal(names, "gbuffer direct output exposure.meter ");
  assert_int_equal(gl_culled(&r, ""), 0);
  gl_result_free(&r);
  for (int e = 0; e < EFFECTS; e++) {
    char on[64];
    snprintf(on, sizeof on, "%s=true", effects[e]);
    const char *sets[] = {on, NULL};
    r = start(pp_lua, "dl", sets);
    gl_pass_names(&r, names, sizeof names);
    /* hdr.tonemap, the last pass, runs the output stage itself (fold_output) */
    snprintf(want, sizeof want, "gbuffer direct %s%sexposure.meter ", passes[e], e == 3 ? "" : "output ");
    assert_string_equal(names, want);
    assert_int_equal(gl_culled(&r, ""), 0);
    char off[64];
    snprintf(off, sizeof off, "%s.enabled=false", effects[e]);
    set(&r, off);
    frame(&r);
    gl_pass_names(&r, names, sizeof names);
    assert_string_equal(names, "gbuffer direct output exposure.meter ");
    assert_int_equal(gl_culled(&r, ""), 0);
    gl_result_free(&r);
  }
}

/* Tone mapping with the output stage folded into it writes what it and the
 * output stage wrote one after the other (the viewer's inspector keeps them
 * apart: sharing off): linear values within a half float's rounding of
 * [0, 1] (the image no longer stored between them), sRGB within 1 of 255. */
static void tone_mapping_folds_the_output_stage_in(void **state) {
  (void)state;
  const char *sets[] = {"hdr=true", "bloom=true", "dof=true", NULL};
  gl_result r[2];
  for (int k = 0; k < 2; k++) {
    r[k] = start(pp_lua, "dl", sets);
    lm_renderer_set_sharing(r[k].renderer, k == 0);
    frame(&r[k]); /* both second frames: the same adaptation */
  }
  char names[1024];
  gl_pass_names(&r[0], names, sizeof names);
  assert_null(strstr(names, "output "));
  gl_pass_names(&r[1], names, sizeof names);
  assert_non_null(strstr(names, "hdr.tonemap output "));
  int n = W * H * 3, srgb_off = 0;
  double most = 0;
  for (int i = 0; i < n; i++) {
    most = fmax(most, fabs(r[0].rgb[i] - r[1].rgb[i]));
    srgb_off = abs(r[0].srgb[i] - r[1].srgb[i]) > srgb_off ? abs(r[0].srgb[i] - r[1].srgb[i]) : srgb_off;
  }
  assert_true(most <= 0.0005);
  assert_true(srgb_off <= 1);
  assert_true(gl_mean_abs_diff(r[0].rgb, r[1].rgb, n) > 0); /* the fold ran: no half-float rounding */
  gl_result_free(&r[0]), gl_result_free(&r[1]);
}

/* Depth of field at half size under tone mapping: post.lua folds its
 * composite into hdr.tonemap and the meter (hdr.reduce1), and bloom's bright
 * pass reads it at the reduced size (dof.glsl). Against the composite written
 * and read, at each of bloom's sizes (each a path of bloom_bright.frag) and
 * without bloom, on the second frame: no dof.composite pass, and the image
 * within TOLERANCE on average (linear display values: bloom's reduced read
 * and the composite's half-float store, gone, differ a little), MOST at a
 * pixel, 2/255 in sRGB. */
static void tone_mapping_folds_the_dof_composite_in(void **state) {
  (void)state;
  enum { CASES = 4 };
  static const char *const bloom[CASES] = {"bloom.downsample=4", "bloom.downsample=2", "bloom.downsample=1",
                                           "bloom.enabled=false"};
  const double TOLERANCE = 0.0005, MOST = 0.02;
  for (int c = 0; c < CASES; c++) {
    const char *sets[] = {"hdr=true", "bloom=true", "dof=true", bloom[c], NULL};
    gl_result folded = start(pp_lua, "dl", sets), unfolded = start(unfolded_lua, "dl", sets);
    frame(&folded), frame(&unfolded);
    char names[1024];
    gl_pass_names(&folded, names, sizeof names);
    assert_null(strstr(names, "dof.composite"));
    assert_non_null(strstr(names, "hdr.tonemap"));
    gl_pass_names(&unfolded, names, sizeof names);
    assert_non_null(strstr(names, "dof.composite"));
    int n = W * H * 3, srgb_off = 0;
    double most = 0;
    for (int i = 0; i < n; i++) {
      most = fmax(most, fabs(folded.rgb[i] - unfolded.rgb[i]));
      srgb_off = abs(folded.srgb[i] - unfolded.srgb[i]) > srgb_off ? abs(folded.srgb[i] - unfolded.srgb[i]) : srgb_off;
    }
    double mean = gl_mean_abs_diff(folded.rgb, unfolded.rgb, n);
    print_message("dof folded into tone mapping, %s: mean %.5f, most %.4f, sRGB at most %d/255\n", bloom[c], mean,
                  most, srgb_off);
    assert_true(mean <= TOLERANCE);
    assert_true(most <= MOST);
    assert_true(srgb_off <= 2);
    assert_true(gl_all_finite(&folded));
    gl_result_free(&folded), gl_result_free(&unfolded);
  }
}

/* Bad values stop the frame with the option's name and what it must be. */
static void bad_options_name_themselves(void **state) {
  (void)state;
  static const gl_bad_option cases[] = {
      {"dl", "dof.mode=pinhole", "dof.mode must be one of range, lens (got pinhole)"},
      {"dl", "bloom.radius=2.5", "bloom.radius must be a whole number in 0..32 (got 2.5)"},
      {"dl", "hdr.white=0", "hdr.white must be a number in (0, 1e+06] (got 0)"},
      {"dl", "sepia.strength=2", "sepia.strength must be a finite number in 0..1 (got 2)"},
      {"dl", "bloom.downsample=3", "bloom.downsample must be one of 1, 2, 4 (got 3)"},
  };
  gl_assert_bad_options(cases, sizeof cases / sizeof *cases, ".lua:");
  gl_result r = start(pp_lua, "dl", NULL);
  assert_false(gl_set(&r, "bloom.nope=1"));
  assert_non_null(strstr(r.err.msg, "bloom.threshold"));
  gl_result_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(tone_mapping_maps_the_log_average_to_the_key),
      cmocka_unit_test(extremes_stay_finite_white_and_black),
      cmocka_unit_test(adaptation_converges_to_the_key_at_its_rate),
      cmocka_unit_test(bloom_spreads_one_bright_pixel_and_nothing_else),
      cmocka_unit_test(bloom_in_the_chain_is_bloom_then_hdr),
      cmocka_unit_test(depth_of_field_keeps_the_focus_plane_sharp),
      cmocka_unit_test(depth_of_field_orders_foreground_and_background),
      cmocka_unit_test(depth_of_field_at_half_size_follows_the_full_size_one),
      cmocka_unit_test(motion_blur_follows_the_camera),
      cmocka_unit_test(every_effect_renders_finite_with_dl_and_isr),
      cmocka_unit_test(degenerate_settings_stay_finite),
      cmocka_unit_test(an_effect_off_records_no_pass),
      cmocka_unit_test(tone_mapping_folds_the_output_stage_in),
      cmocka_unit_test(tone_mapping_folds_the_dof_composite_in),
      cmocka_unit_test(bad_options_name_themselves),
  };
  return cmocka_run_group_tests(tests, setup, gl_test_teardown);
}
