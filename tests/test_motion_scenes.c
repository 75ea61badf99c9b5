/* The scenes that move (data/gen_scenes.c) as the glTF loader reads them:
 * their nodes, cameras and lights; their animations, channels, key ranges
 * and skin; and, posed at known times, where the orbiting camera, the door,
 * the bent tube and the light are. The animation parts skip, saying why,
 * while the loader reads no animations or lm_scene_set_time is a stub
 * (tests/test_scenes_gen.sh checks the files' animation data either way).
 * Each test stands alone (it makes and frees its own), so tests read alike. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/gltf.h"

static lm_scene *load(const char *name) {
  char path[1024];
  snprintf(path, sizeof path, "%s/data/scenes/%s.glb", LIMN_SOURCE_ROOT, name);
  lm_error err;
  lm_scene *s = lm_scene_load_gltf(path, &err);
  if (!s) fail_msg("%s", err.msg);
  return s;
}

static int node(const lm_scene *s, const char *name) {
  int n = lm_scene_find_node(s, name);
  if (n < 0) fail_msg("scene '%s' has no node '%s'", s->name, name);
  return n;
}

/* Why the scene's animation cannot be checked yet (node `moving` stays put
 * between t0 and t1), or NULL. */
static const char *why_not_animated(lm_scene *s, const char *moving, double t0, double t1) {
  if (!lm_scene_animated(s)) return "the glTF loader reads no animations yet";
  int n = node(s, moving);
  float a[16], b[16];
  lm_scene_set_time(s, LM_ANIM_ALL, t0);
  memcpy(a, s->nodes[n].world, sizeof a);
  lm_scene_set_time(s, LM_ANIM_ALL, t1);
  memcpy(b, s->nodes[n].world, sizeof b);
  return memcmp(a, b, sizeof a) ? NULL : "lm_scene_set_time is still a stub";
}

static void skip_because(lm_scene *s, const char *why) {
  print_message("skipped: %s: %s\n", s->name, why);
  lm_scene_destroy(s);
  skip();
}

/* The one animation of the scene: its name, one channel on `target`. */
static const lm_anim_channel *only_channel(const lm_scene *s, const char *name, const char *target,
                                           lm_anim_path path, lm_anim_interp interp, int keys, float start,
                                           float end) {
  assert_int_equal(s->animation_count, 1);
  const lm_animation *a = &s->animations[0];
  assert_string_equal(a->name, name);
  assert_int_equal(a->channel_count, 1);
  const lm_anim_channel *c = &a->channels[0];
  assert_int_equal(c->node, node(s, target));
  assert_int_equal(c->path, path);
  assert_int_equal(c->interp, interp);
  assert_int_equal(c->count, keys);
  assert_int_equal(c->width, path == LM_ANIM_ROTATION ? 4 : 3);
  assert_float_equal(a->start, start, 0);
  assert_float_equal(a->end, end, 0);
  float lo, hi;
  assert_int_equal(lm_scene_find_animation(s, name, &(lm_error){0}), 0);
  lm_scene_animation_range(s, LM_ANIM_ALL, &lo, &hi);
  assert_float_equal(lo, start, 0);
  assert_float_equal(hi, end, 0);
  return c;
}

static void assert_near3(const float *got, float x, float y, float z, float eps) {
  if (fabsf(got[0] - x) > eps || fabsf(got[1] - y) > eps || fabsf(got[2] - z) > eps)
    fail_msg("got (%g, %g, %g), wanted (%g, %g, %g)", got[0], got[1], got[2], x, y, z);
}

/* Node n's world transform applied to the local point p. */
static void world_point(const lm_scene *s, int n, const float p[3], float out[3]) {
  const float *m = s->nodes[n].world;
  for (int i = 0; i < 3; i++) out[i] = m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i];
}

/* Camera 0 rides a pivot at the box's centre, 3.4 in front; a quarter turn a
 * second about +Y (LINEAR), so at 1 s it looks from +X at the centre. */
static void turntable_orbits(void **state) {
  (void)state;
  lm_scene *s = load("turntable");
  int cam = s->cameras[0].node, pivot = node(s, "pivot");
  assert_string_equal(s->nodes[cam].name, "orbit");
  assert_int_equal(s->nodes[cam].parent, pivot);
  assert_near3(s->nodes[cam].world + 12, 0, 1, 3.4f, 1e-5f);
  const char *why = why_not_animated(s, "orbit", 0, 1);
  if (why) {
    skip_because(s, why);
    return;
  }
  only_channel(s, "orbit", "pivot", LM_ANIM_ROTATION, LM_ANIM_LINEAR, 5, 0, 4);
  static const struct { double t; float x, z; } at[] = {{1, 3.4f, 0}, {2, 0, -3.4f}, {2.5, -2.40416f, -2.40416f},
                                                        {4, 0, 3.4f}};
  for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
    lm_scene_set_time(s, LM_ANIM_ALL, at[i].t);
    const float *m = s->nodes[cam].world;
    assert_near3(m + 12, at[i].x, 1, at[i].z, 1e-4f);
    float len = sqrtf(at[i].x * at[i].x + at[i].z * at[i].z);
    assert_near3((float[]){-m[8], -m[9], -m[10]}, -at[i].x / len, 0, -at[i].z / len, 1e-4f); /* at the centre */
  }
  lm_scene_destroy(s);
}

/* The door's free edge (1 from the hinge) swings from the doorway into the
 * room: CUBICSPLINE keys at 0.5 and 1.5 s with zero tangents, so at 1 s the
 * blend is half of each key and the normalized quaternion 45 degrees. */
static void door_swings_open(void **state) {
  (void)state;
  lm_scene *s = load("door");
  int door = node(s, "door");
  assert_int_equal(s->nodes[door].parent, node(s, "hinge"));
  bool sun = false;
  for (int i = 0; i < s->light_count; i++) sun |= s->lights[i].type == LM_LIGHT_DIRECTIONAL;
  assert_true(sun);
  const char *why = why_not_animated(s, "door", 0.5, 1.5);
  if (why) {
    skip_because(s, why);
    return;
  }
  const lm_anim_channel *c = only_channel(s, "open", "hinge", LM_ANIM_ROTATION, LM_ANIM_CUBICSPLINE, 2, 0.5f, 1.5f);
  for (int k = 0; k < 2; k++) /* zero tangents: (in, value, out) a key */
    for (int j = 0; j < 4; j++) assert_true(c->values[k * 12 + j] == 0 && c->values[k * 12 + 8 + j] == 0);
  static const struct { double t; float deg; } at[] = {{0, 0}, {0.5, 0}, {1, 45}, {1.5, 90}, {3, 90}};
  for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
    lm_scene_set_time(s, LM_ANIM_ALL, at[i].t);
    float edge[3], r = at[i].deg * 3.14159265f / 180;
    world_point(s, door, (float[]){0, 1, 1}, edge);
    assert_near3(edge, -2 + sinf(r), 1, -0.5f + cosf(r), 1e-4f);
  }
  lm_scene_destroy(s);
}

/* Two joints, base and bend (1 up); the tube's top (2 up) follows bend as it
 * turns about +Z: 45 degrees at 1 s, 90 at 2 s. Below 0.75 nothing moves. */
static void tube_bends(void **state) {
  (void)state;
  lm_scene *s = load("bending_tube");
  int tube = node(s, "tube");
  const char *why = why_not_animated(s, "bend", 0, 2);
  if (why) {
    skip_because(s, why);
    return;
  }
  only_channel(s, "bend", "bend", LM_ANIM_ROTATION, LM_ANIM_LINEAR, 3, 0, 2);
  assert_int_equal(s->skin_count, 1);
  assert_int_equal(s->skins[0].joint_count, 2);
  assert_int_equal(s->skins[0].joints[0], node(s, "base"));
  assert_int_equal(s->skins[0].joints[1], node(s, "bend"));
  assert_int_equal(s->nodes[tube].skin, 0);
  const lm_scene_mesh *m = &s->meshes[s->nodes[tube].mesh];
  assert_non_null(m->rest);
  assert_int_equal(m->influence_sets, 1);
  int top = -1, low = -1;
  for (int v = 0; v < m->vertex_count; v++) {
    const float *p = m->rest + v * 8;
    float sum = 0;
    for (int k = 0; k < 4; k++) sum += m->joint_weights[v * 4 + k];
    assert_float_equal(sum, 1, 1e-5);
    if (fabsf(p[0]) < 1e-6f && fabsf(p[2]) < 1e-6f && fabsf(p[1] - 2) < 1e-6f) top = v; /* the cap's centre */
    if (p[1] < 0.5f) low = v;
  }
  assert_true(top >= 0 && low >= 0);
  static const struct { double t; float x, y; } at[] = {{0, 0, 2}, {1, -0.70711f, 1.70711f}, {2, -1, 1}};
  for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
    lm_scene_set_time(s, LM_ANIM_ALL, at[i].t);
    float p[3];
    world_point(s, tube, m->vertices + top * 8, p);
    assert_near3(p, at[i].x, at[i].y, 0, 1e-4f);
    world_point(s, tube, m->vertices + low * 8, p);
    assert_near3(p, m->rest[low * 8], m->rest[low * 8 + 1], m->rest[low * 8 + 2], 1e-5f);
  }
  lm_scene_destroy(s);
}

/* The lamp (a point light) crosses the room 2 up: x from -1.5 to 1.5 in 3 s. */
static void light_crosses_the_room(void **state) {
  (void)state;
  lm_scene *s = load("moving_light");
  int lamp = node(s, "lamp");
  assert_int_equal(s->light_count, 1);
  assert_int_equal(s->lights[0].node, lamp);
  assert_int_equal(s->lights[0].type, LM_LIGHT_POINT);
  const char *why = why_not_animated(s, "lamp", 0, 3);
  if (why) {
    skip_because(s, why);
    return;
  }
  only_channel(s, "cross", "lamp", LM_ANIM_TRANSLATION, LM_ANIM_LINEAR, 2, 0, 3);
  static const struct { double t; float x; } at[] = {{-1, -1.5f}, {0, -1.5f}, {1.5, 0}, {2.25, 0.75f}, {3, 1.5f},
                                                     {9, 1.5f}};
  for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
    lm_scene_set_time(s, LM_ANIM_ALL, at[i].t);
    assert_near3(s->nodes[lamp].world + 12, at[i].x, 2, 0, 1e-5f);
  }
  lm_scene_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(turntable_orbits),
      cmocka_unit_test(door_swings_open),
      cmocka_unit_test(tube_bends),
      cmocka_unit_test(light_crosses_the_room),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
