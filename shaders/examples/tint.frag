// The tutorial's post effect (scripts/examples/tint.lua): each channel times
// its own gain, blended with the input by `strength`.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
uniform vec3 gain = vec3(1.0);  // per channel, 0..16
uniform float strength = 1.0;   // 0: unchanged, 1: the gains in full

out vec4 dst;

void main() {
  vec3 c = hdr_clamp(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb, HALF_MAX);
  dst = vec4(hdr_clamp(mix(c, c * gain, saturate(strength)), HALF_MAX), 1.0);
}
