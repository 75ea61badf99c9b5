/* Camera paths of capture jobs (cli/job.c): keyed views (eye, target,
 * vertical field of view at times) interpolated smoothly for fly-throughs,
 * and the look-at transform that turns a view into a camera node's world. */
#ifndef LIMN_CAMERA_PATH_H
#define LIMN_CAMERA_PATH_H

typedef struct camera_key {
  double t;            /* seconds; strictly increasing along a path */
  float eye[3], target[3];
  float fov;           /* vertical, degrees */
} camera_key;

/* The view at `t` on the path through keys[0 .. n-1] (n >= 1): eye, target
 * and fov each on a centripetal Catmull-Rom curve (alpha 0.5), held at the
 * first and last key outside their times. Always finite from finite keys. */
void camera_path_eval(const camera_key *keys, int n, double t, float eye[3], float target[3], float *fov);

#endif
