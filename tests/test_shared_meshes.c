/* Identical meshes shared at load: two nodes whose glTF meshes decode to the
 * same bytes load as one mesh, drawn as instances of it, and render the image
 * of the file whose two nodes name one mesh; meshes a vertex apart, and
 * deforming meshes, stay apart. Files written by the test (gltf_test.h). */
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
#include "gltf_test.h"
#include "scene/gltf.h"

/* An octahedron of radius 1: 6 vertices, 8 triangles (normals computed by the loader). */
static const float octa[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
static const uint16_t octa_idx[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};

typedef enum { TWO_MESHES, ONE_MESH, MORPHED, SKINNED, COLOURED } layout;

/* Nodes "left" (x = -1.5) and "right" (x = 1.5). TWO_MESHES: each its own
 * mesh ("first", "second"), each with its own accessors; the second's
 * vertex 0 moved by `nudge` in x. ONE_MESH: both name mesh "first". MORPHED:
 * as TWO_MESHES, each mesh with one morph target (no motion, weights 0);
 * SKINNED, each bound to joint "bone" (weight 1, at rest); COLOURED, the
 * first red, the second blue. */
static const char *write_pair(const char *name, layout how, float nudge) {
  float second[18];
  memcpy(second, octa, sizeof second);
  second[0] += nudge;
  static const float still[18] = {0};
  static const uint16_t joints[24] = {0};
  float weights1[24] = {0};
  for (int v = 0; v < 6; v++) weights1[v * 4] = 1;
  static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  blob b = {0};
  size_t p0 = blob_add(&b, octa, sizeof octa), i0 = blob_add(&b, octa_idx, sizeof octa_idx);
  size_t p1 = blob_add(&b, second, sizeof second), i1 = blob_add(&b, octa_idx, sizeof octa_idx);
  size_t t = blob_add(&b, still, sizeof still), j = blob_add(&b, joints, sizeof joints);
  size_t w = blob_add(&b, weights1, sizeof weights1), ib = blob_add(&b, identity, sizeof identity);
  const char *targets = how == MORPHED ? ",\"targets\":[{\"POSITION\":4}]" : "";
  const char *weights = how == MORPHED ? ",\"weights\":[0]" : "";
  const char *bound = how == SKINNED ? ",\"JOINTS_0\":5,\"WEIGHTS_0\":6" : "";
  const char *skin = how == SKINNED ? ",\"skin\":0" : "";
  const char *red = how == COLOURED ? ",\"material\":0" : "", *blue = how == COLOURED ? ",\"material\":1" : "";
  char json[4096];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
           "\"nodes\":[{\"name\":\"left\",\"mesh\":0,\"translation\":[-1.5,0,0]%s},"
           "{\"name\":\"right\",\"mesh\":%d,\"translation\":[1.5,0,0]%s},{\"name\":\"bone\"}],"
           "\"skins\":[{\"joints\":[2],\"inverseBindMatrices\":7}],\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1]}},"
           "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,1,1]}}],"
           "\"meshes\":[{\"name\":\"first\",\"primitives\":[{\"attributes\":{\"POSITION\":0%s},\"indices\":1%s%s}]%s},"
           "{\"name\":\"second\",\"primitives\":[{\"attributes\":{\"POSITION\":2%s},\"indices\":3%s%s}]%s}],"
           "\"buffers\":[{\"uri\":\"%%s\",\"byteLength\":%%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":72},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":72},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":72},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":96},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":64}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\","
           "\"min\":[-1,-1,-1],\"max\":[1,1,1]},{\"bufferView\":1,\"componentType\":5123,\"count\":24,\"type\":\"SCALAR\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},"
           "{\"bufferView\":3,\"componentType\":5123,\"count\":24,\"type\":\"SCALAR\"},"
           "{\"bufferView\":4,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"},"
           "{\"bufferView\":5,\"componentType\":5123,\"count\":6,\"type\":\"VEC4\"},"
           "{\"bufferView\":6,\"componentType\":5126,\"count\":6,\"type\":\"VEC4\"},"
           "{\"bufferView\":7,\"componentType\":5126,\"count\":1,\"type\":\"MAT4\"}]}",
           skin, how == ONE_MESH ? 0 : 1, skin, bound, red, targets, weights, bound, blue, targets, weights, p0, i0, p1,
           i1, t, j, w, ib);
  return write_gltf(name, json, &b);
}

static lm_scene *load(const char *path, bool gpu) {
  lm_error err = {""};
  lm_scene *s = gpu ? lm_scene_load_gpu(path, &err) : lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

/* Both loaders (the GPU-only one compares a match with the primitive decoded
 * again: the first mesh's arrays are gone once it is uploaded). */
static void identical_meshes_load_as_one(void **state) {
  (void)state;
  const char *path = write_pair("two.gltf", TWO_MESHES, 0);
  for (int gpu = 0; gpu < 2; gpu++) {
    lm_scene *s = load(path, gpu);
    assert_int_equal(s->mesh_count, 1);
    assert_string_equal(s->meshes[0].name, "first"); /* the first mesh's name is kept */
    assert_int_equal(s->nodes[0].mesh, 0);
    assert_int_equal(s->nodes[1].mesh, 0);
    assert_float_equal(s->nodes[1].world[12], 1.5, 1e-6); /* each node keeps its own place */
    lm_scene_destroy(s);
  }
}

/* The deduplicated file renders the image of the file with one mesh named by
 * both nodes (dl+esm, 64x48): the largest difference of the linear RGB is 0. */
static void shared_meshes_render_as_one_mesh(void **state) {
  (void)state;
  lm_scene *two = load(write_pair("two.gltf", TWO_MESHES, 0), false);
  lm_scene *one = load(write_pair("one.gltf", ONE_MESH, 0), false);
  gl_result want = gl_render_ok(&(gl_run){.scene = one, .tech = "dl+esm", .width = 64, .height = 48});
  gl_result got = gl_render_ok(&(gl_run){.scene = two, .tech = "dl+esm", .width = 64, .height = 48});
  int n = want.width * want.height * 3;
  double mean = 0, worst = 0;
  for (int k = 0; k < n; k++) mean += want.rgb[k], worst = fmax(worst, fabs(want.rgb[k] - got.rgb[k]));
  mean /= n;
  print_message("mean %.4f, largest difference %g\n", mean, worst);
  assert_true(mean > 0.01); /* the octahedra are lit and in view */
  assert_true(worst == 0);
  gl_result_free(&want), gl_result_free(&got);
  lm_scene_destroy(two), lm_scene_destroy(one);
}

/* One vertex a float's step apart: two meshes, each with its own name. */
static void meshes_a_vertex_apart_stay_two(void **state) {
  (void)state;
  const char *path = write_pair("apart.gltf", TWO_MESHES, nextafterf(1, 2) - 1);
  for (int gpu = 0; gpu < 2; gpu++) {
    lm_scene *s = load(path, gpu);
    assert_int_equal(s->mesh_count, 2);
    assert_string_equal(s->meshes[s->nodes[0].mesh].name, "first");
    assert_string_equal(s->meshes[s->nodes[1].mesh].name, "second");
    lm_scene_destroy(s);
  }
}

/* Morphed and skinned meshes (each node's own pose) are never shared, identical or not. */
static void deforming_meshes_are_never_shared(void **state) {
  (void)state;
  lm_scene *s = load(write_pair("morphed.gltf", MORPHED, 0), false);
  assert_int_equal(s->mesh_count, 2);
  assert_int_not_equal(s->nodes[0].mesh, s->nodes[1].mesh);
  assert_int_equal(s->meshes[s->nodes[1].mesh].target_count, 1);
  lm_scene_destroy(s);
  s = load(write_pair("skinned.gltf", SKINNED, 0), false);
  assert_int_equal(s->mesh_count, 2);
  assert_int_not_equal(s->nodes[0].mesh, s->nodes[1].mesh);
  assert_int_equal(s->meshes[s->nodes[1].mesh].influence_sets, 1);
  lm_scene_destroy(s);
}

/* Identical geometry under two materials: one mesh, each node its own material. */
static void shared_meshes_keep_each_nodes_material(void **state) {
  (void)state;
  lm_scene *s = load(write_pair("coloured.gltf", COLOURED, 0), false);
  assert_int_equal(s->mesh_count, 1);
  const float *left = s->materials[s->nodes[0].material].color, *right = s->materials[s->nodes[1].material].color;
  assert_true(left[0] > 0.9f && left[2] < 0.1f);
  assert_true(right[2] > 0.9f && right[0] < 0.1f);
  lm_scene_destroy(s);
}

static int setup(void **state) { return gltf_test_setup(state) ? -1 : gl_test_setup(state); }
static int teardown(void **state) { return gl_test_teardown(state) | gltf_test_teardown(state); }

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(identical_meshes_load_as_one),
      cmocka_unit_test(shared_meshes_render_as_one_mesh),
      cmocka_unit_test(meshes_a_vertex_apart_stay_two),
      cmocka_unit_test(deforming_meshes_are_never_shared),
      cmocka_unit_test(shared_meshes_keep_each_nodes_material),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
