/* glTF animation (engine/scene/anim.c and the loader): small files written
 * by the test (each test's document whole in it, so they read alike), posed at times whose nodes, morphed and skinned vertices are
 * computed by hand here; bad animation data refused naming the animation,
 * channel and field; nothing non-finite whatever the keys and times; the
 * tracer's refit follows deformed vertices. No GL needed. */
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
#include "trace/trace.h"

/* ---- writing files: accessors appended to a blob ------------------------ */

typedef struct doc {
  blob b;
  char views[4096], accessors[8192];
  int count;
} doc;

/* Accessor over `bytes` of p (its own bufferView): `count` elements of
 * `type` ("SCALAR", "VEC3", ...) and component type `ctype`; `extra` is
 * more JSON for it (",\"normalized\":true") or "". Returns its index. */
static int accessor(doc *d, const void *p, size_t bytes, int ctype, int count, const char *type, const char *extra) {
  size_t at = blob_add(&d->b, p, bytes);
  size_t v = strlen(d->views), a = strlen(d->accessors);
  snprintf(d->views + v, sizeof d->views - v, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}",
           d->count ? "," : "", at, bytes);
  snprintf(d->accessors + a, sizeof d->accessors - a,
           "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"%s\"%s}", d->count ? "," : "", d->count,
           ctype, count, type, extra);
  assert_true(strlen(d->accessors) + 1 < sizeof d->accessors);
  return d->count++;
}

static int floats(doc *d, const float *p, int count, const char *type) {
  int n = !strcmp(type, "SCALAR") ? 1 : !strcmp(type, "VEC3") ? 3 : !strcmp(type, "VEC4") ? 4 : 16;
  return accessor(d, p, sizeof(float) * (size_t)(count * n), 5126, count, type, "");
}

/* The file: `body` is the JSON members beside asset, buffers, bufferViews
 * and accessors ("\"scene\":0,\"scenes\":...,\"nodes\":..."). A name
 * ending in .glb writes a GLB, else JSON with a data URI. */
static const char *write_doc(const char *name, const doc *d, const char *body) {
  size_t cap = strlen(body) + strlen(d->views) + strlen(d->accessors) + 256;
  char *json = malloc(cap), buffer[64];
  bool glb = strstr(name, ".glb") != NULL;
  if (glb) snprintf(buffer, sizeof buffer, "{\"byteLength\":%zu}", d->b.len);
  else snprintf(buffer, sizeof buffer, "{\"uri\":\"%%s\",\"byteLength\":%%zu}");
  snprintf(json, cap, "{\"asset\":{\"version\":\"2.0\"},%s,\"buffers\":[%s],\"bufferViews\":[%s],\"accessors\":[%s]}", body,
           buffer, d->views, d->accessors);
  const char *path;
  if (glb) {
    size_t size = strlen(json) + d->b.len + 64;
    unsigned char *bytes = malloc(size);
    path = write_bytes(name, bytes, make_glb(json, &d->b, bytes, size));
    free(bytes);
  } else {
    path = write_gltf(name, json, &d->b);
  }
  free(json);
  return path;
}

static lm_scene *load(const char *path) {
  lm_error err = {0};
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

static const lm_node *node(const lm_scene *s, const char *name) {
  int i = lm_scene_find_node(s, name);
  if (i < 0) fail_msg("no node '%s'", name);
  return &s->nodes[i];
}

/* Vertex v of node n's mesh in world space. */
static void world_vertex(const lm_scene *s, const lm_node *n, int v, float out[3]) {
  const float *p = s->meshes[n->mesh].vertices + v * 8, *w = n->world;
  for (int k = 0; k < 3; k++) out[k] = w[k] * p[0] + w[4 + k] * p[1] + w[8 + k] * p[2] + w[12 + k];
}

static void assert_vec3(const float *got, float x, float y, float z, float eps) {
  if (fabsf(got[0] - x) > eps || fabsf(got[1] - y) > eps || fabsf(got[2] - z) > eps)
    fail_msg("got (%g, %g, %g), want (%g, %g, %g)", got[0], got[1], got[2], x, y, z);
}

static const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

/* ---- interpolation ------------------------------------------------------ */

/* Nodes a, b, c slid along x by STEP, LINEAR and CUBICSPLINE keys at times
 * 1 and 3 (animation "interp"); node d by the unnamed animation 1. */
static const char *write_interp(const char *name) {
  doc d = {0};
  static const float times[2] = {1, 3}, slide[6] = {0, 0, 0, 4, 0, 0}, d_keys[6] = {0, 0, 0, 0, 8, 0};
  /* in-tangent, value, out-tangent a key: out-tangent 1 at key 0, in-tangent 3 at key 1 */
  static const float cubic[18] = {9, 9, 9, 0, 0, 0, 1, 0, 0, 3, 0, 0, 4, 0, 0, 9, 9, 9};
  floats(&d, tri, 3, "VEC3");
  int t = floats(&d, times, 2, "SCALAR"), v = floats(&d, slide, 2, "VEC3"), c = floats(&d, cubic, 6, "VEC3");
  int dv = floats(&d, d_keys, 2, "VEC3");
  char body[2048];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3,4]}],"
           "\"nodes\":[{\"name\":\"a\"},{\"name\":\"b\"},{\"name\":\"c\",\"translation\":[0,0,0]},"
           "{\"name\":\"d\",\"translation\":[0,2,0]},{\"name\":\"tri\",\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
           "\"animations\":[{\"name\":\"interp\",\"channels\":["
           "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}},"
           "{\"sampler\":1,\"target\":{\"node\":1,\"path\":\"translation\"}},"
           "{\"sampler\":2,\"target\":{\"node\":2,\"path\":\"translation\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d,\"interpolation\":\"STEP\"},{\"input\":%d,\"output\":%d},"
           "{\"input\":%d,\"output\":%d,\"interpolation\":\"CUBICSPLINE\"}]},"
           "{\"channels\":[{\"sampler\":0,\"target\":{\"node\":3,\"path\":\"translation\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d}]}]",
           t, v, t, v, t, c, t, dv);
  return write_doc(name, &d, body);
}

static float x_of(const lm_scene *s, const char *name) { return node(s, name)->world[12]; }

static void interpolations_match_hand_values(void **state) {
  (void)state;
  lm_scene *s = load(write_interp("interp.gltf"));
  assert_int_equal(s->animation_count, 2);
  assert_string_equal(s->animations[0].name, "interp");
  assert_string_equal(s->animations[1].name, "animation 1");
  assert_int_equal(s->animations[0].channel_count, 3);
  assert_float_equal(s->animations[0].start, 1, 0), assert_float_equal(s->animations[0].end, 3, 0);
  assert_true(node(s, "a")->trs);
  struct {
    double t;
    float step, linear, cubic;
  } want[] = {
      {0, 0, 0, 0},          /* before the first key: the first value */
      {1.5, 0, 1, 0.625f},   /* u = 1/4: Hermite 0.140625 * 2 * 1 + 0.15625 * 4 - 0.046875 * 2 * 3 */
      {2, 0, 2, 1.5f},       /* u = 1/2: 0.125 * 2 * 1 + 0.5 * 4 - 0.125 * 2 * 3 */
      {2.999, 0, 3.998f, -1}, /* STEP holds key 0 until key 1's time */
      {3, 4, 4, 4},
      {10, 4, 4, 4},         /* after the last key: the last value */
  };
  for (size_t i = 0; i < sizeof want / sizeof *want; i++) {
    lm_scene_set_time(s, 0, want[i].t);
    assert_float_equal(x_of(s, "a"), want[i].step, 1e-6);
    assert_float_equal(x_of(s, "b"), want[i].linear, 1e-5);
    if (want[i].cubic >= 0) assert_float_equal(x_of(s, "c"), want[i].cubic, 1e-5);
    assert_float_equal(node(s, "d")->world[13], 2, 0); /* animation 1 does not play: d at rest */
  }
  /* "all" plays both; switching to animation 1 puts a, b, c back to rest */
  lm_scene_set_time(s, LM_ANIM_ALL, 2);
  assert_float_equal(x_of(s, "b"), 2, 1e-6);
  assert_float_equal(node(s, "d")->world[13], 4, 1e-6);
  lm_scene_set_time(s, 1, 2);
  assert_float_equal(x_of(s, "b"), 0, 0), assert_float_equal(x_of(s, "c"), 0, 0);
  assert_float_equal(node(s, "d")->world[13], 4, 1e-6);
  lm_scene_set_time(s, LM_ANIM_NONE, 2);
  assert_float_equal(node(s, "d")->world[13], 2, 0);
  assert_int_equal(s->animation, LM_ANIM_NONE);
  float lo, hi;
  lm_scene_animation_range(s, LM_ANIM_ALL, &lo, &hi);
  assert_float_equal(lo, 1, 0), assert_float_equal(hi, 3, 0);
  lm_scene_destroy(s);
}

static void animations_are_found_by_name_index_or_all(void **state) {
  (void)state;
  lm_scene *s = load(write_interp("interp.gltf"));
  lm_error err = {0};
  assert_int_equal(lm_scene_find_animation(s, "interp", &err), 0);
  assert_int_equal(lm_scene_find_animation(s, "animation 1", &err), 1);
  assert_int_equal(lm_scene_find_animation(s, "1", &err), 1);
  assert_int_equal(lm_scene_find_animation(s, "all", &err), LM_ANIM_ALL);
  assert_int_equal(lm_scene_find_animation(s, "2", &err), -3);
  assert_int_equal(lm_scene_find_animation(s, "walk", &err), -3);
  assert_non_null(strstr(err.msg, "'walk'"));
  assert_non_null(strstr(err.msg, "0 'interp'"));
  assert_non_null(strstr(err.msg, "1 'animation 1'"));
  /* An index is digits alone: " 1" and "+1" were taken as animation 1 (strtol skips spaces and signs). */
  const char *near_misses[] = {" 1", "1 ", "+1", "interp ", " all"};
  for (size_t i = 0; i < sizeof near_misses / sizeof *near_misses; i++) {
    if (lm_scene_find_animation(s, near_misses[i], &err) != -3) fail_msg("'%s' was taken", near_misses[i]);
    char quoted[32];
    snprintf(quoted, sizeof quoted, "no animation '%s'", near_misses[i]);
    assert_non_null(strstr(err.msg, quoted));
  }
  /* A name two animations share picks neither (exporters write "Take 001" twice): refused with their
   * indices, which still pick each. */
  snprintf(s->animations[1].name, sizeof s->animations[1].name, "interp");
  assert_int_equal(lm_scene_find_animation(s, "interp", &err), -3);
  assert_non_null(strstr(err.msg, "several animations named 'interp' (0, 1): give its index"));
  assert_int_equal(lm_scene_find_animation(s, "1", &err), 1);
  assert_true(lm_scene_animated(s));
  lm_scene_destroy(s);
}

/* ---- rotation ----------------------------------------------------------- */

/* r1: identity to 180 degrees about y; r2: identity to 270 degrees about y
 * (the short way is -90); r3: identity to 90 degrees, CUBICSPLINE with zero
 * tangents; r4: identity to 90 degrees in normalized shorts. Times 0, 1. */
static void rotation_takes_the_short_arc(void **state) {
  (void)state;
  doc d = {0};
  const float h = sqrtf(0.5f), times[2] = {0, 1}, half[8] = {0, 0, 0, 1, 0, 1, 0, 0}, three[8] = {0, 0, 0, 1, 0, h, 0, -h};
  const float cubic[24] = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, h, 0, h, 0, 0, 0, 0};
  const int16_t shorts[8] = {0, 0, 0, 32767, 0, 23170, 0, 23170};
  floats(&d, tri, 3, "VEC3");
  int t = floats(&d, times, 2, "SCALAR"), a = floats(&d, half, 2, "VEC4"), b = floats(&d, three, 2, "VEC4");
  int c = floats(&d, cubic, 6, "VEC4");
  int n = accessor(&d, shorts, sizeof shorts, 5122, 2, "VEC4", ",\"normalized\":true");
  char body[2048];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3]}],"
           "\"nodes\":[{\"name\":\"r1\"},{\"name\":\"r2\"},{\"name\":\"r3\"},{\"name\":\"r4\",\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
           "\"animations\":[{\"name\":\"turn\",\"channels\":["
           "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"rotation\"}},"
           "{\"sampler\":1,\"target\":{\"node\":1,\"path\":\"rotation\"}},"
           "{\"sampler\":2,\"target\":{\"node\":2,\"path\":\"rotation\"}},"
           "{\"sampler\":3,\"target\":{\"node\":3,\"path\":\"rotation\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d},{\"input\":%d,\"output\":%d},"
           "{\"input\":%d,\"output\":%d,\"interpolation\":\"CUBICSPLINE\"},{\"input\":%d,\"output\":%d}]}]",
           t, a, t, b, t, c, t, n);
  lm_scene *s = load(write_doc("turn.gltf", &d, body));
  lm_scene_set_time(s, 0, 0.5);
  /* A rotation by angle about y takes x to (cos, 0, -sin). */
  const float *w = node(s, "r1")->world;
  assert_vec3(w, 0, 0, -1, 1e-5f); /* halfway to 180: 90 degrees */
  assert_vec3(w + 8, 1, 0, 0, 1e-5f);
  for (int col = 0; col < 3; col++) /* unit quaternion: the columns keep unit length */
    assert_float_equal(sqrtf(w[col * 4] * w[col * 4] + w[col * 4 + 1] * w[col * 4 + 1] + w[col * 4 + 2] * w[col * 4 + 2]),
                       1, 1e-5);
  assert_vec3(node(s, "r2")->world, h, 0, h, 1e-5f);     /* -45 degrees, not 135 */
  assert_vec3(node(s, "r3")->world, h, 0, -h, 1e-5f);    /* normalized cubic: 45 degrees */
  lm_scene_set_time(s, 0, 1);
  assert_vec3(node(s, "r4")->world, 0, 0, -1, 1e-4f);    /* normalized shorts: 90 degrees */
  assert_vec3(node(s, "r2")->world, 0, 0, 1, 1e-5f);     /* 270 = -90 */
  lm_scene_destroy(s);
}

/* ---- morph targets ------------------------------------------------------ */

/* Mesh "plane" of two primitives (one triangle each, the second at x + 2),
 * one target each: positions + (0, 0, 2) and normals + (1, 0, -1), and
 * + (0, 0, 4); mesh weights [0.25]. Node "morph" plays animation "grow"
 * (weights 0 to 1 over times 0, 1); node "held" (at x = 10) has weights [1]. */
static const char *write_morph(const char *name) {
  doc d = {0};
  const float tri2[9] = {2, 0, 0, 3, 0, 0, 2, 1, 0}, normals[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float up2[9] = {0, 0, 2, 0, 0, 2, 0, 0, 2}, up4[9] = {0, 0, 4, 0, 0, 4, 0, 0, 4};
  const float tilt[9] = {1, 0, -1, 1, 0, -1, 1, 0, -1}, times[2] = {0, 1}, w[2] = {0, 1};
  int p0 = floats(&d, tri, 3, "VEC3"), p1 = floats(&d, tri2, 3, "VEC3"), n = floats(&d, normals, 3, "VEC3");
  int d0 = floats(&d, up2, 3, "VEC3"), dn = floats(&d, tilt, 3, "VEC3"), d1 = floats(&d, up4, 3, "VEC3");
  int t = floats(&d, times, 2, "SCALAR"), v = floats(&d, w, 2, "SCALAR");
  char body[2048];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"name\":\"morph\",\"mesh\":0},{\"name\":\"held\",\"mesh\":0,\"weights\":[1],"
           "\"translation\":[10,0,0]}],"
           "\"meshes\":[{\"name\":\"plane\",\"weights\":[0.25],\"primitives\":["
           "{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d},\"targets\":[{\"POSITION\":%d,\"NORMAL\":%d}]},"
           "{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d},\"targets\":[{\"POSITION\":%d}]}]}],"
           "\"animations\":[{\"name\":\"grow\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d}]}]",
           p0, n, d0, dn, p1, n, d1, t, v);
  return write_doc(name, &d, body);
}

static float z_of(const lm_scene *s, const char *name, int v) { return s->meshes[node(s, name)->mesh].vertices[v * 8 + 2]; }

static void morph_targets_blend_by_weight(void **state) {
  (void)state;
  lm_scene *s = load(write_morph("morph.gltf"));
  /* each node its own meshes; the weights channel drives both primitives */
  assert_int_not_equal(node(s, "morph.0")->mesh, node(s, "held.0")->mesh);
  assert_int_equal(s->animations[0].channel_count, 2);
  assert_float_equal(z_of(s, "morph.0", 1), 0.5, 1e-6); /* the mesh's weights at rest */
  assert_float_equal(z_of(s, "morph.1", 1), 1, 1e-6);
  assert_float_equal(z_of(s, "held.0", 1), 2, 1e-6);    /* the node's weights override them */
  assert_float_equal(z_of(s, "held.1", 1), 4, 1e-6);
  const lm_scene_mesh *m = &s->meshes[node(s, "morph.0")->mesh];
  assert_float_equal(m->rest[1 * 8 + 2], 0, 0);
  lm_scene_set_time(s, 0, 0.5);
  assert_float_equal(z_of(s, "morph.0", 1), 1, 1e-6);  /* weight 0.5: half the delta */
  assert_float_equal(z_of(s, "morph.1", 2), 2, 1e-6);
  assert_float_equal(z_of(s, "held.0", 1), 2, 1e-6);   /* not animated */
  const float h = sqrtf(0.5f);
  assert_vec3(m->vertices + 3, h, 0, h, 1e-6f);        /* (0, 0, 1) + 0.5 (1, 0, -1), renormalized */
  assert_float_equal(m->bounds[0][2], 1, 1e-6), assert_float_equal(m->bounds[1][2], 1, 1e-6);
  assert_true(m->dirty);
  lm_scene_set_time(s, LM_ANIM_NONE, 0);
  assert_float_equal(z_of(s, "morph.0", 1), 0.5, 1e-6);
  lm_scene_destroy(s);
}

static void prev_positions_hold_the_previous_pose(void **state) {
  (void)state;
  lm_scene *s = load(write_morph("morph.gltf"));
  const lm_scene_mesh *m = &s->meshes[node(s, "morph.0")->mesh];
  assert_null(m->prev_positions); /* never posed by lm_scene_set_time yet */
  lm_scene_set_time(s, 0, 0.4);
  assert_non_null(m->prev_positions);
  assert_float_equal(m->prev_positions[1 * 3 + 2], 0.8, 1e-6); /* the first call: the same as the pose */
  assert_float_equal(z_of(s, "morph.0", 1), 0.8, 1e-6);
  lm_scene_set_time(s, 0, 0.75);
  assert_float_equal(m->prev_positions[1 * 3 + 2], 0.8, 1e-6);
  assert_float_equal(m->prev_positions[1 * 3 + 0], 1, 0);
  assert_float_equal(z_of(s, "morph.0", 1), 1.5, 1e-6);
  lm_scene_set_time(s, 0, 0.25);
  assert_float_equal(m->prev_positions[1 * 3 + 2], 1.5, 1e-6);
  assert_float_equal(z_of(s, "morph.0", 1), 0.5, 1e-6);
  lm_scene_set_time(s, 0, 0.25); /* the same time again: no motion */
  assert_float_equal(m->prev_positions[1 * 3 + 2], 0.5, 1e-6);
  lm_scene_destroy(s);
}

/* The tracer's refit reads the posed vertices, not only node transforms. */
static void trace_refit_follows_morphed_vertices(void **state) {
  (void)state;
  lm_scene *s = load(write_morph("morph.gltf"));
  lm_trace *t = lm_trace_create(s, NULL);
  lm_trace_ray r = {.origin = {0.25f, 0.25f, 10}, .dir = {0, 0, -1}, .tmax = INFINITY};
  lm_trace_hit hit;
  assert_true(lm_trace_intersect(t, &r, &hit));
  assert_float_equal(hit.t, 9.5, 1e-5);
  lm_scene_set_time(s, 0, 1);
  lm_trace_stats st;
  lm_trace_update(t, s, &st);
  assert_true(st.refitted);
  assert_true(lm_trace_intersect(t, &r, &hit));
  assert_float_equal(hit.t, 8, 1e-5); /* weight 1: the plane at z = 2 */
  lm_trace_destroy(t);
  lm_scene_destroy(s);
}

/* ---- skins -------------------------------------------------------------- */

/* Node "skinned" (at x = 5, which skinning ignores) with a skin of joints
 * j0 (root, origin) and j1 (its child at y = 1); j1 turns 0 to 90 degrees
 * about z over times 0, 1 (animation "bend"). Vertices: 0 (0,0,0) and 5
 * (0.5,0,0) on j0; 2 (0,2,0), 3 (0,2,0), 4 (1,2,0) on j1; 1 (1,1,0) a quarter
 * each (weights summing to 0.5: normalized). Normals +x. `joints` and
 * `joint_list` let bad files change the influences and the skin. */
static const char *write_skin(const char *name, const uint8_t joints[24], const char *joint_list, int bind_count) {
  doc d = {0};
  const float pos[18] = {0, 0, 0, 1, 1, 0, 0, 2, 0, 0, 2, 0, 1, 2, 0, 0.5f, 0, 0};
  float normals[18], weights[24] = {0};
  for (int v = 0; v < 6; v++) normals[v * 3] = 1, normals[v * 3 + 1] = normals[v * 3 + 2] = 0;
  for (int v = 0; v < 6; v++) weights[v * 4] = 1;
  weights[1 * 4] = weights[1 * 4 + 1] = 0.25f;
  const float bind[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
  const float h = sqrtf(0.5f), times[2] = {0, 1}, turn[8] = {0, 0, 0, 1, 0, 0, h, h};
  int p = floats(&d, pos, 6, "VEC3"), n = floats(&d, normals, 6, "VEC3");
  int j = accessor(&d, joints, 24, 5121, 6, "VEC4", ""), w = floats(&d, weights, 6, "VEC4");
  int ib = accessor(&d, bind, sizeof(float) * 16 * (size_t)bind_count, 5126, bind_count, "MAT4", "");
  int t = floats(&d, times, 2, "SCALAR"), r = floats(&d, turn, 2, "VEC4");
  char body[2048];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"name\":\"skinned\",\"mesh\":0,\"skin\":0,\"translation\":[5,0,0]},"
           "{\"name\":\"j0\",\"children\":[2]},{\"name\":\"j1\",\"translation\":[0,1,0]},{\"name\":\"loose\"}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,\"JOINTS_0\":%d,"
           "\"WEIGHTS_0\":%d}}]}],"
           "\"skins\":[{\"name\":\"arm\",\"joints\":%s,\"inverseBindMatrices\":%d}],"
           "\"animations\":[{\"name\":\"bend\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"rotation\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d}]}]",
           p, n, j, w, joint_list, ib, t, r);
  return write_doc(name, &d, body);
}

static const uint8_t skin_joints[24] = {0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0};

static void skinned_joint_bends(void **state) {
  (void)state;
  lm_scene *s = load(write_skin("skin.gltf", skin_joints, "[1,2]", 2));
  const lm_node *n = node(s, "skinned");
  assert_int_equal(s->skin_count, 1);
  assert_int_equal(n->skin, 0);
  assert_int_equal(s->skins[0].joint_count, 2);
  const lm_scene_mesh *m = &s->meshes[n->mesh];
  assert_int_equal(m->influence_sets, 1);
  assert_float_equal(m->joint_weights[4], 0.5, 1e-6); /* 0.25 + 0.25 normalized */
  float p[3];
  /* at rest the bind pose: in world space where the file put it, whatever the node's own transform */
  world_vertex(s, n, 4, p);
  assert_vec3(p, 1, 2, 0, 1e-6f);
  assert_float_equal(m->vertices[4 * 8], -4, 1e-6); /* the mesh's own space: x - 5 */
  lm_scene_set_time(s, 0, 1); /* j1 bent 90 degrees about z: (x, y) -> (-y, x) around (0, 1) */
  world_vertex(s, n, 2, p);
  assert_vec3(p, -1, 1, 0, 1e-5f);
  world_vertex(s, n, 4, p);
  assert_vec3(p, -1, 2, 0, 1e-5f);
  world_vertex(s, n, 5, p);
  assert_vec3(p, 0.5f, 0, 0, 1e-6f); /* on j0, which stays */
  world_vertex(s, n, 1, p);
  assert_vec3(p, 0.5f, 1.5f, 0, 1e-5f); /* half (1, 1, 0), half (0, 2, 0) */
  assert_vec3(m->vertices + 2 * 8 + 3, 0, 1, 0, 1e-5f); /* +x bent to +y */
  const float h = sqrtf(0.5f);
  assert_vec3(m->vertices + 1 * 8 + 3, h, h, 0, 1e-5f); /* half the turn: 45 degrees */
  assert_vec3(m->vertices + 0 * 8 + 3, 1, 0, 0, 1e-6f);
  assert_float_equal(m->bounds[0][0], -6, 1e-5); /* bounds follow, in the mesh's space */
  lm_scene_set_time(s, 0, 0.5); /* 45 degrees */
  world_vertex(s, n, 2, p);
  assert_vec3(p, -h, 1 + h, 0, 1e-5f);
  lm_scene_destroy(s);
}

/* A 100 x 100 grid (10,000 vertices) in the xy plane built in code, skinned
 * half to joint j0 and half to j1 (at y = 1, turning about z): every pose
 * lands where the joints' rotations put it; prints what a pose costs. */
static void skinned_grid_poses_where_its_joints_say(void **state) {
  (void)state;
  enum { N = 100, VERTS = N * N };
  lm_scene *s = lm_scene_create("grid");
  float *v = calloc(VERTS * 8, sizeof(float));
  uint32_t *idx = malloc(sizeof(uint32_t) * 6 * (N - 1) * (N - 1));
  int ni = 0;
  for (int i = 0; i < VERTS; i++) {
    v[i * 8] = (float)(i % N) / (N - 1), v[i * 8 + 1] = 2.0f * (float)(i / N) / (N - 1), v[i * 8 + 3] = 1;
    if (i % N < N - 1 && i / N < N - 1) {
      const uint32_t q[6] = {0, 1, N + 1, 0, N + 1, N};
      for (int k = 0; k < 6; k++) idx[ni++] = (uint32_t)i + q[k];
    }
  }
  static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  int mesh = lm_scene_add_mesh(s, "grid", v, VERTS, idx, ni);
  int body = lm_scene_add_node(s, "body", -1, identity, mesh, -1);
  int j0 = lm_scene_add_node(s, "j0", -1, identity, -1, -1);
  float up[16];
  memcpy(up, identity, sizeof up);
  up[13] = 1;
  int j1 = lm_scene_add_node(s, "j1", j0, up, -1, -1);
  s->nodes[j1].trs = true, s->nodes[j1].translation[1] = 1;
  lm_scene_mesh *m = &s->meshes[mesh];
  m->rest = v;
  m->influence_sets = 1;
  m->joints = calloc(VERTS * 4, sizeof(uint16_t));
  m->joint_weights = calloc(VERTS * 4, sizeof(float));
  for (int i = 0; i < VERTS; i++) m->joints[i * 4] = i / N >= N / 2, m->joint_weights[i * 4] = 1;
  lm_skin *k = LM_PUSH(s->skins, s->skin_count, s->skin_cap);
  k->joint_count = 2;
  k->joints = malloc(2 * sizeof(int));
  k->joints[0] = j0, k->joints[1] = j1;
  k->inverse_bind = malloc(32 * sizeof(float));
  memcpy(k->inverse_bind, identity, sizeof identity);
  memcpy(k->inverse_bind + 16, identity, sizeof identity);
  k->inverse_bind[16 + 13] = -1;
  s->nodes[body].skin = 0;
  lm_animation *a = LM_PUSH(s->animations, s->animation_count, s->animation_cap);
  a->channels = calloc(1, sizeof *a->channels);
  a->channel_count = 1;
  a->end = 1;
  lm_anim_channel *c = &a->channels[0];
  const float times[2] = {0, 1}, turn[8] = {0, 0, 0, 1, 0, 0, 1, 0}; /* 0 to 180 degrees about z */
  *c = (lm_anim_channel){.node = j1, .path = LM_ANIM_ROTATION, .interp = LM_ANIM_LINEAR, .count = 2, .width = 4,
                         .times = memcpy(malloc(sizeof times), times, sizeof times),
                         .values = memcpy(malloc(sizeof turn), turn, sizeof turn)};
  free(idx);
  enum { POSES = 200 };
  double t0 = lm_now_ms(), c0 = lm_cpu_ms();
  for (int i = 0; i < POSES; i++) lm_scene_set_time(s, 0, (i + 1.0) / POSES);
  double ms = (lm_now_ms() - t0) / POSES, cpu = (lm_cpu_ms() - c0) / POSES;
  printf("lm_scene_set_time: %.3f ms a pose (CPU %.3f ms) of a skinned mesh of %d vertices\n", ms, cpu, VERTS);
  /* at 180 degrees j1's vertices turn about (0, 1): (x, y) -> (-x, 2 - y); j0's stay */
  for (int i = 0; i < VERTS; i++) {
    const float *p = m->vertices + i * 8, *r = m->rest + i * 8;
    bool turned = i / N >= N / 2;
    assert_float_equal(p[0], turned ? -r[0] : r[0], 1e-5);
    assert_float_equal(p[1], turned ? 2 - r[1] : r[1], 1e-5);
    assert_float_equal(p[3], turned ? -1 : 1, 1e-6); /* normals +x turn to -x */
    assert_float_equal(p[4], 0, 1e-6);
  }
  lm_scene_destroy(s);
}

/* lm_scene_add_root moves every node index up: channels and skin joints
 * follow, and the poses scale with the new root. */
static void a_root_added_above_keeps_channels_and_joints(void **state) {
  (void)state;
  const float twice[16] = {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1};
  lm_scene *s = load(write_interp("interp.gltf"));
  lm_scene_add_root(s, "unit", twice);
  lm_scene_set_time(s, 0, 2);
  assert_float_equal(x_of(s, "b"), 4, 1e-5);
  assert_float_equal(x_of(s, "c"), 3, 1e-5);
  lm_scene_destroy(s);
  s = load(write_skin("skin.gltf", skin_joints, "[1,2]", 2));
  lm_scene_add_root(s, "unit", twice);
  lm_scene_set_time(s, 0, 1);
  float p[3];
  world_vertex(s, node(s, "skinned"), 4, p);
  assert_vec3(p, -2, 4, 0, 1e-5f);
  lm_scene_destroy(s);
}

/* ---- cameras ------------------------------------------------------------ */

/* A file <name>.gltf of a camera "eye" on node 0 "cam" at (0, 0, 5) and a
 * triangle, animation `name` keying the camera node's `path` (translation,
 * scale) from values[0..2] at 0 s to values[3..5] at 1 s; loaded. */
static lm_scene *keyed_camera(const char *name, const char *path, const float values[6]) {
  doc d = {0};
  const float times[2] = {0, 1};
  floats(&d, tri, 3, "VEC3");
  int t = floats(&d, times, 2, "SCALAR"), v = floats(&d, values, 2, "VEC3");
  char body[1024], file[64];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"name\":\"cam\",\"camera\":0,\"translation\":[0,0,5]},{\"name\":\"tri\",\"mesh\":0}],"
           "\"cameras\":[{\"name\":\"eye\",\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1,\"zfar\":100}}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
           "\"animations\":[{\"name\":\"%s\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"%s\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d}]}]",
           name, path, t, v);
  snprintf(file, sizeof file, "%s.gltf", name);
  return load(write_doc(file, &d, body));
}

static void animated_camera_moves_the_view(void **state) {
  (void)state;
  lm_scene *s = keyed_camera("dolly", "translation", (const float[6]){0, 0, 5, 0, 0, 10});
  lm_frame_data f;
  lm_scene_frame_data(s, 0, 64, 48, &f);
  assert_vec3(f.camera_pos, 0, 0, 5, 1e-5f);
  lm_scene_set_time(s, 0, 0.5);
  lm_scene_frame_data(s, 0, 64, 48, &f);
  assert_vec3(f.camera_pos, 0, 0, 7.5f, 1e-5f);
  assert_float_equal(f.view[14], -7.5, 1e-5); /* the view matrix moved with it */
  lm_scene_destroy(s);
}

/* A camera keyed to scale 0 at 1 s loads (its first pose is whole) and
 * renders at 0.5 s; posed at 1 s it is refused naming camera and node, as
 * the loader refuses such a camera at rest (it rendered an empty frame). */
static void a_camera_scaled_to_zero_is_refused_at_that_pose(void **state) {
  (void)state;
  lm_scene *s = keyed_camera("shrink", "scale", (const float[6]){1, 1, 1, 0, 0, 0});
  lm_error err = {0};
  assert_true(lm_scene_camera_check(s, 0, &err));
  lm_scene_set_time(s, 0, 0.5);
  assert_true(lm_scene_camera_check(s, 0, &err));
  lm_scene_set_time(s, 0, 1);
  assert_false(lm_scene_camera_check(s, 0, &err));
  if (!strstr(err.msg, "camera 'eye' (0) on node 'cam'") || !strstr(err.msg, "zero scale"))
    fail_msg("'%s' names no camera, node or cause", err.msg);
  lm_scene_set_time(s, 0, 0.5); /* and back */
  assert_true(lm_scene_camera_check(s, 0, &err));
  lm_scene_destroy(s);
}

/* ---- bad data ----------------------------------------------------------- */

/* Animation "walk": channel 0 a good one on node "box", channel 1 the case
 * (sampler 1: `times`, `values` of `vtype`, `interp`, on node `target`'s
 * `path`). Node 1 "fixed" has a matrix, node 2 "outside" is in no scene;
 * box's mesh has one morph target. */
typedef struct bad_channel {
  const char *file;
  const float *times;
  int ntimes;
  const float *values;
  int nvalues;
  const char *vtype, *interp, *path;
  int target;
  const char *want[3]; /* besides the file, "animation 0 ('walk') channel 1" */
} bad_channel;

static const char *write_walk(const bad_channel *c) {
  doc d = {0};
  const float up[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1}, times[2] = {0, 1}, slide[6] = {0, 0, 0, 1, 0, 0};
  int p = floats(&d, tri, 3, "VEC3"), u = floats(&d, up, 3, "VEC3");
  int t = floats(&d, times, 2, "SCALAR"), v = floats(&d, slide, 2, "VEC3");
  int bt = floats(&d, c->times, c->ntimes, "SCALAR"), bv = floats(&d, c->values, c->nvalues, c->vtype);
  char body[2048];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"name\":\"box\",\"mesh\":0},{\"name\":\"fixed\",\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]},"
           "{\"name\":\"outside\"}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":%d},\"targets\":[{\"POSITION\":%d}]}]}],"
           "\"animations\":[{\"name\":\"walk\",\"channels\":["
           "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}},"
           "{\"sampler\":1,\"target\":{\"node\":%d,\"path\":\"%s\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d},{\"input\":%d,\"output\":%d,\"interpolation\":\"%s\"}]}]",
           p, u, c->target, c->path, t, v, bt, bv, c->interp);
  return write_doc(c->file, &d, body);
}

static void bad_animation_data_is_refused_by_name(void **state) {
  (void)state;
  const float t3[3] = {0, 1, 1}, t012[3] = {0, 1, 2}, t2[2] = {0, 1}, tnan[2] = {0, NAN}, v3[9] = {0}, v2[6] = {0};
  const float vnan[6] = {0, 0, 0, NAN, 0, 0}, w4[4] = {0}, q0[8] = {0};
  const bad_channel cases[] = {
      {"repeat.gltf", t3, 3, v3, 3, "VEC3", "LINEAR", "translation", 0, {"sampler 1: input", "time 2 (1) is not after time 1"}},
      {"nan_time.gltf", tnan, 2, v2, 2, "VEC3", "LINEAR", "scale", 0, {"sampler 1: input", "time 1 is not finite"}},
      {"nan_key.gltf", t2, 2, vnan, 2, "VEC3", "LINEAR", "translation", 0, {"sampler 1: output", "element 1", "non-finite"}},
      {"counts.gltf", t012, 3, v2, 2, "VEC3", "STEP", "translation", 0, {"sampler 1: output", "2 elements for the input's 3 keys"}},
      {"cubic.gltf", t2, 2, v2, 2, "VEC3", "CUBICSPLINE", "translation", 0, {"sampler 1: output", "want 6", "CUBICSPLINE"}},
      {"missing.gltf", t2, 2, v2, 2, "VEC3", "LINEAR", "translation", 9, {"target.node 9 does not exist"}},
      {"matrix.gltf", t2, 2, v2, 2, "VEC3", "LINEAR", "translation", 1, {"target.node 1 ('fixed') has a matrix"}},
      {"width.gltf", t2, 2, w4, 4, "SCALAR", "LINEAR", "weights", 0, {"sampler 1: output", "2 weights a key", "1 morph targets"}},
      {"no_targets.gltf", t2, 2, w4, 2, "SCALAR", "LINEAR", "weights", 1, {"target.node 1 ('fixed') has no mesh with morph"}},
      {"interp.gltf", t2, 2, v2, 2, "VEC3", "SMOOTH", "translation", 0, {"sampler 1: interpolation 'SMOOTH'"}},
      {"zero_q.gltf", t2, 2, q0, 2, "VEC4", "LINEAR", "rotation", 0, {"sampler 1: output", "key 0 is no rotation"}},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    const char *path = write_walk(&cases[i]);
    lm_error err = {0};
    lm_scene *s = lm_scene_load_gltf(path, &err);
    if (s) fail_msg("%s loaded", cases[i].file);
    if (!strstr(err.msg, path) || !strstr(err.msg, "animation 0 ('walk') channel 1"))
      fail_msg("%s: '%s' names no file, animation or channel", cases[i].file, err.msg);
    for (int k = 0; k < 3 && cases[i].want[k]; k++)
      if (!strstr(err.msg, cases[i].want[k])) fail_msg("%s: '%s' lacks '%s'", cases[i].file, err.msg, cases[i].want[k]);
  }
  /* skipped, with a warning: a node in no scene, a path the engine does not move */
  const bad_channel skipped[] = {
      {"outside.gltf", t2, 2, v2, 2, "VEC3", "LINEAR", "translation", 2, {0}},
      {"pointer.gltf", t2, 2, v2, 2, "VEC3", "LINEAR", "pointer", 0, {0}},
  };
  for (size_t i = 0; i < 2; i++) {
    lm_scene *s = load(write_walk(&skipped[i]));
    assert_int_equal(s->animations[0].channel_count, 1);
    lm_scene_destroy(s);
  }
}

static void bad_skins_are_refused_by_name(void **state) {
  (void)state;
  lm_error err = {0};
  uint8_t past[24];
  memcpy(past, skin_joints, sizeof past);
  past[4 * 4] = 5; /* vertex 4's first influence, weight 1 */
  const char *path = write_skin("past.gltf", past, "[1,2]", 2);
  assert_null(lm_scene_load_gltf(path, &err));
  assert_non_null(strstr(err.msg, path));
  assert_non_null(strstr(err.msg, "JOINTS_0 of vertex 4 names joint 5, past the 2 joints of skin 0"));
  path = write_skin("skin_outside.gltf", skin_joints, "[1,3]", 2);
  assert_null(lm_scene_load_gltf(path, &err));
  assert_non_null(strstr(err.msg, "skin 0 ('arm'): joints[1]: node 3 is not in the scene"));
  path = write_skin("bind.gltf", skin_joints, "[1,2]", 1);
  assert_null(lm_scene_load_gltf(path, &err));
  assert_non_null(strstr(err.msg, "skin 0 ('arm'): inverseBindMatrices: accessor 4 has 1 matrices for 2 joints"));
  char many[2048] = "[";
  for (int j = 0; j <= LM_SKIN_MAX_JOINTS; j++) snprintf(many + strlen(many), sizeof many - strlen(many), "%s1", j ? "," : "");
  strcat(many, "]");
  path = write_skin("many.gltf", skin_joints, many, 2);
  assert_null(lm_scene_load_gltf(path, &err));
  assert_non_null(strstr(err.msg, "skin 0 ('arm'): joints: 257 joints, more than the 256"));
}

/* ---- nothing non-finite ------------------------------------------------- */

/* Finite, and within the loader's bounds (so that a world position, their product, is finite too). */
static bool all_finite(const lm_scene *s) {
  for (int i = 0; i < s->node_count; i++)
    for (int k = 0; k < 16; k++)
      if (!(fabsf(s->nodes[i].world[k]) <= LM_GLTF_MAX_COORD)) return false;
  for (int i = 0; i < s->mesh_count; i++) {
    const lm_scene_mesh *m = &s->meshes[i];
    for (int k = 0; k < m->vertex_count * 8; k++)
      if (!(fabsf(m->vertices[k]) <= LM_GLTF_MAX_COORD)) return false;
    for (int k = 0; k < 6; k++)
      if (!isfinite(m->bounds[k / 3][k % 3])) return false;
  }
  return true;
}

/* Six nodes deep, each scaled up to 1e9 (the product overflows floats), and
 * a cubic whose out-tangent 1e9 times a key interval of 1e30 overflows; a
 * morph weight of 1e9. Every time, however odd, poses finite values. */
static void vast_keys_never_pose_non_finite_values(void **state) {
  (void)state;
  doc d = {0};
  const float times[2] = {0, 1}, vast[6] = {1, 1, 1, 1e9f, 1e9f, 1e9f}, far_times[2] = {0, 1e30f};
  const float cubic[18] = {0, 0, 0, 0, 0, 0, 1e9f, 1e9f, 1e9f, 0, 0, 0, 1, 0, 0, 0, 0, 0};
  const float up[9] = {0, 0, 1e9f, 0, 0, 1e9f, 0, 0, 1e9f}, w[2] = {0, 1e9f};
  int p = floats(&d, tri, 3, "VEC3"), u = floats(&d, up, 3, "VEC3");
  int t = floats(&d, times, 2, "SCALAR"), v = floats(&d, vast, 2, "VEC3");
  int ft = floats(&d, far_times, 2, "SCALAR"), c = floats(&d, cubic, 6, "VEC3"), wv = floats(&d, w, 2, "SCALAR");
  char body[4096];
  snprintf(body, sizeof body,
           "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
           "\"nodes\":[{\"name\":\"n0\",\"children\":[1]},{\"name\":\"n1\",\"children\":[2]},{\"name\":\"n2\",\"children\":[3]},"
           "{\"name\":\"n3\",\"children\":[4]},{\"name\":\"n4\",\"children\":[5]},{\"name\":\"n5\",\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":%d},\"targets\":[{\"POSITION\":%d}]}]}],"
           "\"animations\":[{\"name\":\"vast\",\"channels\":["
           "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"scale\"}},{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"scale\"}},"
           "{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"scale\"}},{\"sampler\":0,\"target\":{\"node\":3,\"path\":\"scale\"}},"
           "{\"sampler\":0,\"target\":{\"node\":4,\"path\":\"scale\"}},{\"sampler\":1,\"target\":{\"node\":5,\"path\":\"translation\"}},"
           "{\"sampler\":2,\"target\":{\"node\":5,\"path\":\"weights\"}}],"
           "\"samplers\":[{\"input\":%d,\"output\":%d},{\"input\":%d,\"output\":%d,\"interpolation\":\"CUBICSPLINE\"},"
           "{\"input\":%d,\"output\":%d}]}]",
           p, u, t, v, ft, c, t, wv);
  lm_scene *s = load(write_doc("vast.gltf", &d, body));
  const double times_to_try[] = {0, 0.5, 1, 2, 5e29, 1e30, -1e30, NAN, INFINITY, -INFINITY, 1e300};
  for (size_t i = 0; i < sizeof times_to_try / sizeof *times_to_try; i++) {
    lm_scene_set_time(s, 0, times_to_try[i]);
    if (!all_finite(s)) fail_msg("not finite at time %g", times_to_try[i]);
    lm_scene_set_time(s, LM_ANIM_ALL, times_to_try[i]);
    if (!all_finite(s)) fail_msg("not finite at time %g (all)", times_to_try[i]);
  }
  lm_scene_destroy(s);
}

/* Whatever loads poses sane: channels and joints on real nodes, and every
 * pose finite. */
static void assert_posable(lm_scene *s) {
  for (int a = 0; a < s->animation_count; a++)
    for (int c = 0; c < s->animations[a].channel_count; c++) {
      const lm_anim_channel *ch = &s->animations[a].channels[c];
      assert_true(ch->node >= 0 && ch->node < s->node_count);
      for (int k = 1; k < ch->count; k++) assert_true(ch->times[k] > ch->times[k - 1]);
    }
  for (int k = 0; k < s->skin_count; k++)
    for (int j = 0; j < s->skins[k].joint_count; j++)
      assert_true(s->skins[k].joints[j] >= 0 && s->skins[k].joints[j] < s->node_count);
  const double times[] = {-1, 0, 0.3, 1, 2.5, 1e9};
  for (size_t i = 0; i < sizeof times / sizeof *times; i++) {
    lm_scene_set_time(s, 0, times[i]);
    assert_true(all_finite(s));
    lm_scene_set_time(s, LM_ANIM_ALL, times[i]);
    assert_true(all_finite(s));
  }
}

/* The animated files as GLB, mutated (tests/gltf_test.c): refused with the
 * file named, or loaded and posable; never a crash. */
static void mutated_animations_never_crash(void **state) {
  (void)state;
  lm_log_level level = lm_log_get_level();
  lm_log_set_level(LM_LOG_ERROR); /* mended weights and skipped channels warn */
  const char *seeds[3] = {write_interp("interp.glb"), write_morph("morph.glb"),
                          write_skin("skin.glb", skin_joints, "[1,2]", 2)};
  unsigned char *glb[3];
  size_t lens[3], ends[3];
  for (int i = 0; i < 3; i++) {
    lm_error err;
    glb[i] = (unsigned char *)lm_read_file(seeds[i], &lens[i], &err);
    assert_non_null(glb[i]);
    uint32_t json_len;
    memcpy(&json_len, glb[i] + 12, 4);
    ends[i] = 20 + json_len;
    lm_scene *s = load(seeds[i]); /* the seeds themselves load */
    assert_posable(s);
    lm_scene_destroy(s);
  }
  gltf_mutation_soak(glb, lens, ends, 3, 600, assert_posable);
  for (int i = 0; i < 3; i++) free(glb[i]);
  lm_log_set_level(level);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(interpolations_match_hand_values),
      cmocka_unit_test(animations_are_found_by_name_index_or_all),
      cmocka_unit_test(rotation_takes_the_short_arc),
      cmocka_unit_test(morph_targets_blend_by_weight),
      cmocka_unit_test(prev_positions_hold_the_previous_pose),
      cmocka_unit_test(trace_refit_follows_morphed_vertices),
      cmocka_unit_test(skinned_joint_bends),
      cmocka_unit_test(skinned_grid_poses_where_its_joints_say),
      cmocka_unit_test(a_root_added_above_keeps_channels_and_joints),
      cmocka_unit_test(animated_camera_moves_the_view),
      cmocka_unit_test(a_camera_scaled_to_zero_is_refused_at_that_pose),
      cmocka_unit_test(bad_animation_data_is_refused_by_name),
      cmocka_unit_test(bad_skins_are_refused_by_name),
      cmocka_unit_test(vast_keys_never_pose_non_finite_values),
      cmocka_unit_test(mutated_animations_never_crash),
  };
  return cmocka_run_group_tests(tests, gltf_test_setup, gltf_test_teardown);
}
