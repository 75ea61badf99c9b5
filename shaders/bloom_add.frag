// Bloom's composite: the blurred bright pass, bilinearly enlarged, added to
// the image before tone mapping (seed 001, step 6): post.glsl's bloom_sum.
// With hdr on, its passes add the bloom as they read the image instead.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, bloom;
uniform float strength = 1.0;

out vec4 dst;

void main() {
  vec3 c = texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb; // same size: exact
  dst = vec4(bloom_sum(c, texture(bloom, uv).rgb, strength), 1.0);
}
