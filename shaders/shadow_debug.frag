// The shadow atlas as an image: near depth dark, far light, no-occluder white.
#include "common.glsl"

in vec2 uv;
uniform sampler2D atlas;
out vec4 color;

void main() {
  float d = texture(atlas, uv).r;
  color = vec4(vec3(saturate(d)), 1.0);
}
