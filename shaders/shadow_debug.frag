// The shadow atlas as an image: near depth dark, far light, no-occluder white.
#include "common.glsl"

in vec2 uv;
uniform sampler2D atlas;
out vec4 color;

void main() {
  float d = abs(texture(atlas, uv).r); // negated on faces the light sees from behind (shadow.frag)
  color = vec4(vec3(saturate(d)), 1.0);
}
