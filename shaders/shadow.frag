// Stores depth normalized to the light's range (not exp(c d): filtering in
// log space keeps large c finite, see esm_blur.frag).
#include "common.glsl"

in vec3 world_pos;
uniform vec4 pass_depth;

out float depth01;

void main() {
  if (pass_depth.w > 0.0) // perspective: distance from the light / range
    depth01 = saturate(length(world_pos - pass_depth.xyz) * pass_depth.w);
  else                    // orthographic: window depth is already linear
    depth01 = saturate(gl_FragCoord.z); // casters before the near plane are clamped onto it
}
