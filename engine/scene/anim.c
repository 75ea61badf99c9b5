/* anim: glTF animation evaluated at a time (node transforms, morph weights),
 * skinned and morphed vertices on the CPU. On the CPU rather than in a vertex
 * shader so that every pass that draws geometry, the tracer's refit and the
 * bounds that cull and frame read one posed mesh (lm_scene_mesh.vertices),
 * with the previous pose beside it for velocities. */
#include "scene/gltf.h"
#include "scene/scene_internal.h"

#include <cglm/cglm.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool lm_scene_animated(const lm_scene *s) { return s->animation_count > 0; }

int lm_scene_find_animation(const lm_scene *s, const char *spec, lm_error *err) {
  if (!strcmp(spec, "all")) return LM_ANIM_ALL;
  int found = -1, shared = 0;
  char indices[128] = ""; /* of a name several animations share: it picks none of them */
  for (int a = 0; a < s->animation_count; a++)
    if (!strcmp(s->animations[a].name, spec)) {
      if (found < 0) found = a;
      size_t n = strlen(indices);
      if (shared++ < 8) snprintf(indices + n, sizeof indices - n, "%s%d", a > found ? ", " : "", a);
    }
  if (shared > 1) {
    lm_error_set(err, "scene '%s' has several animations named '%s' (%s%s): give its index", s->name, spec, indices,
                 shared > 8 ? ", ..." : "");
    return -3;
  }
  if (found >= 0) return found;
  /* An index is digits only: strtol would take " 0" or "+0" as animation 0. */
  size_t digits = strspn(spec, "0123456789");
  long i = digits && !spec[digits] && digits < 10 ? strtol(spec, NULL, 10) : -1;
  if (i >= 0 && i < s->animation_count) return (int)i;
  char list[512] = "";
  for (int a = 0; a < s->animation_count && strlen(list) < sizeof list - LM_NAME_MAX - 8; a++)
    snprintf(list + strlen(list), sizeof list - strlen(list), "%s%d '%s'", a ? ", " : "", a, s->animations[a].name);
  lm_error_set(err, "scene '%s' has no animation '%s' (it has %s; or 'all')", s->name, spec,
               s->animation_count ? list : "none");
  return -3;
}

void lm_scene_animation_range(const lm_scene *s, int anim, float *start, float *end) {
  *start = *end = 0;
  bool any = false;
  for (int a = 0; a < s->animation_count; a++) {
    if (anim != LM_ANIM_ALL && anim != a) continue;
    if (!any || s->animations[a].start < *start) *start = s->animations[a].start;
    if (!any || s->animations[a].end > *end) *end = s->animations[a].end;
    any = true;
  }
}

/* In double, and into any float[16] (cglm's SIMD paths want aligned matrices). */
void lm_scene_trs_matrix(const float t[3], const float q[4], const float s[3], float out[16]) {
  double x = q[0], y = q[1], z = q[2], w = q[3];
  double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                 2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                 2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  for (int c = 0; c < 3; c++) {
    for (int k = 0; k < 3; k++) out[c * 4 + k] = (float)(r[c * 3 + k] * s[c]);
    out[c * 4 + 3] = 0;
  }
  for (int k = 0; k < 3; k++) out[12 + k] = t[k];
  out[15] = 1;
}

/* ---- sampling a channel ------------------------------------------------- */

/* The key interval holding t: k with times[k] <= t < times[k + 1], for
 * times[0] <= t < times[count - 1]. */
static int key_before(const float *times, int count, double t) {
  int lo = 0, hi = count - 1;
  while (hi - lo > 1) {
    int mid = lo + (hi - lo) / 2;
    if (times[mid] <= t) lo = mid;
    else hi = mid;
  }
  return lo;
}

/* Key k's value (a cubic spline's keys are in-tangent, value, out-tangent). */
static const float *key_value(const lm_anim_channel *c, int k) {
  size_t at = (size_t)(c->interp == LM_ANIM_CUBICSPLINE ? 3 * k + 1 : k);
  return c->values + at * (size_t)c->width;
}

/* q / |q| into out; false (out untouched) when |q| is zero or not finite. */
static bool normalize4(const double q[4], float out[4]) {
  double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(len > 1e-12) || !isfinite(len)) return false;
  for (int k = 0; k < 4; k++) out[k] = (float)(q[k] / len);
  return true;
}

/* Spherical linear interpolation of unit quaternions the shorter way: b is
 * flipped when a . b < 0 (q and -q are the same rotation). Not cglm's
 * glm_quat_slerp: for nearly opposite keys (q and about -q, the same
 * rotation) it falls back to lerping the unflipped pair, through zero. */
static void slerp(const float a[4], const float b[4], double u, float out[4]) {
  double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2] + (double)a[3] * b[3];
  double sign = d < 0 ? -1 : 1, wa = 1 - u, wb = u;
  d = fmin(fabs(d), 1.0);
  /* Nearly parallel: sin(angle) nears 0 and the quotients lose their
   * precision; the chord is then as good as the arc (normalized below). */
  if (d < 0.9995) {
    double angle = acos(d), sa = sin(angle);
    wa = sin((1 - u) * angle) / sa, wb = sin(u * angle) / sa;
  }
  double q[4];
  for (int k = 0; k < 4; k++) q[k] = wa * a[k] + sign * wb * b[k];
  if (!normalize4(q, out)) memcpy(out, u < 0.5 ? a : b, 4 * sizeof(float));
}

/* Channel c's value at time t into out[c->width]: glTF's interpolation, the
 * first value before the first key and the last after the last. */
static void sample(const lm_anim_channel *c, double t, float *out) {
  int n = c->count, w = c->width;
  size_t bytes = (size_t)w * sizeof(float);
  if (n <= 0) return;
  if (n == 1 || t <= c->times[0]) return (void)memcpy(out, key_value(c, 0), bytes);
  if (t >= c->times[n - 1]) return (void)memcpy(out, key_value(c, n - 1), bytes);
  int k = key_before(c->times, n, t);
  const float *a = key_value(c, k), *b = key_value(c, k + 1);
  double dt = (double)c->times[k + 1] - c->times[k]; /* > 0: the loader checked */
  double u = dt > 0 ? glm_clamp((t - c->times[k]) / dt, 0.0, 1.0) : 0;
  bool rotation = c->path == LM_ANIM_ROTATION && w == 4;
  if (c->interp == LM_ANIM_STEP) {
    memcpy(out, a, bytes);
  } else if (c->interp == LM_ANIM_LINEAR) {
    if (rotation) slerp(a, b, u, out);
    else
      for (int i = 0; i < w; i++) out[i] = (float)(a[i] + u * ((double)b[i] - a[i]));
  } else {
    /* Hermite: key k's value and out-tangent, key k+1's value and
     * in-tangent, the tangents scaled by the key interval. */
    const float *m0 = a + w, *m1 = b - w;
    double u2 = u * u, u3 = u2 * u;
    double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    double q[4] = {0}; /* w is 4 where it is read; gcc 12 under -fsanitize cannot tell (-Werror) */
    for (int i = 0; i < w; i++) {
      double v = h00 * a[i] + h10 * dt * m0[i] + h01 * b[i] + h11 * dt * m1[i];
      if (rotation) q[i] = v;
      else out[i] = (float)v;
    }
    if (rotation && !normalize4(q, out)) memcpy(out, u < 0.5 ? a : b, bytes);
  }
  /* Finite keys, but a vast tangent times a vast interval can overflow. */
  for (int i = 0; i < w; i++)
    if (!isfinite(out[i])) return (void)memcpy(out, u < 0.5 ? a : b, bytes);
}

/* ---- posing ------------------------------------------------------------- */

/* A node's pose at the time being evaluated. */
typedef struct node_pose {
  float t[3], r[4], s[3];
  float *weights; /* its morph weights (scratch); NULL: none */
  bool moved;     /* a channel of some animation moves it: local from t, r, s */
} node_pose;

/* World transforms, finite: a node that moves (or whose parent moves) and
 * whose world transform then reaches past LM_GLTF_MAX_COORD, the loader's
 * bound for rest poses (vast keys down a deep hierarchy, up to overflow),
 * loses its local transform and keeps its parent's frame, which is within
 * since parents come first. Nodes at rest are left as they are. */
static void update_bounded(lm_scene *s, const node_pose *pose) {
  bool *moving = lm_alloc(sizeof *moving * (size_t)s->node_count);
  for (int i = 0; i < s->node_count; i++) {
    int parent = s->nodes[i].parent;
    moving[i] = pose[i].moved || (parent >= 0 && parent < i && moving[parent]);
  }
  for (int from = 0;;) {
    lm_scene_update(s);
    int bad = -1;
    for (int i = from; i < s->node_count && bad < 0; i++)
      for (int k = 0; k < 16 && moving[i]; k++)
        if (!(fabsf(s->nodes[i].world[k]) <= LM_GLTF_MAX_COORD)) {
          bad = i;
          break;
        }
    if (bad < 0) break;
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(s->nodes[bad].local, identity, sizeof identity);
    from = bad + 1;
  }
  free(moving);
}

/* Skin `skin`'s joint matrices for node `node` (glTF: inverse(node world) x
 * joint world x inverse bind), column-major into jm[16 * joint_count]. */
static void joint_matrices(const lm_scene *s, const lm_skin *skin, const lm_node *node, float *jm) {
  mat4 world, inv, joint, bind, out; /* aligned copies: cglm's SIMD loads need them */
  memcpy(world, node->world, sizeof world);
  /* A node scaled to nothing has no inverse: its vertices stay in the
   * joints' frame, and its own world transform flattens them anyway. */
  if (fabsf(glm_mat4_det(world)) > 1e-30f) glm_mat4_inv(world, inv);
  else glm_mat4_identity(inv);
  for (int j = 0; j < skin->joint_count; j++) {
    int jn = skin->joints[j];
    if (jn >= 0 && jn < s->node_count) memcpy(joint, s->nodes[jn].world, sizeof joint);
    else glm_mat4_identity(joint);
    memcpy(bind, skin->inverse_bind + (size_t)j * 16, sizeof bind);
    glm_mat4_mul(joint, bind, joint);
    glm_mat4_mul(inv, joint, out);
    memcpy(jm + (size_t)j * 16, out, sizeof out);
  }
}

/* Finite and within the loader's bound for coordinates. */
static bool bounded3(const float *v) {
  return fabsf(v[0]) <= LM_GLTF_MAX_COORD && fabsf(v[1]) <= LM_GLTF_MAX_COORD && fabsf(v[2]) <= LM_GLTF_MAX_COORD;
}

/* Node n's deformed mesh posed from its rest vertices: morph targets with
 * weights w (NULL: the mesh's defaults), then the node's skin. Positions
 * that come out non-finite or past LM_GLTF_MAX_COORD, and normals that come
 * out non-finite or zero, keep their rest values. */
static void deform(lm_scene *s, const lm_node *n, const float *w) {
  lm_scene_mesh *m = &s->meshes[n->mesh];
  const lm_skin *skin = n->skin >= 0 && n->skin < s->skin_count && m->influence_sets > 0 && m->joints &&
                                m->joint_weights ? &s->skins[n->skin] : NULL;
  float *jm = NULL;
  if (skin) {
    jm = lm_alloc(sizeof *jm * 16 * (size_t)(skin->joint_count + 1));
    joint_matrices(s, skin, n, jm);
  }
  if (!w) w = m->default_weights;
  size_t vc = (size_t)m->vertex_count;
  int influences = 4 * m->influence_sets;
  vec3 lo = {FLT_MAX, FLT_MAX, FLT_MAX}, hi = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
  for (size_t v = 0; v < vc; v++) {
    const float *rest = m->rest + v * 8;
    float *out = m->vertices + v * 8;
    float p[3] = {rest[0], rest[1], rest[2]}, nr[3] = {rest[3], rest[4], rest[5]};
    for (int t = 0; t < m->target_count && w; t++) {
      if (w[t] == 0) continue;
      const float *dp = m->target_positions + ((size_t)t * vc + v) * 3;
      for (int k = 0; k < 3; k++) p[k] += w[t] * dp[k];
      if (m->target_normals) {
        const float *dn = m->target_normals + ((size_t)t * vc + v) * 3;
        for (int k = 0; k < 3; k++) nr[k] += w[t] * dn[k];
      }
    }
    if (skin) {
      /* The weighted sum of the joint matrices (their top three rows). */
      float a[4][3] = {{0}}, total = 0;
      const uint16_t *joints = m->joints + v * (size_t)influences;
      const float *weights = m->joint_weights + v * (size_t)influences;
      for (int i = 0; i < influences; i++) {
        if (!(weights[i] > 0) || joints[i] >= skin->joint_count) continue;
        const float *j = jm + (size_t)joints[i] * 16;
        for (int c = 0; c < 4; c++)
          for (int r = 0; r < 3; r++) a[c][r] += weights[i] * j[c * 4 + r];
        total += weights[i];
      }
      if (total > 0) { /* a vertex without influences stays where it is */
        float q[3], c0[3], c1[3], c2[3];
        for (int r = 0; r < 3; r++) q[r] = a[0][r] * p[0] + a[1][r] * p[1] + a[2][r] * p[2] + a[3][r];
        memcpy(p, q, sizeof p);
        /* Normals by the inverse transpose: its columns are the cross
         * products of the matrix's columns over the determinant, whose sign
         * alone matters before normalizing. */
        glm_vec3_cross(a[1], a[2], c0);
        glm_vec3_cross(a[2], a[0], c1);
        glm_vec3_cross(a[0], a[1], c2);
        float sign = glm_vec3_dot(a[0], c0) < 0 ? -1.0f : 1.0f;
        for (int r = 0; r < 3; r++) q[r] = sign * (c0[r] * nr[0] + c1[r] * nr[1] + c2[r] * nr[2]);
        memcpy(nr, q, sizeof nr);
      }
    }
    float len = sqrtf(nr[0] * nr[0] + nr[1] * nr[1] + nr[2] * nr[2]);
    if (len > 1e-20f && isfinite(len))
      for (int k = 0; k < 3; k++) out[3 + k] = nr[k] / len;
    else
      memcpy(out + 3, rest + 3, 3 * sizeof(float));
    memcpy(out, bounded3(p) ? p : rest, 3 * sizeof(float));
    glm_vec3_minv(lo, out, lo);
    glm_vec3_maxv(hi, out, hi);
  }
  if (vc) {
    glm_vec3_copy(lo, m->bounds[0]);
    glm_vec3_copy(hi, m->bounds[1]);
  }
  m->dirty = true;
  free(jm);
}

static bool plays(int anim, int a) { return anim == LM_ANIM_ALL || anim == a; }

void lm_scene_pose(lm_scene *s, int anim, double seconds) {
  if (s->node_count == 0) return;
  node_pose *pose = lm_alloc(sizeof *pose * (size_t)s->node_count);
  size_t weight_count = 0;
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->weights && n->mesh >= 0 && n->mesh < s->mesh_count) weight_count += (size_t)s->meshes[n->mesh].target_count;
  }
  float *weights = lm_alloc(sizeof *weights * (weight_count + 1)), *next = weights;
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    node_pose *p = &pose[i];
    memcpy(p->t, n->translation, sizeof p->t);
    memcpy(p->r, n->rotation, sizeof p->r);
    memcpy(p->s, n->scale, sizeof p->s);
    if (n->weights && n->mesh >= 0 && n->mesh < s->mesh_count) {
      int count = s->meshes[n->mesh].target_count;
      p->weights = memcpy(next, n->weights, sizeof *next * (size_t)count);
      next += count;
    }
  }
  /* Every node some animation moves takes its pose from its channels (or
   * its rest values), so that one animation's nodes return to rest under another. */
  for (int a = 0; a < s->animation_count; a++)
    for (int c = 0; c < s->animations[a].channel_count; c++) {
      const lm_anim_channel *ch = &s->animations[a].channels[c];
      if (ch->node < 0 || ch->node >= s->node_count) continue;
      node_pose *p = &pose[ch->node];
      if (ch->path != LM_ANIM_WEIGHTS) p->moved = true;
      if (!plays(anim, a)) continue;
      switch (ch->path) {
      case LM_ANIM_TRANSLATION:
        if (ch->width == 3) sample(ch, seconds, p->t);
        break;
      case LM_ANIM_ROTATION:
        if (ch->width == 4) sample(ch, seconds, p->r);
        break;
      case LM_ANIM_SCALE:
        if (ch->width == 3) sample(ch, seconds, p->s);
        break;
      case LM_ANIM_WEIGHTS:
        if (p->weights && ch->width == s->meshes[s->nodes[ch->node].mesh].target_count)
          sample(ch, seconds, p->weights);
        break;
      }
    }
  for (int i = 0; i < s->node_count; i++)
    if (pose[i].moved && s->nodes[i].trs) lm_scene_trs_matrix(pose[i].t, pose[i].r, pose[i].s, s->nodes[i].local);
  update_bounded(s, pose);
  for (int i = 0; i < s->node_count; i++) {
    const lm_node *n = &s->nodes[i];
    if (n->mesh >= 0 && n->mesh < s->mesh_count && s->meshes[n->mesh].rest) deform(s, n, pose[i].weights);
  }
  free(weights);
  free(pose);
}

/* A deformed mesh's positions into prev (xyz a vertex); true when any changed. */
static bool keep_positions(const lm_scene_mesh *m, float *prev) {
  bool changed = false;
  for (size_t v = 0; v < (size_t)m->vertex_count; v++)
    for (int k = 0; k < 3; k++) {
      float x = m->vertices[v * 8 + k];
      changed |= prev[v * 3 + k] != x;
      prev[v * 3 + k] = x;
    }
  return changed;
}

void lm_scene_set_time(lm_scene *s, int anim, double seconds) {
  if (anim != LM_ANIM_ALL && (anim < 0 || anim >= s->animation_count)) anim = LM_ANIM_NONE;
  if (!isfinite(seconds)) seconds = 0;
  bool first = false; /* a deformed mesh never posed here: its previous pose is its first */
  for (int i = 0; i < s->mesh_count; i++) first |= s->meshes[i].rest && !s->meshes[i].prev_positions;
  if (!first && anim == s->animation && seconds == s->time) {
    /* The same pose again: it is its own previous one (no motion). */
    for (int i = 0; i < s->mesh_count; i++)
      if (s->meshes[i].rest && keep_positions(&s->meshes[i], s->meshes[i].prev_positions)) s->meshes[i].dirty = true;
    return;
  }
  for (int i = 0; i < s->mesh_count; i++)
    if (s->meshes[i].rest && s->meshes[i].prev_positions) keep_positions(&s->meshes[i], s->meshes[i].prev_positions);
  lm_scene_pose(s, anim, seconds);
  for (int i = 0; i < s->mesh_count; i++) {
    lm_scene_mesh *m = &s->meshes[i];
    if (!m->rest || m->prev_positions) continue;
    m->prev_positions = lm_alloc(sizeof(float) * 3 * (size_t)(m->vertex_count + 1));
    keep_positions(m, m->prev_positions);
  }
  s->animation = anim;
  s->time = seconds;
}
