// The "shadow" material technique: depth from a light's point of view, one
// shadow-map tile per draw (the engine sets pass_view_proj and pass_depth).
#include "common.glsl"

layout(location = 0) in vec3 in_position;

uniform mat4 model;
uniform mat4 pass_view_proj;
uniform vec4 pass_depth; // light position, 1 / range; w = 0: orthographic

out vec3 world_pos;

void main() {
  vec4 world = model * vec4(in_position, 1.0);
  world_pos = world.xyz;
  gl_Position = pass_view_proj * world;
}
