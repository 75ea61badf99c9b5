// Adds the reflected view to the surface's own light, weighted by its
// reflectivity: POV-Ray's finish { reflection r } without energy
// conservation (engine/scene/pov.h), so the two agree.
#include "common.glsl"

in vec2 uv;
uniform sampler2D lit, refl, mat;

out vec4 dst;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float r = mat_alpha_reflectivity(texelFetch(mat, p, 0).a);
  dst = vec4(texelFetch(lit, p, 0).rgb + r * texture(refl, uv).rgb, 1.0);
}
