/* Rendering on whatever EGL offers (llvmpipe in CI): the Cornell box through
 * scripts/pp.lua, checked for what must be where, against a golden image,
 * and the GL-side errors a script or shader can cause.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_test.h"
#include "image/image.h"

enum { W = 256, H = 192 };

static char real_root[1024]; /* the tree's, before the scratch root takes over */
static bool check_finite; /* render() with the NaN/Inf check */

static int setup(void **state) {
  snprintf(real_root, sizeof real_root, "%s", lm_root_dir());
  return gl_test_setup(state);
}


static gl_result render(const char *script, const char *tech, int frames) {
  return gl_render(&(gl_run){.script = script, .tech = tech, .frames = frames,
                             .width = W, .height = H, .check_finite = check_finite});
}

static char pp_lua[1100];

static void cornell_box_has_light_and_colour_where_it_must(void **state) {
  (void)state;
  gl_result fr = render(pp_lua, "dl", 1);
  if (!fr.ok) fail_msg("%s", fr.err.msg);
  double mean = 0, mean2 = 0;
  for (int i = 0; i < W * H * 3; i++) {
    float v = fr.rgb[i];
    if (!isfinite(v) || v < 0) fail_msg("pixel value %g at %d", v, i / 3);
    mean += v, mean2 += (double)v * v;
  }
  mean /= W * H * 3, mean2 /= W * H * 3;
  assert_true(mean > 0.05);                    /* not black */
  assert_true(sqrt(mean2 - mean * mean) > 0.05); /* not flat */
  /* Regions from the camera's projection (see cornell.c): the walls at mid
   * height, the floor in front of the tall box, the ceiling above the light
   * and near a front corner, and the black outside of the box. */
  float left[3], right[3], floor_[3], ceil_mid[3], ceil_corner[3], outside[3];
  gl_region(&fr, 45, 80, 65, 110, left);
  gl_region(&fr, 191, 80, 211, 110, right);
  gl_region(&fr, 62, 178, 90, 188, floor_);
  gl_region(&fr, 118, 24, 138, 32, ceil_mid);
  gl_region(&fr, 42, 3, 52, 8, ceil_corner);
  gl_region(&fr, 0, 60, 8, 130, outside);
  assert_true(left[0] > 3 * left[1] && left[0] > 3 * left[2]);
  assert_true(right[1] > 2 * right[0] && right[1] > 2 * right[2]);
  assert_true(gl_luminance(floor_) > 0.2f);
  assert_true(floor_[0] > 0.5f * floor_[1] && floor_[0] < 2.0f * floor_[1]); /* white floor stays grey */
  assert_true(gl_luminance(ceil_mid) > 3 * gl_luminance(ceil_corner));                          /* light falls off */
  assert_true(gl_luminance(outside) < 1e-3f);
  char names[256];
  gl_pass_names(&fr, names, sizeof names);
  assert_string_equal(names, "gbuffer direct output exposure.meter ");
  gl_result_free(&fr);
}

/* Golden image: tools/regen-golden.sh rewrites data/golden/cornell_dl.png. */
static void cornell_box_matches_the_golden_image(void **state) {
  (void)state;
  gl_result fr = render(pp_lua, "dl", 1);
  if (!fr.ok) fail_msg("%s", fr.err.msg);
  lm_image golden;
  lm_error err;
  char path[1200];
  snprintf(path, sizeof path, "%s/data/golden/cornell_dl.png", real_root);
  if (!lm_image_read(path, &golden, &err)) fail_msg("%s", err.msg);
  assert_int_equal(golden.width, W);
  assert_int_equal(golden.height, H);
  assert_true(golden.channels >= 3);
  double sum = 0;
  int far_off = 0;
  for (int i = 0; i < W * H; i++)
    for (int c = 0; c < 3; c++) {
      double d = fabs(fr.srgb[i * 3 + c] / 255.0 - golden.pixels[i * golden.channels + c]);
      sum += d;
      far_off += d > 8.0 / 255.0;
    }
  double mean = sum / (W * H * 3);
  /* Tolerance: rasterization and float rounding differ a little between drivers. */
  if (mean > 1.0 / 255.0 || far_off > W * H * 3 / 200)
    fail_msg("mean error %.5f, %d values off by more than 8/255", mean, far_off);
  lm_image_free(&golden);
  gl_result_free(&fr);
}

static void shader_errors_name_the_original_file_and_line(void **state) {
  (void)state;
  assert_true(gl_write_file("shaders/broken.frag", "#include \"common.glsl\"\nin vec2 uv;\nout vec4 o;\n\n"
                                                   "void main() {\n  o = vec4(no_such_thing);\n}\n"));
  assert_true(gl_write_file("shaders/bad_include.glsl", "float helper() {\n  return undefined_value;\n}\n"));
  assert_true(gl_write_file("shaders/uses_bad.frag",
                            "#include \"bad_include.glsl\"\nout vec4 o;\nvoid main() { o = vec4(helper()); }\n"));
  lm_error err;
  assert_null(lm_program_get("fullscreen.vert", "broken.frag", NULL, &err));
  if (!strstr(err.msg, "shaders/broken.frag:6:")) fail_msg("%s", err.msg);
  assert_null(lm_program_get("fullscreen.vert", "uses_bad.frag", "X=1", &err));
  if (!strstr(err.msg, "shaders/bad_include.glsl:2:")) fail_msg("%s", err.msg);
  assert_null(lm_program_get("fullscreen.vert", "nope.frag", NULL, &err));
  if (!strstr(err.msg, "nope.frag: cannot open")) fail_msg("%s", err.msg);
}

/* A pipeline that runs direct.frag with the given extra pass fields. */
static gl_result direct_with(const char *fields) {
  char text[2048];
  snprintf(text, sizeof text,
           "local gbuffer = require 'gbuffer'\nTechniques = { 'dl' }\n"
           "function OnRender(tech)\n  local G = gbuffer.render(gbuffer.targets())\n"
           "  local lit = target{ 'lit', format = 'rgba16f' }\n"
           "  pass{ 'direct', shader = 'direct.frag', out = lit, %s }\n  present(lit)\nend\n", fields);
  assert_true(gl_write_file("bindings.lua", text));
  return render("bindings.lua", NULL, 1);
}

static void wrong_uniforms_and_inputs_name_the_pass_and_parameter(void **state) {
  (void)state;
  static const struct {
    const char *fields, *expect;
  } cases[] = {
      {"inputs = gbuffer.inputs(G), params = { bogus = 1 }",
       "bindings.lua:6: pass 'direct': parameter 'bogus': shaders/direct.frag declares no uniform of that name"},
      {"inputs = gbuffer.inputs(G), params = { ambient = 1 }",
       "bindings.lua:6: pass 'direct': parameter 'ambient': the shader's uniform is a vec3; the pass gives one number"},
      {"inputs = gbuffer.inputs(G), params = { ambient = true }", "the pass gives a boolean"},
      {"inputs = { clr = G.clr, nrm = G.nrm, dpt = G.dpt }",
       "pass 'direct': shaders/direct.frag samples 'mat' but the pass gives no input of that name"},
      {"inputs = { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat, extra = G.clr }",
       "input 'extra': shaders/direct.frag declares no sampler of that name"},
      {"inputs = { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat, ambient = G.clr }",
       "input 'ambient': shaders/direct.frag declares no sampler of that name"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    gl_result fr = direct_with(cases[i].fields);
    if (fr.ok || !strstr(fr.err.msg, cases[i].expect))
      fail_msg("case %zu: %s", i, fr.ok ? "rendered" : fr.err.msg);
    gl_result_free(&fr);
  }
  gl_result fr = direct_with("inputs = gbuffer.inputs(G), params = { ambient = { 0.1, 0.1, 0.1 } }");
  if (!fr.ok) fail_msg("%s", fr.err.msg);
  gl_result_free(&fr);
}

static void no_nan_or_inf_leaves_the_output_stage(void **state) {
  (void)state;
  assert_true(gl_write_file("shaders/poison.frag",
                            "in vec2 uv;\nuniform float zero = 0.0;\nout vec4 o;\nvoid main() {\n  float z = zero;\n"
                            "  o = uv.x < 0.33 ? vec4(z / z) : uv.x < 0.66 ? vec4(1.0 / z) : vec4(-1.0 / z);\n}\n"));
  assert_true(gl_write_file("poison.lua", "Techniques = { 'x' }\nfunction OnRender()\n  present(pass{ 'poison', "
                                          "shader = 'poison.frag', out = target{ 'p', format = 'rgba32f' } })\nend\n"));
  gl_result fr = render("poison.lua", NULL, 1);
  if (!fr.ok) fail_msg("%s", fr.err.msg);
  for (int i = 0; i < W * H * 3; i++)
    if (!isfinite(fr.rgb[i]) || fr.rgb[i] < 0) fail_msg("value %g at pixel %d", fr.rgb[i], i / 3);
  gl_result_free(&fr);
  /* The debug check names the pass, the target and the first bad pixel. */
  check_finite = true;
  fr = render("poison.lua", NULL, 1);
  check_finite = false;
  assert_false(fr.ok);
  if (!strstr(fr.err.msg, "poison.lua:3: pass 'poison' wrote NaN to target 'p' at pixel (0, 0)"))
    fail_msg("%s", fr.err.msg);
  gl_result_free(&fr);
}

/* The output stage's sRGB encoding (common.glsl's srgb_encode, a polynomial
 * for pow's power) against IEC 61966-2-1's formula over a ramp of display
 * values through [0, 1]: never a step off, and off by one only where the
 * formula's value falls within a rounding tie (measured: 2 in 100000 values;
 * allowed 1 in 10000). */
static void the_output_stage_encodes_srgb_as_the_formula(void **state) {
  (void)state;
  assert_true(gl_write_file("shaders/ramp.frag",
                            "out vec4 o;\nvoid main() {\n  ivec2 p = ivec2(gl_FragCoord.xy);\n"
                            "  float v = (float(p.y * 256 + p.x) + 0.5) / 49152.0;\n"
                            "  o = vec4(v, v * v, 1.0 - v, 1.0);\n}\n"));
  assert_true(gl_write_file("ramp.lua", "Techniques = { 'x' }\nfunction OnRender()\n  present(pass{ 'ramp', "
                                        "shader = 'ramp.frag', out = target{ 'r', format = 'rgba32f' } }, "
                                        "'display')\nend\n"));
  gl_result fr = render("ramp.lua", NULL, 1);
  if (!fr.ok) fail_msg("%s", fr.err.msg);
  int off = 0;
  for (int i = 0; i < W * H * 3; i++) {
    double c = fr.rgb[i], e = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1 / 2.4) - 0.055;
    int d = abs((int)fr.srgb[i] - (int)lround(e * 255));
    if (d > 1) fail_msg("value %g encoded %d, the formula %g", c, fr.srgb[i], e * 255);
    off += d;
  }
  if (off > W * H * 3 / 10000) fail_msg("%d of %d values off by one", off, W * H * 3);
  gl_result_free(&fr);
}

/* The G-buffer's normals in rgba8 (common.glsl's gbuffer_normal_encode and
 * _decode) through a real rgba8 target: 49152 directions on a Fibonacci
 * sphere come back unit and within 0.07 degrees (measured: 0.064, 0.058 of
 * it the 12 bits' rounding); the six
 * axes, +-z among them, bit for bit; vectors of any length down to
 * denormal sizes, and zero, come back finite and unit; a texel of zeros (a
 * pixel nothing drew) reads as (0, 1, 0). The shininess in the alpha: 0 and 1
 * exact, the rest within 2.2% of 1 + shininess, up to 60000. */
static double sphere(int i, int k) {
  /* the golden angle's turns in 16 bits, the same in C and in the shader's floats */
  double z = 1.0 - 2.0 * (i + 0.5) / (W * H), r = sqrt(fmax(1.0 - z * z, 0.0)),
         phi = 6.283185307179586 * (double)(((unsigned)i * 40503u) & 65535u) / 65536.0;
  return k == 0 ? r * cos(phi) : k == 1 ? r * sin(phi) : z;
}

static void gbuffer_normals_survive_their_eight_bits(void **state) {
  (void)state;
  static const float special[][3] = {{1, 0, 0},  {-1, 0, 0},      {0, 1, 0},          {0, -1, 0},   {0, 0, 1},
                                     {0, 0, -1}, {1e-20f, 0, -1e-20f}, {1e-40f, 1e-40f, -1e-40f}, {0, 0, 0}};
  enum { SPECIAL = sizeof special / sizeof special[0] };
  char src[2400];
  int n = snprintf(src, sizeof src,
                   "#include \"common.glsl\"\nout vec4 o;\nconst vec3 special[%d] = vec3[](", SPECIAL);
  for (int i = 0; i < SPECIAL; i++)
    n += snprintf(src + n, sizeof src - n, "%svec3(%g, %g, %g)", i ? ", " : "", special[i][0], special[i][1],
                  special[i][2]);
  snprintf(src + n, sizeof src - n,
           ");\nvoid main() {\n  ivec2 p = ivec2(gl_FragCoord.xy);\n  int i = p.y * %d + p.x;\n"
           "  float z = 1.0 - 2.0 * (float(i) + 0.5) / %d.0, r = sqrt(max(1.0 - z * z, 0.0)), phi = 6.283185307179586 * "
           "float((uint(i) * 40503u) & 65535u) / 65536.0;\n  vec3 n = i < %d ? special[i] : vec3(r * cos(phi), r * sin(phi), z);\n"
           "  float s = i == %d ? 1.0 : float(i - %d) * 60000.0 / %d.0;\n"
           "  o = i == %d ? vec4(0.0) : gbuffer_normal_encode(n, s);\n}\n",
           W, W * H, SPECIAL, SPECIAL + 2, SPECIAL + 1, W * H, SPECIAL);
  assert_true(gl_write_file("shaders/nrm_encode.frag", src));
  assert_true(gl_write_file("shaders/nrm_decode.frag",
                            "#include \"common.glsl\"\nuniform sampler2D src;\nuniform int shininess = 0;\nout vec4 o;\n"
                            "void main() {\n  vec4 n = gbuffer_normal_decode(texelFetch(src, ivec2(gl_FragCoord.xy), 0));\n"
                            "  o = shininess == 1 ? vec4(n.w / 65536.0, 0.0, 0.0, 1.0) : vec4(n.xyz * 0.5 + 0.5, 1.0);\n}\n"));
  for (int pass = 0; pass < 2; pass++) {
    char lua[600];
    snprintf(lua, sizeof lua,
             "Techniques = { 'x' }\nfunction OnRender()\n  local e = pass{ 'encode', shader = 'nrm_encode.frag', "
             "out = target{ 'e', format = 'rgba8' } }\n  present(pass{ 'decode', shader = 'nrm_decode.frag', inputs = "
             "{ src = e }, params = { shininess = %d }, out = target{ 'd', format = 'rgba32f' } }, 'display')\nend\n",
             pass);
    assert_true(gl_write_file("normals.lua", lua));
    gl_result fr = render("normals.lua", NULL, 1);
    if (!fr.ok) fail_msg("%s", fr.err.msg);
    double worst = 0;
    for (int i = 0; i < W * H; i++) {
      /* i counts from GL's bottom row; the result's rows are top first */
      int row = i / W, col = i % W, at = ((H - 1 - row) * W + col) * 3;
      const float *v = fr.rgb + at;
      if (pass == 1) {
        double s = i == SPECIAL + 2 ? 1 : i > SPECIAL ? (i - SPECIAL - 1) * 60000.0 / (W * H) : 0, got = v[0] * 65536.0;
        if (!isfinite(got) || fabs((1 + got) / (1 + s) - 1) > 0.022)
          fail_msg("shininess %g came back %g (pixel %d)", s, got, i);
        if ((s == 0 || s == 1) && got != s) fail_msg("shininess %g came back %g", s, got);
        continue;
      }
      double d[3], len = 0;
      for (int k = 0; k < 3; k++) {
        if (!isfinite(v[k])) fail_msg("normal %d: %g", i, v[k]);
        d[k] = v[k] * 2.0 - 1.0;
        len += d[k] * d[k];
      }
      if (fabs(sqrt(len) - 1) > 1e-5) fail_msg("normal %d not unit: %g", i, sqrt(len));
      if (i < 6) {
        for (int k = 0; k < 3; k++)
          if (d[k] != special[i][k]) fail_msg("axis %d came back (%g, %g, %g)", i, d[0], d[1], d[2]);
      } else if (i == SPECIAL - 1 || i == SPECIAL) {
        /* zero, and the texel of zeros: (0, 1, 0) is what nothing drawn reads as; zero's direction is any unit */
        if (i == SPECIAL && (d[0] != 0 || d[1] != 1 || d[2] != 0)) fail_msg("zeros came back (%g, %g, %g)", d[0], d[1], d[2]);
      } else if (i >= SPECIAL) {
        double dot = 0;
        for (int k = 0; k < 3; k++) dot += d[k] * sphere(i, k);
        worst = fmax(worst, acos(fmin(dot, 1.0)) * 57.29577951308232);
      }
    }
    if (pass == 0) {
      print_message("gbuffer normals: worst %.4f degrees\n", worst);
      if (worst > 0.07) fail_msg("a normal came back %g degrees off", worst);
    }
    gl_result_free(&fr);
  }
}

static void textures_are_pooled_across_frames(void **state) {
  (void)state;
  lm_error err;
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = pp_lua}, &err);
  assert_true(lm_pipeline_set_technique(p, "dl", &err));
  lm_scene *scene = lm_scene_builtin("cornell", &err);
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = p, .width = 64,
                                                          .height = 48}, &err);
  int textures[4];
  double bytes;
  for (int f = 0; f < 4; f++) {
    assert_true(lm_renderer_frame(r, &err));
    lm_graph_pool_stats(lm_renderer_graph(r), &textures[f], &bytes);
  }
  /* G-buffer (5) + lit + the exposure meter's 16x16; the rgba8 output
   * reuses a G-buffer texture whose last reader has run. Made on the first
   * frame, then reused. */
  assert_int_equal(textures[0], 7);
  assert_int_equal(textures[3], textures[0]);
  assert_int_equal(lm_program_count() > 0, 1);
  lm_renderer_destroy(r);
  lm_scene_destroy(scene);
  lm_pipeline_destroy(p);
}

/* The CPU step of a hybrid technique: "fill" writes (x, y, 0.5, 1) per
 * texel, "invert" reads it back and writes 1 - it; what reaches the GPU is
 * what the functions wrote, top row first. An unread CPU pass does not run. */
typedef struct cpu_calls {
  int fill, invert;
} cpu_calls;

static bool run_cpu(void *user, const lm_cpu_pass *cp, lm_error *err) {
  cpu_calls *calls = user;
  if (!strcmp(cp->desc->shader, "fill")) {
    calls->fill++;
    lm_cpu_image *o = &cp->outputs[0];
    for (int y = 0; y < o->height; y++)
      for (int x = 0; x < o->width; x++) {
        float *px = o->rgba + ((size_t)y * o->width + x) * 4;
        px[0] = (float)x, px[1] = (float)y, px[2] = 0.5f, px[3] = 1;
      }
    return true;
  }
  if (!strcmp(cp->desc->shader, "invert")) {
    calls->invert++;
    const lm_cpu_image *i = &cp->inputs[0];
    assert_string_equal(i->name, "src");
    for (size_t k = 0; k < (size_t)i->width * i->height * 4; k++) cp->outputs[0].rgba[k] = 1 - i->rgba[k];
    return true;
  }
  lm_error_set(err, "no CPU function '%s'", cp->desc->shader);
  return false;
}

static void cpu_passes_read_back_and_upload(void **state) {
  (void)state;
  lm_graph *g = lm_graph_create();
  lm_error err;
  for (int frame = 0; frame < 2; frame++) {
    lm_graph_begin(g, 16, 12);
    int a = lm_graph_add_target(g, &(lm_target_desc){.name = "a", .format = LM_FORMAT_RGBA32F, .scale = 0.5f}, &err);
    int b = lm_graph_add_target(g, &(lm_target_desc){.name = "b", .format = LM_FORMAT_RGBA16F, .scale = 0.5f}, &err);
    int c = lm_graph_add_target(g, &(lm_target_desc){.name = "c", .format = LM_FORMAT_RGBA32F, .scale = 0.5f}, &err);
    lm_pass_input in = {"src", a};
    lm_pass_desc fill = {.kind = LM_PASS_CPU, .name = "fill", .where = "test:1", .shader = "fill",
                         .outputs = &a, .output_count = 1, .depth = -1};
    lm_pass_desc inv = {.kind = LM_PASS_CPU, .name = "invert", .where = "test:2", .shader = "invert",
                        .inputs = &in, .input_count = 1, .outputs = &b, .output_count = 1, .depth = -1};
    lm_pass_desc unread = inv;
    unread.name = "unread", unread.outputs = &c;
    assert_true(lm_graph_add_pass(g, &fill, &err) >= 0 && lm_graph_add_pass(g, &inv, &err) >= 0 &&
                lm_graph_add_pass(g, &unread, &err) >= 0);
    lm_graph_mark_output(g, b);
    assert_true(lm_graph_compile(g, &err));
    cpu_calls calls = {0};
    lm_graph_exec_desc x = {.run_cpu = run_cpu, .user = &calls, .check_finite = true};
    if (!lm_graph_execute(g, &x, &err)) fail_msg("%s", err.msg);
    assert_int_equal(calls.fill, 1);
    assert_int_equal(calls.invert, 1);
    assert_true(lm_graph_pass(g, 1).ms >= 0);
    float px[8 * 6 * 4];
    lm_texture_read(lm_graph_target(g, b).texture, 8, 6, true, px);
    for (int y = 0; y < 6; y++)
      for (int xx = 0; xx < 8; xx++) {
        const float *p = px + (y * 8 + xx) * 4;
        assert_float_equal(p[0], 1 - xx, 1e-3);
        assert_float_equal(p[1], 1 - y, 1e-3);
        assert_float_equal(p[2], 0.5, 1e-3);
      }
  }
  /* a failing function names the pass; with none given, the pass is named too */
  lm_graph_begin(g, 16, 12);
  int a = lm_graph_add_target(g, &(lm_target_desc){.name = "a", .format = LM_FORMAT_RGBA32F}, &err);
  lm_pass_desc bad = {.kind = LM_PASS_CPU, .name = "odd", .where = "test:3", .shader = "nosuch",
                      .outputs = &a, .output_count = 1, .depth = -1};
  lm_graph_add_pass(g, &bad, &err);
  lm_graph_mark_output(g, a);
  assert_true(lm_graph_compile(g, &err));
  cpu_calls calls = {0};
  assert_false(lm_graph_execute(g, &(lm_graph_exec_desc){.run_cpu = run_cpu, .user = &calls}, &err));
  assert_non_null(strstr(err.msg, "test:3: pass 'odd': no CPU function 'nosuch'"));
  assert_false(lm_graph_execute(g, &(lm_graph_exec_desc){0}, &err));
  assert_non_null(strstr(err.msg, "test:3: pass 'odd': CPU function 'nosuch' is not available here"));
  lm_graph_destroy(g);
}

/* The field's 60 posts share a mesh and a material: the camera draws them in
 * one instanced call (and the ground in another), each where its own
 * matrices put it. Given a copy of the mesh each, they draw one call a post,
 * and the image, shadows included (shadow.vert reads the same instances), is
 * the same. */
static void copies_of_a_mesh_draw_in_one_call_and_look_the_same(void **state) {
  (void)state;
  lm_error err;
  lm_scene *shared = lm_scene_builtin("field", &err), *own = lm_scene_builtin("field", &err);
  assert_true(shared && own);
  int posts = 0;
  for (int i = 0; i < own->node_count; i++) {
    lm_node *n = &own->nodes[i];
    if (strncmp(n->name, "post_", 5)) continue;
    const lm_scene_mesh *m = &own->meshes[n->mesh];
    float *v = malloc(sizeof(float) * 8 * (size_t)m->vertex_count);
    uint32_t *idx = malloc(sizeof(uint32_t) * (size_t)m->index_count);
    memcpy(v, m->vertices, sizeof(float) * 8 * (size_t)m->vertex_count);
    memcpy(idx, m->indices, sizeof(uint32_t) * (size_t)m->index_count);
    n->mesh = lm_scene_add_mesh(own, n->name, v, m->vertex_count, idx, m->index_count); /* may move meshes */
    free(v);
    free(idx);
    posts++;
  }
  assert_int_equal(posts, 60);
  gl_result a = gl_render(&(gl_run){.scene = shared, .tech = "dl+esm", .width = W, .height = H});
  gl_result b = gl_render(&(gl_run){.scene = own, .tech = "dl+esm", .width = W, .height = H});
  assert_true(a.ok && b.ok);
  lm_scene_draw_stats sa = lm_renderer_draw_stats(a.renderer), sb = lm_renderer_draw_stats(b.renderer);
  printf("field: %d nodes drawn in %d calls shared, %d in %d calls with a mesh each\n", sa.drawn, sa.calls, sb.drawn,
         sb.calls);
  assert_int_equal(sa.drawn, sb.drawn);
  assert_int_equal(sa.calls, 2);
  assert_int_equal(sb.calls, sb.drawn);
  float worst = 0;
  for (int i = 0; i < W * H * 3; i++) worst = fmaxf(worst, fabsf(a.rgb[i] - b.rgb[i]));
  printf("largest difference between the images: %g\n", worst);
  assert_true(worst <= 1e-5f);
  gl_result_free(&a);
  gl_result_free(&b);
  lm_scene_destroy(shared);
  lm_scene_destroy(own);
  /* A technique still reading the per-node uniform `model` is told what to read instead. */
  assert_true(gl_write_file("shaders/oldtech.vert", "#include \"common.glsl\"\nlayout(location = 0) in vec3 p;\n"
                                                    "uniform mat4 model;\nvoid main() { gl_Position = frame.view_proj "
                                                    "* model * vec4(p, 1.0); }\n"));
  assert_true(gl_write_file("shaders/oldtech.frag", "out vec4 o;\nvoid main() { o = vec4(1.0); }\n"));
  assert_true(gl_write_file("oldtech.lua", "Techniques = { 'x' }\nfunction OnRender()\n  local t = target{ 't', "
                                           "format = 'rgba8' }\n  scene{ 'old', technique = 'oldtech', out = t }\n"
                                           "  present(t)\nend\n"));
  gl_result r = render("oldtech.lua", NULL, 1);
  assert_false(r.ok);
  if (!strstr(r.err.msg, "oldtech") || !strstr(r.err.msg, "instance_model")) fail_msg("%s", r.err.msg);
  gl_result_free(&r);
}

/* The fragments a frame's passes shade (GL_SAMPLES_PASSED) with the scene:
 * a ceiling of material "near" 2 above a camera looking up, and with
 * `hidden` another of material "far" 3 behind it, which sorts first. */
static GLuint64 fragments_under_a_ceiling(bool hidden) {
  lm_scene *s = lm_scene_create("ceiling");
  const float F = 20, down[3] = {0, -1, 0};
  if (hidden) {
    int far = gl_material(s, "far", 1, 0, 0);
    gl_quad(s, "far", far, (const float[4][3]){{-F, 5, -F}, {F, 5, -F}, {F, 5, F}, {-F, 5, F}}, down);
  }
  int near = gl_material(s, "near", 0, 1, 0);
  gl_quad(s, "near", near, (const float[4][3]){{-F, 2, -F}, {F, 2, -F}, {F, 2, F}, {-F, 2, F}}, down);
  gl_camera_up(s, 0);
  lm_scene_update(s);
  assert_true(gl_write_file("gbuffer_only.lua", "local gbuffer = require 'gbuffer'\nTechniques = { 'g' }\n"
                                                "function OnRender()\n  present(gbuffer.render(gbuffer.targets()).clr)\n"
                                                "end\n"));
  GLuint query;
  glGenQueries(1, &query);
  glBeginQuery(GL_SAMPLES_PASSED, query);
  gl_result r = gl_render(&(gl_run){.scene = s, .script = "gbuffer_only.lua", .width = W, .height = H});
  glEndQuery(GL_SAMPLES_PASSED);
  GLuint64 fragments = 0;
  glGetQueryObjectui64v(query, GL_QUERY_RESULT, &fragments);
  glDeleteQueries(1, &query);
  assert_true(r.ok);
  float green[3];
  gl_region(&r, 0, 0, W - 1, H - 1, green);
  assert_true(green[1] > 0 && green[0] <= 1e-3f * green[1]); /* the near ceiling, nothing of the far one */
  gl_result_free(&r);
  lm_scene_destroy(s);
  return fragments;
}

/* The camera's draws go nearest first (lm_scene_draw), not by material: a
 * node hidden whole behind another costs the G-buffer no fragment shaded,
 * though its material sorts first (drawn by material, it cost a screenful). */
static void hidden_draws_shade_no_fragment(void **state) {
  (void)state;
  GLuint64 alone = fragments_under_a_ceiling(false), with_hidden = fragments_under_a_ceiling(true);
  printf("fragments shaded: %llu with the near ceiling alone, %llu with one hidden behind it\n",
         (unsigned long long)alone, (unsigned long long)with_hidden);
  assert_true(alone >= (GLuint64)W * H);
  assert_true(with_hidden == alone);
}

/* A points pass scatters: 1000 points, point i on texel i % 4 of a 4 x 2
 * target's top row, each adding (1, i, 0, 0), sum exactly what each texel
 * gets; the target starts from zero every frame, so a second frame gives
 * the same sums; the other row stays 0. Bad fields are named. */
static void points_passes_scatter_and_add(void **state) {
  (void)state;
  assert_true(gl_write_file("shaders/scatter.vert",
                            "uniform int columns = 4;\nflat out vec4 v;\nvoid main() {\n"
                            "  int x = gl_VertexID % columns;\n"
                            "  gl_Position = vec4((float(x) + 0.5) / float(columns) * 2.0 - 1.0, 0.5, 0.0, 1.0);\n"
                            "  v = vec4(1.0, float(gl_VertexID), 0.0, 0.0);\n}\n"));
  assert_true(gl_write_file("shaders/scatter.frag", "flat in vec4 v;\nout vec4 o;\nvoid main() { o = v; }\n"));
  static const char *const good =
      "Techniques = { 'x' }\nfunction OnRender(tech)\n"
      "  present(points{ 'scatter', vertex = 'scatter.vert', shader = 'scatter.frag', count = 1000,\n"
      "                  out = target{ 'scatter', format = 'rgba32f', size = { 4, 2 } } })\nend\n";
  assert_true(gl_write_file("points.lua", good));
  gl_result r = gl_render(&(gl_run){.script = "points.lua", .width = 8, .height = 4, .frames = 2});
  if (!r.ok) fail_msg("%s", r.err.msg);
  int w, h;
  float *px = gl_read_target(&r, "scatter", &w, &h);
  assert_non_null(px);
  assert_int_equal(w, 4), assert_int_equal(h, 2);
  for (int x = 0; x < 4; x++) {
    double sum = 0; /* i = x, x + 4, ... < 1000 */
    for (int i = x; i < 1000; i += 4) sum += i;
    assert_float_equal(px[x * 4 + 0], 250, 1e-3);          /* rows top first: the top row */
    assert_float_equal(px[x * 4 + 1], sum, 1e-6 * sum);
    assert_float_equal(px[(4 + x) * 4 + 0], 0, 0);         /* the bottom row, untouched */
  }
  free(px);
  assert_true(gl_has_pass(&r, "scatter"));
  gl_result_free(&r);
  static const struct {
    const char *fields, *expect;
  } cases[] = {
      {"count = -1", "points.lua:3: pass 'scatter': count must be a whole number in 0 .. 67108864 (got -1)"},
      {"count = 1.5", "pass 'scatter': count must be a whole number"},
      {"count = 'many'", "pass 'scatter': count must be a whole number"},
      {"count = 1e9", "pass 'scatter': count must be a whole number"},
      {"count = 4, vertex = nil", "pass 'scatter': field 'vertex' is missing"},
      {"count = 4, depth = 1", "pass 'scatter': unknown field 'depth'"},
      {"count = 4, vertex = 'nope.vert'", "pass 'scatter'"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char text[1024];
    snprintf(text, sizeof text,
             "Techniques = { 'x' }\nfunction OnRender(tech)\n"
             "  present(points{ 'scatter', vertex = 'scatter.vert', shader = 'scatter.frag', %s,\n"
             "                  out = target{ 'scatter', format = 'rgba32f', size = { 4, 2 } } })\nend\n",
             cases[i].fields);
    assert_true(gl_write_file("points.lua", text));
    gl_result fr = gl_render(&(gl_run){.script = "points.lua", .width = 8, .height = 4});
    if (fr.ok || !strstr(fr.err.msg, cases[i].expect)) fail_msg("case %zu: %s", i, fr.ok ? "rendered" : fr.err.msg);
    gl_result_free(&fr);
  }
}

/* Two passes of one shader (one cached program): the first sets `gain`, the
 * second does not and gets the shader's initializer, not the first's value;
 * an int keeps its initializer alike. */
static void a_uniform_a_pass_leaves_unset_keeps_its_initializer(void **state) {
  (void)state;
  assert_true(gl_write_file("gain.lua",
                            "Techniques = { 'x' }\nfunction OnRender(tech)\n"
                            "  local a = target{ 'a', format = 'rgba32f', size = { 2, 2 } }\n"
                            "  local b = target{ 'b', format = 'rgba32f', size = { 2, 2 } }\n"
                            "  local z = target{ 'z', format = 'rgba32f', size = { 2, 2 } }\n"
                            "  pass{ 'zero', shader = 'zero.frag', out = z }\n"
                            "  pass{ 'set', shader = 'gain.frag', inputs = { x = z }, params = { gain = 1.0, step = 7 },"
                            " out = a }\n"
                            "  pass{ 'unset', shader = 'gain.frag', inputs = { x = a }, out = b }\n"
                            "  present(b)\nend\n"));
  /* Each pass reads the one before, so all run, in order. */
  assert_true(gl_write_file("shaders/zero.frag", "out vec4 o;\nvoid main() { o = vec4(0.0); }\n"));
  assert_true(gl_write_file("shaders/gain.frag", "uniform sampler2D x;\nuniform float gain = 0.25;\n"
                                                 "uniform int step = 3;\nout vec4 o;\n"
                                                 "void main() { o = vec4(gain, float(step), texelFetch(x, ivec2(0), 0).x, 1.0); }\n"));
  gl_result r = gl_render(&(gl_run){.script = "gain.lua", .width = 2, .height = 2, .frames = 2});
  if (!r.ok) fail_msg("%s", r.err.msg);
  int w, h;
  float *px = gl_read_target(&r, "b", &w, &h);
  assert_non_null(px);
  printf("unset pass after a set one: gain %g, step %g (set pass wrote gain %g)\n", px[0], px[1], px[2]);
  assert_float_equal(px[0], 0.25, 1e-6);
  assert_float_equal(px[1], 3, 0);
  assert_float_equal(px[2], 1.0, 1e-6);
  free(px);
  gl_result_free(&r);
}

int main(void) {
  snprintf(pp_lua, sizeof pp_lua, "%s/scripts/pp.lua", lm_root_dir());
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(cornell_box_has_light_and_colour_where_it_must),
      cmocka_unit_test(cornell_box_matches_the_golden_image),
      cmocka_unit_test(copies_of_a_mesh_draw_in_one_call_and_look_the_same),
      cmocka_unit_test(hidden_draws_shade_no_fragment),
      cmocka_unit_test(shader_errors_name_the_original_file_and_line),
      cmocka_unit_test(wrong_uniforms_and_inputs_name_the_pass_and_parameter),
      cmocka_unit_test(no_nan_or_inf_leaves_the_output_stage),
      cmocka_unit_test(the_output_stage_encodes_srgb_as_the_formula),
      cmocka_unit_test(gbuffer_normals_survive_their_eight_bits),
      cmocka_unit_test(textures_are_pooled_across_frames),
      cmocka_unit_test(cpu_passes_read_back_and_upload),
      cmocka_unit_test(points_passes_scatter_and_add),
      cmocka_unit_test(a_uniform_a_pass_leaves_unset_keeps_its_initializer),
  };
  return cmocka_run_group_tests(tests, setup, gl_test_teardown);
}
