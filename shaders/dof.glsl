// Depth of field's circle of confusion (scripts/dof.lua), shared by the
// passes that compute it from the G-buffer's linear depth (dpt = depth /
// far; far is frame.clip.y): signed in pixels, negative in front of the
// focus, positive behind.
//   RANGE: |coc| = max_radius * saturate(|z - focus| / range)
//   LENS (thin lens, focal length f, aperture A = f / N, focused at s):
//          coc = A f (z - s) / (z (s - f)) on the sensor, in pixels
//          through the sensor height, capped at max_radius.
// The focus is clamped into [near, far] and beyond the focal length, so a
// focus on either plane, or closer than the lens can focus, stays finite.
// Lengths of 0 are relative to the view (scripts/dof.lua), so any unit gives
// the same image: focus the depth at the centre, range focus / 3, focal
// length focus / 70, sensor 2 f tan(fov_y / 2).
#ifndef LIMN_DOF_GLSL
#define LIMN_DOF_GLSL
#include "post.glsl"

uniform sampler2D dpt;
uniform float focus = 0.0;        // world units from the eye; 0: the depth at the centre
uniform float range = 0.0;        // RANGE: depth distance to full blur; 0: focus / 3
uniform float max_radius = 8.0;   // pixels, >= 0
uniform float focal_length = 0.0; // LENS: world units; 0: focus / 70 (50 mm at 3.5 m)
uniform float f_number = 2.8;     // LENS: > 0
uniform float sensor = 0.0;       // LENS: sensor height, world units; 0: from the field of view

// The focus distance: the option, or the depth at the image's centre.
float dof_focus() {
  return focus > 0.0 ? focus : eye_depth(texelFetch(dpt, textureSize(dpt, 0) / 2, 0).r);
}

// The signed circle of confusion, in full-size pixels, of eye depth z.
float dof_coc(float z, float focused) {
  float near = frame.clip.x, far = max(frame.clip.y, near);
  float tiny = near * 1e-6; // a length under anything the view resolves
  float cap = max(max_radius, 0.0);
  float c;
#ifdef LENS
  float f = max(focal_length > 0.0 ? focal_length : focused / 70.0, tiny);
  float s = clamp(focused, max(near, 1.001 * f), max(far, 1.001 * f));
  float aperture = f / max(f_number, 1e-3);
  float on_sensor = aperture * f * (z - s) / (max(z, tiny) * (s - f)); // s - f >= 0.001 f
  float height = sensor > 0.0 ? sensor : 2.0 * f * frame.clip.w;
  c = on_sensor / max(height, tiny) * frame.output_size.y;
#else
  float s = clamp(focused, near, far);
  float r = range > 0.0 ? range : s / 3.0;
  c = sign(z - s) * saturate(abs(z - s) / max(r, tiny)) * cap;
#endif
  return clamp(c, -cap, cap);
}
#endif
