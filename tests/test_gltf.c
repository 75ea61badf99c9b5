/* glTF loading: small files written by the test itself (JSON with base64
 * data URIs, and GLB; each test's document whole in it, so they read alike), what they load into, the malformed ones each refused
 * with a message naming the file and the element, and a mutation loop that
 * must never crash. No GL needed. */
#define _DEFAULT_SOURCE /* mkdtemp */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_test.h"
#include "scene/gltf.h"

/* ---- the files ---------------------------------------------------------- */

static const float tri_pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

/* One triangle; indices of component type `ctype` (0: not indexed). */
static const char *write_triangle(const char *name, int ctype) {
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  size_t isize = ctype == 5121 ? 1 : ctype == 5123 ? 2 : 4, ioff = 0;
  unsigned char idx[12] = {0};
  for (int i = 0; i < 3; i++) {
    uint32_t v = (uint32_t)i;
    memcpy(idx + i * isize, &v, isize); /* little-endian */
  }
  if (ctype) ioff = blob_add(&b, idx, 3 * isize);
  char json[2048];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
           "\"nodes\":[{\"name\":\"tri\",\"mesh\":0}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}%s,\"material\":0}]}],"
           "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,1],"
           "\"metallicFactor\":0,\"roughnessFactor\":0.5}}],"
         "\"buffers\":[{\"uri\":\"%%s\",\"byteLength\":%%zu}],"
         "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}"
           ",{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}"
           ",{\"bufferView\":1,\"componentType\":%d,\"count\":3,\"type\":\"SCALAR\"}]}",
           ctype ? ",\"indices\":1" : "", ioff, 3 * isize, ctype ? ctype : 5125);
  return write_gltf(name, json, &b);
}

static void assert_triangle(const lm_scene *s) {
  assert_int_equal(s->mesh_count, 1);
  const lm_scene_mesh *m = &s->meshes[0];
  assert_int_equal(m->vertex_count, 3);
  assert_int_equal(m->index_count, 3);
  for (int i = 0; i < 3; i++) {
    assert_int_equal(m->indices[i], i);
    const float *v = m->vertices + i * 8;
    for (int k = 0; k < 3; k++) assert_float_equal(v[k], tri_pos[i * 3 + k], 0);
    assert_float_equal(v[3], 0, 1e-6), assert_float_equal(v[4], 0, 1e-6);
    assert_float_equal(v[5], 1, 1e-6); /* computed: counter-clockwise in XY faces +Z */
    assert_float_equal(v[6], 0, 0), assert_float_equal(v[7], 0, 0);
  }
  assert_string_equal(s->nodes[0].name, "tri");
  assert_int_equal(s->nodes[0].mesh, 0);
  assert_int_equal(s->material_count, 1);
  assert_int_equal(s->nodes[0].material, 0);
  const lm_material *mat = &s->materials[0];
  assert_float_equal(mat->color[0], 0.5, 1e-6);
  assert_float_equal(mat->color[1], 0.25, 1e-6);
  assert_float_equal(mat->color[2], 1.0, 1e-6);
  assert_float_equal(mat->kd, 1.0, 1e-6);        /* not metallic */
  assert_float_equal(mat->ka, 1.0, 1e-6);        /* ambient as the diffuse part */
  assert_float_equal(mat->ks, 0.04, 1e-6);       /* dielectric F0 */
  assert_float_equal(mat->shininess, 30.0, 1e-3); /* 2 / 0.5^4 - 2 */
  assert_float_equal(mat->rho, 1.0, 1e-6);
}

/* The default camera looks at the bounds' centre; the default light shines down. */
static void assert_defaults(const lm_scene *s, const float centre[3]) {
  assert_int_equal(s->light_count, 1);
  assert_string_equal(s->lights[0].name, "default_light");
  assert_int_equal(s->lights[0].type, LM_LIGHT_DIRECTIONAL);
  const float *lw = s->nodes[s->lights[0].node].world;
  assert_true(-lw[9] < -0.5f); /* -Z points down */
  assert_int_equal(s->camera_count, 1);
  assert_string_equal(s->cameras[0].name, "default_camera");
  const float *w = s->nodes[s->cameras[0].node].world;
  float to[3], len = 0, dot = 0;
  for (int k = 0; k < 3; k++) to[k] = centre[k] - w[12 + k], len += to[k] * to[k];
  len = sqrtf(len);
  for (int k = 0; k < 3; k++) dot += -w[8 + k] * to[k] / len;
  assert_float_equal(dot, 1.0, 1e-4);
  assert_true(s->cameras[0].znear > 0 && s->cameras[0].znear < len);
  assert_true(s->cameras[0].zfar > len);
}

static void triangle_loads_with_every_index_type(void **state) {
  (void)state;
  static const int types[] = {5121, 5123, 5125, 0};
  for (int i = 0; i < 4; i++) {
    char name[32];
    snprintf(name, sizeof name, "tri%d.gltf", types[i]);
    lm_error err = {""};
    lm_scene *s = lm_scene_load_gltf(write_triangle(name, types[i]), &err);
    if (!s) fail_msg("%s", err.msg);
    assert_triangle(s);
    assert_defaults(s, (float[3]){0.5f, 0.5f, 0});
    lm_scene_destroy(s);
  }
}

/* Vertices `pos` (n of them, xyz) drawn as `mode`, through u16 `idx` when ni > 0. */
static const char *write_topology(const char *name, const float *pos, int n, const uint16_t *idx, int ni,
                                  int mode) {
  blob b = {0};
  blob_add(&b, pos, sizeof(float) * 3 * (size_t)n);
  size_t ioff = ni ? blob_add(&b, idx, sizeof(uint16_t) * (size_t)ni) : 0;
  char json[2048];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":%d%s}]}],"
           "\"buffers\":[{\"uri\":\"%%s\",\"byteLength\":%%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%d}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},"
           "{\"bufferView\":1,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}]}",
           mode, ni ? ",\"indices\":1" : "", 12 * n, ioff, ni ? 2 * ni : 2, n, ni ? ni : 1);
  return write_gltf(name, json, &b);
}

/* The scene's triangles as 9 floats each, each rotated to start at its
 * smallest vertex (winding kept) and the list sorted: equal lists draw the
 * same image. */
static int compare_tri(const void *a, const void *b) {
  return memcmp(a, b, 9 * sizeof(float)) ? (memcmp(a, b, 9 * sizeof(float)) < 0 ? -1 : 1) : 0;
}
static int vertex_less(const float *a, const float *b) {
  for (int k = 0; k < 3; k++)
    if (a[k] != b[k]) return a[k] < b[k];
  return 0;
}
static int scene_triangles(const lm_scene *s, float *out, int cap) {
  assert_int_equal(s->mesh_count, 1);
  const lm_scene_mesh *m = &s->meshes[0];
  int n = m->index_count / 3;
  assert_true(n <= cap);
  for (int t = 0; t < n; t++) {
    const float *v[3];
    for (int j = 0; j < 3; j++) v[j] = m->vertices + m->indices[t * 3 + j] * 8;
    int first = vertex_less(v[1], v[0]) ? 1 : 0;
    if (vertex_less(v[2], v[first])) first = 2;
    for (int j = 0; j < 3; j++) memcpy(out + t * 9 + j * 3, v[(first + j) % 3], 3 * sizeof(float));
    for (int j = 0; j < 3; j++) /* planar: every normal +Z, as in the list */
      assert_float_equal(v[j][5], 1, 1e-6);
  }
  qsort(out, (size_t)n, 9 * sizeof(float), compare_tri);
  return n;
}

/* A strip, a fan and their indexed forms load as the same triangles, wound
 * the same way, as the triangle list of that shape; points and lines are
 * skipped (one warning for the file). */
static void strips_and_fans_become_triangles(void **state) {
  (void)state;
  /* a unit square's corners and a fifth point: 3 counter-clockwise triangles */
  static const float v[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
  static const int list[] = {0, 1, 2, 1, 3, 2, 1, 4, 3};
  static const int strip[] = {0, 1, 2, 3}, fan[] = {1, 4, 3, 2, 0};
  float pos[16][3];
  uint16_t idx[16];
  for (int i = 0; i < 9; i++) memcpy(pos[i], v[list[i]], sizeof pos[i]);
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_topology("list.gltf", &pos[0][0], 9, NULL, 0, 4), &err);
  if (!s) fail_msg("%s", err.msg);
  float want[8 * 9], got[8 * 9];
  int n = scene_triangles(s, want, 8);
  assert_int_equal(n, 3);
  lm_scene_destroy(s);
  /* the strip covers the square (2 triangles), the fan all 3 (it pivots on vertex 1) */
  struct { const char *name; const int *order; int count, mode, tris; } shapes[] = {
      {"strip", strip, 4, 5, 2}, {"fan", fan, 5, 6, 3}};
  for (int k = 0; k < 2; k++) {
    for (int indexed = 0; indexed < 2; indexed++) {
      char name[32];
      snprintf(name, sizeof name, "%s%d.gltf", shapes[k].name, indexed);
      const char *path;
      if (!indexed) {
        for (int i = 0; i < shapes[k].count; i++) memcpy(pos[i], v[shapes[k].order[i]], sizeof pos[i]);
        path = write_topology(name, &pos[0][0], shapes[k].count, NULL, 0, shapes[k].mode);
      } else { /* the vertices stored in reverse, reached through indices */
        for (int i = 0; i < 5; i++) memcpy(pos[i], v[4 - i], sizeof pos[i]);
        for (int i = 0; i < shapes[k].count; i++) idx[i] = (uint16_t)(4 - shapes[k].order[i]);
        path = write_topology(name, &pos[0][0], 5, idx, shapes[k].count, shapes[k].mode);
      }
      s = lm_scene_load_gltf(path, &err);
      if (!s) fail_msg("%s: %s", name, err.msg);
      assert_int_equal(scene_triangles(s, got, 8), shapes[k].tris);
      lm_scene_destroy(s);
      if (shapes[k].tris == 3) {
        assert_memory_equal(got, want, sizeof(float) * 27);
      } else { /* the list's first two triangles */
        float part[2 * 9];
        for (int i = 0; i < 6; i++) memcpy(pos[i], v[list[i]], sizeof pos[i]);
        s = lm_scene_load_gltf(write_topology("half.gltf", &pos[0][0], 6, NULL, 0, 4), &err);
        assert_non_null(s);
        scene_triangles(s, part, 2);
        lm_scene_destroy(s);
        assert_memory_equal(got, part, sizeof part);
      }
    }
  }
  /* lines and points: nothing to draw, no error */
  for (int mode = 0; mode <= 3; mode++) {
    s = lm_scene_load_gltf(write_topology("lines.gltf", &v[0][0], 4, NULL, 0, mode), &err);
    if (!s) fail_msg("%s", err.msg);
    assert_int_equal(s->mesh_count, 0);
    lm_scene_destroy(s);
  }
  /* a strip too short, and a mode glTF does not have */
  assert_null(lm_scene_load_gltf(write_topology("short.gltf", &v[0][0], 2, NULL, 0, 5), &err));
  assert_non_null(strstr(err.msg, "mesh 0 primitive 0: a triangle strip of 2 vertices, fewer than 3"));
  assert_null(lm_scene_load_gltf(write_topology("mode7.gltf", &v[0][0], 3, NULL, 0, 7), &err));
  assert_non_null(strstr(err.msg, "mesh 0 primitive 0: mode 7 is not a glTF primitive mode"));
}

/* A required extension the engine lacks is named, in .gltf and .glb alike,
 * before any of the data it governs is read (here: an accessor with no
 * bufferView, as a compression extension would leave them). (pbr_materials_come_over requires a
 * supported one.) */
static void unsupported_required_extension_is_named(void **state) {
  (void)state;
  static const char json[] =
      "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\",\"%s\"],"
      "\"extensionsRequired\":[\"KHR_lights_punctual\",\"%s\"],\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
      "\"accessors\":[{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
      "{\"bufferView\":7,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}";
  char text[2048];
  snprintf(text, sizeof text, json, "EXT_mesh_features", "EXT_mesh_features");
  lm_error err = {""};
  assert_null(lm_scene_load_gltf(write_bytes("features.gltf", text, strlen(text)), &err));
  assert_non_null(strstr(err.msg, "features.gltf: extensionsRequired names 'EXT_mesh_features', which "));
  blob b = {0};
  unsigned char glb[4096];
  size_t n = make_glb(text, &b, glb, sizeof glb);
  assert_null(lm_scene_load_gltf(write_bytes("features.glb", glb, n), &err));
  assert_non_null(strstr(err.msg, "features.glb: extensionsRequired names 'EXT_mesh_features'"));
}

/* Every corner of the scene's bounds, seen through camera `cam` at w x h,
 * lies inside the view; returns the largest |NDC| (how tight the framing is). */
static float corners_in_view(const lm_scene *s, int cam, int w, int h) {
  float lo[3], hi[3], most = 0;
  lm_scene_bounds(s, lo, hi);
  lm_frame_data f;
  lm_scene_frame_data(s, cam, w, h, &f);
  for (int k = 0; k < 8; k++) {
    float p[3] = {(k & 1 ? hi : lo)[0], (k & 2 ? hi : lo)[1], (k & 4 ? hi : lo)[2]}, clip[4];
    for (int r = 0; r < 4; r++)
      clip[r] = f.view_proj[r] * p[0] + f.view_proj[4 + r] * p[1] + f.view_proj[8 + r] * p[2] + f.view_proj[12 + r];
    assert_true(clip[3] > 0);
    for (int r = 0; r < 3; r++) {
      float ndc = clip[r] / clip[3];
      assert_true(ndc >= -1 && ndc <= 1);
      if (r < 2) most = fmaxf(most, fabsf(ndc));
    }
  }
  return most;
}

/* A file without a camera gets one framing its bounds (a long, flat part off
 * the origin, as an engine block might be): every corner in view on wide
 * outputs, and tightly (the longest side fills most of the frame). An
 * "auto" camera fits a given output, a tall one too. A glTF orthographic
 * camera keeps its index and is refused by name where it would be used. */
static void cameras_frame_the_bounds(void **state) {
  (void)state;
  static const float v[4][3] = {{100, 20, -5}, {160, 20, -5}, {100, 26, 3}, {160, 26, 3}};
  static const uint16_t idx[6] = {0, 1, 2, 1, 3, 2};
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_topology("long.gltf", &v[0][0], 4, idx, 6, 4), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->camera_count, 1);
  assert_string_equal(s->cameras[0].name, "default_camera");
  corners_in_view(s, 0, 96, 72);
  corners_in_view(s, 0, 192, 72);
  assert_true(corners_in_view(s, 0, 72, 72) > 0.8f); /* fitted for square and wider outputs */
  int tall = lm_scene_add_framing_camera(s, "auto", 0.5f);
  assert_int_equal(tall, 1);
  assert_true(corners_in_view(s, tall, 48, 96) > 0.8f);
  assert_true(lm_scene_camera_check(s, 0, &err));
  lm_scene_destroy(s);

  static const char ortho_json[] =
      "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0,1,2]}],"
      "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,5]},{\"camera\":1,\"translation\":[0,0,4]}],"
      "\"cameras\":[{\"name\":\"plan\",\"type\":\"orthographic\",\"orthographic\":{\"xmag\":2,\"ymag\":1.5,"
      "\"znear\":0.1,\"zfar\":10}},{\"name\":\"eye\",\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,"
      "\"znear\":0.1}}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  s = lm_scene_load_gltf(write_gltf("ortho.gltf", ortho_json, &b), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->camera_count, 2); /* the file's indices hold */
  assert_string_equal(s->cameras[1].name, "eye");
  assert_float_equal(s->cameras[0].ortho[0], 2, 0);
  assert_false(lm_scene_camera_check(s, 0, &err));
  assert_non_null(strstr(err.msg, "camera 'plan' (0) is orthographic (xmag 2, ymag 1.5)"));
  assert_true(lm_scene_camera_check(s, 1, &err));
  lm_scene_destroy(s);
}

/* glTF's metallic-roughness material comes over whole for the pbr
 * technique: factors, textures (data ones linear), KHR_texture_transform,
 * KHR_materials_emissive_strength, alpha mode and cutoff; a bad extension
 * value is named. */
static void pbr_materials_come_over(void **state) {
  (void)state;
  static const char json[] =
      "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_texture_transform\","
      "\"KHR_materials_emissive_strength\"],\"extensionsRequired\":[\"KHR_texture_transform\"],"
      "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
      "\"materials\":[{\"name\":\"lamp\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0.5,0.25,0.6],"
      "\"metallicFactor\":0.75,\"roughnessFactor\":0.4,\"baseColorTexture\":{\"index\":0,"
      "\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0,1],\"rotation\":1.5707963268,"
      "\"scale\":[0.5,0.5]}}},\"metallicRoughnessTexture\":{\"index\":0}},"
      "\"normalTexture\":{\"index\":0,\"scale\":0.5},\"occlusionTexture\":{\"index\":0,\"strength\":0.25},"
      "\"emissiveTexture\":{\"index\":0},\"emissiveFactor\":[1,0.5,0],\"alphaMode\":\"MASK\",\"alphaCutoff\":0.3,"
      "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%s}}}],"
      "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,"
      "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR4nGM4kWL0HwAFtAJeHzr7ywAAAABJRU5ErkJggg==\"}],"
      "\"buffers\":[{\"uri\":\"%%s\",\"byteLength\":%%zu}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  char text[4096];
  snprintf(text, sizeof text, json, "4");
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_gltf("pbr.gltf", text, &b), &err);
  if (!s) fail_msg("%s", err.msg);
  const lm_material *m = &s->materials[0];
  const lm_material_pbr *p = &s->material_pbr[0];
  assert_true(p->set);
  assert_float_equal(p->metallic, 0.75, 1e-6), assert_float_equal(p->roughness, 0.4, 1e-6);
  assert_float_equal(m->kd, 0.25, 1e-6); /* the std technique's view of it stays */
  assert_float_equal(m->ka, 0.25, 1e-6); /* a part-metal reflects the sky by its diffuse part too */
  assert_float_equal(p->alpha, 0.6, 1e-6);
  assert_int_equal(p->alpha_mode, LM_ALPHA_MASK);
  assert_float_equal(p->alpha_cutoff, 0.3, 1e-6);
  assert_float_equal(p->normal_scale, 0.5, 1e-6), assert_float_equal(p->occlusion_strength, 0.25, 1e-6);
  assert_float_equal(p->emissive[0], 4, 1e-6), assert_float_equal(p->emissive[1], 2, 1e-6);
  /* one image, two textures: sRGB for colour, linear for data */
  assert_int_equal(s->texture_count, 2);
  int colour = m->base_color_texture - 1, data = p->textures[LM_TEX_METALLIC_ROUGHNESS] - 1;
  assert_false(s->textures[colour].linear);
  assert_true(s->textures[data].linear);
  assert_int_equal(p->textures[LM_TEX_NORMAL] - 1, data);
  assert_int_equal(p->textures[LM_TEX_OCCLUSION] - 1, data);
  assert_int_equal(p->textures[LM_TEX_EMISSIVE] - 1, colour);
  /* uv' = T R S uv: the spec's example, the lower left quadrant turned: (1, 0) -> (0, 0.5), (0, 1) -> (0.5, 1) */
  const float *t = p->uv_transform[LM_TEX_BASE_COLOR];
  assert_float_equal(t[0] * 1 + t[2], 0, 1e-6), assert_float_equal(t[3] * 1 + t[5], 0.5, 1e-6);
  assert_float_equal(t[1] * 1 + t[2], 0.5, 1e-6), assert_float_equal(t[4] * 1 + t[5], 1, 1e-6);
  for (int k = 0; k < 6; k++) assert_float_equal(p->uv_transform[LM_TEX_NORMAL][k], 0, 0); /* none: identity */
  lm_scene_destroy(s);

  snprintf(text, sizeof text, json, "-1");
  assert_null(lm_scene_load_gltf(write_gltf("pbr.gltf", text, &b), &err));
  assert_non_null(strstr(err.msg, "material 0: KHR_materials_emissive_strength wants emissiveStrength"));
}

static const char two_prims_json[] =
    "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0,1]}],"
    "\"nodes\":[{\"name\":\"two\",\"mesh\":0},{\"name\":\"again\",\"mesh\":0,\"translation\":[5,0,0]}],"
    "\"meshes\":[{\"name\":\"pair\",\"primitives\":["
    "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3,\"material\":0},"
    "{\"attributes\":{\"POSITION\":0},\"indices\":4,\"material\":1}]}],"
    "\"materials\":[{\"name\":\"metal\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.6,0.2,1]}},"
    "{\"name\":\"plastic\",\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":1}}],"
    "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
    "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},"
    "{\"buffer\":0,\"byteOffset\":128,\"byteLength\":6},{\"buffer\":0,\"byteOffset\":136,\"byteLength\":6}],"
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
    "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
    "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
    "{\"bufferView\":3,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
    "{\"bufferView\":4,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}";

static blob two_prims_blob(void) {
  blob b = {0};
  static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  static const float nrm[12] = {0, 0, 2, 0, 0, 2, 0, 0, 2, 0, 0, 2}; /* not unit: normalized */
  static const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
  static const uint16_t i0[4] = {0, 1, 2, 0}, i1[4] = {0, 2, 3, 0};
  blob_add(&b, pos, 48), blob_add(&b, nrm, 48), blob_add(&b, uv, 32);
  blob_add(&b, i0, 8), blob_add(&b, i1, 8);
  return b;
}

static void two_primitives_become_two_meshes_and_children(void **state) {
  (void)state;
  blob b = two_prims_blob();
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_gltf("two.gltf", two_prims_json, &b), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->mesh_count, 2); /* the second node shares them */
  assert_int_equal(s->meshes[0].vertex_count, 4);
  assert_int_equal(s->meshes[1].vertex_count, 4);
  assert_int_equal(s->meshes[0].index_count, 3);
  assert_string_equal(s->meshes[0].name, "pair.0");
  /* two, two.0, two.1, again, again.0, again.1, default light and camera */
  assert_int_equal(s->node_count, 8);
  const char *names[] = {"two", "two.0", "two.1", "again", "again.0", "again.1"};
  const int parents[] = {-1, 0, 0, -1, 3, 3}, meshes[] = {-1, 0, 1, -1, 0, 1};
  for (int i = 0; i < 6; i++) {
    assert_string_equal(s->nodes[i].name, names[i]);
    assert_int_equal(s->nodes[i].parent, parents[i]);
    assert_int_equal(s->nodes[i].mesh, meshes[i]);
  }
  assert_int_equal(s->nodes[1].material, 0);
  assert_int_equal(s->nodes[2].material, 1);
  assert_int_equal(s->nodes[5].material, 1);
  assert_float_equal(s->nodes[4].world[12], 5.0, 0); /* children follow their parent */
  assert_int_equal(s->material_count, 2);
  const lm_material *metal = &s->materials[0], *plastic = &s->materials[1];
  assert_string_equal(metal->name, "metal");
  assert_float_equal(metal->kd, 0.0, 1e-6);  /* glTF's default metallic is 1 */
  assert_float_equal(metal->ks, 0.8, 1e-6);  /* F0 from the base color */
  assert_float_equal(metal->shininess, 1.0, 0); /* roughness 1 */
  assert_float_equal(metal->rho, 0.0, 1e-6);
  assert_float_equal(metal->ka, 0.0, 1e-6);  /* the sky and ambient light reflect as light does: no diffuse part */
  assert_float_equal(plastic->color[0], 1.0, 0); /* default base color */
  assert_float_equal(plastic->kd, 1.0, 1e-6);
  assert_float_equal(plastic->ka, 1.0, 1e-6);
  const float *v = s->meshes[0].vertices + 2 * 8;
  assert_float_equal(v[5], 1.0, 1e-6); /* the file's normal, normalized */
  assert_float_equal(v[6], 1.0, 0), assert_float_equal(v[7], 1.0, 0);
  lm_scene_destroy(s);
}

static void hierarchy_composes_rotated_parents(void **state) {
  (void)state;
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  const char *json =
      "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0, 3]}],"
      "\"nodes\":[{\"name\":\"parent\",\"translation\":[1,0,0],"
      "\"rotation\":[0,0,0.7071067811865476,0.7071067811865476],\"children\":[1]},"
      "{\"name\":\"child\",\"translation\":[1,0,0],\"children\":[2]},"
      "{\"name\":\"leaf\",\"mesh\":0,\"scale\":[2,2,2]},"
      "{\"name\":\"m\",\"matrix\":[2,0,0,0, 0,3,0,0, 0,0,4,0, 7,8,9,1]}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_gltf("tree.gltf", json, &b), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_string_equal(s->nodes[2].name, "leaf");
  assert_int_equal(s->nodes[1].parent, 0), assert_int_equal(s->nodes[2].parent, 1);
  assert_int_equal(s->nodes[2].material, -1); /* no material: the engine's default */
  /* The parent turns +X into +Y: the child sits at (1,0,0) + (0,1,0). */
  const float *w = s->nodes[1].world;
  assert_float_equal(w[12], 1, 1e-6), assert_float_equal(w[13], 1, 1e-6);
  assert_float_equal(w[14], 0, 1e-6);
  /* Leaf vertex (1,0,0) scaled by 2 and rotated: (1,1,0) + (0,2,0). */
  const float *l = s->nodes[2].world;
  float x = l[0] * 1 + l[12], y = l[1] * 1 + l[13];
  assert_float_equal(x, 1, 1e-5), assert_float_equal(y, 3, 1e-5);
  const float *m = s->nodes[3].world;
  assert_float_equal(m[0], 2, 0), assert_float_equal(m[5], 3, 0), assert_float_equal(m[10], 4, 0);
  assert_float_equal(m[12], 7, 0), assert_float_equal(m[13], 8, 0), assert_float_equal(m[14], 9, 0);
  lm_scene_destroy(s);
}

static const char lights_json[] =
    "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
    "{\"name\":\"spot\",\"type\":\"spot\",\"color\":[1,0.5,0.25],\"intensity\":5,\"range\":10,"
    "\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.6}},"
    "{\"name\":\"bulb\",\"type\":\"point\",\"intensity\":2},"
    "{\"name\":\"sun\",\"type\":\"directional\",\"extras\":{\"size\":0.02}}]}},"
    "\"scenes\":[{\"nodes\":[0,1,2,3,4,5]}],"
    "\"nodes\":[{\"name\":\"tri\",\"mesh\":0},"
    "{\"name\":\"spot_node\",\"translation\":[0,4,0],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
    "{\"name\":\"bulb_node\",\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
    "{\"name\":\"sun_node\",\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}},"
    "{\"name\":\"cam_node\",\"translation\":[0,0,5],\"camera\":0},"
    "{\"name\":\"far_node\",\"camera\":1}],"
    "\"cameras\":[{\"name\":\"main\",\"type\":\"perspective\",\"perspective\":"
    "{\"yfov\":0.7,\"znear\":0.05,\"zfar\":50,\"aspectRatio\":1.5}},"
    "{\"type\":\"perspective\",\"perspective\":{\"yfov\":1.0,\"znear\":0.1}}],"
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
    "\"buffers\":[{%s\"byteLength\":%zu}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";

static void assert_lights_and_cameras(const lm_scene *s) {
  assert_int_equal(s->light_count, 3);
  const lm_light *spot = &s->lights[0], *bulb = &s->lights[1], *sun = &s->lights[2];
  assert_string_equal(spot->name, "spot");
  assert_int_equal(spot->type, LM_LIGHT_SPOT);
  assert_float_equal(spot->color[1], 0.5, 1e-6);
  /* KHR_lights_punctual: candela and lux through the exposure, the range window */
  assert_float_equal(spot->power / LM_GLTF_EXPOSURE, 5, 1e-4);
  assert_int_equal(spot->falloff, LM_FALLOFF_RANGE);
  assert_float_equal(spot->radius, 10, 0);
  assert_float_equal(spot->inner_cone, 0.2, 1e-6);
  assert_float_equal(spot->outer_cone, 0.6, 1e-6);
  assert_string_equal(s->nodes[spot->node].name, "spot_node");
  assert_float_equal(s->nodes[spot->node].world[13], 4, 0);
  assert_int_equal(bulb->type, LM_LIGHT_POINT);
  assert_float_equal(bulb->color[0], 1, 0); /* default white */
  assert_float_equal(bulb->power / LM_GLTF_EXPOSURE, 2, 1e-4);
  /* No range: no window, the light reaches everywhere. */
  assert_float_equal(bulb->radius, 0, 0);
  assert_true(isinf(lm_light_reach(bulb)));
  assert_float_equal(lm_light_reach(spot), 10, 0);
  assert_int_equal(sun->type, LM_LIGHT_DIRECTIONAL);
  assert_float_equal(sun->power / LM_GLTF_EXPOSURE, 1, 1e-4);
  assert_float_equal(sun->size, 0.02, 1e-7); /* extras.size: PCSS's angular diameter */
  assert_float_equal(spot->size, 0, 0);       /* none given: the default */
  assert_int_equal(s->camera_count, 2);
  assert_string_equal(s->cameras[0].name, "main");
  assert_float_equal(s->cameras[0].fov_y, 0.7, 1e-6);
  assert_float_equal(s->cameras[0].znear, 0.05, 1e-6);
  assert_float_equal(s->cameras[0].zfar, 50, 0);
  assert_string_equal(s->nodes[s->cameras[0].node].name, "cam_node");
  assert_float_equal(s->cameras[1].zfar, LM_GLTF_INFINITE_ZFAR_RATIO * 0.1f, 1e-2);
  /* aspectRatio 1.5 is kept (for export), but a 2:1 output keeps yfov and
   * widens x, as Blender does (so Cycles references agree): not stretched to 1.5. */
  assert_float_equal(s->cameras[0].aspect, 1.5, 1e-6);
  lm_frame_data f;
  lm_scene_frame_data(s, 0, 64, 32, &f);
  float u = sqrtf(f.frustum_u[0] * f.frustum_u[0] + f.frustum_u[1] * f.frustum_u[1] + f.frustum_u[2] * f.frustum_u[2]);
  float v = sqrtf(f.frustum_v[0] * f.frustum_v[0] + f.frustum_v[1] * f.frustum_v[1] + f.frustum_v[2] * f.frustum_v[2]);
  assert_float_equal(f.clip[3], tanf(0.35f), 1e-6);
  assert_float_equal(u / v, 2, 1e-5);
}

static void lights_and_cameras_come_over(void **state) {
  (void)state;
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  char json[4096];
  snprintf(json, sizeof json, lights_json, "\"uri\":\"%s\",", (size_t)36);
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_gltf("lights.gltf", json, &b), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_lights_and_cameras(s);
  lm_scene_destroy(s);
}

static void glb_loads_like_gltf(void **state) {
  (void)state;
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  char json[4096];
  snprintf(json, sizeof json, lights_json, "", (size_t)36);
  unsigned char glb[8192];
  size_t n = make_glb(json, &b, glb, sizeof glb);
  lm_error err = {""};
  /* Told apart by the magic, so even a misnamed file loads. */
  const char *names[] = {"lights.glb", "lights_glb.gltf"};
  for (int i = 0; i < 2; i++) {
    lm_scene *s = lm_scene_load_gltf(write_bytes(names[i], glb, n), &err);
    if (!s) fail_msg("%s", err.msg);
    assert_lights_and_cameras(s);
    assert_int_equal(s->meshes[0].vertex_count, 3);
    lm_scene_destroy(s);
  }
}

static void zero_area_triangles_keep_finite_normals(void **state) {
  (void)state;
  blob b = {0};
  /* A good triangle, and two degenerate ones: collinear, and all one point. */
  static const float pos[27] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 1, 2, 2, 2,
                                3, 3, 3, 3, 3, 3, 3, 3, 3};
  blob_add(&b, pos, sizeof pos);
  const char *json =
      "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":108}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"}]}";
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_gltf("flat.gltf", json, &b), &err);
  if (!s) fail_msg("%s", err.msg);
  const lm_scene_mesh *m = &s->meshes[0];
  assert_int_equal(m->vertex_count, 9);
  assert_int_equal(m->index_count, 9); /* degenerate triangles are kept */
  for (int i = 0; i < 9; i++) {
    const float *n = m->vertices + i * 8 + 3;
    for (int k = 0; k < 3; k++) assert_true(isfinite(n[k]));
    assert_float_equal(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-5);
  }
  assert_float_equal(m->vertices[3 * 8 + 5], 1.0, 0); /* fallback +Z */
  assert_string_equal(s->nodes[0].name, "node0");
  lm_scene_destroy(s);
}

/* A .bin next to the .gltf, found from the file's directory, not the cwd. */
static void external_buffer_resolves_next_to_the_file(void **state) {
  (void)state;
  write_bytes("ext.bin", tri_pos, sizeof tri_pos);
  const char *json =
      "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"buffers\":[{\"uri\":\"ext.bin\",\"byteLength\":%d}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
  char text[1024];
  snprintf(text, sizeof text, json, 36);
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_bytes("ext.gltf", text, strlen(text)), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->meshes[0].vertex_count, 3);
  assert_float_equal(s->meshes[0].vertices[8], 1.0, 0);
  lm_scene_destroy(s);
  snprintf(text, sizeof text, json, 40); /* the file is shorter than promised */
  const char *path = write_bytes("ext_short.gltf", text, strlen(text));
  assert_null(lm_scene_load_gltf(path, &err));
  if (!strstr(err.msg, path) || !strstr(err.msg, "ext.bin")) fail_msg("%s", err.msg);
}

/* ---- bad input ---------------------------------------------------------- */

/* Loads a triangle file whose JSON has `from` replaced by `to`; expects an
 * error with the file's path and every one of `want` (NULL-terminated). */
static void expect_error(const char *name, const char *from, const char *to, const char *want[]) {
  const char *path = write_triangle(name, 5123);
  FILE *f = fopen(path, "rb");
  char text[4096];
  size_t n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[n] = '\0';
  char *at = strstr(text, from), out[4096];
  if (!at) fail_msg("test bug: '%s' not in %s", from, text);
  snprintf(out, sizeof out, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
  write_bytes(name, out, strlen(out));
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (s) fail_msg("%s: loaded, but %s -> %s should fail", name, from, to);
  if (getenv("LIMN_TEST_VERBOSE")) print_message("%s\n", err.msg);
  if (!strstr(err.msg, path)) fail_msg("message without the path: %s", err.msg);
  for (int i = 0; want[i]; i++)
    if (!strstr(err.msg, want[i])) fail_msg("message without '%s': %s", want[i], err.msg);
}

#define EXPECT(name, from, to, ...) expect_error(name, from, to, (const char *[]){__VA_ARGS__, NULL})

static void malformed_files_name_the_element(void **state) {
  (void)state;
  EXPECT("bad_json.gltf", "\"scene\":0,", "\"scene\":0,,", "");
  EXPECT("no_key.gltf", "\"meshes\"", "", "");
  EXPECT("no_buffer.gltf", "data:application/octet-stream;base64,", "missing_", "missing_");
  EXPECT("short_buffer.gltf", "\"byteLength\":42", "\"byteLength\":30", "");
  EXPECT("index_range.gltf", "\"indices\":1", "\"indices\":7",
         "mesh 0 primitive 0: indices: accessor 7 does not exist");
  EXPECT("count.gltf", "\"count\":3,\"type\":\"VEC3\"", "\"count\":4,\"type\":\"VEC3\"",
         "mesh 0 primitive 0: POSITION: accessor 0", "run past the end of bufferView 0");
  EXPECT("view.gltf", "\"byteOffset\":0,\"byteLength\":36", "\"byteOffset\":0,\"byteLength\":400",
         "mesh 0 primitive 0: POSITION: accessor 0: bufferView 0", "runs past the end of buffer 0");
  EXPECT("view_off.gltf", "\"byteOffset\":0,\"byteLength\":36",
         "\"byteOffset\":18446744073709551615,\"byteLength\":36", "");
  EXPECT("stride.gltf", "\"byteOffset\":0,\"byteLength\":36", "\"byteOffset\":0,\"byteLength\":36,\"byteStride\":8",
         "mesh 0 primitive 0: POSITION: accessor 0: bufferView 0 has byteStride 8");
  EXPECT("type.gltf", "\"type\":\"VEC3\"", "\"type\":\"VEC2\"",
         "mesh 0 primitive 0: POSITION: accessor 0 has 2 components per element, want 3");
  EXPECT("ctype.gltf", "\"componentType\":5123", "\"componentType\":5126",
         "mesh 0 primitive 0: indices: accessor 1 has component type 5126");
  EXPECT("material.gltf", "\"material\":0", "\"material\":3",
         "mesh 0 primitive 0: material 3 does not exist");
  EXPECT("mesh.gltf", "\"mesh\":0", "\"mesh\":2", "node 0: mesh 2 does not exist");
  EXPECT("child.gltf", "\"mesh\":0}", "\"mesh\":0,\"children\":[9]}", "node 0: child 9 does not exist");
  EXPECT("cycle.gltf", "\"mesh\":0}", "\"mesh\":0,\"children\":[0]}", "node 0 is reached twice");
  EXPECT("scene.gltf", "\"nodes\":[0]}", "\"nodes\":[4]}", "scene 0: node 4 does not exist");
  EXPECT("no_pos.gltf", "\"POSITION\"", "\"COLOR_0\"", "mesh 0 primitive 0: no POSITION attribute");
  EXPECT("camera.gltf", "\"mesh\":0}", "\"mesh\":0,\"camera\":0}", "node 0: camera 0 does not exist");
  EXPECT("light.gltf", "\"mesh\":0}", "\"mesh\":0,\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
         "node 0: KHR_lights_punctual light 0 does not exist");
  EXPECT("rotation.gltf", "\"mesh\":0}", "\"mesh\":0,\"rotation\":[0,0,0,0]}",
         "node 0: rotation is not a usable quaternion");
  EXPECT("matrix.gltf", "\"mesh\":0}", "\"mesh\":0,\"matrix\":[1,0,0]}", "node 0: matrix needs 16");
  EXPECT("overflow.gltf", "\"mesh\":0}", "\"mesh\":0,\"scale\":[1e5,1,1],\"children\":[1]},{\"scale\":[1e5,1,1]}",
         "node 1: world transform reaches 1e+10");
  EXPECT("flat_cam.gltf", "\"mesh\":0}",
         "\"mesh\":0,\"scale\":[0,1,1],\"children\":[1]},{\"name\":\"eye\",\"camera\":0}],"
         "\"cameras\":[{\"name\":\"c\",\"type\":\"perspective\",\"perspective\":{\"yfov\":1,\"znear\":1}}",
         "camera 'c' on node 'eye'", "cannot be inverted");
  EXPECT("bad_cam.gltf", "\"mesh\":0}",
         "\"mesh\":0,\"camera\":0}],\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":4,\"znear\":1}}",
         "camera 0: want 0 < yfov < pi");
  EXPECT("bad_light.gltf", "\"mesh\":0}",
         "\"mesh\":0,\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
         "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.9,\"outerConeAngle\":0.5}}]}},\"extras\":[0",
         "light 0: spot cone angles");
  EXPECT("bad_size.gltf", "\"mesh\":0}",
         "\"mesh\":0,\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
         "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"extras\":{\"size\":-1}}]}},\"extras\":[0",
         "light 0: extras.size must be a finite number >= 0");
  /* A light's intensity, range and colour each named with its value; negative colour and intensity times
   * colour past 1e30 (Inf in the lit target) refused with it. */
  static const struct {
    const char *file, *light, *want;
  } lights[] = {
      {"light_huge.gltf", "\"intensity\":1e30", "light 0 ('lamp'): intensity 1e+30 is not a number in [0, 1e30)"},
      {"light_range.gltf", "\"range\":-1", "light 0 ('lamp'): range -1 is not a number in [0, 1e30)"},
      {"light_neg.gltf", "\"color\":[-1,2,0]", "light 0 ('lamp'): color (-1, 2, 0) has a negative component"},
      {"light_over.gltf", "\"intensity\":1e29,\"color\":[1e30,1,1]",
       "light 0 ('lamp'): intensity 1e+29 times color 1e+30 is past 1e30"},
  };
  for (size_t i = 0; i < sizeof lights / sizeof *lights; i++) {
    char to[512];
    snprintf(to, sizeof to,
             "\"mesh\":0,\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"name\":\"lamp\",\"type\":\"point\",%s}]}},"
             "\"extras\":[0",
             lights[i].light);
    EXPECT(lights[i].file, "\"mesh\":0}", to, lights[i].want);
  }
  EXPECT("color.gltf", "[0.5,0.25,1,1]", "[0.5,0.25]", "baseColorFactor");
  EXPECT("metal.gltf", "\"metallicFactor\":0", "\"metallicFactor\":1e999", "");
  EXPECT("reflect.gltf", "\"materials\":[{", "\"materials\":[{\"extras\":{\"reflectivity\":1.5},",
         "material 0 ('material'): extras.reflectivity must be a number in [0, 1]");
  EXPECT("reflect_text.gltf", "\"materials\":[{", "\"materials\":[{\"extras\":{\"reflectivity\":\"yes\"},",
         "extras.reflectivity");
}

/* A material's extras.reflectivity comes over; without it a material is not reflective. */
static void reflectivity_comes_from_extras(void **state) {
  (void)state;
  const char *path = write_triangle("mirror.gltf", 5123);
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(path, &err);
  assert_non_null(s);
  assert_float_equal(s->materials[0].reflectivity, 0, 0);
  lm_scene_destroy(s);
  FILE *f = fopen(path, "rb");
  char text[4096], out[4200];
  size_t n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[n] = '\0';
  const char *from = "\"materials\":[{", *at = strstr(text, from);
  assert_non_null(at);
  snprintf(out, sizeof out, "%.*s%s\"extras\":{\"reflectivity\":0.8},%s", (int)(at - text), text, from, at + strlen(from));
  write_bytes("mirror.gltf", out, strlen(out));
  s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  assert_float_equal(s->materials[0].reflectivity, 0.8, 1e-6);
  lm_scene_destroy(s);
}

/* One indexed triangle: 36 bytes of positions, then 3 uint16 indices; the
 * buffer goes in as a data uri (write_gltf fills in the uri and length). */
static const char tri_indexed_json[] =
    "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],"
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
    "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%zu}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
    "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}";

/* Vertex data a JSON edit cannot reach: written into the buffer itself. */
static void bad_vertex_values_are_refused(void **state) {
  (void)state;
  static const float bad[] = {NAN, INFINITY, 1e30f, -2e9f};
  for (int i = 0; i < 4; i++) {
    blob b = {0};
    float pos[9];
    memcpy(pos, tri_pos, sizeof pos);
    pos[4] = bad[i];
    blob_add(&b, pos, sizeof pos);
    static const uint16_t idx[4] = {0, 1, 2, 0};
    blob_add(&b, idx, 8);
    lm_error err = {""};
    const char *path = write_gltf("nan.gltf", tri_indexed_json, &b);
    assert_null(lm_scene_load_gltf(path, &err));
    assert_non_null(strstr(err.msg, path));
    if (!strstr(err.msg, "mesh 0 primitive 0: POSITION: accessor 0: element 1 has a non-finite or huge value"))
      fail_msg("%s", err.msg);
  }
  /* An index past the vertices, in the buffer. */
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  static const uint16_t idx[4] = {0, 1, 3, 0};
  blob_add(&b, idx, 8);
  lm_error err = {""};
  assert_null(lm_scene_load_gltf(write_gltf("index.gltf", tri_indexed_json, &b), &err));
  if (!strstr(err.msg, "mesh 0 primitive 0: indices: index 2 is 3, past the 3 vertices"))
    fail_msg("%s", err.msg);
}

static void truncated_and_missing_files_are_refused(void **state) {
  (void)state;
  blob b = two_prims_blob();
  char json[4096];
  /* GLB wants buffer 0 without a uri: drop it from the JSON text. */
  snprintf(json, sizeof json, "%s", two_prims_json);
  char *uri = strstr(json, "\"uri\":\"%s\",");
  memmove(uri, uri + 11, strlen(uri + 11) + 1);
  char glb_json[4096];
  snprintf(glb_json, sizeof glb_json, json, b.len);
  unsigned char glb[8192];
  size_t n = make_glb(glb_json, &b, glb, sizeof glb);
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_bytes("two.glb", glb, n), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->mesh_count, 2);
  lm_scene_destroy(s);
  for (size_t cut = 0; cut < n; cut += n / 16 + 1) {
    const char *path = write_bytes("cut.glb", glb, cut);
    assert_null(lm_scene_load_gltf(path, &err));
    if (!strstr(err.msg, path)) fail_msg("%s", err.msg);
  }
  /* The same for a .gltf cut short. */
  const char *path = write_triangle("cut.gltf", 5123);
  FILE *f = fopen(path, "rb");
  char text[4096];
  size_t len = fread(text, 1, sizeof text, f);
  fclose(f);
  for (size_t cut = 0; cut < len; cut += len / 16 + 1) {
    write_bytes("cut.gltf", text, cut);
    assert_null(lm_scene_load_gltf(path, &err));
    if (!strstr(err.msg, path)) fail_msg("%s", err.msg);
  }
  const char *missing = path_of("nothing_here.gltf");
  assert_null(lm_scene_load_gltf(missing, &err));
  assert_non_null(strstr(err.msg, missing));
  assert_null(lm_scene_load_gltf(gltf_test_dir, &err)); /* a directory */
  assert_non_null(strstr(err.msg, gltf_test_dir));
}

/* ---- mutations ---------------------------------------------------------- */

/* Whatever loads must be usable: finite vertices, indices in range, world
 * transforms for every node, lights and cameras on real nodes. */
static void assert_sane(lm_scene *s) {
  for (int i = 0; i < s->mesh_count; i++) {
    const lm_scene_mesh *m = &s->meshes[i];
    for (int v = 0; v < m->vertex_count * 8; v++) assert_true(isfinite(m->vertices[v]));
    for (int k = 0; k < m->index_count; k++) assert_true(m->indices[k] < (uint32_t)m->vertex_count);
  }
  for (int i = 0; i < s->node_count; i++) {
    assert_true(s->nodes[i].parent < i);
    for (int k = 0; k < 16; k++) assert_true(isfinite(s->nodes[i].world[k]));
    assert_true(s->nodes[i].mesh < s->mesh_count);
    assert_true(s->nodes[i].material < s->material_count);
  }
  assert_true(s->light_count >= 1 && s->camera_count >= 1);
  for (int i = 0; i < s->light_count; i++)
    assert_true(s->lights[i].node >= 0 && s->lights[i].node < s->node_count);
  for (int i = 0; i < s->camera_count; i++) {
    assert_true(s->cameras[i].node >= 0 && s->cameras[i].node < s->node_count);
    assert_true(s->cameras[i].znear > 0 && s->cameras[i].zfar > s->cameras[i].znear);
  }
}

/* Two seeds: the two-primitive mesh, and the lights and cameras file. */
static size_t seed_glb(int which, unsigned char *glb, size_t cap, size_t *json_end) {
  blob b = {0};
  char json[4096], text[4096];
  if (which == 0) {
    b = two_prims_blob();
    snprintf(json, sizeof json, "%s", two_prims_json);
    char *uri = strstr(json, "\"uri\":\"%s\",");
    memmove(uri, uri + 11, strlen(uri + 11) + 1);
    snprintf(text, sizeof text, json, b.len);
  } else {
    blob_add(&b, tri_pos, sizeof tri_pos);
    snprintf(text, sizeof text, lights_json, "", (size_t)36);
  }
  *json_end = 20 + ((strlen(text) + 3) & ~(size_t)3);
  return make_glb(text, &b, glb, cap);
}

static void mutated_glb_never_crashes(void **state) {
  (void)state;
  lm_log_level level = lm_log_get_level();
  lm_log_set_level(LM_LOG_ERROR); /* skipped primitives warn */
  unsigned char glb[2][8192];
  size_t lens[2], ends[2];
  for (int i = 0; i < 2; i++) lens[i] = seed_glb(i, glb[i], sizeof glb[i], &ends[i]);
  gltf_mutation_soak((unsigned char *[]){glb[0], glb[1]}, lens, ends, 2, 600, assert_sane);
  lm_log_set_level(level);
}

/* EXT_mesh_gpu_instancing: a triangle placed three times by a node moved to
 * x = 10; each copy a child node holding the mesh, its world transform the
 * node's times its own TRS. `attrs` is the extension's attributes object;
 * accessors 1 (SCALAR, 3), 2 (TRANSLATION, 3), 3 (ROTATION, 3), 4 (SCALE, 3), 5 (ROTATION, 2). */
static const char *write_instanced(const char *name, const char *attrs) {
  static const float t[9] = {0, 0, 0, 1, 2, 3, -4, 0, 0}, sc[9] = {1, 1, 1, 2, 2, 2, 1, 1, 1};
  const float h = 0.70710678f; /* a quarter turn about z, then none, then a half turn about y */
  const float r[12] = {0, 0, h, h, 0, 0, 0, 1, 0, 1, 0, 0};
  blob b = {0};
  blob_add(&b, tri_pos, sizeof tri_pos);
  size_t ot = blob_add(&b, t, sizeof t), orr = blob_add(&b, r, sizeof r), os = blob_add(&b, sc, sizeof sc);
  char json[4096];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],"
           "\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\"],\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
           "\"nodes\":[{\"name\":\"row\",\"mesh\":0,\"translation\":[10,0,0],"
           "\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":%s}}}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
           "\"buffers\":[{\"uri\":\"%%s\",\"byteLength\":%%zu}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":48},"
           "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":36}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
           "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"},"
           "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
           "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"VEC4\"}]}",
           attrs, ot, orr, os);
  return write_gltf(name, json, &b);
}

static void gpu_instancing_places_copies(void **state) {
  (void)state;
  lm_error err = {""};
  lm_scene *s = lm_scene_load_gltf(write_instanced("inst.gltf", "{\"TRANSLATION\":2,\"ROTATION\":3,\"SCALE\":4}"), &err);
  if (!s) fail_msg("%s", err.msg);
  assert_int_equal(s->mesh_count, 1); /* the copies share it */
  assert_string_equal(s->nodes[0].name, "row");
  assert_int_equal(s->nodes[0].mesh, -1); /* the node itself draws nothing */
  /* Where each copy puts the triangle's vertex (1, 0, 0): node x 10, then the instance's TRS. */
  const float want[3][3] = {{10, 1, 0}, {10 + 1 + 2, 2, 3}, {10 - 4 - 1, 0, 0}};
  for (int i = 0; i < 3; i++) {
    const lm_node *n = &s->nodes[1 + i];
    char name[16];
    snprintf(name, sizeof name, "row[%d]", i);
    assert_string_equal(n->name, name);
    assert_int_equal(n->parent, 0);
    assert_int_equal(n->mesh, 0);
    for (int k = 0; k < 3; k++) assert_float_equal(n->world[k] + n->world[12 + k], want[i][k], 1e-5);
  }
  lm_scene_destroy(s);
  /* Bad data names the node, the extension and the attribute. */
  static const struct { const char *attrs, *want; } bad[] = {
      {"{\"TRANSLATION\":2,\"ROTATION\":5}", "attributes.ROTATION: accessor 5 has 2 elements, the other attributes 3"},
      {"{\"ROTATION\":2}", "attributes.ROTATION: accessor 2 has 3 components per element, want 4"},
      {"{\"SCALE\":9}", "attributes.SCALE: accessor 9 does not exist"},
      {"{\"SCALE\":\"4\"}", "attributes.SCALE: want an accessor index"},
      {"{\"ROTATION\":3,\"SCALE\":1}", "attributes.SCALE: accessor 1 has 1 components per element, want 3"},
      {"{\"COLOR\":2}", "attributes names none of TRANSLATION, ROTATION, SCALE"},
      {"[]", "attributes: want an object"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    const char *path = write_instanced("bad_inst.gltf", bad[i].attrs);
    s = lm_scene_load_gltf(path, &err);
    if (s) fail_msg("%s loaded", bad[i].attrs);
    if (!strstr(err.msg, path) || !strstr(err.msg, "node 0 ('row'): EXT_mesh_gpu_instancing: ") ||
        !strstr(err.msg, bad[i].want))
      fail_msg("%s: want '%s', got: %s", bad[i].attrs, bad[i].want, err.msg);
  }
}

static void names_pick_files_or_builtins(void **state) {
  (void)state;
  assert_true(lm_scene_is_gltf_name("a/b.gltf"));
  assert_true(lm_scene_is_gltf_name("B.GLB"));
  assert_false(lm_scene_is_gltf_name("cornell"));
  assert_false(lm_scene_is_gltf_name("dir.gltf/cornell"));
  lm_error err;
  lm_scene *s = lm_scene_load("cornell", &err);
  assert_non_null(s);
  lm_scene_destroy(s);
  assert_null(lm_scene_load("nope", &err));
  assert_non_null(strstr(err.msg, "unknown scene 'nope'"));
  const char *path = write_triangle("by_name.glTF", 5125);
  s = lm_scene_load(path, &err);
  assert_non_null(s);
  assert_triangle(s);
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(triangle_loads_with_every_index_type),
      cmocka_unit_test(two_primitives_become_two_meshes_and_children),
      cmocka_unit_test(strips_and_fans_become_triangles),
      cmocka_unit_test(unsupported_required_extension_is_named),
      cmocka_unit_test(cameras_frame_the_bounds),
      cmocka_unit_test(pbr_materials_come_over),
      cmocka_unit_test(hierarchy_composes_rotated_parents),
      cmocka_unit_test(lights_and_cameras_come_over),
      cmocka_unit_test(glb_loads_like_gltf),
      cmocka_unit_test(zero_area_triangles_keep_finite_normals),
      cmocka_unit_test(external_buffer_resolves_next_to_the_file),
      cmocka_unit_test(malformed_files_name_the_element),
      cmocka_unit_test(reflectivity_comes_from_extras),
      cmocka_unit_test(bad_vertex_values_are_refused),
      cmocka_unit_test(truncated_and_missing_files_are_refused),
      cmocka_unit_test(mutated_glb_never_crashes),
      cmocka_unit_test(names_pick_files_or_builtins),
      cmocka_unit_test(gpu_instancing_places_copies),
  };
  return cmocka_run_group_tests(tests, gltf_test_setup, gltf_test_teardown);
}
