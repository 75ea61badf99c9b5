/* Materials on whatever EGL offers: base-colour textures (decoded, sRGB,
 * sampled), per-pass parameter overrides from scripts, reloading, frustum
 * culling, and the messages a bad texture or override gives.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gl_test.h"
#include "image/image.h"
#include "scene/gltf.h"

enum { W = 96, H = 72 };

static char pp_lua[1024];

static void scene_path(const char *name, char *out, size_t cap) {
  snprintf(out, cap, "%s/data/scenes/%s.glb", LIMN_SOURCE_ROOT, name);
}

static lm_scene *load(const char *name) {
  char path[1024];
  scene_path(name, path, sizeof path);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

static void write_file(const char *name, const char *text, char *path, size_t cap) {
  assert_true(gl_write_file(name, text));
  snprintf(path, cap, "%s/%s", gl_root(), name);
}

typedef struct shot {
  bool ok;
  lm_error err;
  unsigned char rgb[W * H * 3];
  lm_scene_draw_stats stats;
} shot;

/* One frame of `scene` from camera `cam` through `script` (pp.lua when NULL). */
static shot *render(lm_scene *scene, const char *script, int cam, bool no_culling) {
  shot *s = calloc(1, sizeof *s);
  lm_pipeline *p = lm_pipeline_load(&(lm_pipeline_desc){.path = script ? script : pp_lua}, &s->err);
  if (!p) return s;
  lm_renderer *r = lm_renderer_create(&(lm_renderer_desc){.scene = scene, .pipeline = p, .width = W, .height = H,
                                                          .camera = cam, .no_culling = no_culling}, &s->err);
  s->ok = r && lm_renderer_frame(r, &s->err) && lm_renderer_read(r, false, s->rgb, &s->err);
  if (r) s->stats = lm_renderer_draw_stats(r);
  lm_renderer_destroy(r);
  lm_pipeline_destroy(p);
  return s;
}

/* Mean absolute difference between horizontal neighbours in rows y0..y1:
 * texture detail is high-frequency energy that flat colour lacks. */
static double detail(const unsigned char *rgb, int y0, int y1) {
  double sum = 0;
  int n = 0;
  for (int y = y0; y < y1; y++)
    for (int x = 0; x + 1 < W; x++)
      for (int c = 0; c < 3; c++, n++) sum += abs(rgb[(y * W + x) * 3 + c] - rgb[(y * W + x + 1) * 3 + c]);
  return sum / n;
}

static double mean_channel(const unsigned char *rgb, int c, int y0, int y1) {
  double sum = 0;
  for (int y = y0; y < y1; y++)
    for (int x = 0; x < W; x++) sum += rgb[(y * W + x) * 3 + c];
  return sum / ((y1 - y0) * W);
}

static void textures_show_as_detail(void **state) {
  (void)state;
  lm_scene *s = load("primitives");
  assert_int_equal(s->texture_count, 1);
  assert_int_equal(s->textures[0].width, 64);
  int ground = lm_scene_find_material(s, "ground");
  assert_true(ground >= 0 && s->materials[ground].base_color_texture == 1);
  shot *with = render(s, NULL, 2, false); /* "top": the checker floor fills the view */
  assert_true(with->ok);
  s->materials[ground].base_color_texture = 0; /* the same scene with the texture taken off */
  shot *without = render(s, NULL, 2, false);
  assert_true(without->ok);
  double a = detail(with->rgb, 0, H), b = detail(without->rgb, 0, H);
  printf("detail with texture %.2f, without %.2f\n", a, b);
  assert_true(a > 3 * b && a > 8);
  /* sRGB decoding: the checker's light cells (230 stored) light like an albedo of 0.79, not 0.9. */
  free(with), free(without);
  lm_scene_destroy(s);
}

static void culling_drops_what_the_camera_cannot_see(void **state) {
  (void)state;
  lm_scene *s = load("office");
  shot *culled = render(s, NULL, 3, false); /* "shelf": the back wall, desks behind the eye */
  shot *all = render(s, NULL, 3, true);
  assert_true(culled->ok && all->ok);
  printf("close-up: drawn %d, culled %d of %d\n", culled->stats.drawn, culled->stats.culled, all->stats.drawn);
  assert_true(culled->stats.culled > 0);
  assert_int_equal(culled->stats.drawn + culled->stats.culled, all->stats.drawn);
  assert_int_equal(all->stats.culled, 0);
  assert_memory_equal(culled->rgb, all->rgb, sizeof culled->rgb); /* conservative: nothing visible lost */
  free(culled), free(all);
  lm_scene_destroy(s);

  s = load("outdoor");
  shot *over = render(s, NULL, 0, false);
  shot *ground = render(s, NULL, 2, false);
  assert_true(over->ok && ground->ok);
  printf("outdoor overview: %d drawn, %d culled, %ld triangles; ground view: %d drawn, %d culled\n",
         over->stats.drawn, over->stats.culled, over->stats.triangles, ground->stats.drawn, ground->stats.culled);
  /* most of the forest in view (4201 mesh nodes): drawn, though far trees draw simplified copies */
  assert_true(over->stats.drawn >= 3000 && over->stats.drawn > 3 * over->stats.culled);
  assert_true(ground->stats.culled > ground->stats.drawn); /* most of the forest is behind or beside */
  free(over), free(ground);
  lm_scene_destroy(s);
}

static void scripts_override_materials_by_name(void **state) {
  (void)state;
  char path[512];
  const char *fmt =
      "Techniques = { 'dl' }\n"
      "function OnRender(tech)\n"
      "  local G = { clr = target{ 'c', format = 'rgba8' }, nrm = target{ 'n', format = 'rgba8' },\n"
      "              dpt = target{ 'd', format = 'r32f' }, mat = target{ 'm', format = 'rgba8' },\n"
      "              depth = target{ 'z', format = 'depth32f' } }\n"
      "  scene{ 'gbuffer', out = { G.clr, G.nrm, G.dpt, G.mat }, depth = G.depth, materials = %s }\n"
      "  present(pass{ 'direct', shader = 'direct.frag', out = target{ 'lit', format = 'rgba16f' },\n"
      "    inputs = { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat } })\n"
      "end\n";
  char text[2048];
  lm_scene *s = load("primitives");
  snprintf(text, sizeof text, fmt, "{}");
  write_file("plain.lua", text, path, sizeof path);
  shot *plain = render(s, path, 2, false);
  assert_true(plain->ok);
  snprintf(text, sizeof text, fmt, "{ ground = { color = { 1, 0, 0 } } }");
  write_file("red.lua", text, path, sizeof path);
  shot *red = render(s, path, 2, false);
  assert_true(red->ok);
  double g0 = mean_channel(plain->rgb, 1, 0, H), g1 = mean_channel(red->rgb, 1, 0, H);
  double r0 = mean_channel(plain->rgb, 0, 0, H), r1 = mean_channel(red->rgb, 0, 0, H);
  printf("ground red override: green %.1f -> %.1f, red %.1f -> %.1f\n", g0, g1, r0, r1);
  assert_true(g1 < 0.5 * g0 && r1 > 0.7 * r0);
  /* The scene's own material is untouched: the override lives in the pass. */
  assert_true(s->materials[lm_scene_find_material(s, "ground")].color[1] == 1.0f);

  static const struct {
    const char *materials, *expect;
  } bad[] = {
      {"{ nosuch = { ks = 1 } }", "material 'nosuch': scene 'primitives.glb' has no material of that name (it has: ground,"},
      {"{ ground = { shine = 1 } }", "material 'ground': unknown parameter 'shine' (known: color, rho, ka, kd, ks, shininess, reflectivity)"},
      {"{ ground = { color = 1 } }", "material 'ground': parameter 'color' takes 3 numbers, not 1"},
      {"{ ground = { color = { 1, 'x', 0 } } }", "material 'ground': parameter 'color': element 2 is a string"},
      {"{ ground = 3 }", "materials are named tables"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    snprintf(text, sizeof text, fmt, bad[i].materials);
    write_file("bad.lua", text, path, sizeof path);
    shot *b = render(s, path, 2, false);
    assert_false(b->ok);
    if (!strstr(b->err.msg, bad[i].expect)) fail_msg("got '%s', want '%s'", b->err.msg, bad[i].expect);
    assert_non_null(strstr(b->err.msg, "pass 'gbuffer'"));
    free(b);
  }
  free(plain), free(red);
  lm_scene_destroy(s);
}

static void materials_reload_without_a_restart(void **state) {
  (void)state;
  lm_scene *s = load("cornell");
  shot *before = render(s, NULL, 0, false); /* uploads s */
  assert_true(before->ok);
  lm_scene *edited = load("cornell");
  int red = lm_scene_find_material(edited, "red");
  edited->materials[red].color[0] = 0.05f, edited->materials[red].color[2] = 0.8f; /* red wall to blue */
  lm_error err;
  assert_true(lm_scene_reload_materials(s, edited, &err));
  lm_programs_clear(); /* the shaders too, as the viewer does */
  shot *after = render(s, NULL, 0, false);
  assert_true(after->ok);
  /* The left wall: the left quarter of the image. */
  double r0 = 0, r1 = 0, b0 = 0, b1 = 0;
  for (int y = H / 4; y < 3 * H / 4; y++)
    for (int x = 0; x < W / 6; x++) {
      r0 += before->rgb[(y * W + x) * 3], b0 += before->rgb[(y * W + x) * 3 + 2];
      r1 += after->rgb[(y * W + x) * 3], b1 += after->rgb[(y * W + x) * 3 + 2];
    }
  assert_true(r0 > 2 * b0 && b1 > 2 * r1);
  lm_scene *other = load("office");
  assert_false(lm_scene_reload_materials(s, other, &err));
  assert_non_null(strstr(err.msg, "nodes changed"));
  free(before), free(after);
  lm_scene_destroy(other);
  lm_scene_destroy(edited);
  lm_scene_destroy(s);
}

/* A one-triangle glTF whose material has a base-colour texture from `image` (JSON). */
static const char *textured_gltf(const char *textures, const char *images) {
  static char text[4096];
  snprintf(text, sizeof text,
           "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
           "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
           "\"textures\":%s,\"images\":%s,"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
           "\"min\":[0,0,0],\"max\":[1,1,0]}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
           "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
           "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}",
           textures, images);
  return text;
}

static void bad_textures_name_material_texture_and_image(void **state) {
  (void)state;
  static const struct {
    const char *textures, *images, *expect;
  } cases[] = {
      {"[{\"source\":0}]", "[{\"uri\":\"data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAA\"}]",
       "material 0: baseColorTexture: texture 0: image 0"},
      {"[{\"source\":0}]", "[{\"uri\":\"missing.png\"}]", "material 0: baseColorTexture: texture 0: image 0 ('missing.png'): no image data"},
      {"[{\"source\":3}]", "[{\"uri\":\"missing.png\"}]", "material 0: baseColorTexture: texture 0: image 3 does not exist"},
      {"[]", "[]", "material 0: baseColorTexture: texture 0 does not exist (the file has 0)"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char path[512];
    write_file("tex.gltf", textured_gltf(cases[i].textures, cases[i].images), path, sizeof path);
    lm_error err;
    lm_scene *s = lm_scene_load_gltf(path, &err);
    assert_null(s);
    if (!strstr(err.msg, cases[i].expect)) fail_msg("case %zu: got '%s', want '%s'", i, err.msg, cases[i].expect);
    assert_non_null(strstr(err.msg, "tex.gltf"));
  }
}

/* ---- the test scenes, mutated --------------------------------------------- */
static uint32_t rng_state = 777;
static uint32_t rng(void) {
  rng_state = rng_state * 1664525u + 1013904223u;
  return rng_state >> 8;
}

/* Mutations of data/scenes files, aimed at the JSON's numbers and at the
 * embedded PNG: whatever loads is consistent, whatever fails names the file. */
static void mutated_scene_files_never_crash(void **state) {
  (void)state;
  static const char *const seeds[] = {"primitives", "cornell"};
  const char *env = getenv("LIMN_GLTF_MUTATIONS");
  int iters = env && atoi(env) > 0 ? atoi(env) : 300, loaded = 0;
  for (int iter = 0; iter < iters; iter++) {
    char path[1024], out[512];
    scene_path(seeds[iter % 2], path, sizeof path);
    size_t len;
    lm_error err;
    unsigned char *b = (unsigned char *)lm_read_file(path, &len, &err);
    assert_non_null(b);
    uint32_t json_len;
    memcpy(&json_len, b + 12, 4);
    size_t json_end = 20 + json_len, png = 0;
    for (size_t i = json_end; i + 4 < len && !png; i++)
      if (!memcmp(b + i, "\x89PNG", 4)) png = i;
    int edits = 1 + (int)(rng() % 3);
    for (int e = 0; e < edits; e++) {
      switch (rng() % 4) {
      case 0: { /* a digit of the JSON for another */
        size_t j = 20 + rng() % json_len;
        for (size_t k = 0; k < 64 && j + k < json_end; k++)
          if (b[j + k] >= '0' && b[j + k] <= '9') {
            b[j + k] = (unsigned char)('0' + rng() % 10);
            break;
          }
        break;
      }
      case 1: /* a byte of the image (or of the buffer when there is none) */
        b[png ? png + rng() % 800 : json_end + rng() % (len - json_end)] = (unsigned char)rng();
        break;
      case 2: b[rng() % len] ^= (unsigned char)(1u << (rng() % 8)); break;
      default: len = json_end + rng() % (len - json_end); break; /* cut the buffer short */
      }
    }
    snprintf(out, sizeof out, "%s/mutant.glb", gl_root());
    FILE *f = fopen(out, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, len, f), len);
    fclose(f);
    free(b);
    lm_scene *s = lm_scene_load_gltf(out, &err);
    if (s) {
      loaded++;
      for (int i = 0; i < s->material_count; i++)
        assert_true(s->materials[i].base_color_texture >= 0 && s->materials[i].base_color_texture <= s->texture_count);
      for (int i = 0; i < s->texture_count; i++)
        assert_true(s->textures[i].width > 0 && s->textures[i].height > 0 && s->textures[i].rgba);
      lm_scene_destroy(s);
    } else if (!strstr(err.msg, "mutant.glb")) {
      fail_msg("iteration %d: message without the path: %s", iter, err.msg);
    }
  }
  printf("scene mutations: %d of %d still loaded\n", loaded, iters);
  assert_true(loaded > 0 && loaded < iters);
}

/* The pbr technique over a grid of spheres, metallic (rows) by roughness
 * (columns), lit from the eye: every value finite, each row's highlight
 * falls as roughness grows while the diffuse part stays, a metal's
 * highlight takes its base colour; and the GI passes take the same
 * G-buffer (finite, lit). */
static void pbr_sphere_grid_is_finite_and_monotonic(void **state) {
  (void)state;
  enum { GW = 128, GH = 96, ROWS = 3, COLS = 4 };
  static const float metallic[ROWS] = {0, 0.5f, 1}, roughness[COLS] = {0.3f, 0.5f, 0.7f, 1.0f};
  lm_scene *s = lm_scene_create("grid");
  int sphere = gl_uv_sphere(s, "sphere", 0.42f);
  float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (int r = 0; r < ROWS; r++)
    for (int c = 0; c < COLS; c++) {
      lm_material mat = {.color = {0.8f, 0.35f, 0.1f}, .rho = 0.8f, .ka = 1, .kd = 1, .ks = 0.04f, .shininess = 16};
      snprintf(mat.name, sizeof mat.name, "m%d_r%d", r, c);
      int id = lm_scene_add_material(s, &mat);
      s->material_pbr[id] = (lm_material_pbr){.set = true, .metallic = metallic[r], .roughness = roughness[c],
                                              .normal_scale = 1, .occlusion_strength = 1, .alpha = 1};
      m[12] = ((float)c - 1.5f), m[13] = (1.0f - (float)r);
      lm_scene_add_node(s, mat.name, -1, m, sphere, id);
    }
  m[12] = 0, m[13] = 0, m[14] = 8;
  int eye = lm_scene_add_node(s, "eye", -1, m, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "eye", .fov_y = 0.42f, .znear = 1, .zfar = 20, .node = eye});
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 2,
                                     .outer_cone = 1.5707964f, .node = eye});
  lm_scene_update(s);
  const char *sets[] = {"materials=pbr", "ambient=0", NULL};
  gl_result g = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = GW, .height = GH,
                                    .check_finite = true});
  if (!g.ok) fail_msg("%s", g.err.msg);
  assert_true(gl_all_finite(&g));
  lm_frame_data f;
  lm_scene_frame_data(s, 0, GW, GH, &f);
  float peak[ROWS][COLS], peak_rgb[ROWS][COLS][3], edge[ROWS][COLS];
  for (int r = 0; r < ROWS; r++)
    for (int c = 0; c < COLS; c++) {
      float p[3] = {(float)c - 1.5f, 1.0f - (float)r, 0}, clip[4];
      for (int k = 0; k < 4; k++)
        clip[k] = f.view_proj[k] * p[0] + f.view_proj[4 + k] * p[1] + f.view_proj[8 + k] * p[2] + f.view_proj[12 + k];
      int cx = (int)((clip[0] / clip[3] * 0.5f + 0.5f) * GW), cy = (int)((0.5f - clip[1] / clip[3] * 0.5f) * GH);
      peak[r][c] = 0;
      for (int y = cy - 4; y <= cy + 4; y++)
        for (int x = cx - 4; x <= cx + 4; x++) {
          const float *q = g.rgb + (y * GW + x) * 3;
          float l = gl_luminance(q);
          if (l > peak[r][c]) peak[r][c] = l, memcpy(peak_rgb[r][c], q, sizeof peak_rgb[r][c]);
        }
      float side[3]; /* a patch toward the rim, away from the highlight: the diffuse part */
      gl_region(&g, cx + 7, cy - 1, cx + 8, cy + 1, side);
      edge[r][c] = gl_luminance(side);
    }
  for (int r = 0; r < ROWS; r++) {
    printf("metallic %.1f: peak", (double)metallic[r]);
    for (int c = 0; c < COLS; c++) printf(" %.3f", (double)peak[r][c]);
    printf("  rim");
    for (int c = 0; c < COLS; c++) printf(" %.3f", (double)edge[r][c]);
    printf("\n");
    for (int c = 0; c + 1 < COLS; c++) assert_true(peak[r][c] > peak[r][c + 1]);
  }
  /* dielectrics keep their diffuse colour at the rim; a full metal has none */
  assert_true(edge[0][COLS - 1] > 0.05f);
  assert_true(edge[ROWS - 1][COLS - 1] < edge[0][COLS - 1]);
  /* a metal's highlight is its base colour (F0 = base), a dielectric's is white */
  assert_true(peak_rgb[ROWS - 1][0][0] > 2 * peak_rgb[ROWS - 1][0][2]);
  gl_result_free(&g);

  static const char *const gi[] = {"isr", "ssdo", "ssao"};
  for (int i = 0; i < 3; i++) {
    g = gl_render(&(gl_run){.scene = s, .tech = gi[i], .sets = sets, .width = 64, .height = 48,
                            .check_finite = true});
    if (!g.ok) fail_msg("%s: %s", gi[i], g.err.msg);
    assert_true(gl_all_finite(&g));
    float all[3];
    gl_region(&g, 0, 0, 63, 47, all);
    assert_true(gl_luminance(all) > 0.01f);
    gl_result_free(&g);
  }

  /* alpha mask: a sphere under its cutoff is not drawn; emission lights a
   * sphere the sun does not (the sun off); a blended one is drawn by the
   * forward pass (tests/test_transparency.c), with either technique */
  s->lights[0].power = 0;
  s->material_pbr[0].alpha = 0.3f, s->material_pbr[0].alpha_mode = LM_ALPHA_MASK;
  s->material_pbr[0].alpha_cutoff = 0.5f;
  s->material_pbr[5].emissive[1] = 0.5f;
  g = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = GW, .height = GH});
  if (!g.ok) fail_msg("%s", g.err.msg);
  float pix[3];
  int sphere_px[2][2] = {{0, 0}, {1, 1}}; /* (row, column) of materials 0 and 5 */
  for (int k = 0; k < 2; k++) {
    float p[3] = {(float)sphere_px[k][1] - 1.5f, 1.0f - (float)sphere_px[k][0], 0}, clip[4];
    for (int i = 0; i < 4; i++)
      clip[i] = f.view_proj[i] * p[0] + f.view_proj[4 + i] * p[1] + f.view_proj[8 + i] * p[2] + f.view_proj[12 + i];
    int cx = (int)((clip[0] / clip[3] * 0.5f + 0.5f) * GW), cy = (int)((0.5f - clip[1] / clip[3] * 0.5f) * GH);
    gl_region(&g, cx - 1, cy - 1, cx + 1, cy + 1, pix);
    if (k == 0) assert_true(gl_luminance(pix) < 1e-4f); /* masked away: background */
    else assert_float_equal(pix[1], 0.5, 0.02), assert_true(pix[0] < 1e-3f); /* its emission alone */
  }
  gl_result_free(&g);
  s->material_pbr[3].alpha_mode = LM_ALPHA_BLEND;
  for (int k = 0; k < 2; k++) {
    g = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = k ? sets : NULL, .width = GW, .height = GH});
    if (!g.ok) fail_msg("%s", g.err.msg);
    assert_true(gl_has_pass(&g, "transparent"));
    gl_result_free(&g);
  }
  lm_scene_destroy(s);
}

/* glTF alphaMode MASK in both material techniques: a sphere whose alpha is
 * under its cutoff is no surface in the G-buffer and casts no shadow, so the
 * floor below it is lit as if it were not there; opaque, the same sphere
 * shadows the floor. */
static void alpha_masked_casters_cast_no_shadow(void **state) {
  (void)state;
  enum { W = 96, H = 72 };
  lm_scene *s = lm_scene_create("mask");
  int sphere = gl_uv_sphere(s, "sphere", 0.5f);
  static const float floor_v[4 * 8] = {-4, 0, -4, 0, 1, 0, 0, 0, 4, 0, -4, 0, 1, 0, 1, 0,
                                       4, 0, 4,  0, 1, 0, 1, 1, -4, 0, 4, 0, 1, 0, 0, 1};
  static const uint32_t floor_i[6] = {0, 2, 1, 0, 3, 2};
  int floor_mesh = lm_scene_add_mesh(s, "floor", floor_v, 4, floor_i, 6);
  lm_material white = {.name = "white", .color = {0.8f, 0.8f, 0.8f}, .rho = 0.8f, .ka = 1, .kd = 1, .shininess = 1};
  lm_material ball = white;
  snprintf(ball.name, sizeof ball.name, "ball");
  int m_white = lm_scene_add_material(s, &white), m_ball = lm_scene_add_material(s, &ball);
  float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  lm_scene_add_node(s, "floor", -1, m, floor_mesh, m_white);
  m[13] = 1.5f;
  lm_scene_add_node(s, "ball", -1, m, sphere, m_ball);
  /* the eye straight above, looking down; the sun at 45 degrees, its light
   * toward +x: the ball's shadow lies 1.5 to the right of it (16 pixels) */
  float down[16] = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 6, 0, 1};
  const float c = 0.70710678f;
  float slant[16] = {c, c, 0, 0, 0, 0, -1, 0, -c, c, 0, 0, 0, 0, 0, 1};
  int eye = lm_scene_add_node(s, "eye", -1, down, -1, -1), sun = lm_scene_add_node(s, "sun", -1, slant, -1, -1);
  lm_scene_add_camera(s, &(lm_camera){.name = "eye", .fov_y = 1.0f, .znear = 0.5f, .zfar = 20, .node = eye});
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                     .outer_cone = 1.5707964f, .casts_shadows = true, .node = sun});
  lm_scene_update(s);
  static const char *const materials[] = {"materials=phong", "materials=pbr"};
  for (int k = 0; k < 2; k++) {
    const char *sets[] = {materials[k], "ambient=0", NULL};
    float lit[2][3], ring[2][3];
    for (int masked = 0; masked < 2; masked++) {
      s->material_pbr[m_ball] = (lm_material_pbr){.set = true, .roughness = 1, .normal_scale = 1,
                                                  .occlusion_strength = 1, .alpha = masked ? 0.3f : 1.0f,
                                                  .alpha_mode = LM_ALPHA_MASK, .alpha_cutoff = 0.5f};
      gl_result g = gl_render(&(gl_run){.scene = s, .tech = "dl+esm", .sets = sets, .width = W, .height = H,
                                        .check_finite = true});
      if (!g.ok) fail_msg("%s: %s", materials[k], g.err.msg);
      gl_region(&g, W / 2 + 14, H / 2 - 2, W / 2 + 18, H / 2 + 2, lit[masked]);  /* the ball's shadow */
      gl_region(&g, W / 2 + 30, H / 2 - 2, W / 2 + 34, H / 2 + 2, ring[masked]); /* open floor */
      gl_result_free(&g);
    }
    printf("%s: where the ball's shadow falls %.4f opaque, %.4f masked; open floor %.4f\n", materials[k],
           (double)gl_luminance(lit[0]), (double)gl_luminance(lit[1]), (double)gl_luminance(ring[1]));
    assert_true(gl_luminance(ring[1]) > 0.1f);
    assert_true(gl_luminance(lit[0]) < 0.1f * gl_luminance(ring[1]));               /* opaque: its shadow */
    assert_float_equal(gl_luminance(lit[1]), gl_luminance(ring[1]), 0.02f * gl_luminance(ring[1])); /* masked: none */
  }
  lm_scene_destroy(s);
}

/* A file drawing `n` float3 vertices (`b64`, then `ni` u16 indices when ni >
 * 0) as primitive `mode`, seen by one camera. */
static lm_scene *topology_scene(const char *b64, int n, int ni, int mode) {
  char json[2048], path[512];
  size_t bytes = (size_t)n * 12 + (size_t)ni * 2, padded = (bytes + 3) & ~(size_t)3;
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[1.5,0.75,5]}],"
           "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1,\"zfar\":20}}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":%d%s}]}],"
           "\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\",\"byteLength\":%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
           "\"min\":[0,0,0],\"max\":[3,1.5,0]},{\"bufferView\":1,\"componentType\":5123,\"count\":%d,"
           "\"type\":\"SCALAR\"}]}",
           mode, ni ? ",\"indices\":1" : "", b64, padded, n * 12, n * 12, ni ? ni * 2 : 2, n, ni ? ni : 1);
  write_file("topology.gltf", json, path, sizeof path);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

/* A triangle strip, a fan and their indexed forms render the same image as
 * the triangle list of the same triangles (a square, and with a fifth
 * vertex three triangles). */
static void strips_and_fans_render_as_their_triangle_lists(void **state) {
  (void)state;
  static const struct { const char *b64; int n, ni, mode; } shapes[] = {
      /* the square as a list, a strip, an indexed strip (vertices stored in reverse) */
      {"AAAAAAAAAAAAAAAAAAAAQAAAAAAAAAAAAAAAAAAAwD8AAAAAAAAAQAAAAAAAAAAAAAAAQAAAwD8AAAAAAAAAAAAAwD8AAAAA", 6, 0, 4},
      {"AAAAAAAAAAAAAAAAAAAAQAAAAAAAAAAAAAAAAAAAwD8AAAAAAAAAQAAAwD8AAAAA", 4, 0, 5},
      {"AABAQAAAwD8AAAAAAAAAQAAAwD8AAAAAAAAAAAAAwD8AAAAAAAAAQAAAAAAAAAAAAAAAAAAAAAAAAAAABAADAAIAAQA=", 5, 4, 5},
      /* three triangles as a list, a fan, an indexed fan */
      {"AAAAAAAAAAAAAAAAAAAAQAAAAAAAAAAAAAAAAAAAwD8AAAAAAAAAQAAAAAAAAAAAAAAAQAAAwD8AAAAAAAAAAAAAwD8AAAAAAAAAQAAAAAAA"
       "AAAAAABAQAAAwD8AAAAAAAAAQAAAwD8AAAAA", 9, 0, 4},
      {"AAAAQAAAAAAAAAAAAABAQAAAwD8AAAAAAAAAQAAAwD8AAAAAAAAAAAAAwD8AAAAAAAAAAAAAAAAAAAAA", 5, 0, 6},
      {"AABAQAAAwD8AAAAAAAAAQAAAwD8AAAAAAAAAAAAAwD8AAAAAAAAAQAAAAAAAAAAAAAAAAAAAAAAAAAAAAwAAAAEAAgAEAAAA", 5, 5, 6},
  };
  const char *sets[] = {"ambient=0.1", NULL};
  gl_result ref = {0};
  lm_scene *ref_scene = NULL; /* kept while its renderer is */
  for (int i = 0; i < 6; i++) {
    lm_scene *s = topology_scene(shapes[i].b64, shapes[i].n, shapes[i].ni, shapes[i].mode);
    gl_result g = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = 64, .height = 48});
    if (!g.ok) fail_msg("shape %d: %s", i, g.err.msg);
    if (i % 3 == 0) { /* the list: what the other two must show */
      gl_result_free(&ref);
      lm_scene_destroy(ref_scene);
      ref = g, ref_scene = s;
      float all[3];
      gl_region(&ref, 0, 0, 63, 47, all);
      assert_true(gl_luminance(all) > 0.02f); /* something drawn */
    } else {
      double worst = 0;
      for (int k = 0; k < 64 * 48 * 3; k++) worst = fmax(worst, fabs((double)g.rgb[k] - ref.rgb[k]));
      printf("shape %d against its list: max difference %g\n", i, worst);
      assert_true(worst < 1e-6);
      gl_result_free(&g);
      lm_scene_destroy(s);
    }
  }
  gl_result_free(&ref);
  lm_scene_destroy(ref_scene);
}

/* Normal maps take the mesh's tangents (glTF TANGENT, B = N x T times w)
 * where it has them, else a frame from screen derivatives with T along +u:
 * a quad facing the camera (u along +x) whose map tilts the normal 37
 * degrees towards T (or B), lit at 45 degrees from +x (or +y). */
typedef struct quad_data {
  float pos[12], nrm[12], uv[8], tan[16];
  uint16_t idx[6];
} quad_data;

static const char *normal_map_quad(const char *name, const float *tangents, const char *tangent_type,
                                   const unsigned char texel[3]) {
  char dir[1024], png[1100], bin[1100], json[4096];
  snprintf(dir, sizeof dir, "%s", gl_root());
  snprintf(png, sizeof png, "%s/%s.png", dir, name);
  unsigned char image[4 * 4 * 3];
  for (int i = 0; i < 16; i++) memcpy(image + i * 3, texel, 3);
  lm_error err;
  if (!lm_image_write(png, 4, 4, 3, false, image, &err)) fail_msg("%s", err.msg);
  quad_data data = {{-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1},
            {0, 1, 1, 1, 1, 0, 0, 0}, {0}, {0, 1, 2, 0, 2, 3}};
  int ncomp = strcmp(tangent_type, "VEC4") ? 3 : 4;
  for (int v = 0; v < 4 && tangents; v++) memcpy(data.tan + v * ncomp, tangents, sizeof(float) * (size_t)ncomp);
  snprintf(bin, sizeof bin, "%s/%s.bin", dir, name);
  FILE *f = fopen(bin, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(&data, sizeof data, 1, f), 1);
  fclose(f);
  size_t at_tan = offsetof(quad_data, tan), at_idx = offsetof(quad_data, idx);
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,3]}],"
           "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1,\"zfar\":20}}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2%s},"
           "\"indices\":4,\"material\":0}]}],"
           "\"materials\":[{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":1},"
           "\"normalTexture\":{\"index\":0}}],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"%s.png\"}],"
           "\"buffers\":[{\"uri\":\"%s.bin\",\"byteLength\":%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},"
           "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":64},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":12}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
           "\"min\":[-1,-1,0],\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
           "{\"bufferView\":3,\"componentType\":5126,\"count\":4,\"type\":\"%s\"},"
           "{\"bufferView\":4,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}",
           tangents ? ",\"TANGENT\":3" : "", name, name, sizeof data, at_tan, at_idx, tangent_type);
  static char path[1200];
  write_file(name, json, path, sizeof path);
  return path;
}

static float lit_quad(const float *tangents, const unsigned char texel[3], const float light_dir[3]) {
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(normal_map_quad("nmap.gltf", tangents, "VEC4", texel), &err);
  if (!s) fail_msg("%s", err.msg);
  s->lights[0].power = 0; /* the loader's default light (the file has none) */
  mat4 m;
  glm_lookat((vec3){0, 0, 0}, (float *)light_dir, (vec3){0, 1, 0}, m);
  glm_mat4_inv(m, m); /* the node looks along -Z towards light_dir */
  lm_scene_add_light(s, &(lm_light){.name = "sun", .type = LM_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .power = 1,
                                    .node = lm_scene_add_node(s, "sun", -1, (float *)m, -1, -1)});
  lm_scene_update(s);
  const char *sets[] = {"materials=pbr", "ambient=0", NULL};
  gl_result g = gl_render(&(gl_run){.scene = s, .tech = "dl", .sets = sets, .width = 64, .height = 48});
  if (!g.ok) fail_msg("%s", g.err.msg);
  float rgb[3];
  gl_region(&g, 20, 14, 43, 33, rgb);
  gl_result_free(&g);
  lm_scene_destroy(s);
  return gl_luminance(rgb);
}

static void normal_maps_take_the_mesh_tangents(void **state) {
  (void)state;
  const unsigned char towards_t[3] = {204, 128, 230}, towards_b[3] = {128, 204, 230}; /* (0.6, 0, 0.8), (0, 0.6, 0.8) */
  const float from_x[3] = {-1, 0, -1}, from_y[3] = {0, -1, -1}; /* where the light shines */
  const float along_x[4] = {1, 0, 0, 1}, along_y[4] = {0, 1, 0, 1}, mirrored[4] = {1, 0, 0, -1};
  float derived = lit_quad(NULL, towards_t, from_x), given_x = lit_quad(along_x, towards_t, from_x);
  float given_y = lit_quad(along_y, towards_t, from_x);
  float b_up = lit_quad(along_x, towards_b, from_y), b_down = lit_quad(mirrored, towards_b, from_y);
  printf("tilted towards T, light from +x: derived frame %.4f, T = +x %.4f, T = +y %.4f\n", derived, given_x, given_y);
  printf("tilted towards B, light from +y: w = 1 %.4f, w = -1 %.4f\n", b_up, b_down);
  /* n.l: 0.99 tilted towards the light, 0.57 across it, 0.14 away from it. */
  assert_true(fabsf(given_x - derived) < 0.02f * derived);
  assert_true(given_y < 0.7f * given_x && given_y > 0.45f * given_x);
  assert_true(b_down < 0.25f * b_up);
  lm_error err;
  assert_null(lm_scene_load_gltf(normal_map_quad("nmap3.gltf", along_x, "VEC3", towards_t), &err));
  if (!strstr(err.msg, "TANGENT")) fail_msg("%s", err.msg);
}

static int setup(void **state) {
  int rc = gl_test_setup(state);
  lm_log_set_level(LM_LOG_ERROR); /* the bad-texture cases warn by design */
  return rc;
}

int main(void) {
  snprintf(pp_lua, sizeof pp_lua, "%s/scripts/pp.lua", LIMN_SOURCE_ROOT);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(textures_show_as_detail),
      cmocka_unit_test(normal_maps_take_the_mesh_tangents),
      cmocka_unit_test(culling_drops_what_the_camera_cannot_see),
      cmocka_unit_test(scripts_override_materials_by_name),
      cmocka_unit_test(materials_reload_without_a_restart),
      cmocka_unit_test(bad_textures_name_material_texture_and_image),
      cmocka_unit_test(pbr_sphere_grid_is_finite_and_monotonic),
      cmocka_unit_test(alpha_masked_casters_cast_no_shadow),
      cmocka_unit_test(strips_and_fans_render_as_their_triangle_lists),
      cmocka_unit_test(mutated_scene_files_never_crash),
  };
  return cmocka_run_group_tests(tests, setup, gl_test_teardown);
}
