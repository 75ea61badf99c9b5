// Ray casting buffer of the hybrid reflections (seed 003 section 6.2.6): for
// each texel of an image 1/factor of the G-buffer, the reflection ray of the
// G-buffer texel at its block's centre (as filters.glsl's geometry_at takes
// it, so the upsampling matches), where the surface is reflective. The CPU
// traces what this writes (engine/trace, the "trace" CPU pass).
#include "common.glsl"

uniform sampler2D nrm, dpt, mat; // full-size G-buffer
uniform int factor = 2;
uniform float max_distance = 0.0; // world units; 0: unlimited

layout(location = 0) out vec4 ray_o; // origin, w = 1 where a ray leaves
layout(location = 1) out vec4 ray_d; // unit direction, w = max_distance

void main() {
  int f = max(factor, 1);
  ivec2 size = textureSize(dpt, 0);
  ivec2 g = clamp(ivec2(gl_FragCoord.xy) * f + f / 2, ivec2(0), size - 1);
  float r = mat_alpha_reflectivity(texelFetch(mat, g, 0).a);
  ray_o = vec4(0.0);
  ray_d = vec4(0.0);
  if (r <= 0.0) return;
  vec3 n = gbuffer_normal_decode(texelFetch(nrm, g, 0)).xyz;
  vec3 p = position_from_depth((vec2(g) + 0.5) / vec2(size), max(texelFetch(dpt, g, 0).r, 0.0));
  vec3 to_p = p - frame.camera_pos.xyz;
  float dist = length(to_p);
  vec3 v = safe_normalize(to_p, -n);
  // Off the surface by a share of the distance to the eye: the depth buffer's
  // own error grows with it, and no unit is assumed.
  ray_o = vec4(p + n * (1e-4 * dist), 1.0);
  ray_d = vec4(reflect(v, n), max(max_distance, 0.0));
}
