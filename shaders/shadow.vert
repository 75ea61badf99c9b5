// The "shadow" material technique: depth from a light's point of view, one
// shadow-map tile per draw (the engine sets pass_view_proj and pass_depth).
// With RSM, also what a reflective shadow map stores (shadow.frag).
#include "common.glsl"

layout(location = 0) in vec3 in_position;
#if defined(RSM) || defined(ALPHA_MASK) || defined(ALPHA_BLEND)
layout(location = 2) in vec2 in_uv;
out vec2 tex_uv;
#endif
#ifdef RSM
layout(location = 1) in vec2 in_normal; // octahedral (lm_mesh)
layout(location = 7) in mat3 instance_normal; // the model matrix's inverse transpose
out vec3 world_normal;
#endif

layout(location = 3) in mat4 instance_model; // the node's (lm_instance: one draw, many nodes)
uniform mat4 pass_view_proj;
uniform vec4 pass_depth; // light position, 1 / range; w = 0: orthographic

out vec3 world_pos;

void main() {
  vec4 world = instance_model * vec4(in_position, 1.0);
  world_pos = world.xyz;
#if defined(RSM) || defined(ALPHA_MASK) || defined(ALPHA_BLEND)
  tex_uv = in_uv;
#endif
#ifdef RSM
  world_normal = instance_normal * oct_decode(in_normal);
#endif
  gl_Position = pass_view_proj * world;
}
