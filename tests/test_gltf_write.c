/* lm_scene_write_gltf (engine/scene/gltf_write.cpp): a scene written and read
 * back is the scene written, as far as glTF holds it: every built-in scene,
 * a glTF file's metallic-roughness materials and lights, and an animated
 * scene posed at a time. Where glTF cannot hold Limn's values (a Phong
 * material no metallic-roughness one reads back as, a window falloff) a
 * warning names the material or light, and only those differ. No GL.
 * Each test stands alone (it makes and frees its own), so tests read alike. */
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

#include "scene/gltf.h"

static void close_to(float a, float b, float tol, const char *what) {
  if (!(fabsf(a - b) <= tol * fmaxf(1.0f, fabsf(b)))) fail_msg("%s: %g, want %g", what, a, b);
}

/* Writes s to a temporary .glb (its warnings into w) and reads it back. */
static lm_scene *round_trip(const lm_scene *s, const char *ext, lm_buf *w) {
  char path[64];
  snprintf(path, sizeof path, "/tmp/limn-gltf-write-%ld%s", (long)getpid(), ext);
  lm_error err;
  if (!lm_scene_write_gltf(s, path, w, &err)) fail_msg("write: %s", err.msg);
  lm_scene *back = lm_scene_load_gltf(path, &err);
  if (!back) fail_msg("read back: %s", err.msg);
  remove(path);
  return back;
}

/* The world matrix of the mesh node of `s` named `name`. */
static const float *world_of(const lm_scene *s, const char *name) {
  int n = lm_scene_find_node(s, name);
  if (n < 0) fail_msg("node '%s' is not there", name);
  return s->nodes[n].world;
}

/* Geometry, lights, cameras and the materials that did not warn come back. */
static void same_scene(const lm_scene *a, const lm_scene *b, const char *warnings) {
  float lo[2][3], hi[2][3];
  lm_scene_bounds(a, lo[0], hi[0]);
  lm_scene_bounds(b, lo[1], hi[1]);
  for (int k = 0; k < 3; k++) close_to(lo[1][k], lo[0][k], 1e-5f, "bounds"), close_to(hi[1][k], hi[0][k], 1e-5f, "bounds");
  for (int i = 0; i < a->node_count; i++) {
    if (a->nodes[i].mesh < 0) continue;
    const float *wb = world_of(b, a->nodes[i].name);
    for (int k = 0; k < 16; k++) close_to(wb[k], a->nodes[i].world[k], 1e-5f, a->nodes[i].name);
    const lm_scene_mesh *ma = &a->meshes[a->nodes[i].mesh], *mb = &b->meshes[b->nodes[lm_scene_find_node(b, a->nodes[i].name)].mesh];
    assert_int_equal(ma->vertex_count, mb->vertex_count);
    assert_int_equal(ma->index_count, mb->index_count);
    for (int v = 0; v < ma->vertex_count * 8; v++) close_to(mb->vertices[v], ma->vertices[v], 1e-6f, "vertex");
  }
  assert_int_equal(a->light_count, b->light_count);
  for (int i = 0; i < a->light_count; i++) {
    const lm_light *la = &a->lights[i], *lb = &b->lights[i];
    assert_string_equal(la->name, lb->name);
    assert_int_equal(la->type, lb->type);
    close_to(lb->power, la->power, 1e-5f, la->name);
    for (int c = 0; c < 3; c++) close_to(lb->color[c], la->color[c], 1e-6f, la->name);
    if (la->type == LM_LIGHT_SPOT) close_to(lb->outer_cone, la->outer_cone, 1e-6f, la->name);
    if (la->falloff == LM_FALLOFF_RANGE) close_to(lb->radius, la->radius, 1e-6f, la->name);
    else if (la->type != LM_LIGHT_DIRECTIONAL && la->falloff != LM_FALLOFF_INVERSE_SQUARE && !strstr(warnings, la->name))
      fail_msg("light '%s': its falloff changed without a warning", la->name);
    const float *wa = a->nodes[la->node].world, *wb = b->nodes[lb->node].world;
    for (int k = 0; k < 16; k++) close_to(wb[k], wa[k], 1e-5f, la->name);
  }
  assert_true(b->camera_count >= a->camera_count);
  for (int i = 0; i < a->camera_count; i++) {
    close_to(b->cameras[i].fov_y, a->cameras[i].fov_y, 1e-6f, a->cameras[i].name);
    close_to(b->cameras[i].znear, a->cameras[i].znear, 1e-6f, a->cameras[i].name);
    const float *wa = a->nodes[a->cameras[i].node].world, *wb = b->nodes[b->cameras[i].node].world;
    for (int k = 0; k < 16; k++) close_to(wb[k], wa[k], 1e-5f, a->cameras[i].name);
  }
  /* Materials by name: the loader reads those a mesh uses, in the order of first use. */
  for (int i = 0; i < a->material_count; i++) {
    bool used = false;
    for (int n = 0; n < a->node_count; n++) used |= a->nodes[n].mesh >= 0 && a->nodes[n].material == i;
    int k = lm_scene_find_material(b, a->materials[i].name);
    if (!used) continue;
    if (k < 0) fail_msg("material '%s' did not come back", a->materials[i].name);
    const lm_material *ma = &a->materials[i], *mb = &b->materials[k];
    for (int c = 0; c < 3; c++) close_to(mb->color[c], ma->color[c], 1e-6f, ma->name);
    close_to(mb->reflectivity, ma->reflectivity, 1e-6f, ma->name);
    char quoted[LM_NAME_MAX + 16];
    snprintf(quoted, sizeof quoted, "material '%s'", ma->name);
    if (strstr(warnings, quoted)) continue; /* said to differ */
    close_to(mb->kd, ma->kd, 1e-3f, ma->name);
    close_to(mb->ks, ma->ks, 1e-3f, ma->name);
    close_to(mb->rho, ma->rho, 1e-3f, ma->name);
    close_to(mb->shininess, ma->shininess, 1e-3f, ma->name);
  }
}

static void builtin_scenes_come_back(void **state) {
  (void)state;
  static const char *const names[] = {"cornell", "cornell_pov", "cornell_mirror", "field"};
  for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
    lm_error err;
    lm_scene *s = lm_scene_builtin(names[i], &err);
    assert_non_null(s);
    lm_buf w = {0};
    lm_scene *back = round_trip(s, i % 2 ? ".gltf" : ".glb", &w);
    printf("%s: %s", names[i], w.data ? w.data : "no warnings\n");
    same_scene(s, back, w.data ? w.data : "");
    lm_buf_free(&w);
    lm_scene_destroy(back);
    lm_scene_destroy(s);
  }
}

/* A glTF file's own metallic-roughness values and light units pass unchanged, without a warning. */
static void gltf_materials_and_lights_pass_unchanged(void **state) {
  (void)state;
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(LIMN_TEST_DIR "/../data/scenes/pov_ball.gltf", &err);
  if (!s) fail_msg("%s", err.msg);
  lm_buf w = {0};
  lm_scene *back = round_trip(s, ".glb", &w);
  if (w.data && strstr(w.data, "material '")) fail_msg("a glTF material warned: %s", w.data);
  same_scene(s, back, "");
  for (int i = 0; i < s->material_count; i++) {
    lm_material_pbr pa = lm_scene_material_pbr(s, i, &s->materials[i]);
    lm_material_pbr pb = lm_scene_material_pbr(back, i, &back->materials[i]);
    assert_true(pb.set);
    close_to(pb.metallic, pa.metallic, 1e-6f, "metallic");
    close_to(pb.roughness, pa.roughness, 1e-6f, "roughness");
  }
  lm_buf_free(&w);
  lm_scene_destroy(back);
  lm_scene_destroy(s);
}

/* An animated scene posed at a time is written as posed: read back (no animation), its rest pose is that pose. */
static void a_posed_scene_is_written_posed(void **state) {
  (void)state;
  static const char *const files[] = {"door.glb", "bending_tube.glb"};
  for (size_t f = 0; f < sizeof files / sizeof *files; f++) {
    char path[1024];
    snprintf(path, sizeof path, LIMN_TEST_DIR "/../data/scenes/%s", files[f]);
    lm_error err;
    lm_scene *s = lm_scene_load_gltf(path, &err);
    if (!s) fail_msg("%s", err.msg);
    assert_true(lm_scene_animated(s));
    float start, end;
    lm_scene_animation_range(s, LM_ANIM_ALL, &start, &end);
    lm_scene_set_time(s, LM_ANIM_ALL, 0.5 * (start + end));
    lm_buf w = {0};
    lm_scene *back = round_trip(s, ".glb", &w);
    assert_non_null(strstr(w.data, "not written: the scene as posed"));
    assert_false(lm_scene_animated(back));
    same_scene(s, back, w.data);
    lm_buf_free(&w);
    lm_scene_destroy(back);
    lm_scene_destroy(s);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(builtin_scenes_come_back),
      cmocka_unit_test(gltf_materials_and_lights_pass_unchanged),
      cmocka_unit_test(a_posed_scene_is_written_posed),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
