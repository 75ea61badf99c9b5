/* Camera paths: centripetal Catmull-Rom through keyed views.
 *
 * Catmull-Rom with centripetal knots (knot intervals d = |P(i+1) - P(i)|^0.5)
 * neither cusps nor loops within a segment, unlike the uniform kind, where
 * keys are unevenly spaced. Its tangent at key i in the knot parameter is
 *   m(i) = (P(i) - P(i-1)) / d(i-1) - (P(i+1) - P(i-1)) / (d(i-1) + d(i)) + (P(i+1) - P(i)) / d(i)
 * and a segment is the cubic Hermite through P(i), P(i+1) with tangents
 * m(i) d(i), m(i+1) d(i). Keys come at times, not knots: a camera must move
 * without a jolt at a key, so the tangent per second at key i is m(i) times
 * the smaller of the rates d / dt on its two sides. The curve is then C1 in
 * time, equals the centripetal one where the rates agree, and its tangents
 * are never longer than the centripetal curve's (no overshoot beyond it).
 * The ends are duplicated keys: a zero interval, whose term is dropped (its
 * limit), so the path starts and ends at rest; coincident keys give zero
 * intervals too and the camera holds still between them. Hand-written: a
 * dozen lines of arithmetic that no Debian library offers in this form. */
#include "camera_path.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* A knot interval below this is a zero one (coincident keys). */
#define KNOT_EPS 1e-12

static double knot(const float *a, const float *b, int dim) {
  double d = 0;
  for (int k = 0; k < dim; k++) d += ((double)b[k] - a[k]) * ((double)b[k] - a[k]);
  return sqrt(sqrt(d)); /* |b - a|^0.5 */
}

/* Key i's value of the channel at `offset` (floats into camera_key). */
static const float *value(const camera_key *keys, int i, size_t offset) {
  return (const float *)((const char *)&keys[i] + offset);
}

/* The tangent per second at key i (0 at the ends). */
static void tangent(const camera_key *keys, int n, int i, size_t offset, int dim, double out[3]) {
  for (int k = 0; k < dim; k++) out[k] = 0;
  if (i == 0 || i == n - 1) return;
  const float *p0 = value(keys, i - 1, offset), *p1 = value(keys, i, offset), *p2 = value(keys, i + 1, offset);
  double d0 = knot(p0, p1, dim), d1 = knot(p1, p2, dim);
  double dt0 = keys[i].t - keys[i - 1].t, dt1 = keys[i + 1].t - keys[i].t;
  if (d0 < KNOT_EPS || d1 < KNOT_EPS || !(dt0 > 0) || !(dt1 > 0)) return; /* held still, or a bad key */
  double rate = fmin(d0 / dt0, d1 / dt1);
  for (int k = 0; k < dim; k++) {
    double m = ((double)p1[k] - p0[k]) / d0 - ((double)p2[k] - p0[k]) / (d0 + d1) + ((double)p2[k] - p1[k]) / d1;
    out[k] = m * rate;
  }
}

static void channel(const camera_key *keys, int n, int i, double u, size_t offset, int dim, float *out) {
  const float *a = value(keys, i, offset), *b = value(keys, i + 1, offset);
  double dt = keys[i + 1].t - keys[i].t, ta[3], tb[3];
  tangent(keys, n, i, offset, dim, ta);
  tangent(keys, n, i + 1, offset, dim, tb);
  double u2 = u * u, u3 = u2 * u;
  double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
  for (int k = 0; k < dim; k++)
    out[k] = (float)(h00 * a[k] + h10 * ta[k] * dt + h01 * b[k] + h11 * tb[k] * dt);
}

void camera_path_eval(const camera_key *keys, int n, double t, float eye[3], float target[3], float *fov) {
  int i = 0;
  while (i < n - 2 && !(t < keys[i + 1].t)) i++;
  if (n == 1 || !(t > keys[0].t) || !(t < keys[n - 1].t)) { /* outside (or NaN): the nearer end */
    const camera_key *k = n == 1 || !(t > keys[0].t) ? &keys[0] : &keys[n - 1];
    memcpy(eye, k->eye, sizeof k->eye);
    memcpy(target, k->target, sizeof k->target);
    *fov = k->fov;
    return;
  }
  double dt = keys[i + 1].t - keys[i].t, u = dt > 0 ? (t - keys[i].t) / dt : 0;
  channel(keys, n, i, u, offsetof(camera_key, eye), 3, eye);
  channel(keys, n, i, u, offsetof(camera_key, target), 3, target);
  channel(keys, n, i, u, offsetof(camera_key, fov), 1, fov);
  *fov = fminf(fmaxf(*fov, 0.1f), 179.0f); /* a field of view the projection takes */
}
