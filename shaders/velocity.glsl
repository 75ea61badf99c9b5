// The G-buffer's velocity target (VELOCITY = its output location; see
// docs/motion.md): per pixel, rg the screen motion of its surface point since
// the previous frame in output pixels (x right, y up; now minus then), b the
// point's view depth in the previous frame (0: unknown), a: 0 no surface (the
// clear; readers take the camera's motion of the far plane), 1 a surface that
// moved with the camera alone, 2 one that moved on its own (its node, or a
// deformation). std.vert passes the point's clip positions now and then
// (the node's previous model matrix, a deformed mesh's previous positions,
// the previous view-projection). A first frame (after a cut) has no motion.
#ifndef LIMN_VELOCITY_GLSL
#define LIMN_VELOCITY_GLSL
#include "common.glsl"

#ifdef VELOCITY
in vec4 clip_now, clip_prev;
flat in float self_moved; // 1: the node or its vertices moved
layout(location = VELOCITY) out vec4 out_vel;

void write_velocity() {
  vec2 motion = vec2(0.0);
  float then = 0.0;
  // Behind either eye (w <= 0) the projection means nothing: no motion known.
  if (frame.time.y < 0.5) {
    then = clip_now.w;
  } else if (clip_now.w > EPS && clip_prev.w > EPS) {
    motion = (clip_now.xy / clip_now.w - clip_prev.xy / clip_prev.w) * 0.5 * frame.output_size.xy;
    then = clip_prev.w;
  }
  // Half floats end at 65504: a motion past any screen is clamped, NaN is none.
  motion = clamp(motion, vec2(-16384.0), vec2(16384.0));
  if (any(isnan(motion))) motion = vec2(0.0);
  bool alone = self_moved > 0.5 && frame.time.y >= 0.5;
  out_vel = vec4(motion, clamp(isnan(then) ? 0.0 : then, 0.0, 65000.0), alone ? 2.0 : 1.0);
}
#else
void write_velocity() {}
#endif
#endif
