/* Materials on whatever EGL offers: base-colour textures (decoded, sRGB,
 * sampled), per-pass parameter overrides from scripts, reloading, frustum
 * culling, and the messages a bad texture or override gives. */
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
#include <unistd.h>

#include "gl_test.h"
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
  assert_true(over->stats.triangles >= 200000);
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
      "  local G = { clr = target{ 'c', format = 'rgba8' }, nrm = target{ 'n', format = 'rgba16f' },\n"
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
       "material 0: texture 0: image 0"},
      {"[{\"source\":0}]", "[{\"uri\":\"missing.png\"}]", "material 0: texture 0: image 0 ('missing.png'): no image data"},
      {"[{\"source\":3}]", "[{\"uri\":\"missing.png\"}]", "material 0: texture 0: image 3 does not exist"},
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

static int setup(void **state) {
  int rc = gl_test_setup(state);
  lm_log_set_level(LM_LOG_ERROR); /* the bad-texture cases warn by design */
  return rc;
}

int main(void) {
  snprintf(pp_lua, sizeof pp_lua, "%s/scripts/pp.lua", LIMN_SOURCE_ROOT);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(textures_show_as_detail),
      cmocka_unit_test(culling_drops_what_the_camera_cannot_see),
      cmocka_unit_test(scripts_override_materials_by_name),
      cmocka_unit_test(materials_reload_without_a_restart),
      cmocka_unit_test(bad_textures_name_material_texture_and_image),
      cmocka_unit_test(mutated_scene_files_never_crash),
  };
  return cmocka_run_group_tests(tests, setup, gl_test_teardown);
}
