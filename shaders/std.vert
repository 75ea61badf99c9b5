// The "std" material technique: geometry into the G-buffer (pbr.vert too).
#include "common.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec2 in_normal;   // octahedral (lm_mesh)
layout(location = 2) in vec2 in_uv;
layout(location = 3) in mat4 instance_model;  // the node's (lm_instance: one draw, many nodes), its
                                              // mesh's dequantization included (lm_mesh_dequantize)
layout(location = 7) in mat3 instance_normal; // its inverse transpose
layout(location = 10) in vec4 in_tangent;     // glTF TANGENT; (0, 0, 0, 1) when the mesh has none

out vec3 world_normal;
out vec3 world_pos;     // for derivative tangent frames (pbr.frag)
out vec4 world_tangent; // w: the handedness, +-1, or 0 when the mesh has no tangents
out float view_depth;
out vec2 tex_uv;
#ifdef VELOCITY // the G-buffer's velocity target (velocity.glsl)
layout(location = 11) in mat4 instance_prev_model; // the node's in the previous frame
layout(location = 15) in vec4 in_prev_position;    // a deformed mesh's then; (0, 0, 0, 0): in_position
out vec4 clip_now, clip_prev;
flat out float self_moved;
#endif

void main() {
  vec4 world = instance_model * vec4(in_position, 1.0);
  world_normal = instance_normal * oct_decode(in_normal);
  world_pos = world.xyz;
  // Tangents follow the surface (the model matrix, not its inverse transpose).
  float handed = dot(in_tangent.xyz, in_tangent.xyz) > 0.0 ? (in_tangent.w < 0.0 ? -1.0 : 1.0) : 0.0;
  world_tangent = vec4(mat3(instance_model) * in_tangent.xyz, handed);
  view_depth = -(frame.view * world).z; // OpenGL looks down -z
  tex_uv = in_uv;
  gl_Position = frame.view_proj * world;
#ifdef VELOCITY
  vec3 then = in_prev_position.w > 0.0 ? in_prev_position.xyz : in_position;
  clip_now = gl_Position;
  clip_prev = frame.prev_view_proj * (instance_prev_model * vec4(then, 1.0));
  self_moved = instance_prev_model != instance_model || in_prev_position.w > 0.0 ? 1.0 : 0.0;
#endif
}
