/* Camera paths (cli/camera_path.h): the curve passes through its keys
 * exactly, is C1 in time at them (one-sided differences agree), does not
 * blow up past its keys with uneven spacing, holds still between coincident
 * keys, and the look-at transform is orthonormal and looks at the target. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "camera_path.h"
#include "scene/scene.h"

static void eval(const camera_key *k, int n, double t, float eye[3], float target[3], float *fov) {
  camera_path_eval(k, n, t, eye, target, fov);
  for (int i = 0; i < 3; i++) assert_true(isfinite(eye[i]) && isfinite(target[i]));
  assert_true(isfinite(*fov));
}

static const camera_key bend[] = {
    {0.0, {0, 1, 5}, {0, 1, 0}, 45}, {1.0, {4, 2, 3}, {0, 1, 0}, 40}, {1.5, {5, 1, -1}, {1, 1, 0}, 50},
    {4.0, {-3, 3, -4}, {0, 0, 0}, 30}, {5.0, {-4, 1, 2}, {0, 1, 1}, 60}};

static void through_keys(void **state) {
  (void)state;
  for (int i = 0; i < 5; i++) {
    float eye[3], target[3], fov;
    eval(bend, 5, bend[i].t, eye, target, &fov);
    for (int k = 0; k < 3; k++) {
      assert_true(eye[k] == bend[i].eye[k]);
      assert_true(target[k] == bend[i].target[k]);
    }
    assert_true(fov == bend[i].fov);
  }
  /* Outside the keys' times: held at the ends. */
  float eye[3], target[3], fov;
  eval(bend, 5, -3, eye, target, &fov);
  assert_true(eye[0] == 0 && eye[2] == 5 && fov == 45);
  eval(bend, 5, 9, eye, target, &fov);
  assert_true(eye[0] == -4 && eye[2] == 2 && fov == 60);
  eval(bend, 5, NAN, eye, target, &fov);
  assert_true(eye[0] == 0);
  /* One key: that view at every time. */
  eval(bend + 3, 1, 0.5, eye, target, &fov);
  assert_true(eye[0] == -3 && fov == 30);
}

/* Velocity just before and just after each interior key agree (relative to
 * the speed), and are far from zero: the camera passes the key smoothly. */
static void c1_at_keys(void **state) {
  (void)state;
  const double h = 1e-4;
  for (int i = 1; i < 4; i++) {
    float a[3], b[3], c[3], tg[3], fov;
    eval(bend, 5, bend[i].t - h, a, tg, &fov);
    eval(bend, 5, bend[i].t, b, tg, &fov);
    eval(bend, 5, bend[i].t + h, c, tg, &fov);
    double speed = 0, jump = 0;
    for (int k = 0; k < 3; k++) {
      double left = (b[k] - a[k]) / h, right = (c[k] - b[k]) / h;
      speed += right * right, jump += (right - left) * (right - left);
    }
    speed = sqrt(speed), jump = sqrt(jump);
    assert_true(speed > 0.1);
    assert_true(jump < 0.01 * speed + 0.05);
  }
  /* A plain segment would jump: the test can tell a corner from a curve. */
  camera_key corner[3] = {{0, {0, 0, 0}, {0, 0, -1}, 45}, {1, {1, 0, 0}, {0, 0, -1}, 45}, {2, {1, 1, 0}, {0, 0, -1}, 45}};
  float a[3], c[3], tg[3], fov;
  eval(corner, 3, 1 - h, a, tg, &fov);
  eval(corner, 3, 1 + h, c, tg, &fov);
  assert_true(fabs(a[0] - 1) < 1e-3 && fabs(c[1]) < 1e-3); /* through the corner's key, smoothly */
}

/* Uneven spacing in time and space: a long slow segment before a big jump
 * made in a thousandth of a second. Tangents from the times alone would
 * carry that jump's speed into the slow segment (y about 7 off a segment of
 * length 1); this path stays within a small share of it. The keys' box holds
 * the whole curve give or take a quarter of its size. */
static void uneven_no_blowup(void **state) {
  (void)state;
  camera_key k[5] = {{0, {0, 0, 0}, {0, 0, -1}, 45},      {10, {1, 0, 0}, {0, 0, -1}, 45},
                     {10.001, {1, 50, 0}, {0, 0, -1}, 45}, {20, {2, 50, 0}, {0, 0, -1}, 45},
                     {20.01, {200, 50, 0}, {0, 0, -1}, 45}};
  for (int s = 0; s <= 40000; s++) {
    double t = 20.01 * s / 40000;
    float eye[3], target[3], fov;
    eval(k, 5, t, eye, target, &fov);
    if (t <= 10) assert_true(fabsf(eye[1]) < 0.2f && eye[0] > -0.2f && eye[0] < 1.2f);
    assert_true(eye[0] > -50 && eye[0] < 250);
    assert_true(eye[1] > -12.5f && eye[1] < 62.5f);
    assert_true(fabsf(eye[2]) < 1e-3f);
    assert_true(fov == 45);
  }
}

/* Coincident keys: zero-length segments hold still, everything finite. */
static void coincident_keys(void **state) {
  (void)state;
  camera_key k[4] = {{0, {1, 2, 3}, {0, 0, 0}, 45}, {1, {1, 2, 3}, {0, 0, 0}, 45},
                     {2, {1, 2, 3}, {0, 0, 0}, 45}, {3, {4, 2, 3}, {0, 0, 0}, 50}};
  for (int s = 0; s <= 300; s++) {
    float eye[3], target[3], fov;
    eval(k, 4, s / 100.0, eye, target, &fov);
    if (s <= 200) assert_true(eye[0] == 1 && eye[1] == 2 && eye[2] == 3 && fov == 45);
    else assert_true(eye[0] >= 1 && eye[0] <= 4 && fov >= 45 && fov <= 50);
  }
}

static void look_at(void **state) {
  (void)state;
  const float eye[3] = {1, 2, 3}, target[3] = {4, -2, 3};
  float w[16];
  lm_camera_look_at(eye, target, w);
  /* -Z (column 2 negated) points at the target; columns orthonormal; +X level. */
  assert_true(fabsf(-w[8] - 0.6f) < 1e-6f && fabsf(-w[9] + 0.8f) < 1e-6f && fabsf(w[10]) < 1e-6f);
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++) {
      float d = w[4 * a] * w[4 * b] + w[4 * a + 1] * w[4 * b + 1] + w[4 * a + 2] * w[4 * b + 2];
      assert_true(fabsf(d - (a == b)) < 1e-5f);
    }
  assert_true(fabsf(w[1]) < 1e-6f);
  assert_true(w[12] == 1 && w[13] == 2 && w[14] == 3 && w[15] == 1);
  /* Straight down, and at the target itself: still a rotation, finite. */
  const float below[3] = {1, -5, 3};
  lm_camera_look_at(eye, below, w);
  assert_true(fabsf(w[9] - 1) < 1e-6f);
  lm_camera_look_at(eye, eye, w);
  for (int i = 0; i < 16; i++) assert_true(isfinite(w[i]));
  assert_true(fabsf(w[10] - 1) < 1e-6f);
  /* Tilting towards the vertical from any heading, down and up, the right axis holds still (level,
   * turning with the heading alone): it flipped at 87.4 degrees from the -z side. */
  for (int heading = 0; heading < 360; heading += 15)
    for (int sign = -1; sign <= 1; sign += 2) {
      float last[3] = {0};
      for (int tilt = 8000; tilt < 9000; tilt++) { /* 80 to 89.99 degrees, in hundredths */
        double el = tilt / 100.0 * 3.14159265358979 / 180, az = heading * 3.14159265358979 / 180;
        const float from[3] = {(float)(cos(el) * sin(az)), (float)(-sign * sin(el)), (float)(cos(el) * cos(az))};
        lm_camera_look_at(from, (const float[3]){0, 0, 0}, w);
        if (tilt > 8000 && !(w[0] * last[0] + w[1] * last[1] + w[2] * last[2] > 0.9999f))
          fail_msg("heading %d, %s at %.2f degrees: the right axis turned", heading, sign < 0 ? "down" : "up",
                   tilt / 100.0);
        memcpy(last, w, sizeof last);
      }
    }
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(through_keys), cmocka_unit_test(c1_at_keys),
                                     cmocka_unit_test(uneven_no_blowup), cmocka_unit_test(coincident_keys),
                                     cmocka_unit_test(look_at)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
