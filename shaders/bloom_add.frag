// Bloom's composite: the blurred bright pass, bilinearly enlarged, added to
// the image before tone mapping (seed 001, step 6). The sum is clamped under
// the half-float limit, so a very bright source cannot overflow to Inf.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, bloom;
uniform float strength = 1.0;

out vec4 dst;

void main() {
  vec3 c = hdr_clamp(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb, HALF_MAX); // same size: exact
  vec3 b = hdr_clamp(texture(bloom, uv).rgb, HALF_MAX);
  dst = vec4(hdr_clamp(c + max(strength, 0.0) * b, HALF_MAX), 1.0);
}
