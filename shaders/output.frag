// The engine's output stage: no NaN, Inf or negative value leaves it, in any
// mode; out_srgb is sRGB-encoded for 8-bit files and displays. Radiance
// arrives pre-exposed (common.glsl's exposed()) and leaves as radiance, in
// the float linear output whatever half floats would have held; DISPLAY
// values (present(t, "display"): tone mapped) leave as they are.
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;

layout(location = 0) out vec4 out_srgb;
#ifdef LINEAR_OUTPUT
layout(location = 1) out vec4 out_linear;
#endif

void main() {
  vec3 c = finite_or_zero(texture(src, uv).rgb);
#ifndef DISPLAY
  c = min(c * frame.exposure.y, vec3(3e38));
#endif
  out_srgb = vec4(srgb_encode(c), 1.0);
#ifdef LINEAR_OUTPUT
  out_linear = vec4(c, 1.0);
#endif
}
