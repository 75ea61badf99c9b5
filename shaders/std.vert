// The "std" material technique: geometry into the G-buffer (pbr.vert too).
#include "common.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in mat4 instance_model;  // the node's (lm_instance: one draw, many nodes)
layout(location = 7) in mat3 instance_normal; // its inverse transpose

out vec3 world_normal;
out vec3 world_pos; // for derivative tangent frames (pbr.frag)
out float view_depth;
out vec2 tex_uv;

void main() {
  vec4 world = instance_model * vec4(in_position, 1.0);
  world_normal = instance_normal * in_normal;
  world_pos = world.xyz;
  view_depth = -(frame.view * world).z; // OpenGL looks down -z
  tex_uv = in_uv;
  gl_Position = frame.view_proj * world;
}
