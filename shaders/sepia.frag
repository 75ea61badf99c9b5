// Sepia tone (the seed viewer's F11; seed 000, lines 3048-3118): the classic
// sepia matrix, blended with the input by `strength`.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
uniform float strength = 1.0; // 0: unchanged, 1: full sepia

out vec4 dst;

void main() {
  vec3 c = hdr_clamp(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb, HALF_MAX);
  vec3 s = vec3(dot(c, vec3(0.393, 0.769, 0.189)), dot(c, vec3(0.349, 0.686, 0.168)),
                dot(c, vec3(0.272, 0.534, 0.131)));
  dst = vec4(hdr_clamp(mix(c, s, saturate(strength)), HALF_MAX), 1.0);
}
