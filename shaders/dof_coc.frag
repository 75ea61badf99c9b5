// Depth of field, step 1: the signed circle of confusion in pixels (negative
// in front of the focus, positive behind) and the eye depth, from the
// G-buffer's linear depth (dpt = depth / far; far is frame.clip.y).
//   RANGE: |coc| = max_radius * saturate(|z - focus| / range)
//   LENS (thin lens, focal length f, aperture A = f / N, focused at s):
//          coc = A f (z - s) / (z (s - f)) on the sensor, in pixels
//          through the sensor height, capped at max_radius.
// The focus is clamped into [near, far] and beyond the focal length, so a
// focus on either plane, or closer than the lens can focus, stays finite.
#include "post.glsl"

in vec2 uv;
uniform sampler2D dpt;
uniform float focus = 3.5;        // world units from the eye
uniform float range = 1.0;        // RANGE: depth distance to full blur, > 0
uniform float max_radius = 8.0;   // pixels, >= 0
uniform float focal_length = 0.05;// LENS: world units (50 mm)
uniform float f_number = 2.8;     // LENS: > 0
uniform float sensor = 0.024;     // LENS: sensor height in world units (24 mm)

out vec4 coc;

void main() {
  float z = eye_depth(texture(dpt, uv).r);
  float near = max(frame.clip.x, EPS), far = max(frame.clip.y, near);
  float cap = max(max_radius, 0.0);
  float c;
#ifdef LENS
  float f = max(focal_length, 1e-6);
  float s = clamp(focus, max(near, 1.001 * f), max(far, 1.001 * f));
  float aperture = f / max(f_number, 1e-3);
  float on_sensor = aperture * f * (z - s) / (max(z, EPS) * (s - f)); // s - f >= 0.001 f
  c = on_sensor / max(sensor, 1e-6) * frame.output_size.y;
#else
  float s = clamp(focus, near, far);
  c = sign(z - s) * saturate(abs(z - s) / max(range, 1e-6)) * cap;
#endif
  coc = vec4(clamp(c, -cap, cap), z, 0.0, 0.0);
}
